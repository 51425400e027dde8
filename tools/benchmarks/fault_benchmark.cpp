// Tooth-fault benchmarks (issue 12; Google Benchmark, Release build):
//   (a) lumped: the potential-energy TVMS table of seed 001's sun-planet pair (18/34, m_n 1.5 mm,
//       21.3 deg, 30 mm; 200 samples per mesh period): one healthy period, and a whole planet
//       revolution (18 periods) healthy, with a broken tooth, a Chen-Shao crack front and a spall
//       at 1429 N; and the per-step cost of the lumped mesh's table look-ups (MeshStiffness +
//       MeshTransmissionError, mbd/gear_mesh.h) against the constant-stiffness mesh;
//   (b) flexible: the seed 003 planet of models/bodies/seed003_planet.yaml (14 teeth, m_n 4 mm,
//       22.5 deg, 40 mm, coarse hex20) meshed and reduced (bore RBE2, 24 modes) healthy, with a
//       broken tooth (half height, whole width) and with a root crack (with its healthy twin of
//       the same, finer division across the tooth).
//
//   fault_benchmark                                  all (about half a minute)
//   fault_benchmark --benchmark_filter=Tvms
#include <benchmark/benchmark.h>

#include <numbers>
#include <vector>

#include "flex/craig_bampton.h"
#include "flex/fe_assembly.h"
#include "flex/fe_interface.h"
#include "mbd/gear_mesh.h"
#include "mbd/model.h"
#include "models/gear_fe_mesh.h"
#include "models/mesh_stiffness.h"

