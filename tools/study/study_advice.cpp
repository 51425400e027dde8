#include "tools/study/study_advice.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <filesystem>
#include <stdexcept>

#include "mbd/hdf5_reader.h"

namespace orrery::study {
namespace {

namespace fs = std::filesystem;

// One study's index, as far as advice needs it
struct IndexColumns {
  std::string label;                    // the folder's name
  std::vector<std::string> status;      // per run
  std::vector<std::string> parameters;  // per run: "key=value ..."
  std::vector<double> output, cost;     // per run
  std::string unit;                     // the output's unit
};

std::string ShortestText(double x) {
  char buffer[64];
  const auto r = std::to_chars(buffer, buffer + sizeof buffer, x);
  return std::string(buffer, r.ptr);
}

// A parameter column as text per run (numbers as the shortest text, else the YAML text)
std::vector<std::string> ParameterTexts(const Hdf5Reader& index, const std::string& key) {
  const std::string path = "/parameters/" + key;
  try {
    const std::vector<double> numbers = index.ReadVector(path);
    std::vector<std::string> texts;
    for (double x : numbers) texts.push_back(ShortestText(x));
    return texts;
  } catch (const std::exception&) {
    return index.ReadStrings(path);
  }
}

// The index file of a study folder or an index path, and the study's label
std::pair<std::string, std::string> IndexPath(const std::string& study) {
  const fs::path p(study);
  if (fs::is_directory(p)) return {(p / "index.h5").string(), p.filename().string()};
  fs::path folder = p.parent_path();
  std::string label = folder.filename().string();
  return {study, label.empty() ? p.stem().string() : label};
}

IndexColumns ReadIndex(const std::string& study, const AdviceRequest& q) {
  const auto [path, label] = IndexPath(study);
  if (!fs::is_regular_file(path))
    throw std::invalid_argument("--study " + study + ": no study index " + path +
                                " (a folder that `orrery study` wrote, or its index.h5)");
  const Hdf5Reader index(path);
  IndexColumns c;
  c.label = label;
  c.status = index.ReadStrings("/runs/status");
  const std::vector<std::string> names = index.ReadStrings("/outputs/names");
  if (std::find(names.begin(), names.end(), q.output) == names.end()) {
    std::string known;
    for (const std::string& n : names) known += (known.empty() ? "" : ", ") + n;
    throw std::invalid_argument("--output " + q.output + ": not an output of " + path +
                                " (outputs: " + known + ")");
  }
  const std::string output = "/outputs/" + q.output;
  c.output = index.ReadVector(output);
  if (index.HasAttribute(output, "unit")) c.unit = index.ReadStringAttribute(output, "unit");
  c.cost = index.ReadVector("/runs/" + q.cost);
  // Parameters as "key=value ..."
  c.parameters.assign(c.status.size(), "");
  for (const std::string& key : index.ReadStrings("/parameters/keys")) {
    const std::vector<std::string> texts = ParameterTexts(index, key);
    for (std::size_t r = 0; r < texts.size() && r < c.parameters.size(); ++r)
      c.parameters[r] += (c.parameters[r].empty() ? "" : " ") + key + "=" + texts[r];
  }
  if (c.output.size() != c.status.size() || c.cost.size() != c.status.size())
    throw std::runtime_error(path + ": columns of different lengths");
  return c;
}

// The reference as (study position, run); "" is the last run of the last study
std::pair<std::size_t, int> ParseReference(const std::string& text,
                                           const std::vector<IndexColumns>& indexes) {
  if (text.empty()) return {indexes.size() - 1, static_cast<int>(indexes.back().status.size()) - 1};
  std::size_t study = indexes.size() - 1;
  std::string run_text = text;
  if (const std::size_t colon = text.rfind(':'); colon != std::string::npos) {
    const std::string label = text.substr(0, colon);
    run_text = text.substr(colon + 1);
    study = indexes.size();
    for (std::size_t i = 0; i < indexes.size(); ++i)
      if (indexes[i].label == label) study = i;
    if (study == indexes.size())
      throw std::invalid_argument("--reference " + text + ": no study '" + label +
                                  "' among --study (labels are the folders' names)");
  }
  int run = -1;
  const auto r = std::from_chars(run_text.data(), run_text.data() + run_text.size(), run);
  if (r.ec != std::errc() || r.ptr != run_text.data() + run_text.size() || run < 0 ||
      run >= static_cast<int>(indexes[study].status.size()))
    throw std::invalid_argument("--reference " + text + ": not a run of study " +
                                indexes[study].label + " (0 to " +
                                std::to_string(indexes[study].status.size() - 1) + ")");
  return {study, run};
}

bool Usable(const IndexColumns& c, std::size_t r) {
  return c.status[r] == "ok" && std::isfinite(c.output[r]) && std::isfinite(c.cost[r]);
}

void CheckRequest(const AdviceRequest& q) {
  if (q.studies.empty()) throw std::invalid_argument("--study: give at least one study folder");
  if (!(q.error_bound > 0) || !std::isfinite(q.error_bound))
    throw std::invalid_argument("--error " + ShortestText(q.error_bound) +
                                ": the bound must be a positive number");
  if (q.cost != "cpu_time_s" && q.cost != "wall_time_s" && q.cost != "peak_memory_mib")
    throw std::invalid_argument("--cost " + q.cost +
                                ": one of cpu_time_s, wall_time_s, peak_memory_mib");
  if (q.output.empty()) throw std::invalid_argument("--output: name an output of the study");
}

}  // namespace

std::vector<bool> ParetoFront(const std::vector<double>& cost, const std::vector<double>& error) {
  if (cost.size() != error.size())
    throw std::invalid_argument("ParetoFront: " + std::to_string(cost.size()) + " costs, " +
                                std::to_string(error.size()) + " errors");
  std::vector<bool> front(cost.size(), true);
  for (std::size_t i = 0; i < cost.size(); ++i)
    for (std::size_t j = 0; j < cost.size() && front[i]; ++j)
      if (j != i && cost[j] <= cost[i] && error[j] <= error[i] &&
          (cost[j] < cost[i] || error[j] < error[i]))
        front[i] = false;
  return front;
}

Advice AdviseSetting(const AdviceRequest& q) {
  CheckRequest(q);
  std::vector<IndexColumns> indexes;
  for (const std::string& s : q.studies) indexes.push_back(ReadIndex(s, q));
  const auto [ref_study, ref_run] = ParseReference(q.reference, indexes);
  const IndexColumns& rc = indexes[ref_study];
  const std::string ref_name = rc.label + " run " + std::to_string(ref_run);
  if (!Usable(rc, static_cast<std::size_t>(ref_run)))
    throw std::invalid_argument("--reference: " + ref_name + " is not usable (status " +
                                rc.status[ref_run] + ", " + q.output + " " +
                                ShortestText(rc.output[ref_run]) + ", " + q.cost + " " +
                                ShortestText(rc.cost[ref_run]) + ")");
  const double x_ref = rc.output[ref_run];
  if (q.relative && x_ref == 0)
    throw std::invalid_argument("--error: the reference's " + q.output + " (" + ref_name +
                                ") is 0, so a relative error has no meaning; use --absolute");
  // Every usable run with its error
  Advice a;
  a.unit = indexes.back().unit;
  for (std::size_t s = 0; s < indexes.size(); ++s) {
    const IndexColumns& c = indexes[s];
    for (std::size_t r = 0; r < c.status.size(); ++r) {
      if (!Usable(c, r)) {
        ++a.skipped;
        continue;
      }
      MeasuredSetting m;
      m.study = c.label, m.run = static_cast<int>(r), m.parameters = c.parameters[r];
      m.value = c.output[r], m.cost = c.cost[r];
      m.error = std::abs(m.value - x_ref) / (q.relative ? std::abs(x_ref) : 1.0);
      m.reference = s == ref_study && static_cast<int>(r) == ref_run;
      if (m.reference) m.error = 0;
      a.settings.push_back(m);
    }
  }
  std::stable_sort(a.settings.begin(), a.settings.end(), [](const auto& x, const auto& y) {
    return x.cost < y.cost || (x.cost == y.cost && x.error < y.error);
  });
  // The front and the cheapest setting within the bound
  std::vector<double> cost, error;
  for (const MeasuredSetting& m : a.settings) cost.push_back(m.cost), error.push_back(m.error);
  const std::vector<bool> front = ParetoFront(cost, error);
  for (std::size_t i = 0; i < a.settings.size(); ++i) {
    a.settings[i].on_front = front[i];
    if (a.settings[i].reference) a.reference = static_cast<int>(i);
    if (a.chosen < 0 && a.settings[i].error <= q.error_bound) a.chosen = static_cast<int>(i);
  }
  return a;
}

}  // namespace orrery::study
