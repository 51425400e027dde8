#include "tools/study/run_record.h"

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <sstream>
#include <stdexcept>

namespace orrery::study {
namespace {

constexpr std::string_view kMagic = "orrery-study-run 1";

std::string Hex(double x) {
  if (std::isnan(x)) return "nan";
  char buffer[64];
  std::snprintf(buffer, sizeof buffer, "%a", x);
  return buffer;
}

// A number written by Hex; throws when the text is not one
double ParseHex(const std::string& text, int line) {
  if (text == "nan") return std::numeric_limits<double>::quiet_NaN();
  char* end = nullptr;
  const double x = std::strtod(text.c_str(), &end);
  if (text.empty() || end != text.c_str() + text.size())
    throw std::runtime_error("line " + std::to_string(line) + ": not a number: '" + text + "'");
  return x;
}

int ParseInt(const std::string& text, int line) {
  char* end = nullptr;
  const long x = std::strtol(text.c_str(), &end, 10);
  if (text.empty() || end != text.c_str() + text.size())
    throw std::runtime_error("line " + std::to_string(line) + ": not an integer: '" + text + "'");
  return static_cast<int>(x);
}

std::string OneLine(std::string text) {
  for (char& c : text)
    if (c == '\n' || c == '\r') c = ' ';
  return text;
}

}  // namespace

std::string_view RunStatusName(RunStatus status) {
  switch (status) {
    case RunStatus::kOk: return "ok";
    case RunStatus::kFailed: return "failed";
    case RunStatus::kOutputFailed: return "output_failed";
  }
  return "?";
}

std::string EncodeRunRecord(const RunRecord& r, const std::vector<std::string>& parameters) {
  std::string s(kMagic);
  s += "\nrun " + std::to_string(r.run);
  s += "\nstatus " + std::string(RunStatusName(r.status));
  s += "\nexit_status " + std::to_string(r.exit_status);
  s += "\nwall_time_s " + Hex(r.wall_time_s);
  s += "\ncpu_time_s " + Hex(r.cpu_time_s);
  s += "\npeak_memory_mib " + Hex(r.peak_memory_mib);
  s += "\nrank " + std::to_string(r.rank);
  s += "\nhost " + OneLine(r.host);
  s += "\nreason " + OneLine(r.reason);
  for (std::size_t i = 0; i < r.outputs.size(); ++i) {
    s += "\noutput " + std::to_string(i) + " " + Hex(r.outputs[i]);
    if (i < r.units.size()) {
      s += ' ';
      s += OneLine(r.units[i]);
    }
  }
  for (const std::string& p : parameters) s += "\nparameter " + OneLine(p);
  s += "\nend\n";
  return s;
}

RunRecord DecodeRunRecord(std::string_view text) {
  std::istringstream in{std::string(text)};
  std::string line;
  if (!std::getline(in, line) || line != kMagic)
    throw std::runtime_error("line 1: not a run record");
  RunRecord r;
  bool has_run = false, has_status = false, ended = false;
  int number = 1;
  while (std::getline(in, line)) {
    ++number;
    if (line == "end") {
      ended = true;
      break;
    }
    const std::size_t space = line.find(' ');
    const std::string key = line.substr(0, space);
    const std::string value = space == std::string::npos ? "" : line.substr(space + 1);
    if (key == "run") {
      r.run = ParseInt(value, number);
      has_run = true;
    } else if (key == "status") {
      if (value == "ok")
        r.status = RunStatus::kOk;
      else if (value == "failed")
        r.status = RunStatus::kFailed;
      else if (value == "output_failed")
        r.status = RunStatus::kOutputFailed;
      else
        throw std::runtime_error("line " + std::to_string(number) + ": unknown status '" + value +
                                 "'");
      has_status = true;
    } else if (key == "exit_status") {
      r.exit_status = ParseInt(value, number);
    } else if (key == "wall_time_s") {
      r.wall_time_s = ParseHex(value, number);
    } else if (key == "cpu_time_s") {
      r.cpu_time_s = ParseHex(value, number);
    } else if (key == "peak_memory_mib") {
      r.peak_memory_mib = ParseHex(value, number);
    } else if (key == "rank") {
      r.rank = ParseInt(value, number);
    } else if (key == "host") {
      r.host = value;
    } else if (key == "reason") {
      r.reason = value;
    } else if (key == "output") {
      // index, value, unit (the rest of the line)
      const std::size_t a = value.find(' ');
      const std::size_t b = a == std::string::npos ? a : value.find(' ', a + 1);
      const int i = ParseInt(value.substr(0, a), number);
      if (i != static_cast<int>(r.outputs.size()))
        throw std::runtime_error("line " + std::to_string(number) + ": output " +
                                 std::to_string(i) + " out of order");
      r.outputs.push_back(
          ParseHex(a == std::string::npos ? "" : value.substr(a + 1, b - a - 1), number));
      r.units.push_back(b == std::string::npos ? "" : value.substr(b + 1));
    } else if (key != "parameter") {
      throw std::runtime_error("line " + std::to_string(number) + ": unknown key '" + key + "'");
    }
  }
  if (!has_run || !has_status || !ended)
    throw std::runtime_error("incomplete record (no run, status or end line)");
  return r;
}

}  // namespace orrery::study
