// The seed 003 scenes as the fault study runs them (models/scenes/seed003_*.yaml; 22/14/50,
// 3 planets, ring +80.6 rad/s, sun -10 rad/s, 6000 N m on the carrier; docs/validation/
// scenarios.md), checked against what the kinematics and the published study say:
// - healthy, rigid tooth contact on all six meshes: the lines of planet 1's angular acceleration
//   (the study's default signal) sit at the kinematic mesh frequency f_m = 220.3 Hz (seed 003
//   Table 1; Willis' equation with Z_r = 50) and its harmonics, each within the spectrum's
//   resolution (an interpolated Hann peak of one dominant sine lies within a small fraction of a
//   bin of it, Grandke 1983; a whole bin allows for the neighbouring lines' leakage), and every
//   line of the band down to -60 dB of the largest is a mesh harmonic (a healthy periodic mesh
//   excites nothing else once the start transient has died out). A local maximum that the
//   harmonics' own leakage explains is no line: the Hann window's kernel at d bins from a line of
//   amplitude A is A |sin(pi d)| / (pi |d| |d^2 - 1|) (Harris 1978, Proc. IEEE 66(1), table I's
//   window as a sum of three shifted Dirichlet kernels), at most A / (pi |d| (d^2 - 1)) for
//   |d| > 1, summed over the harmonics; the mesh harmonics sit 220.3 / 19.96 = 11.04 bins apart,
//   so between two strong ones the sidelobes reach about -55 dB of them.
// - flexible planet 1 (seed003_flexible_healthy.yaml, 0.01 s, twice): the largest von Mises stress sits
//   in the tooth-root region, between the root circle r_f and the form circle r_form (where the
//   rack-generated fillet meets the involute; both closed forms of models/gear_geometry.h: for
//   z = 14, m = 4 mm, alpha = 22.5 deg, h_fP* = 1.25, rho_fP* = 0.38: r_f = 23.0 mm, r_form
//   from the rack's flank/fillet tangency), and on the side of its tooth that the load direction
//   implies. The load: the carrier carries -6000 N m against its rotation (+52.9 rad/s), so the
//   sun and the ring both push planet 1 along +e_theta (the carrier's tangential direction at the
//   planet, e_z x e_R; the planet's moment balance makes the two mesh forces equal and alike in
//   direction). A planet tooth in either mesh is pushed by the mating tooth on its flank facing
//   -e_theta (the loaded flank: its fillet in tension); the opposite fillet, on the +e_theta
//   side, is in compression. Lewis' cantilever (bending sigma_b = 6 F_t h / (b s^2)) plus the
//   direct stress of the load's radial component F_r = F_t tan(alpha) towards the gear centre
//   (sigma_c = F_r / (b s)) gives sigma_b + sigma_c on the compressed fillet against sigma_b -
//   sigma_c on the tensile one (Dudley, Handbook of Practical Gear Design, root stresses): for
//   this tooth (h ~ 5 mm, s ~ 7.5 mm) about 1.2 times, so the von Mises maximum (|sigma| at the
//   free fillet surface) is the compressed fillet's: the +e_theta side. The oracle's sign is
//   checked both ways: with the carrier's torque reversed (+6000 N m, the planets now brake it)
//   the mesh forces and the hot spot move to the other side (-e_theta).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <numbers>
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include <gtest/gtest.h>

#include "import/scene.h"
#include "mbd/hdf5_reader.h"
#include "mbd/result_file.h"
#include "mbd/simulation.h"
#include "models/gear_geometry.h"
#include "tools/signal/amplitude_spectrum.h"
#include "tools/signal/peaks.h"
#include "tools/signal/signal_io.h"

