#include "tools/cli/advise_command.h"

#include <charconv>
#include <cmath>
#include <cstdio>
#include <stdexcept>

#include "tools/cli/error_message.h"
#include "tools/cli/json_writer.h"
#include "tools/study/study_advice.h"

namespace orrery::cli {
namespace {

using study::Advice;
using study::AdviceRequest;
using study::MeasuredSetting;

// The bound: "0.01" or "1%" (relative), a number in the output's unit with --absolute
double ParseBound(const AdviseArgs& a) {
  std::string text = a.error;
  const bool percent = !text.empty() && text.back() == '%';
  if (percent) text.pop_back();
  double x = 0;
  const auto r = std::from_chars(text.data(), text.data() + text.size(), x);
  if (text.empty() || r.ec != std::errc() || r.ptr != text.data() + text.size() ||
      !std::isfinite(x) || x <= 0)
    throw std::invalid_argument("--error " + a.error +
                                ": the bound must be a positive number (0.01, 1%)");
  if (percent && a.absolute)
    throw std::invalid_argument("--error " + a.error +
                                ": a percentage is a relative bound; drop --absolute");
  return percent ? x / 100 : x;
}

std::string CostColumn(const std::string& cost) {
  if (cost == "cpu") return "cpu_time_s";
  if (cost == "wall") return "wall_time_s";
  if (cost == "memory") return "peak_memory_mib";
  throw std::invalid_argument("--cost " + cost + ": one of cpu, wall, memory");
}

std::string Num(double x) {
  char b[32];
  std::snprintf(b, sizeof b, "%.6g", x);
  return b;
}

std::string ErrorText(double e, bool relative) { return relative ? Num(100 * e) + " %" : Num(e); }

std::string Line(const MeasuredSetting& m, const AdviseArgs& a, const std::string& unit) {
  return m.study + " run " + std::to_string(m.run) + " (" + m.parameters + "): " + a.output +
         " = " + Num(m.value) + (unit.empty() || unit == "1" ? "" : " " + unit) + ", error " +
         ErrorText(m.error, !a.absolute) + ", " + a.cost + " " + Num(m.cost) +
         (a.cost == "memory" ? " MiB" : " s");
}

void Setting(JsonWriter& w, const MeasuredSetting& m) {
  w.BeginObject().Key("study").String(m.study).Key("run").Int(m.run);
  w.Key("parameters").String(m.parameters).Key("value").Number(m.value);
  w.Key("error").Number(m.error).Key("cost").Number(m.cost).EndObject();
}

void WriteJson(std::ostream& out, const AdviceRequest& q, const Advice& v) {
  JsonWriter w(out);
  w.BeginObject().Key("output").String(q.output).Key("unit").String(v.unit);
  w.Key("cost").String(q.cost).Key("bound").Number(q.error_bound).Key("relative").Bool(q.relative);
  w.Key("reference");
  Setting(w, v.settings[v.reference]);
  w.Key("advice");
  Setting(w, v.settings[v.chosen]);
  w.Key("reference_only").Bool(v.chosen == v.reference).Key("skipped").Int(v.skipped);
  w.Key("front").BeginArray();
  for (const MeasuredSetting& m : v.settings)
    if (m.on_front) Setting(w, m);
  w.EndArray().EndObject();
  out << "\n";
}

void WriteText(std::ostream& out, const AdviseArgs& a, const AdviceRequest& q, const Advice& v) {
  out << "reference  " << Line(v.settings[v.reference], a, v.unit) << "\n";
  const std::string bound = a.absolute ? Num(q.error_bound) : Num(100 * q.error_bound) + " %";
  if (v.chosen == v.reference)
    out << "advice     no measured setting but the reference meets " << bound
        << ": the reference itself (its own error is that of its convergence, not measured)\n";
  else
    out << "advice     " << Line(v.settings[v.chosen], a, v.unit) << " (bound " << bound << ")\n";
  out << "front      " << a.cost << " cost against error, cheapest first (" << v.settings.size()
      << " runs measured" << (v.skipped ? ", " + std::to_string(v.skipped) + " not usable" : "")
      << "):\n";
  for (const MeasuredSetting& m : v.settings)
    if (m.on_front)
      out << "  " << Num(m.cost) << (a.cost == "memory" ? " MiB" : " s") << "  error "
          << ErrorText(m.error, !a.absolute) << "  " << m.study << " run " << m.run << " ("
          << m.parameters << ")" << (m.reference ? " [reference]" : "") << "\n";
}

}  // namespace

int AdviseCommand(const AdviseArgs& a, std::ostream& out, std::ostream& err) {
  AdviceRequest q;
  Advice v;
  try {
    q.studies = a.studies;
    q.output = a.output;
    q.error_bound = ParseBound(a);
    q.relative = !a.absolute;
    q.cost = CostColumn(a.cost);
    q.reference = a.reference;
    v = study::AdviseSetting(q);
  } catch (const std::invalid_argument& e) {
    ReportError(err, e.what());
    return kExitUsage;
  } catch (const std::exception& e) {
    ReportError(err, e.what());
    return kExitFailure;
  }
  if (a.json)
    WriteJson(out, q, v);
  else
    WriteText(out, a, q, v);
  return kExitSuccess;
}

}  // namespace orrery::cli
