#include "tools/study/study_index.h"

#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <limits>
#include <stdexcept>
#include <system_error>

#include "mbd/result_file.h"

namespace orrery::study {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// Whether `text` is one finite or infinite number, as the scene reader would read it
bool ParseNumber(const std::string& text, double* value) {
  if (text.empty()) return false;
  char* end = nullptr;
  *value = std::strtod(text.c_str(), &end);
  return end == text.c_str() + text.size() && !std::isnan(*value);
}

// A parameter column: numbers when every value is one
struct ParameterColumn {
  bool numeric = true;
  std::vector<double> numbers;
  std::vector<std::string> texts;
};

std::vector<ParameterColumn> ParameterColumns(const StudyPlan& plan) {
  std::vector<ParameterColumn> columns(plan.parameters.size());
  for (std::size_t k = 0; k < columns.size(); ++k) {
    ParameterColumn& c = columns[k];
    for (const RunSpec& run : plan.runs) {
      double x = 0;
      c.numeric = c.numeric && ParseNumber(run.values[k], &x);
      c.numbers.push_back(x);
      c.texts.push_back(run.values[k]);
    }
  }
  return columns;
}

// The shortest text that reads back as the same double
std::string Number(double x) {
  if (std::isnan(x)) return "nan";
  char buffer[40];
  const auto [end, ec] = std::to_chars(buffer, buffer + sizeof buffer, x);
  return ec == std::errc() ? std::string(buffer, end) : "nan";
}

std::string CsvField(const std::string& text) {
  if (text.find_first_of(",\"\r\n") == std::string::npos) return text;
  std::string quoted = "\"";
  for (char c : text) quoted += c == '"' ? std::string("\"\"") : std::string(1, c);
  return quoted + "\"";
}

std::string RelativeResult(const StudyFolder& folder, int run) {
  return std::filesystem::path(folder.ResultPath(run)).lexically_relative(folder.path()).string();
}

// The unit of output i: from the first record that has one
std::string OutputUnit(const std::vector<std::optional<RunRecord>>& records, std::size_t i) {
  for (const std::optional<RunRecord>& r : records)
    if (r && i < r->units.size() && !r->units[i].empty()) return r->units[i];
  return "";
}

void WriteHdf5(const StudyPlan& plan, const StudyFolder& folder,
               const std::vector<std::optional<RunRecord>>& records, const std::string& study_hash,
               const std::string& path) {
  const std::size_t n = records.size();
  ResultFile out = ResultFile::Create(path);
  // Runs
  std::vector<std::int64_t> run(n), exit_status(n), rank(n);
  std::vector<std::string> status(n), reason(n), result(n), host(n);
  std::vector<double> wall(n, kNaN), cpu(n, kNaN), memory(n, kNaN);
  for (std::size_t i = 0; i < n; ++i) {
    run[i] = static_cast<std::int64_t>(i);
    result[i] = RelativeResult(folder, static_cast<int>(i));
    const std::optional<RunRecord>& r = records[i];
    status[i] = r ? std::string(RunStatusName(r->status)) : "pending";
    exit_status[i] = r ? r->exit_status : 0;
    if (!r) continue;
    reason[i] = r->reason;
    rank[i] = r->rank;
    host[i] = r->host;
    wall[i] = r->wall_time_s, cpu[i] = r->cpu_time_s, memory[i] = r->peak_memory_mib;
  }
  out.WriteIntVector("/runs/run", run);
  out.WriteStrings("/runs/status", status);
  out.WriteIntVector("/runs/exit_status", exit_status);
  out.WriteStrings("/runs/reason", reason);
  out.WriteStrings("/runs/result_file", result);
  out.WriteIntVector("/runs/rank", rank);
  out.WriteStrings("/runs/host", host);
  out.WriteVector("/runs/wall_time_s", wall, "s");
  out.WriteVector("/runs/cpu_time_s", cpu, "s");
  out.WriteVector("/runs/peak_memory_mib", memory, "MiB");
  // Parameters
  const std::vector<ParameterColumn> columns = ParameterColumns(plan);
  out.WriteStrings("/parameters/keys", plan.parameters);
  for (std::size_t k = 0; k < columns.size(); ++k) {
    const std::string p = "/parameters/" + plan.parameters[k];
    if (columns[k].numeric)
      out.WriteVector(p, columns[k].numbers, "");
    else
      out.WriteStrings(p, columns[k].texts);
  }
  // Outputs
  std::vector<std::string> names;
  for (const StudyOutput& o : plan.study.outputs) names.push_back(o.name);
  out.WriteStrings("/outputs/names", names);
  for (std::size_t i = 0; i < names.size(); ++i) {
    std::vector<double> v(n, kNaN);
    for (std::size_t r = 0; r < n; ++r)
      if (records[r] && i < records[r]->outputs.size()) v[r] = records[r]->outputs[i];
    out.WriteVector("/outputs/" + names[i], v, OutputUnit(records, i));
  }
  // The study
  const StudyCounts c = CountRecords(records);
  out.SetAttribute("/", "study", plan.study.name);
  out.SetAttribute("/", "study_file", plan.study.file);
  out.SetAttribute("/", "study_hash", study_hash);
  out.SetAttribute("/", "scene", plan.study.scene_path);
  out.SetAttribute("/", "runs", static_cast<std::int64_t>(n));
  out.SetAttribute("/", "ok", static_cast<std::int64_t>(c.ok));
  out.SetAttribute("/", "failed", static_cast<std::int64_t>(c.failed));
  out.SetAttribute("/", "output_failed", static_cast<std::int64_t>(c.output_failed));
  out.SetAttribute("/", "pending", static_cast<std::int64_t>(c.pending));
  out.Close();
}

}  // namespace

