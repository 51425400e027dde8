// Cross-check of a generated gear mesh (models/gear_fe_mesh.h) against CalculiX (an external
// solver): seed 001's planet (18 teeth, m_n 1.5 mm, alpha_n 21.3 deg, 30 mm face width,
// scenarios.md) with a 7 mm bore, steel, the bore held fixed. The mesh is written by flex's
// WriteInp, ccx solves *FREQUENCY for 20 modes, CalcFeModes solves the same mesh.
// Requirement: every frequency within 0.1 %. Both codes integrate C3D8 with 2x2x2 and C3D20 with
// 3x3x3 Gauss points (full integration, mass by the same rule: flex/fe_element.h), so the
// discrete problems are identical and the only differences are ccx's 7-digit eigenvalue output
// (2.5e-7 in f) and the solvers' convergence (~1e-10): the test asserts 1e-5, far inside the
// requirement, so a formulation difference (incompatible modes C3D8I, reduced C3D20R) would show.
// The mesh handed to ccx is translated by (1, 1, 1) m: ccx reads at most 20 characters per
// field, and WriteInp's 17-digit numbers of coordinates below 1e-4 m in magnitude take 22-23
// (exponent form, "-3.8867686406668911E-16"), which ccx truncates into a read error or a wrong
// value. Shifted coordinates lie in [0.98, 1.02] m and print in at most 19 characters; a rigid
// translation leaves the modes unchanged.
// Faulty planets (models/gear_fe_mesh.h): the same check on the mesh with a tooth's upper half
// removed over half the face width, and on the mesh with an open root crack (duplicated nodes):
// the FE model with the fault is exactly what ccx solves, so the same 1e-5 holds.
// Skipped (GTEST_SKIP, with a message) when no ccx program is on PATH.
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <unistd.h>
#include <vector>

#include "flex/calculix.h"
#include "flex/fe_assembly.h"
#include "flex/fe_modes.h"
#include "models/gear_fe_mesh.h"
#include "models/tooth_fault.h"

