#include "tools/signal/signal_io.h"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>

namespace orrery::signal {
namespace {

[[noreturn]] void Fail(const Hdf5Reader& file, const std::string& object, const std::string& reason) {
  throw std::runtime_error(file.path() + ": " + object + ": " + reason);
}

std::vector<std::string> ColumnNames(const Hdf5Reader& file, const std::string& path) {
  return file.HasAttribute(path, "columns") ? SplitAttributeList(file.ReadStringAttribute(path, "columns"))
                                            : std::vector<std::string>{};
}

}  // namespace

std::vector<std::string> SplitAttributeList(const std::string& text) {
  std::vector<std::string> names;
  std::stringstream in(text);
  std::string name;
  while (std::getline(in, name, ',')) {
    name.erase(0, name.find_first_not_of(' '));
    name.erase(name.find_last_not_of(' ') + 1);
    names.push_back(name);
  }
  return names;
}

int DatasetColumn(const Hdf5Reader& file, const std::string& path, const std::string& column, int count) {
  if (column.empty()) return 0;
  // A number is an index
  std::size_t used = 0;
  int index = -1;
  try {
    index = std::stoi(column, &used);
  } catch (const std::exception&) {
    used = 0;
  }
  if (used == column.size()) {
    if (index < 0 || index >= count)
      Fail(file, path, "no column " + column + " (" + std::to_string(count) + " columns, indices from 0)");
    return index;
  }
  // A name is looked up in the "columns" attribute
  const std::vector<std::string> names = ColumnNames(file, path);
  const auto it = std::find(names.begin(), names.end(), column);
  if (it == names.end()) {
    std::string listed;
    for (const std::string& n : names) listed += (listed.empty() ? "" : ", ") + n;
    Fail(file, path, "no column '" + column + "'" + (listed.empty() ? " (the dataset names no columns)" : " (columns " + listed + ")"));
  }
  return static_cast<int>(it - names.begin());
}

std::string RecordedSignal::Describe() const { return file + ":" + path + "[" + column_name + "]"; }

RecordedSignal ReadSignal(const Hdf5Reader& file, const std::string& path, const std::string& column, double t0_s) {
  if (!file.IsDataset(path)) Fail(file, path, "no such dataset");
  if (!file.IsDataset("/time")) Fail(file, "/time", "no such dataset (not a result file?)");
  const Eigen::MatrixXd data = file.ReadMatrix(path);
  const std::vector<double> time = file.ReadVector("/time");
  if (data.rows() != static_cast<Eigen::Index>(time.size()))
    Fail(file, path, std::to_string(data.rows()) + " rows, /time has " + std::to_string(time.size()));

  // Column by index or name
  RecordedSignal s;
  s.file = file.path();
  s.path = path;
  if (file.HasAttribute(path, "unit")) s.unit = file.ReadStringAttribute(path, "unit");
  const std::vector<std::string> names = ColumnNames(file, path);
  s.column = DatasetColumn(file, path, column, static_cast<int>(data.cols()));
  s.column_name = s.column < static_cast<int>(names.size()) ? names[s.column] : std::to_string(s.column);

  // Rows from t0 on
  for (std::size_t i = 0; i < time.size(); ++i) {
    if (!(time[i] >= t0_s)) continue;
    const double v = data(static_cast<Eigen::Index>(i), s.column);
    if (!std::isfinite(v)) Fail(file, path, "value at t = " + std::to_string(time[i]) + " s is not finite");
    s.time_s.push_back(time[i]);
    s.values.push_back(v);
  }
  const int n = static_cast<int>(s.values.size());
  if (n < kMinSignalSamples) {
    std::ostringstream msg;
    msg << "record too short: " << n << " samples";
    if (std::isfinite(t0_s)) msg << " from t0 = " << t0_s << " s";
    msg << " (need at least " << kMinSignalSamples << ")";
    Fail(file, path, msg.str());
  }

  // Uniform sampling
  const double span = s.time_s.back() - s.time_s.front();
  const double step = span / (n - 1);
  for (int i = 1; i < n; ++i) {
    const double dt = s.time_s[i] - s.time_s[i - 1];
    if (!(std::abs(dt - step) <= 1e-3 * step)) {
      std::ostringstream msg;
      msg << "not uniformly sampled: step " << dt << " s at t = " << s.time_s[i] << " s, mean step " << step << " s";
      Fail(file, "/time", msg.str());
    }
  }
  s.sample_rate_hz = (n - 1) / span;
  return s;
}

std::string ReferenceAnglePath(const std::string& member) {
  return !member.empty() && member.front() == '/' ? member : "/joints/" + member + "/q";
}

std::vector<double> ReadReferenceAngle(const Hdf5Reader& file, const std::string& member, const RecordedSignal& signal) {
  const std::string path = ReferenceAnglePath(member);
  if (!file.IsDataset(path)) Fail(file, path, "no such dataset (reference member '" + member + "')");
  const Eigen::MatrixXd q = file.ReadMatrix(path);
  const std::vector<double> time = file.ReadVector("/time");
  if (q.rows() != static_cast<Eigen::Index>(time.size()) || q.cols() < 1)
    Fail(file, path, std::to_string(q.rows()) + " rows, /time has " + std::to_string(time.size()));
  // The rows of the signal: the last n rows from its first time on
  const auto first = std::lower_bound(time.begin(), time.end(), signal.time_s.front());
  const std::size_t start = static_cast<std::size_t>(first - time.begin());
  if (start + signal.values.size() > time.size()) Fail(file, path, "does not cover the signal's times");
  std::vector<double> angle(signal.values.size());
  for (std::size_t i = 0; i < angle.size(); ++i) angle[i] = q(static_cast<Eigen::Index>(start + i), 0);
  return angle;
}

bool HasKinematicLines(const Hdf5Reader& file) { return file.IsGroup("/kinematics/lines"); }

std::vector<KinematicLine> ReadKinematicLines(const Hdf5Reader& file) {
  const std::string group = "/kinematics/lines";
  if (!HasKinematicLines(file)) Fail(file, group, "no kinematic lines (the file was not written by a gear scene)");
  const std::vector<std::string> names = file.ReadStrings(group + "/name");
  const std::vector<double> frequencies = file.ReadVector(group + "/frequency_hz");
  const std::vector<std::string> kinds = file.ReadStrings(group + "/kind");
  if (names.size() != frequencies.size() || names.size() != kinds.size())
    Fail(file, group, "name, frequency_hz and kind differ in length (" + std::to_string(names.size()) + ", " +
                          std::to_string(frequencies.size()) + ", " + std::to_string(kinds.size()) + ")");
  if (names.empty()) Fail(file, group, "no kinematic lines (the datasets are empty)");
  std::vector<KinematicLine> lines(names.size());
  for (std::size_t i = 0; i < names.size(); ++i) {
    lines[i].name = names[i];
    lines[i].frequency_hz = frequencies[i];
    if (!std::isfinite(frequencies[i]) || frequencies[i] < 0)
      Fail(file, group + "/frequency_hz", "line '" + names[i] + "' has frequency " + std::to_string(frequencies[i]));
    try {
      lines[i].kind = ParseLineKind(kinds[i]);
    } catch (const std::invalid_argument& e) {
      Fail(file, group + "/kind", e.what());
    }
  }
  return lines;
}

}  // namespace orrery::signal
