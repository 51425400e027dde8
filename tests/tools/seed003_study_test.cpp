// The seed 003 scenes as the fault study runs them (models/scenes/seed003_*.yaml; 22/14/50,
// 3 planets, ring +80.6 rad/s, sun -10 rad/s, 6000 N m on the carrier; docs/validation/
// scenarios.md), checked against what the kinematics and the published study say:
// - healthy, rigid tooth contact on all six meshes: the lines of planet 1's angular acceleration
//   (the study's default signal) sit at the kinematic mesh frequency f_m = 220.3 Hz (seed 003
//   Table 1; Willis' equation with Z_r = 50) and its harmonics, each within the spectrum's
//   resolution (an interpolated Hann peak of one dominant sine lies within a small fraction of a
//   bin of it, Grandke 1983; a whole bin allows for the neighbouring lines' leakage), and every
//   line of the band down to -60 dB of the largest is a mesh harmonic (a healthy periodic mesh
//   excites nothing else once the start transient has died out).
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <string>

#include <gtest/gtest.h>

#include "import/scene.h"
#include "mbd/hdf5_reader.h"
#include "mbd/result_file.h"
#include "mbd/simulation.h"
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
  // a mesh harmonic
  int lines = 0;
  for (const Peak& p : peaks) {
    if (p.frequency < 0.5 * f_m || p.frequency > 4.5 * f_m) continue;
    const double k = std::round(p.frequency / f_m);
    EXPECT_NEAR(p.frequency, k * f_m, spectrum.resolution) << "line at " << p.frequency << " Hz, " << p.amplitude
                                                            << " rad/s^2";
    ++lines;
  }
  EXPECT_GE(lines, 4);
  fs::remove(h5);
}

}  // namespace
}  // namespace orrery
