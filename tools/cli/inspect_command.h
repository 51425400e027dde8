#pragma once
// `orrery inspect FILE.h5`: what a result file holds, from Hdf5Reader::List().
//
// Prints the file's attributes (engine version, scene name, integrator, end time, ...; a
// multi-line value such as the stored scene as its first line and "(N lines)"), then the tree
// of groups and datasets: datasets with their shape ("21 x 3"), unit and other attributes,
// groups with their attributes. Example:
//
//   file     run.h5
//   engine_version  0.1.0
//   scene           name: p  (9 lines)
//   ...
//   /
//     bodies/
//       bob/
//         angular_acceleration   21 x 3  rad/s^2  columns=x,y,z
//     time                       21 x 1  s
//
// Failures (missing or unreadable file) print one line "orrery: error: <reason>" on `err` and
// return kExitFailure (1).
#include <ostream>
#include <string>

namespace orrery::cli {

struct InspectArgs {
  std::string path;  // the result file
};

// Runs the command; returns the process exit code.
int InspectCommand(const InspectArgs& args, std::ostream& out, std::ostream& err);

// An attribute value for one line of the listing: a multi-line value becomes its first line and
// "(N lines)"; a value longer than `max_chars` is cut and ends with "...".
std::string AttributeSummary(const std::string& value, std::size_t max_chars = 72);

}  // namespace orrery::cli
