#include "tools/study/study_progress.h"

#include <cstdio>

namespace orrery::study {
namespace {

std::string Duration(double s) {
  char buffer[32];
  if (s < 60)
    std::snprintf(buffer, sizeof buffer, "%.1f s", s);
  else if (s < 3600)
    std::snprintf(buffer, sizeof buffer, "%d min %02d s", static_cast<int>(s) / 60,
                  static_cast<int>(s) % 60);
  else
    std::snprintf(buffer, sizeof buffer, "%d h %02d min", static_cast<int>(s) / 3600,
                  static_cast<int>(s) / 60 % 60);
  return buffer;
}

}  // namespace

StudyProgress::StudyProgress(std::ostream& err, Style style, std::string name, int runs,
                             int done_before, double min_redraw_s)
    : err_(err),
      style_(style),
      name_(std::move(name)),
      runs_(runs),
      done_before_(done_before),
      min_redraw_s_(min_redraw_s),
      start_(std::chrono::steady_clock::now()) {}

double StudyProgress::elapsed_s() const {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
}

std::string StudyProgress::Line(int done, int failed, int running) const {
  const double elapsed = elapsed_s();
  std::string line =
      "study " + name_ + ": " + std::to_string(done) + "/" + std::to_string(runs_) + " done";
  if (failed > 0) line += " (" + std::to_string(failed) + " failed)";
  line += ", " + std::to_string(running) + " running, " + Duration(elapsed) + " elapsed";
  const int finished_now = done - done_before_;
  if (done < runs_ && finished_now > 0)
    line += ", ~" + Duration(elapsed / finished_now * (runs_ - done)) + " left";
  return line;
}

void StudyProgress::Draw(const std::string& line, bool final) {
  if (style_ == Style::kBar) {
    std::string padded = line;
    if (padded.size() < drawn_width_) padded.append(drawn_width_ - padded.size(), ' ');
    err_ << '\r' << padded << (final ? "\n" : "") << std::flush;
    drawn_width_ = final ? 0 : line.size();
  } else {
    err_ << line << '\n' << std::flush;
  }
  last_draw_s_ = elapsed_s();
}

void StudyProgress::Update(int done, int failed, int running) {
  if (style_ == Style::kNone) return;
  const double now = elapsed_s();
  if (style_ == Style::kBar) {
    if (now - last_draw_s_ >= min_redraw_s_) Draw(Line(done, failed, running), false);
    return;
  }
  // Lines: when a run ended, at most every 10 s unless a tenth of the study passed
  if (done == last_line_done_) return;
  const bool tenth = (done - std::max(last_line_done_, 0)) * 10 >= runs_;
  if (last_line_done_ < 0 || now - last_draw_s_ >= 10 || tenth || runs_ <= 20) {
    Draw(Line(done, failed, running), false);
    last_line_done_ = done;
  }
}

void StudyProgress::RunFailed(const RunRecord& record) {
  if (style_ == Style::kNone) return;
  Abandon();
  err_ << "run " << record.run << " " << RunStatusName(record.status) << ": " << record.reason
       << '\n'
       << std::flush;
}

void StudyProgress::Finish(int done, int failed) {
  if (style_ == Style::kNone || (style_ == Style::kLines && done == last_line_done_)) return;
  Draw(Line(done, failed, 0), true);
}

void StudyProgress::Abandon() {
  if (style_ == Style::kBar && drawn_width_ > 0) {
    err_ << '\r' << std::string(drawn_width_, ' ') << '\r' << std::flush;
    drawn_width_ = 0;
    last_draw_s_ = -1e9;
  }
}

}  // namespace orrery::study
