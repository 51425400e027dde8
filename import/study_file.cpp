#include "import/study_file.h"

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>

#include "import/scene_reader.h"

namespace orrery {
namespace {

using namespace scene_reader;

// "FILE:LINE: PATH" of an item, for errors found after reading.
std::string Where(const Context& ctx, const Item& it) {
  std::string w = ctx.file();
  if (it.mark.line >= 0) w += ":" + std::to_string(it.mark.line + 1);
  return w + ": " + it.path;
}

// A study value as text for `--set key=TEXT`: a plain scalar as written, anything else as flow
// YAML (quoted strings kept quoted).
std::string ValueText(const Context& ctx, const Item& it) {
  if (!it.node.IsDefined() || it.node.IsNull())
    ctx.Fail(it, "expected a value, got nothing (null)");
  if (it.node.IsScalar() && it.node.Tag() != "!") return it.node.Scalar();
  YAML::Emitter out;
  EmitYaml(out, it.node, true);
  return out.c_str();
}

// A scene key path as `--set` takes it: no blanks, no '=', no empty element.
std::string SceneKey(const Context& ctx, const Item& it) {
  const std::string key = ToString(ctx, it);
  if (key.find_first_of(" \t=") != std::string::npos)
    ctx.Fail(it, "'" + key + "' is not a scene key path (a.b.c or a[name].c, no blanks or '=')");
  if (key.front() == '.' || key.back() == '.' || key.find("..") != std::string::npos)
    ctx.Fail(it, "'" + key + "' has an empty element");
  return key;
}

// Keys set by the study: each scene key once, across end_time, output_interval, settings and axes.
class KeyRegistry {
 public:
  explicit KeyRegistry(const Context& ctx) : ctx_(ctx) {}
  void Add(const std::string& key, const Item& at) {
    for (const auto& [seen, where] : keys_)
      if (seen == key) ctx_.Fail(at, "scene key '" + key + "' is already set at " + where);
    keys_.emplace_back(key, Where(ctx_, at));
  }