namespace orrery {
namespace {

constexpr double kDeg = std::numbers::pi / 180;

// ---- (a) Lumped -----------------------------------------------------------------------------

gears::GearPair SunPlanet() {
  auto spec = [](int z) {
    return gears::GearSpec{.teeth = z, .normal_module_m = 1.5e-3, .normal_pressure_angle_rad = 21.3 * kDeg,
                           .face_width_m = 0.03};
  };
  return gears::GearPair(gears::Gear(spec(18)), gears::Gear(spec(34)));
}

// Arg: 0 one healthy period, 1 a healthy revolution, 2 broken, 3 crack, 4 spall.
void BM_TvmsTable(benchmark::State& st) {
  using gears::ToothFaultSpec;
  const gears::GearPair pair = SunPlanet();
  gears::TvmsOptions o{.bore_radius1_m = 6e-3, .rim_radius2_m = 10e-3, .samples_per_period = 200};
  const double s0 = pair.contact_start_m(), s1 = pair.contact_end_m();
  const char* labels[] = {"healthy period", "healthy revolution", "broken tooth", "crack front", "spall at 1429 N"};
  switch (st.range(0)) {
    case 1: o.periods = 18; break;
    case 2: o.faults = {{1, {.kind = ToothFaultSpec::Kind::kBrokenTooth, .tooth = 0, .height_fraction = 0.5}}}; break;
    case 3:
      o.faults = {{1, {.kind = ToothFaultSpec::Kind::kRootCrack, .tooth = 0, .crack_depth_m = 1e-3,
                       .crack_angle_rad = 45 * kDeg, .crack_end_depth_m = 0.0}}};
      break;
    case 4:
      o.faults = {{1, {.kind = ToothFaultSpec::Kind::kSpall, .tooth = 0, .roll_start_m = s0 + 0.3 * (s1 - s0),
                       .roll_end_m = s0 + 0.6 * (s1 - s0), .axial_start_m = 0.01, .axial_end_m = 0.02,
                       .depth_m = 20e-6}}};
      o.load_n = 1429;
      break;
    default: break;
  }
  gears::Tvms t;
  for (auto _ : st) t = gears::CalcTvms(pair, o);
  st.SetLabel(labels[st.range(0)]);
  st.counters["samples"] = double(t.stiffness_n_per_m.size());
  st.counters["slices"] = t.slices;
}
BENCHMARK(BM_TvmsTable)->DenseRange(0, 4)->Unit(benchmark::kMillisecond);

// Per step of a lumped mesh: stiffness and static TE at a mesh phase. Arg 0: constant stiffness,
// 1: tables over a revolution (18 x 200 samples) with a TE table.
void BM_LumpedMeshLookup(benchmark::State& st) {
  GearMeshSpec s;
  s.stiffness = 5e8;
  if (st.range(0) == 1) {
    s.stiffness_table.assign(3600, 5e8);
    s.ste_table_m.assign(3600, 1e-6);
    s.table_cycles = s.ste_table_cycles = 18;
  }
  double psi = 0.1234, sum = 0;
  for (auto _ : st) {
    sum += MeshStiffness(s, psi) * (1 - MeshTransmissionError(s, psi));
    psi += 0.0371;
    benchmark::DoNotOptimize(sum);
  }
  st.SetLabel(st.range(0) ? "TVMS and TE tables over a revolution" : "constant stiffness");
}
BENCHMARK(BM_LumpedMeshLookup)->Arg(0)->Arg(1);

// ---- (b) Flexible ---------------------------------------------------------------------------

gears::Gear Seed003Planet() {
  return gears::Gear({.teeth = 14, .normal_module_m = 4e-3, .normal_pressure_angle_rad = 22.5 * kDeg,
                      .hand = gears::HelixHand::kLeft, .face_width_m = 0.04});
}

gears::GearFeMeshSpec PlanetSpec(int fault) {
  using gears::ToothFaultSpec;
  gears::GearFeMeshSpec s{.bore_radius_m = 11.2e-3, .type = flex::ElementType::kHex20, .flank_divisions = 4,
                          .fillet_divisions = 2, .tooth_divisions = 2, .root_layer_divisions = 1, .rim_divisions = 2,
                          .face_divisions = 2};
  s.material = {.name = "STEEL", .youngs_modulus_pa = 206e9, .poissons_ratio = 0.3, .density_kg_m3 = 7850};
  if (fault == 1) s.faults = {{.kind = ToothFaultSpec::Kind::kBrokenTooth, .tooth = 0, .height_fraction = 0.5}};
  if (fault >= 2) s.tooth_divisions = 4;  // a crack row needs room across the tooth
  if (fault == 2) {
    s.faults = {{.kind = ToothFaultSpec::Kind::kRootCrack, .tooth = 0, .crack_depth_m = 2e-3,
                 .crack_angle_rad = 45 * kDeg}};
  }
  return s;
}

const char* kPlanetLabels[] = {"healthy", "broken tooth (half height)", "root crack 2 mm (tooth_divisions 4)",
                               "healthy (tooth_divisions 4)"};

void BM_FaultyPlanetMesh(benchmark::State& st) {
  const gears::Gear g = Seed003Planet();
  flex::FeMesh mesh;
  for (auto _ : st) mesh = gears::MakeGearFeMesh(g, PlanetSpec(static_cast<int>(st.range(0))));
  st.SetLabel(kPlanetLabels[st.range(0)]);
  st.counters["nodes"] = mesh.num_nodes();
  st.counters["elements"] = mesh.num_elements();
}
BENCHMARK(BM_FaultyPlanetMesh)->DenseRange(0, 3)->Unit(benchmark::kMillisecond);

void BM_FaultyPlanetReduction(benchmark::State& st) {
  const flex::FeMesh mesh = gears::MakeGearFeMesh(Seed003Planet(), PlanetSpec(static_cast<int>(st.range(0))));
  const std::vector<flex::FeInterface> ifs = {flex::MakeInterface(mesh, "BORE", flex::InterfaceKind::kRbe2)};
  flex::CraigBamptonModel cb;
  for (auto _ : st) {
    const flex::FeSystem sys = flex::AssembleFeSystem(mesh);
    cb = flex::ReduceCraigBampton(mesh, sys, ifs, {.num_modes = 24});
  }
  st.SetLabel(kPlanetLabels[st.range(0)]);
  st.counters["dofs"] = 3.0 * mesh.num_nodes();
  st.counters["f1_Hz"] = cb.frequencies_hz[cb.num_rigid];
}
BENCHMARK(BM_FaultyPlanetReduction)->DenseRange(0, 3)->Unit(benchmark::kMillisecond)->Iterations(2);

}  // namespace
}  // namespace orrery

BENCHMARK_MAIN();
