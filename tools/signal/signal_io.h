#pragma once
// Signals and kinematic lines read from a result file (mbd/hdf5_reader.h), for the analyses of
// this folder and the `orrery spectrum | compare | octave` commands.
//
// A signal is one column of a time series dataset (rows at the times of /time, result_recorder.h),
// e.g. /bodies/S.planet1/angular_acceleration column z, or /gear_meshes/S1.sun-planet1/force. The
// recorded times must be uniform (the recorder's output interval); the sample rate is
// (n - 1) / (t_last - t_first).
//
// Every failure throws std::runtime_error naming the file and the dataset, e.g.
//   "run.h5: /bodies/planet/linear_acceleration: no such dataset"
//   "run.h5: /bodies/planet/linear_acceleration: no column 'w' (columns x, y, z)"
//   "run.h5: /kinematics/lines: no kinematic lines (the file was not written by a gear scene)"
//
// Usage:
//   Hdf5Reader file("run.h5");
//   RecordedSignal s = ReadSignal(file, "/bodies/planet/angular_acceleration", "z", 0.1);
//   std::vector<KinematicLine> lines = ReadKinematicLines(file);
#include <limits>
#include <string>
#include <vector>

#include "mbd/hdf5_reader.h"
#include "tools/signal/kinematic_lines.h"

namespace orrery::signal {

struct RecordedSignal {
  std::string file;            // the result file
  std::string path;            // the dataset
  std::string unit;            // its "unit" attribute ("" when it has none)
  std::string column_name;     // the column's name from the "columns" attribute, else its index
  int column = 0;              // 0-based column index
  std::vector<double> time_s;  // sample times (from t0 on)
  std::vector<double> values;  // the column's values at those times
  double sample_rate_hz = 0;
  std::string Describe() const;  // "run.h5:/bodies/planet/angular_acceleration[z]"
};

// The fewest samples an analysis accepts.
inline constexpr int kMinSignalSamples = 16;

// The entries of a comma-separated attribute ("x, y, z"), trimmed.
std::vector<std::string> SplitAttributeList(const std::string& text);
// The index of column `column` of dataset `path` (`count` columns): "" is 0, a number is an
// index, a name is looked up in the dataset's "columns" attribute. Throws
// "<file>: <path>: no column ..." naming the columns there are.
int DatasetColumn(const Hdf5Reader& file, const std::string& path, const std::string& column, int count);

// Column `column` (a 0-based index, or a name listed in the dataset's "columns" attribute; ""
// for the first) of dataset `path`, from time `t0_s` on. Throws (see above) for a missing
// dataset or /time, a row count that differs from /time's, an unknown column, non-uniform or
// non-increasing times, non-finite values, or fewer than kMinSignalSamples samples from t0_s on.
RecordedSignal ReadSignal(const Hdf5Reader& file, const std::string& path, const std::string& column = "",
                          double t0_s = -std::numeric_limits<double>::infinity());

// The angle of a reference member for order analysis at the signal's times: `member` is a
// dataset path ("/joints/S.carrier/q") or a joint name ("S.carrier" for /joints/S.carrier/q);
// its first column, cut to the rows of `signal` (which must come from the same file).
std::vector<double> ReadReferenceAngle(const Hdf5Reader& file, const std::string& member, const RecordedSignal& signal);
// The dataset path ReadReferenceAngle reads for `member`.
std::string ReferenceAnglePath(const std::string& member);

// Whether the file holds /kinematics/lines.
bool HasKinematicLines(const Hdf5Reader& file);
// The lines of /kinematics/lines (layout in kinematic_lines.h). Throws when the group is missing
// or empty, the three datasets differ in length, a kind is unknown, or a frequency is not
// finite and >= 0.
std::vector<KinematicLine> ReadKinematicLines(const Hdf5Reader& file);

}  // namespace orrery::signal