 private:
  const Context& ctx_;
  std::vector<std::pair<std::string, std::string>> keys_;
};

StudyRange ReadRange(const Context& ctx, const Item& item) {
  const MapReader m(ctx, item, {"start", "stop", "step", "count", "spacing"});
  StudyRange r;
  r.start = m.Number("start");
  r.stop = m.Number("stop");
  if (m.Has("step") == m.Has("count")) ctx.Fail(item, "give either 'step' or 'count'");
  r.log = m.Choice("spacing", {"linear", "log"}, "linear") == "log";
  if (const auto step = m.Find("step")) {
    r.step = ToNumber(ctx, *step);
    if (r.log) ctx.Fail(*m.Find("spacing"), "log spacing takes a 'count', not a 'step'");
    if (r.step == 0 || (r.stop - r.start) * r.step < 0)
      ctx.Fail(*step, "the step must be non-zero and point from start toward stop, got " +
                          step->node.Scalar());
    if ((r.stop - r.start) / r.step > 1e6)
      ctx.Fail(*step, "more than 10^6 values from start to stop");
  } else {
    const Item count = m.Need("count");
    r.count = ToInt(ctx, count);
    if (r.count < 1)
      ctx.Fail(count, "an axis needs at least one value, got count " + count.node.Scalar());
    if (r.count > 1000000) ctx.Fail(count, "more than 10^6 values");
  }
  if (r.log && !(r.start > 0 && r.stop > 0)) ctx.Fail(item, "log spacing needs start and stop > 0");
  return r;
}

StudyAxis ReadAxis(const Context& ctx, const Item& item, KeyRegistry& keys) {
  const MapReader m(ctx, item, {"key", "values", "range"},
                    {{"uniform", "random values belong in a 'random:' entry"},
                     {"log_uniform", "random values belong in a 'random:' entry"},
                     {"choice", "random values belong in a 'random:' entry"}});
  StudyAxis axis;
  const Item key = m.Need("key");
  axis.key = SceneKey(ctx, key);
  axis.at = Where(ctx, key);
  keys.Add(axis.key, key);
  if (m.Has("values") == m.Has("range")) ctx.Fail(item, "give either 'values' or 'range'");
  if (const auto values = m.Find("values")) {
    if (!values->node.IsSequence())
      ctx.Fail(*values, "expected a list of values, got " + Describe(values->node));
    if (values->node.size() == 0)
      ctx.Fail(*values, "an axis needs at least one value, got an empty list");
    for (size_t i = 0; i < values->node.size(); ++i)
      axis.values.push_back(ValueText(ctx, Element(*values, i)));
  } else {
    axis.range = ReadRange(ctx, m.Need("range"));
    for (const double v : ExpandStudyRange(*axis.range)) axis.values.push_back(RangeValueText(v));
  }
  return axis;
}

std::size_t AxisLength(const StudyAxis& axis) { return axis.values.size(); }

StudyBlock ReadRandom(const Context& ctx, const Item& item, KeyRegistry& keys) {
  const MapReader m(ctx, item, {"samples", "seed", "keys"});
  StudyBlock block;
  block.kind = StudyBlock::Kind::kRandom;
  const Item samples = m.Need("samples");
  block.samples = ToInt(ctx, samples);
  if (block.samples < 1)
    ctx.Fail(samples, "needs at least one sample, got " + samples.node.Scalar());
  const Item seed = m.Need("seed");
  const int seed_value = ToInt(ctx, seed);
  if (seed_value < 0) ctx.Fail(seed, "must be >= 0, got " + seed.node.Scalar());
  block.seed = static_cast<std::uint64_t>(seed_value);
  const Item list = m.Need("keys");
  const std::vector<Item> items = ListItems(ctx, list);
  if (items.empty()) ctx.Fail(list, "needs at least one key");
  for (const Item& k : items) {
    const MapReader km(ctx, k, {"key", "uniform", "log_uniform", "choice"});
    StudyRandomKey& r = block.keys.emplace_back();
    const Item key = km.Need("key");
    r.key = SceneKey(ctx, key);
    r.at = Where(ctx, key);
    keys.Add(r.key, key);
    const int given = int(km.Has("uniform")) + int(km.Has("log_uniform")) + int(km.Has("choice"));
    if (given != 1) ctx.Fail(k, "give exactly one of 'uniform', 'log_uniform' or 'choice'");
    if (const auto choice = km.Find("choice")) {
      r.distribution = StudyDistribution::kChoice;
      if (!choice->node.IsSequence() || choice->node.size() == 0)
        ctx.Fail(*choice, "expected a non-empty list of values, got " + Describe(choice->node));
      for (size_t i = 0; i < choice->node.size(); ++i)
        r.choices.push_back(ValueText(ctx, Element(*choice, i)));
      continue;
    }
    const bool log = km.Has("log_uniform");
    r.distribution = log ? StudyDistribution::kLogUniform : StudyDistribution::kUniform;
    const Item bounds = km.Need(log ? "log_uniform" : "uniform");
    const std::vector<double> b = ToNumbers(ctx, bounds, 2);
    r.low = b[0], r.high = b[1];
    if (!(r.low < r.high)) ctx.Fail(bounds, "expected [low, high] with low < high");
    if (log && !(r.low > 0)) ctx.Fail(bounds, "log_uniform needs low > 0");
  }
  return block;
}

StudyBlock ReadBlock(const Context& ctx, const Item& item, KeyRegistry& keys) {
  StudyBlock block;
  block.at = Where(ctx, item);
  if (item.node.IsMap() && RawField(item, "zip")) {
    const MapReader m(ctx, item, {"zip"});
    block.kind = StudyBlock::Kind::kZip;
    const Item list = m.Need("zip");
    const std::vector<Item> items = ListItems(ctx, list);
    if (items.size() < 2) ctx.Fail(list, "zip needs at least two axes");
    for (const Item& a : items) {
      block.axes.push_back(ReadAxis(ctx, a, keys));
      if (AxisLength(block.axes.back()) != AxisLength(block.axes.front()))
        ctx.Fail(a, "zipped axes need equal lengths: " +
                        std::to_string(AxisLength(block.axes.back())) + " values here, " +
                        std::to_string(AxisLength(block.axes.front())) + " in the first");
    }
  } else if (item.node.IsMap() && RawField(item, "random")) {
    const MapReader m(ctx, item, {"random"});
    block = ReadRandom(ctx, m.Need("random"), keys);
    block.at = Where(ctx, item);
  } else {
    block.kind = StudyBlock::Kind::kAxis;
    block.axes.push_back(ReadAxis(ctx, item, keys));
  }
  return block;
}

// Output types and the keys each takes (besides name and type).
const std::vector<std::pair<std::string, StudyOutputKind>>& OutputTypes() {
  static const std::vector<std::pair<std::string, StudyOutputKind>> kTypes{
      {"peak", StudyOutputKind::kPeak},
      {"rms", StudyOutputKind::kRms},
      {"mean", StudyOutputKind::kMean},
      {"min", StudyOutputKind::kMin},
      {"max", StudyOutputKind::kMax},
      {"final", StudyOutputKind::kFinal},
      {"amplitude", StudyOutputKind::kAmplitude},
      {"sideband_energy_ratio", StudyOutputKind::kSidebandEnergyRatio},
      {"indicator", StudyOutputKind::kIndicator},
      {"max_stress", StudyOutputKind::kMaxStress}};
  return kTypes;
}

std::vector<std::string> OutputKeys(StudyOutputKind kind) {
  std::vector<std::string> keys{"name", "type", "from", "from_fraction", "to"};
  const auto add = [&](std::initializer_list<const char*> more) {
    keys.insert(keys.end(), more.begin(), more.end());
  };
  switch (kind) {
    case StudyOutputKind::kMaxStress: add({"body"}); break;
    case StudyOutputKind::kAmplitude:
      add({"dataset", "column", "window", "frequency_hz", "line", "harmonic", "sideband",
           "modulation", "modulation_hz"});
      break;
    case StudyOutputKind::kSidebandEnergyRatio:
      add({"dataset", "column", "window", "mesh", "mesh_hz", "modulation", "modulation_hz",
           "harmonics", "sidebands"});
      break;
    case StudyOutputKind::kIndicator:
      add({"dataset", "column", "indicator", "tsa", "mesh_order", "mesh", "mesh_hz",
           "samples_per_revolution"});
      break;
    default: add({"dataset", "column"}); break;
  }
  return keys;
}

// One of `a` (a name) or `b` (a positive frequency), required when `required`.
void LineOrFrequency(const MapReader& m, const std::string& a, const std::string& b,
                     std::string& name, double& hz, bool required) {
  if (m.Has(a) && m.Has(b))
    m.ctx().Fail(*m.Find(b), "give either '" + a + "' or '" + b + "', not both");
  if (const auto it = m.Find(a)) name = ToString(m.ctx(), *it);
  if (const auto it = m.Find(b)) {
    hz = ToNumber(m.ctx(), *it);
    if (!(hz > 0)) m.ctx().Fail(*it, "must be > 0 (Hz), got " + it->node.Scalar());
  }
  if (required && name.empty() && hz == 0)
    m.FailMissing(
        a, "missing required key '" + a + "' (a kinematic line of the result file) or '" + b + "'");
}

int AtLeast(const MapReader& m, const std::string& key, int fallback, int lo) {
  const auto it = m.Find(key);
  if (!it) return fallback;
  const int v = ToInt(m.ctx(), *it);
  if (v < lo) m.ctx().Fail(*it, "must be >= " + std::to_string(lo) + ", got " + it->node.Scalar());
  return v;
}

// The keys of the spectral and indicator outputs.
void ReadAnalysis(const MapReader& m, StudyOutput& o) {
  const Context& ctx = m.ctx();
  if (o.kind == StudyOutputKind::kAmplitude) {
    o.window = m.Choice("window", {"hann", "flattop", "rect"}, "hann");
    LineOrFrequency(m, "line", "frequency_hz", o.line, o.frequency_hz, true);
    o.harmonic = AtLeast(m, "harmonic", 1, 1);
    if (const auto it = m.Find("sideband")) o.sideband = ToInt(ctx, *it);
    LineOrFrequency(m, "modulation", "modulation_hz", o.modulation, o.modulation_hz,
                    o.sideband != 0);
    if (o.sideband == 0 && (m.Has("modulation") || m.Has("modulation_hz")))
      ctx.Fail(*m.Find(m.Has("modulation") ? "modulation" : "modulation_hz"),
               "a modulation goes with a 'sideband: n' (n != 0)");
  } else if (o.kind == StudyOutputKind::kSidebandEnergyRatio) {
    o.window = m.Choice("window", {"hann", "flattop", "rect"}, "hann");
    LineOrFrequency(m, "mesh", "mesh_hz", o.mesh, o.mesh_hz, true);
    LineOrFrequency(m, "modulation", "modulation_hz", o.modulation, o.modulation_hz, true);
    o.harmonics = AtLeast(m, "harmonics", 3, 1);
    o.sidebands = AtLeast(m, "sidebands", 6, 1);
  } else if (o.kind == StudyOutputKind::kIndicator) {
    o.indicator =
        m.Choice("indicator", {"rms", "peak", "crest_factor", "kurtosis", "fm0", "fm4", "na4"});
    if (m.Has("tsa")) o.tsa = m.String("tsa");
    o.mesh_order = AtLeast(m, "mesh_order", 0, 1);
    LineOrFrequency(m, "mesh", "mesh_hz", o.mesh, o.mesh_hz, false);
    if (o.mesh_order > 0 && (!o.mesh.empty() || o.mesh_hz > 0))
      ctx.Fail(*m.Find("mesh_order"), "give either 'mesh_order' or 'mesh'/'mesh_hz', not both");
    o.samples_per_revolution = AtLeast(m, "samples_per_revolution", 0, 8);
    const bool tsa_indicator = o.indicator == "fm0" || o.indicator == "fm4" || o.indicator == "na4";
    if (tsa_indicator && o.tsa.empty())
      m.FailMissing(
          "tsa",
          o.indicator + " is an indicator of a time-synchronous average: name the member in 'tsa'");
    if (!o.tsa.empty() && o.mesh_order == 0 && o.mesh.empty() && o.mesh_hz == 0)
      m.FailMissing("mesh_order",
                    "a time-synchronous average needs 'mesh_order' (teeth of the gear on the "
                    "member) or 'mesh'");
    if (o.tsa.empty() && (o.mesh_order > 0 || o.samples_per_revolution > 0))
      ctx.Fail(*m.Find(o.mesh_order > 0 ? "mesh_order" : "samples_per_revolution"),
               "goes with 'tsa'");
  }
}

StudyOutput ReadOutput(const Context& ctx, const Item& item) {
  std::vector<std::string> type_names;
  for (const auto& [name, kind] : OutputTypes()) type_names.push_back(name);
  const std::string type = ItemType(ctx, item, type_names);
  StudyOutput o;
  o.type = type;
  for (const auto& [name, kind] : OutputTypes())
    if (name == type) o.kind = kind;
  const MapReader m(ctx, item, OutputKeys(o.kind));
  const Item name = m.Need("name");
  o.name = ToString(ctx, name);
  const bool name_ok =
      std::isalpha(static_cast<unsigned char>(o.name.front())) &&
      o.name.find_first_not_of(
          "abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789_.-") == std::string::npos;
  if (!name_ok)
    ctx.Fail(name, "'" + o.name +
                       "' is not an output name (a letter, then letters, digits, '_', '.', '-')");
  o.at = Where(ctx, item);
  // Dataset and column, or the body of max_stress
  if (o.kind == StudyOutputKind::kMaxStress) {
    const Item body = m.Need("body");
    o.dataset = "/flexible_bodies/" + ToString(ctx, body) + "/von_mises_max";
  } else {
    const Item dataset = m.Need("dataset");
    o.dataset = ToString(ctx, dataset);
    if (o.dataset.front() != '/')
      ctx.Fail(dataset, "a dataset path starts with '/', got '" + o.dataset + "'");
    if (const auto column = m.Find("column")) o.column = ToString(ctx, *column);
  }
  // Time window
  o.from_s = m.Number("from", o.from_s);
  o.to_s = m.Number("to", o.to_s);
  if (const auto f = m.Find("from_fraction")) {
    if (m.Has("from")) ctx.Fail(*f, "give either from or from_fraction, not both");
    o.from_fraction = ToNumber(ctx, *f);
    if (!(o.from_fraction >= 0 && o.from_fraction < 1))
      ctx.Fail(*f, "from_fraction must be in [0, 1), got " + f->node.Scalar());
  }
  if (m.Has("from") && m.Has("to") && !(o.from_s < o.to_s))
    ctx.Fail(*m.Find("to"), "the window needs from < to, got from " + Num(o.from_s) + " s, to " +
                                Num(o.to_s) + " s");
  ReadAnalysis(m, o);
  return o;
}

// Column names of the index that outputs and parameters must not take.
const std::set<std::string>& ReservedColumns() {
  static const std::set<std::string> kReserved{
      "run",        "status",          "exit_status", "reason", "wall_time_s",
      "cpu_time_s", "peak_memory_mib", "rank",        "host",   "result_file"};
  return kReserved;
}

void ReadSettings(const Context& ctx, const MapReader& top, StudyDescription& s,
                  KeyRegistry& keys) {
  // end_time and output_interval: solver.end_time and output.interval
  for (const auto& [key, scene_key] :
       {std::pair<const char*, const char*>{"end_time", "solver.end_time"},
        {"output_interval", "output.interval"}})
    if (const auto it = top.Find(key)) {
      const double v = ToNumber(ctx, *it);
      if (!(v > 0)) ctx.Fail(*it, "must be > 0 (s), got " + it->node.Scalar());
      keys.Add(scene_key, *it);
      s.settings.push_back({scene_key, it->node.Scalar(), Where(ctx, *it)});
    }
  // settings: a map of scene keys
  if (const auto it = top.Find("settings")) {
    if (it->node.IsNull()) return;
    if (!it->node.IsMap())
      ctx.Fail(*it, "expected a map of scene keys and values, got " + Describe(it->node));
    for (auto kv = it->node.begin(); kv != it->node.end(); ++kv) {
      const Item key{kv->first, it->path + "." + (kv->first.IsScalar() ? kv->first.Scalar() : "?"),
                     kv->first.Mark()};
      const Item value{kv->second, key.path, kv->first.Mark()};
      const std::string k = SceneKey(ctx, key);
      keys.Add(k, key);
      s.settings.push_back({k, ValueText(ctx, value), Where(ctx, key)});
    }
  }
}

StudyDescription Read(const Context& ctx, const YAML::Node& root) {
  StudyDescription s;
  s.file = ctx.file();
  const MapReader top(ctx, {root, "", root.Mark()},
                      {"name", "scene", "folder", "end_time", "output_interval", "settings", "axes",
                       "outputs", "jobs", "limits"});
  const std::filesystem::path file(ctx.file());
  s.name = top.Has("name") ? top.String("name") : file.stem().string();
  // Base scene, relative to the study file
  const Item scene = top.Need("scene");
  const std::filesystem::path scene_path(ToString(ctx, scene));
  s.scene_path = (scene_path.is_absolute() ? scene_path : file.parent_path() / scene_path)
                     .lexically_normal()
                     .string();
  s.scene_at = Where(ctx, scene);
  if (top.Has("folder")) s.folder = top.String("folder");
  KeyRegistry keys(ctx);
  ReadSettings(ctx, top, s, keys);
  // Axes
  if (const auto axes = top.Find("axes"))
    for (const Item& item : ListItems(ctx, axes)) s.blocks.push_back(ReadBlock(ctx, item, keys));
  // Outputs
  std::set<std::string> names;
  for (const Item& item : ListItems(ctx, top.Find("outputs"))) {
    s.outputs.push_back(ReadOutput(ctx, item));
    const std::string& n = s.outputs.back().name;
    if (ReservedColumns().count(n) > 0)
      ctx.Fail(item, "output name '" + n + "' is a column of the index already");
    if (!names.insert(n).second) ctx.Fail(item, "duplicate output name '" + n + "'");
  }
  // Execution
  s.jobs = AtLeast(top, "jobs", 0, 1);
  if (const auto limits = top.Find("limits")) {
    const MapReader m(ctx, *limits, {"wall_time_s", "memory_mib"});
    for (const auto& [key, field] :
         {std::pair<const char*, double*>{"wall_time_s", &s.limits.wall_time_s},
          {"memory_mib", &s.limits.memory_mib}})
      if (const auto it = m.Find(key)) {
        *field = ToNumber(ctx, *it);
        if (!(*field > 0)) ctx.Fail(*it, "must be > 0, got " + it->node.Scalar());
      }
  }
  return s;
}

}  // namespace

std::vector<double> ExpandStudyRange(const StudyRange& r) {
  std::vector<double> v;
  if (r.count == 0) {
    // start + i step up to stop, stop included within 1e-9 of a step
    const double q = (r.stop - r.start) / r.step;
    const auto n = static_cast<std::size_t>(std::floor(q + 1e-9)) + 1;
    for (std::size_t i = 0; i < n; ++i) v.push_back(r.start + static_cast<double>(i) * r.step);
    return v;
  }
  // count values from start to stop, both included
  for (int i = 0; i < r.count; ++i) {
    const double s = r.count == 1 ? 0.0 : static_cast<double>(i) / (r.count - 1);
    v.push_back(r.log ? r.start * std::pow(r.stop / r.start, s) : r.start + (r.stop - r.start) * s);
  }
  if (r.count > 1) v.back() = r.stop;
  return v;
}

std::string RangeValueText(double value) {
  char buffer[40];
  std::snprintf(buffer, sizeof buffer, "%.15g", value);
  return buffer;
}

StudyDescription ParseStudyFile(const std::string& text, const std::string& file) {
  YAML::Node root;
  try {
    root = YAML::Load(text);
  } catch (const YAML::ParserException& e) {
    throw SceneError(file + ":" + std::to_string(e.mark.line + 1) +
                     ": YAML syntax error: " + e.msg);
  } catch (const YAML::Exception& e) {
    throw SceneError(file + ": YAML error: " + e.msg);
  }
  if (root.IsNull()) throw SceneError(file + ": the study file is empty");
  if (!root.IsMap())
    throw SceneError(file + ":1: the study file must be a map of sections, got " + Describe(root));
  const Context ctx(file);
  return Read(ctx, root);
}

StudyDescription LoadStudyFile(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw SceneError(path + ": cannot open the study file");
  std::ostringstream text;
  text << in.rdbuf();
  return ParseStudyFile(text.str(), path);
}

}  // namespace orrery
