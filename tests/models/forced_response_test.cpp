// Seed 001 Fig. 6 (Inalpolat & Kahraman 2009): dynamic mesh response of the three-stage train in 1st
// gear over the input speed, excited by the Table 4 transmission-error harmonics with 4 % modal
// damping (CalcForcedResponse, modal_analysis.h). Oracle: every prominent resonance peak sits where
// a mesh-frequency harmonic l f_m^(j)(speed) of a stage j crosses a natural frequency f_i of a mode
// in which stage j takes part, within the mode's half-power band |l f_m - f_i| <= zeta f_i (plus
// the speed grid). The paper's peaks (stage 1: 1880, 3765, 5540 r/min) are printed next to ours:
// its member inertias and connection scheme are not known (planetary_scenes.h), so its natural
// frequencies and peak speeds are compared, not asserted.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <numbers>

#include "models/modal_analysis.h"
#include "models/planetary_scenes.h"
#include "models/train_dynamics.h"

namespace orrery::gears {
namespace {

constexpr double kPi = std::numbers::pi;
constexpr double kRpm = 2 * kPi / 60;

// Seed 001 1st gear: Table 2 stiffnesses, Table 4 harmonics (um, E sin(l w t), phases 0: the mesh
// element's cosine series takes phi - pi/2), planet inertia calibrated as in modal_analysis_test.
TrainModel Seed001FirstGear(const PlanetaryTrain& train) {
  TrainModelOptions o;
  o.face_width_m = 0.030;
  o.input = TrainModelOptions::Input::kNone;
  o.input_torque_n_m = 300;
  const double k[3][2] = {{437, 526}, {451, 546}, {447, 540}};
  const double e[3][2][5] = {{{0.3, 0.022, 0.012, 0.004, 0.002}, {0.036, 0.018, 0.010, 0.008, 0.008}},
                             {{0.5, 0.06, 0.032, 0.021, 0.006}, {0.011, 0.012, 0.014, 0.006, 0.001}},
                             {{0.5, 0.049, 0.019, 0.012, 0.005}, {0.067, 0.058, 0.021, 0.007, 0.003}}};
  const double rbp = train.gears[train.planet_sets[0].gear].base_radius_m;
  const double ip = rbp * rbp * 963e6 / std::pow(2 * kPi * 10.54e3, 2);
  for (int s = 0; s < 3; ++s) {
    const std::string st = std::string("S").append(std::to_string(s + 1));  // (GCC 12 -Wrestrict false positive on "S" + string)
    o.members[st + ".planet"].polar_inertia_kg_m2 = ip;
    for (int m = 0; m < 2; ++m) {
      TrainMeshOverride& ov = o.meshes[st + (m == 0 ? ".sun-planet" : ".ring-planet")];
      ov.stiffness_n_per_m = k[s][m] * 1e6;
      ov.ste_amplitudes_m = std::vector<double>(e[s][m], e[s][m] + 5);
      for (double& a : *ov.ste_amplitudes_m) a *= 1e-6;
      ov.ste_phases_rad = std::vector<double>(5, -kPi / 2);
    }
  }
  return BuildTrainModel(train, train.RangeIndex("1st"), o);
}

TEST(ForcedResponse, Seed001FigureSixPeaksSitOnMeshHarmonicCrossings) {
  const auto train = MakeSeed001AutomaticTransmission();
  const TrainModel tm = Seed001FirstGear(*train);
  const TrainModes modes = CalcTrainModes(tm);
  const double zeta = 0.04;
  // Fig. 6 speed range, 0-6000 r/min, on a grid of 5 r/min (well inside the 8 % half-power width).
  std::vector<double> speeds;
  const double step_rpm = 10;
  for (double rpm = 500; rpm <= 6500; rpm += step_rpm) speeds.push_back(rpm * kRpm);
  const ForcedResponse fr = CalcForcedResponse(tm, modes, {.input_speeds_rad_s = speeds, .modal_damping_ratio = zeta,
                                                                 .samples_per_period = 16});
  // Per stage, the sun-planet mesh of branch 1 (the paper's "sun-planet 1").
  for (int stage = 0; stage < 3; ++stage) {
    int mesh = -1;
    for (const TrainMeshElement& e : tm.meshes)
      if (e.stage == stage && e.branch == 0 && train->meshes[e.train_mesh].name.find("sun-planet") != std::string::npos)
        mesh = e.model_mesh;
    ASSERT_GE(mesh, 0);
    // The motion along the line of action, J q: the dynamic part of the mesh force k (J q - e),
    // whose quasi-static -k e term (up to 0.5 um x 450 N/um) hides the resonances of the small
    // higher harmonics.
    const Eigen::VectorXd f = fr.mesh_deflection_p2p_m.col(mesh);
    std::printf("stage %d sun-planet 1 resonance peaks (mode kHz, harmonic l of stage j):\n", stage + 1);
    int peaks = 0;
    for (int i = 1; i + 1 < f.size(); ++i) {
      if (!(f(i) > f(i - 1) && f(i) >= f(i + 1))) continue;
      // Prominence: a peak must rise above the lowest points on either side by more than the
      // p2p sampling error of 16 samples per period, 1 - cos(pi / 16) (smaller bumps may be
      // artefacts of sampling the multi-harmonic signal).
      double left = f(i), right = f(i);
      for (int k = i; k >= 0 && f(k) <= f(i); --k) left = std::min(left, f(k));
      for (int k = i; k < f.size() && f(k) <= f(i); ++k) right = std::min(right, f(k));
      if (f(i) * std::cos(kPi / 16) <= std::max(left, right)) continue;
      ++peaks;
      // The crossing: a mode with stage j taking part, l f_m^(j) within its half-power band.
      const double rpm = speeds[i] / kRpm;
      bool found = false;
      std::string why;
      for (const TrainMode& m : modes.modes) {
        if (m.mode_class == ModeClass::kRigidBody) continue;
        for (int j : m.stages)
          for (int l = 1; l <= 5; ++l) {
            const double fm = l * fr.stage_mesh_frequencies_hz(i, j);
            // Grid: the mesh frequency moves by l f_m step / speed between grid points.
            const double grid = fm * step_rpm / rpm;
            if (std::abs(fm - m.frequency_hz) <= zeta * m.frequency_hz + grid) {
              if (!found) why = std::to_string(m.frequency_hz / 1e3).substr(0, 5) + " kHz, l = " +
                                std::to_string(l) + " of S" + std::to_string(j + 1);
              found = true;
            }
          }
      }
      std::printf("  %6.0f r/min: J q %8.3g um p2p, force %7.1f N p2p;  %s\n", rpm, f(i) * 1e6,
                  fr.mesh_force_p2p_n(i, mesh), found ? why.c_str() : "NO CROSSING");
      EXPECT_TRUE(found) << "stage " << stage + 1 << " peak at " << rpm << " r/min";
    }
    EXPECT_GT(peaks, 0);
  }
  std::printf("paper Fig. 6: stage 1 peaks 1880 (2.88 kHz, l = 4 of S1), 3765, 5540 r/min; stage 2 at 3470 "
              "(1.79 kHz, l = 2 of S3 and l = 3 of S2); stage 3 (1.79 kHz, l = 3 of S2)\n");
  std::printf("modes (kHz, class, stages):");
  for (const ModeGroup& g : modes.groups)
    if (g.frequency_hz < 12e3 && g.frequency_hz > 1) std::printf(" %.2f(%s)", g.frequency_hz / 1e3, ModeClassName(g.mode_class));
  std::printf("\n");
}

}  // namespace
}  // namespace orrery::gears
