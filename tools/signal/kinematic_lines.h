#pragma once
// Kinematic lines of a gear scene and the labelling of spectral peaks with them.
//
// A line is a named frequency of the kinematics: mesh frequencies (`f_m`, `f_m S1` per stage),
// member rotation frequencies (`f_s`, `f_r`, `f_c`, planet `f_p` and `f_p^H` relative to the
// carrier), planet-pass frequencies (`f_pp`) and tooth-fault frequencies (`f_fault S.planet`).
// Gear scenes write them to their result files (signal_io.h reads them):
//   /kinematics/lines/name          1-D strings
//   /kinematics/lines/frequency_hz  1-D float64
//   /kinematics/lines/kind          1-D strings: mesh | shaft | planet_pass | fault
//
// A peak at f is labelled with the simplest expression within the tolerance |f - f_label| <= tol
// (the spectrum's resolution by default):
//   a line               "f_x"                    complexity 0
//   a harmonic           "k f_x"                  complexity k - 1       (k = 2 .. max_harmonic)
//   a mesh sideband      "k f_m + n f_x",         complexity (k - 1) + n (k = 1 .. max_harmonic,
//                        "k f_m - n f_x"                                  n = 1 .. max_sideband)
// where sidebands are formed around mesh lines (kind mesh) with the other kinds (shaft,
// planet_pass, fault) as modulation. The lowest complexity wins (the simplest explanation), then
// the smallest |f - f_label|. Example: "2 f_m - 1 f_p^H" is the first lower sideband at the
// planet's frequency relative to the carrier around the second mesh harmonic.
//
// Usage:
//   std::vector<Peak> peaks = FindPeaks(s);
//   LabelPeaks(peaks, lines, s.resolution);   // peaks[i].label = "f_m", "2 f_m - 1 f_p^H", ...
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "tools/signal/peaks.h"

namespace orrery::signal {

enum class LineKind { kMesh, kShaft, kPlanetPass, kFault };

struct KinematicLine {
  std::string name;       // "f_m", "f_p^H", "f_fault S.planet", ...
  double frequency_hz = 0;
  LineKind kind = LineKind::kShaft;
};

// "mesh", "shaft", "planet_pass", "fault"; throws std::invalid_argument naming the value.
LineKind ParseLineKind(std::string_view text);
std::string_view LineKindName(LineKind kind);

struct LabelOptions {
  int max_harmonic = 10;  // k of harmonics and of the mesh harmonics that carry sidebands
  int max_sideband = 6;   // n of sidebands
};

// What a frequency was matched to.
struct LineMatch {
  std::string label;        // as above
  double frequency_hz = 0;  // the expression's frequency
  int carrier = -1;         // index of the line (harmonic) or mesh line (sideband) in `lines`
  int harmonic = 1;         // k
  int modulator = -1;       // index of the modulating line of a sideband; -1 for a harmonic
  int sideband = 0;         // signed n of a sideband (+ upper, - lower); 0 for a harmonic
};

// The simplest expression within `tolerance_hz` of `frequency_hz`, or none. Lines with a
// frequency that is not positive and finite are skipped.
std::optional<LineMatch> MatchKinematicLine(double frequency_hz, const std::vector<KinematicLine>& lines,
                                            double tolerance_hz, const LabelOptions& options = {});

// Sets each peak's label (MatchKinematicLine; "" when nothing matches). The peaks' frequencies
// are read as Hz.
void LabelPeaks(std::vector<Peak>& peaks, const std::vector<KinematicLine>& lines, double tolerance_hz,
                const LabelOptions& options = {});

// The first line of `kind` (or named `name` when given), or none.
std::optional<KinematicLine> FindLine(const std::vector<KinematicLine>& lines, LineKind kind,
                                      std::string_view name = {});

}  // namespace orrery::signal
