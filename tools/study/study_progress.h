#pragma once
// Progress of a whole study on the error stream:
//   study quick: 4/6 done (1 failed), 2 running, 12.3 s elapsed, ~6.1 s left
// On a terminal one line redrawn in place with '\r' (at most every `min_redraw_s`); elsewhere a
// line whenever a run ends, at most one every 10 s unless a tenth of the study has passed since
// the last (so logs of large studies stay short); or nothing. A failed run always gets its own
// line ("run 3 failed: reason"). The time left is the wall time per run finished in this
// session times the runs still to do (runs recorded before a resume do not count toward it).
//
// Usage:
//   StudyProgress p(std::cerr, StudyProgress::Style::kBar, "quick", 6, 2);
//   p.Update(done, failed, running);  p.RunFailed(record);  p.Finish(done, failed);
#include <chrono>
#include <ostream>
#include <string>

#include "tools/study/run_record.h"

namespace orrery::study {

class StudyProgress {
 public:
  enum class Style { kBar, kLines, kNone };

  // `done_before`: runs already recorded when this session started.
  StudyProgress(std::ostream& err, Style style, std::string name, int runs, int done_before,
                double min_redraw_s = 0.25);

  // `done` and `failed` count every recorded run (failed includes output_failed).
  void Update(int done, int failed, int running);
  void RunFailed(const RunRecord& record);
  // The last line; ends the bar.
  void Finish(int done, int failed);
  // Erases the bar before another message.
  void Abandon();

  double elapsed_s() const;
  // The line as drawn (tests).
  std::string Line(int done, int failed, int running) const;

 private:
  void Draw(const std::string& line, bool final);
  std::ostream& err_;
  Style style_;
  std::string name_;
  int runs_ = 0, done_before_ = 0;
  double min_redraw_s_ = 0.25;
  std::chrono::steady_clock::time_point start_;
  double last_draw_s_ = -1e9;
  int last_line_done_ = -1;
  std::size_t drawn_width_ = 0;
};

}  // namespace orrery::study
