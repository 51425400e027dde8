#pragma once
// `orrery advise --study DIR --output NAME --error BOUND`: the cheapest measured setting of one or
// more studies whose output lies within BOUND of the reference run's (tools/study/study_advice.h,
// docs/tradeoff.md). BOUND is a fraction (0.01) or a percentage (1%) of the reference value, or
// with --absolute a number in the output's unit. The text names the reference, the advice (its
// parameters, value, error and cost) and the Pareto front of (cost, error); --json the same as
// JSON: {"output", "unit", "cost", "bound", "relative", "reference": SETTING, "advice": SETTING,
// "reference_only": bool, "skipped": n, "front": [SETTING...]}, SETTING = {"study", "run",
// "parameters", "value", "error", "cost"}.
//
// Exit codes: 0 with advice (the reference itself when no other run meets the bound: the text
// says so), 2 for a bad argument (one line naming it), 1 when an index cannot be read.
//
// Usage:
//   AdviseArgs a;  a.studies = {"results/studies/tradeoff/seed003_lumped_healthy"};
//   a.output = "mesh_force_peak";  a.error = "1%";
//   int code = AdviseCommand(a, std::cout, std::cerr);
#include <ostream>
#include <string>
#include <vector>

namespace orrery::cli {

struct AdviseArgs {
  std::vector<std::string> studies;  // --study (repeatable): folders or index.h5 files
  std::string output;                // --output NAME
  std::string error;                 // --error BOUND: "0.01", "1%", or with --absolute "250"
  bool absolute = false;             // --absolute: BOUND in the output's unit
  std::string cost = "cpu";          // --cost cpu | wall | memory
  std::string reference;             // --reference [STUDY:]RUN ("" the last run of the last study)
  bool json = false;                 // --json
};

int AdviseCommand(const AdviseArgs& args, std::ostream& out, std::ostream& err);

}  // namespace orrery::cli
