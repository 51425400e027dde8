#include "tools/cli/progress_bar.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace orrery::cli {
namespace {

// Fraction of the run done, in [0, 1]
double Fraction(const SimulationProgress& p) {
  if (!(p.end_time > 0)) return 0;
  return std::clamp(p.t / p.end_time, 0.0, 1.0);
}

// Whole percent done; 0.18 / 0.2 counts as 90 % despite rounding, 99.9 % stays 99 %
int Percent(const SimulationProgress& p) { return static_cast<int>(Fraction(p) * 100 + 1e-6); }

// Wall time left, extrapolated from the rate so far; "?" before any simulated time passed
std::string TimeLeft(const SimulationProgress& p) {
  const double f = Fraction(p);
  if (f <= 0) return "?";
  return FormatDuration(p.wall_s * (1 - f) / f);
}

}  // namespace

std::string FormatDuration(double seconds) {
  char buffer[48];
  if (!(seconds >= 0) || !std::isfinite(seconds)) return "?";
  if (seconds < 10) {
    std::snprintf(buffer, sizeof buffer, "%.2f s", seconds);
  } else if (seconds < 60) {
    std::snprintf(buffer, sizeof buffer, "%.1f s", seconds);
  } else if (seconds < 3600) {
    const long s = std::lround(seconds);
    std::snprintf(buffer, sizeof buffer, "%ld min %02ld s", s / 60, s % 60);
  } else {
    const long m = std::lround(seconds / 60);
    std::snprintf(buffer, sizeof buffer, "%ld h %02ld min", m / 60, m % 60);
  }
  return buffer;
}

std::string FormatProgressBar(const SimulationProgress& p, int bar_width) {
  const double f = Fraction(p);
  // The bar itself
  const int filled = std::clamp(static_cast<int>(f * bar_width), 0, bar_width);
  std::string line;
  line.reserve(static_cast<std::size_t>(bar_width) + 96);
  line.push_back('[');
  line.append(static_cast<std::size_t>(filled), '#');
  line.append(static_cast<std::size_t>(bar_width - filled), '.');
  line.push_back(']');
  // The numbers
  char buffer[160];
  std::snprintf(buffer, sizeof buffer, " %3d%%  t %.4g / %.4g s  %ld steps  wall %s  left %s",
                Percent(p), p.t, p.end_time, p.steps, FormatDuration(p.wall_s).c_str(),
                TimeLeft(p).c_str());
  line += buffer;
  return line;
}

std::string FormatProgressLine(const SimulationProgress& p) {
  char buffer[160];
  std::snprintf(buffer, sizeof buffer, "progress %3d%%  t = %.4g / %.4g s, %ld steps, wall %s, left %s",
                Percent(p), p.t, p.end_time, p.steps,
                FormatDuration(p.wall_s).c_str(), TimeLeft(p).c_str());
  return buffer;
}

ProgressBar::ProgressBar(std::ostream& err, Style style, double min_redraw_s)
    : err_(err), style_(style), min_redraw_s_(min_redraw_s) {}

void ProgressBar::Update(const SimulationProgress& progress) {
  last_ = progress;
  updated_ = true;
  switch (style_) {
    case Style::kNone:
      return;
    // Redraw at most every min_redraw_s
    case Style::kBar:
      if (progress.wall_s - last_draw_wall_s_ >= min_redraw_s_) Draw(progress);
      return;
    // One line per 10 % mark passed (several marks at once give one line)
    case Style::kLines: {
      const int percent = Percent(progress);
      if (percent < next_mark_percent_) return;
      err_ << FormatProgressLine(progress) << '\n' << std::flush;
      next_mark_percent_ = (percent / 10 + 1) * 10;
      return;
    }
  }
}

void ProgressBar::Draw(const SimulationProgress& progress) {
  // Overwrite the previous bar, padding with blanks if it was longer
  const std::string line = FormatProgressBar(progress);
  err_ << '\r' << line;
  if (line.size() < drawn_width_) err_ << std::string(drawn_width_ - line.size(), ' ');
  err_ << std::flush;
  drawn_width_ = std::max(drawn_width_, line.size());
  last_draw_wall_s_ = progress.wall_s;
}

void ProgressBar::Finish() {
  if (style_ != Style::kBar || !updated_) return;
  Draw(last_);
  err_ << '\n' << std::flush;
  drawn_width_ = 0;
}

void ProgressBar::Abandon() {
  if (style_ != Style::kBar || drawn_width_ == 0) return;
  err_ << '\r' << std::string(drawn_width_, ' ') << '\r' << std::flush;
  drawn_width_ = 0;
}

}  // namespace orrery::cli
