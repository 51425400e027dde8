#include "tools/signal/kinematic_lines.h"

#include <cmath>
#include <stdexcept>
#include <string>

namespace orrery::signal {
namespace {

bool Usable(const KinematicLine& line) { return line.frequency_hz > 0 && std::isfinite(line.frequency_hz); }

// A candidate replaces the best so far when simpler, or as simple and closer
struct Best {
  std::optional<LineMatch> match;
  int complexity = 0;
  double error = 0;
  void Offer(LineMatch candidate, int candidate_complexity, double candidate_error) {
    if (match && (candidate_complexity > complexity ||
                  (candidate_complexity == complexity && candidate_error >= error)))
      return;
    match = std::move(candidate);
    complexity = candidate_complexity;
    error = candidate_error;
  }
};

}  // namespace

LineKind ParseLineKind(std::string_view text) {
  if (text == "mesh") return LineKind::kMesh;
  if (text == "shaft") return LineKind::kShaft;
  if (text == "planet_pass") return LineKind::kPlanetPass;
  if (text == "fault") return LineKind::kFault;
  throw std::invalid_argument("unknown kinematic line kind '" + std::string(text) +
                              "' (expected mesh, shaft, planet_pass or fault)");
}

std::string_view LineKindName(LineKind kind) {
  switch (kind) {
    case LineKind::kMesh: return "mesh";
    case LineKind::kShaft: return "shaft";
    case LineKind::kPlanetPass: return "planet_pass";
    case LineKind::kFault: return "fault";
  }
  return "unknown";
}

std::optional<LineMatch> MatchKinematicLine(double frequency_hz, const std::vector<KinematicLine>& lines,
                                            double tolerance_hz, const LabelOptions& options) {
  Best best;
  const int count = static_cast<int>(lines.size());
  for (int i = 0; i < count; ++i) {
    const KinematicLine& line = lines[i];
    if (!Usable(line)) continue;
    for (int k = 1; k <= options.max_harmonic; ++k) {
      // Harmonic k of the line
      const double f = k * line.frequency_hz;
      const double error = std::abs(f - frequency_hz);
      if (error <= tolerance_hz) {
        LineMatch m;
        m.label = k == 1 ? line.name : std::to_string(k) + " " + line.name;
        m.frequency_hz = f;
        m.carrier = i;
        m.harmonic = k;
        best.Offer(std::move(m), k - 1, error);
      }
      // Sidebands of a mesh harmonic at the other kinds' frequencies
      if (line.kind != LineKind::kMesh) continue;
      for (int j = 0; j < count; ++j) {
        const KinematicLine& mod = lines[j];
        if (mod.kind == LineKind::kMesh || !Usable(mod)) continue;
        for (int n = 1; n <= options.max_sideband; ++n) {
          for (int sign : {1, -1}) {
            const double fs = f + sign * n * mod.frequency_hz;
            const double e = std::abs(fs - frequency_hz);
            if (fs <= 0 || e > tolerance_hz) continue;
            LineMatch m;
            m.label = std::to_string(k) + " " + line.name + (sign > 0 ? " + " : " - ") + std::to_string(n) + " " + mod.name;
            m.frequency_hz = fs;
            m.carrier = i;
            m.harmonic = k;
            m.modulator = j;
            m.sideband = sign * n;
            best.Offer(std::move(m), k - 1 + n, e);
          }
        }
      }
    }
  }
  return best.match;
}

void LabelPeaks(std::vector<Peak>& peaks, const std::vector<KinematicLine>& lines, double tolerance_hz,
                const LabelOptions& options) {
  for (Peak& p : peaks) {
    const std::optional<LineMatch> m = MatchKinematicLine(p.frequency, lines, tolerance_hz, options);
    p.label = m ? m->label : std::string();
  }
}

std::optional<KinematicLine> FindLine(const std::vector<KinematicLine>& lines, LineKind kind, std::string_view name) {
  for (const KinematicLine& line : lines)
    if (line.kind == kind && (name.empty() || line.name == name)) return line;
  return std::nullopt;
}

}  // namespace orrery::signal