namespace orrery::gears {
namespace {

using flex::ElementType;
constexpr double kPi = 3.14159265358979323846;

// A copy of `mesh` with every node moved by `offset_m` (ids, elements, sets, material kept).
flex::FeMesh Translated(const flex::FeMesh& mesh, const Eigen::Vector3d& offset_m) {
  flex::FeMesh out;
  for (int n = 0; n < mesh.num_nodes(); ++n) out.AddNode(mesh.node_ids()[n], mesh.positions()[n] + offset_m);
  for (const flex::FeElement& e : mesh.elements()) {
    std::vector<int> ids(flex::NodeCount(e.type));
    for (std::size_t a = 0; a < ids.size(); ++a) ids[a] = mesh.node_ids()[e.nodes[a]];
    out.AddElement(e.id, e.type, ids);
  }
  for (const auto& [name, nodes] : mesh.node_sets()) out.AddToNodeSet(name, nodes);
  out.AssignMaterialToAll(mesh.materials().at(0));
  return out;
}

TEST(GearFeCalculixTest, PlanetModesMatchCalculix) {
  const std::optional<std::filesystem::path> ccx = flex::FindCalculix();
  if (!ccx) GTEST_SKIP() << "CalculiX (ccx) not found on PATH: gear mesh cross-check skipped";
  const Gear planet({.teeth = 18, .normal_module_m = 1.5e-3, .normal_pressure_angle_rad = 21.3 * kPi / 180,
                     .face_width_m = 0.03});
  constexpr int kModes = 20;
  struct Case {
    ElementType type;
    GearFeMeshSpec spec;
  };
  const Case cases[] = {
      {ElementType::kHex20, {.bore_radius_m = 7e-3, .type = ElementType::kHex20, .flank_divisions = 3,
                             .fillet_divisions = 2, .tooth_divisions = 4, .root_layer_divisions = 1,
                             .rim_divisions = 2, .face_divisions = 4}},
      {ElementType::kHex8, {.bore_radius_m = 7e-3, .type = ElementType::kHex8, .flank_divisions = 4,
                            .fillet_divisions = 3, .tooth_divisions = 5, .root_layer_divisions = 2,
                            .rim_divisions = 2, .face_divisions = 6}},
  };
  for (const Case& c : cases) {
    const flex::FeMesh mesh = MakeGearFeMesh(planet, c.spec);
    const std::filesystem::path dir = std::filesystem::temp_directory_path() /
                                      (std::string("orrery_gear_ccx_") + flex::CalculixName(c.type) + "_" +
                                       std::to_string(::getpid()));
    const auto t0 = std::chrono::steady_clock::now();
    const std::vector<double> w2_ccx =
        flex::RunCalculixFrequency(*ccx, Translated(mesh, Eigen::Vector3d::Ones()), {"BORE"}, kModes, dir);
    const auto t1 = std::chrono::steady_clock::now();
    std::filesystem::remove_all(dir);
    ASSERT_EQ(static_cast<int>(w2_ccx.size()), kModes) << flex::CalculixName(c.type);
    const flex::FeModes ours = flex::CalcFeModes(flex::AssembleFeSystem(mesh), flex::NodeDofs(mesh.NodeSet("BORE")),
                                                 {.num_modes = kModes});
    const auto t2 = std::chrono::steady_clock::now();
    double worst = 0;
    for (int i = 0; i < kModes; ++i) {
      const double f_ccx = flex::EigenvalueToHz(w2_ccx[i]);
      const double dev = ours.frequencies_hz[i] / f_ccx - 1;
      worst = std::max(worst, std::abs(dev));
      std::printf("  %s mode %2d: %10.2f Hz (ccx %10.2f Hz) %+.2e\n", flex::CalculixName(c.type), i + 1,
                  ours.frequencies_hz[i], f_ccx, dev);
    }
    std::printf("%s planet: %d DOFs, max relative difference %.2g; ccx %.1f s, Orrery %.1f s\n",
                flex::CalculixName(c.type), static_cast<int>(ours.free_dofs.size()), worst,
                std::chrono::duration<double>(t1 - t0).count(), std::chrono::duration<double>(t2 - t1).count());
    EXPECT_EQ(ours.num_rigid_body_modes, 0);
    EXPECT_LT(worst, 1e-5) << flex::CalculixName(c.type);
  }
}


TEST(GearFeCalculixTest, FaultyPlanetModesMatchCalculix) {
  const std::optional<std::filesystem::path> ccx = flex::FindCalculix();
  if (!ccx) GTEST_SKIP() << "CalculiX (ccx) not found on PATH: faulty gear mesh cross-check skipped";
  const Gear planet({.teeth = 18, .normal_module_m = 1.5e-3, .normal_pressure_angle_rad = 21.3 * kPi / 180,
                     .face_width_m = 0.03});
  constexpr int kModes = 8;
  const GearFeMeshSpec base{.bore_radius_m = 7e-3, .type = ElementType::kHex20, .flank_divisions = 3,
                            .fillet_divisions = 2, .tooth_divisions = 4, .root_layer_divisions = 1,
                            .rim_divisions = 1, .face_divisions = 2};
  const ToothFaultSpec faults[] = {
      {.kind = ToothFaultSpec::Kind::kBrokenTooth, .tooth = 0, .height_fraction = 0.5, .face_fraction = 0.5},
      {.kind = ToothFaultSpec::Kind::kRootCrack, .tooth = 0, .crack_depth_m = 0.8e-3,
       .crack_angle_rad = 60 * kPi / 180, .crack_face_fraction = 1.0}};
  const flex::FeMesh healthy_mesh = MakeGearFeMesh(planet, base);
  const flex::FeModes healthy = flex::CalcFeModes(flex::AssembleFeSystem(healthy_mesh),
                                                  flex::NodeDofs(healthy_mesh.NodeSet("BORE")), {.num_modes = kModes});
  for (const ToothFaultSpec& fault : faults) {
    GearFeMeshSpec spec = base;
    spec.faults = {fault};
    const flex::FeMesh mesh = MakeGearFeMesh(planet, spec);
    const std::filesystem::path dir = std::filesystem::temp_directory_path() /
                                      (std::string("orrery_gear_ccx_") + KindName(fault.kind) + "_" +
                                       std::to_string(::getpid()));
    const auto t0 = std::chrono::steady_clock::now();
    const std::vector<double> w2_ccx =
        flex::RunCalculixFrequency(*ccx, Translated(mesh, Eigen::Vector3d::Ones()), {"BORE"}, kModes, dir);
    const double ccx_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    std::filesystem::remove_all(dir);
    ASSERT_EQ(static_cast<int>(w2_ccx.size()), kModes) << KindName(fault.kind);
    const flex::FeModes ours = flex::CalcFeModes(flex::AssembleFeSystem(mesh), flex::NodeDofs(mesh.NodeSet("BORE")),
                                                 {.num_modes = kModes});
    double worst = 0, shift = 0;
    for (int i = 0; i < kModes; ++i) {
      const double f_ccx = flex::EigenvalueToHz(w2_ccx[i]);
      worst = std::max(worst, std::abs(ours.frequencies_hz[i] / f_ccx - 1));
      shift = std::max(shift, std::abs(ours.frequencies_hz[i] / healthy.frequencies_hz[i] - 1));
    }
    std::printf("%s planet: %d nodes, max relative difference to ccx %.2g (ccx %.1f s); largest shift from the healthy "
                "planet %.2g\n", KindName(fault.kind), mesh.num_nodes(), worst, ccx_s, shift);
    EXPECT_LT(worst, 1e-5) << KindName(fault.kind);
    // The fault changes the structure it is meant to change (a frequency moves), so the check is
    // not the healthy mesh's again.
    EXPECT_GT(shift, 1e-4) << KindName(fault.kind);
  }
}

}  // namespace
}  // namespace orrery::gears