StudyCounts CountRecords(const std::vector<std::optional<RunRecord>>& records) {
  StudyCounts c;
  for (const std::optional<RunRecord>& r : records) {
    if (!r)
      ++c.pending;
    else if (r->status == RunStatus::kOk)
      ++c.ok;
    else if (r->status == RunStatus::kFailed)
      ++c.failed;
    else
      ++c.output_failed;
  }
  return c;
}

std::string StudyIndexCsv(const StudyPlan& plan, const StudyFolder& folder,
                          const std::vector<std::optional<RunRecord>>& records) {
  // Header
  std::string csv = "run,status";
  const auto field = [&csv](const std::string& text) {
    csv += ',';
    csv += text;
  };
  for (const std::string& key : plan.parameters) field(CsvField(key));
  for (const StudyOutput& o : plan.study.outputs) field(CsvField(o.name));
  csv += ",wall_time_s,cpu_time_s,peak_memory_mib,exit_status,reason,rank,host,result_file\n";
  // One row per run
  const std::vector<ParameterColumn> columns = ParameterColumns(plan);
  for (std::size_t i = 0; i < records.size(); ++i) {
    const std::optional<RunRecord>& r = records[i];
    csv += std::to_string(i);
    field(r ? std::string(RunStatusName(r->status)) : "pending");
    for (const ParameterColumn& c : columns)
      field(c.numeric ? Number(c.numbers[i]) : CsvField(c.texts[i]));
    for (std::size_t k = 0; k < plan.study.outputs.size(); ++k)
      field(r && k < r->outputs.size() ? Number(r->outputs[k]) : std::string());
    if (r) {
      for (double x : {r->wall_time_s, r->cpu_time_s, r->peak_memory_mib}) field(Number(x));
      field(std::to_string(r->exit_status));
      field(CsvField(r->reason));
      field(std::to_string(r->rank));
      field(CsvField(r->host));
    } else {
      csv += ",,,,,,,";
    }
    field(CsvField(RelativeResult(folder, static_cast<int>(i))));
    csv += '\n';
  }
  return csv;
}

void WriteStudyIndex(const StudyPlan& plan, const StudyFolder& folder,
                     const std::vector<std::optional<RunRecord>>& records,
                     const std::string& study_hash) {
  WriteFileAtomically(folder.IndexCsvPath(), StudyIndexCsv(plan, folder, records));
  // HDF5: written beside, then renamed over the index
  const std::string h5 = folder.IndexHdf5Path(), tmp = h5 + ".tmp";
  WriteHdf5(plan, folder, records, study_hash, tmp);
  if (std::rename(tmp.c_str(), h5.c_str()) != 0)
    throw std::runtime_error(h5 + ": cannot rename " + tmp + " to it");
}

}  // namespace orrery::study
