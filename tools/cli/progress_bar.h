#pragma once
// Progress of a simulation on the error stream of `orrery run`.
//
// Three styles: on a terminal a one-line bar redrawn in place with '\r' at most every
// `min_redraw_s` of wall time; elsewhere (a log file, CI) a plain line at every 10 % of the
// simulated time; or nothing (--quiet). Each shows simulated time / end time, percent, integrator
// steps, wall time and the time left, extrapolated linearly from the simulated time reached
// (runs start at t = 0).
//
// Usage:
//   ProgressBar bar(std::cerr, ProgressBar::Style::kBar);
//   Simulate(model, options, &out, [&](const SimulationProgress& p) { bar.Update(p); });
//   bar.Finish();     // or bar.Abandon() before printing an error
#include <ostream>
#include <string>

#include "mbd/simulation.h"

namespace orrery::cli {

class ProgressBar {
 public:
  enum class Style { kBar, kLines, kNone };

  // Keeps a reference to `err`.
  ProgressBar(std::ostream& err, Style style, double min_redraw_s = 0.1);

  // Called after every output row: redraws the bar (rate limited) or prints a line when a new
  // 10 % mark is passed.
  void Update(const SimulationProgress& progress);

  // Draws the bar a last time at the latest progress and ends its line.
  void Finish();

  // Erases the bar so that an error message starts on a clean line.
  void Abandon();

 private:
  void Draw(const SimulationProgress& progress);

  std::ostream& err_;
  Style style_;
  double min_redraw_s_;
  SimulationProgress last_;          // latest Update
  bool updated_ = false;             // Update called at least once
  double last_draw_wall_s_ = -1e300;  // wall time of the last redraw
  std::size_t drawn_width_ = 0;      // characters on the bar's line, 0: nothing drawn
  int next_mark_percent_ = 10;       // kLines: next 10 % mark to report
};

// The bar's line: "[#####.....]  42%  t 0.084 / 0.2 s  123 steps  wall 1.2 s  left 1.7 s".
// `bar_width` characters between the brackets.
std::string FormatProgressBar(const SimulationProgress& progress, int bar_width = 24);

// The plain line: "progress  40%  t = 0.08 / 0.2 s, 123 steps, wall 1.2 s, left 1.7 s".
std::string FormatProgressLine(const SimulationProgress& progress);

// A duration for people: "0.35 s", "12.4 s", "3 min 05 s", "2 h 07 min".
std::string FormatDuration(double seconds);

}  // namespace orrery::cli