namespace orrery {
namespace {

namespace fs = std::filesystem;
using namespace orrery::signal;

const fs::path kModels = fs::path(ORRERY_SOURCE_DIR) / "models";

// The scene run to its end into `h5`.
void RunScene(const Scene& scene, const std::string& h5) {
  ResultFile out = ResultFile::Create(h5);
  Simulate(*scene.model, scene.simulation, &out);
}

TEST(Seed003Study, HealthyRigidContactLinesSitAtTheKinematicMeshHarmonics) {
  // 0.02 s of start transient (steady from then on: docs/fault_study.md), 0.05 s analysed:
  // resolution 20 Hz, f_m 11 bins from its neighbours. 10 us steps instead of the scene's 5 us:
  // the lines' frequencies are the kinematics' (the test's cost halves: about 10 s of CPU)
  const Scene scene = LoadScene((kModels / "scenes" / "seed003_contact_healthy.yaml").string(),
                                {"solver.end_time=0.07", "solver.step=1e-5"});
  const std::string h5 = (fs::path(::testing::TempDir()) / "seed003_contact_healthy_lines.h5").string();
  RunScene(scene, h5);
  const Hdf5Reader r(h5);
  const RecordedSignal s = ReadSignal(r, "/sensors/planet1/angular_acceleration", "", 0.02);
  const Spectrum spectrum = AmplitudeSpectrum(s.values, s.sample_rate_hz, WindowKind::kHann);
  const double f_m = 220.3;  // seed 003 Table 1, case 1
  ASSERT_NEAR(spectrum.resolution, 20.0, 0.5);

  // Each of the first four mesh harmonics: a peak within one bin
  const std::vector<Peak> peaks = FindPeaks(spectrum, {.max_peaks = 200});
  for (int k = 1; k <= 4; ++k) {
    const auto near = std::find_if(peaks.begin(), peaks.end(),
                                   [&](const Peak& p) { return std::abs(p.frequency - k * f_m) <= spectrum.resolution; });
    ASSERT_NE(near, peaks.end()) << "no line within " << spectrum.resolution << " Hz of " << k << " f_m";
    EXPECT_NEAR(near->frequency, k * f_m, spectrum.resolution) << k << " f_m";
  }
  // Every line between f_m / 2 and 4.5 f_m down to -60 dB of the largest (FindPeaks' floor) is
  // a mesh harmonic, unless the harmonics' leakage bounds it (header)
  const auto harmonic_amplitude = [&](int k) {
    double a = 0;
    for (const Peak& p : peaks)
      if (std::abs(p.frequency - k * f_m) <= spectrum.resolution) a = std::max(a, p.amplitude);
    return a;
  };
  const auto leakage = [&](double f) {
    double bound = 0;
    for (int k = 1; k * f_m < 0.5 * s.sample_rate_hz; ++k) {
      const double d = std::abs(f - k * f_m) / spectrum.resolution;
      if (d > 1.5) bound += harmonic_amplitude(k) / (std::numbers::pi * d * (d * d - 1));
    }
    return bound;
  };
  int lines = 0;
  for (const Peak& p : peaks) {
    if (p.frequency < 0.5 * f_m || p.frequency > 4.5 * f_m) continue;
    const double k = std::round(p.frequency / f_m);
    if (std::abs(p.frequency - k * f_m) > 1.5 * spectrum.resolution && p.amplitude <= leakage(p.frequency))
      continue;  // the harmonics' sidelobes
    EXPECT_NEAR(p.frequency, k * f_m, spectrum.resolution) << "line at " << p.frequency << " Hz, " << p.amplitude
                                                            << " rad/s^2";
    ++lines;
  }
  EXPECT_GE(lines, 4);
  fs::remove(h5);
}

// models/scenes and models/bodies copied to a scratch folder (the reduced body made on the first
// load must not land in the source tree; a changed reduce input clears the old one)
fs::path ScratchModels(const std::string& name) {
  const fs::path copy = fs::path(::testing::TempDir()) / name;
  for (const char* folder : {"scenes", "bodies"}) {
    fs::create_directories(copy / folder);
    for (const auto& entry : fs::directory_iterator(kModels / folder)) {
      if (entry.path().extension() != ".yaml") continue;
      const fs::path to = copy / folder / entry.path().filename();
      if (folder == std::string("bodies") && fs::exists(to) &&
          fs::last_write_time(to) < fs::last_write_time(entry.path()))
        for (const auto& made : fs::directory_iterator(copy / folder))
          if (made.path().extension() == ".h5") fs::remove(made.path());
      fs::copy_file(entry.path(), to, fs::copy_options::overwrite_existing);
    }
  }
  return copy;
}

// Where planet 1's von Mises maximum of one output row sits
struct HotSpot {
  double t_s, stress_pa, radius_m;
  double side;  // > 0: on the +e_theta side of its tooth's centre line (world, at that instant)
};

std::vector<HotSpot> PlanetHotSpots(const std::string& h5, int teeth) {
  const Hdf5Reader r(h5);
  const Eigen::MatrixXd vm = r.ReadMatrix("/flexible_bodies/S.planet1/von_mises_max");  // stress,node,x,y,z
  const Eigen::MatrixXd q = r.ReadMatrix("/bodies/S.planet1/orientation");              // w,x,y,z
  const Eigen::MatrixXd p = r.ReadMatrix("/bodies/S.planet1/position");
  const Eigen::MatrixXd t = r.ReadMatrix("/time");
  const double pitch = 2 * M_PI / teeth;
  std::vector<HotSpot> spots;
  for (Eigen::Index i = 0; i < vm.rows(); ++i) {
    const Eigen::Vector3d node(vm(i, 2), vm(i, 3), vm(i, 4));
    const double k = std::round(std::atan2(node.y(), node.x()) / pitch);  // nearest tooth centre line
    const Eigen::Matrix3d R = Eigen::Quaterniond(q(i, 0), q(i, 1), q(i, 2), q(i, 3)).normalized().toRotationMatrix();
    const Eigen::Vector3d c = R * Eigen::Vector3d(std::cos(k * pitch), std::sin(k * pitch), 0), d = R * node;
    const Eigen::Vector3d e_r = Eigen::Vector3d(p(i, 0), p(i, 1), 0).normalized();
    const Eigen::Vector3d e_theta = Eigen::Vector3d::UnitZ().cross(e_r);
    spots.push_back({t(i, 0), vm(i, 0), std::hypot(node.x(), node.y()), (d - d.dot(c) * c).dot(e_theta)});
  }
  return spots;
}

TEST(Seed003Study, FlexiblePlanetHotSpotSitsAtTheCompressedToothRootOfTheLoadedTooth) {
  const fs::path copy = ScratchModels("seed003_hot_spot");
  const std::string scene_path = (copy / "scenes" / "seed003_flexible_healthy.yaml").string();
  const gears::Gear planet({.teeth = 14, .normal_module_m = 4e-3, .normal_pressure_angle_rad = 22.5 * M_PI / 180,
                            .face_width_m = 0.04});
  const double r_f = planet.root_radius_m(), r_form = planet.form_radius_m();
  ASSERT_NEAR(r_f, 23.0e-3, 1e-9);
  ASSERT_GT(r_form, r_f);
  // Nominal load (+e_theta: side +1), then the carrier's torque reversed (side -1)
  for (const auto& [torque, side] : {std::pair{"-6000", 1.0}, std::pair{"6000", -1.0}}) {
    const Scene scene = LoadScene(scene_path, {"solver.end_time=0.01", std::string("gear_train.output_torque=") + torque},
                                  {.make_reduced_bodies = true});
    const std::string h5 = (copy / ("hot_spot_" + std::string(torque) + ".h5")).string();
    RunScene(scene, h5);
    const std::vector<HotSpot> spots = PlanetHotSpots(h5, 14);
    // The run's maximum (what `orrery run` and the fault study report)
    const HotSpot& top = *std::max_element(spots.begin(), spots.end(),
                                           [](const HotSpot& a, const HotSpot& b) { return a.stress_pa < b.stress_pa; });
    EXPECT_GE(top.radius_m, r_f - 1e-9) << "torque " << torque;
    EXPECT_LE(top.radius_m, r_form) << "torque " << torque;
    EXPECT_GT(top.side * side, 0) << "torque " << torque << ": max at t = " << top.t_s << " s";
    // Every output row once the teeth carry the load (from 2 ms, above 20 MPa): the root region
    // always; the predicted side in most rows. Measured: 63 of 73 rows (nominal), 66 of 73
    // (reversed); over 0.02 s 154 and 153 of 173; the others recur once per mesh period
    // (4.5 ms), as the loaded tooth pair changes, at r = 23.25 mm or 23.95 mm (the bottom of the
    // space between two loaded teeth, where one's compressed fillet meets the next one's tensile
    // fillet).
    // Reversing the load turns 86-90 % into 10-14 %, so 3 rows in 4 separates the two clearly.
    int rows = 0, right = 0;
    for (const HotSpot& s : spots) {
      if (s.t_s < 2e-3 || s.stress_pa < 20e6) continue;
      ++rows;
      EXPECT_TRUE(s.radius_m >= r_f - 1e-9 && s.radius_m <= r_form) << "t = " << s.t_s << " s: r = " << s.radius_m;
      right += s.side * side > 0;
    }
    EXPECT_GE(rows, 70) << "torque " << torque;
    EXPECT_GT(right, 0.75 * rows) << "torque " << torque << ": " << right << " of " << rows;
    std::printf("torque %s N m: max %.1f MPa at t = %.4f s, r = %.2f mm (r_f %.2f, r_form %.2f), side %+.2f mm; "
                "%d of %d rows on the predicted side\n", torque, top.stress_pa * 1e-6, top.t_s, top.radius_m * 1e3,
                r_f * 1e3, r_form * 1e3, top.side * 1e3, right, rows);
    fs::remove(h5);
  }
}

}  // namespace
}  // namespace orrery
