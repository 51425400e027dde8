#pragma once
// Helpers shared by the scene readers of import/ (scene.cpp: bodies and joints, overrides;
// gear_scene.cpp: lumped_stage and gear_train): key paths and "FILE:LINE: KEY: reason" errors
// (Context, Item), maps with a fixed set of keys (MapReader), typed reads, suggestions for
// misspelt keys and names, rotations, functions of time, and builder errors placed at their key.
// Internal to import/: it includes yaml-cpp, which no other folder sees.
#include <algorithm>
#include <cmath>
#include <map>
#include <numbers>
#include <optional>
#include <regex>
#include <sstream>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/SVD>
#include <yaml-cpp/yaml.h>

#include "import/scene.h"
#include "mbd/model.h"
#include "mbd/time_function.h"

namespace orrery::scene_reader {

inline constexpr double kDegToRad = std::numbers::pi / 180.0;
inline constexpr double kRpmToRadPerS = 2.0 * std::numbers::pi / 60.0;

// ---------------------------------------------------------------------------------------------
// Suggestions

// Optimal-string-alignment distance: insertions, deletions, substitutions, adjacent swaps.
inline int EditDistance(const std::string& a, const std::string& b) {
  const size_t n = a.size(), m = b.size();
  std::vector<std::vector<int>> d(n + 1, std::vector<int>(m + 1, 0));
  for (size_t i = 0; i <= n; ++i) d[i][0] = static_cast<int>(i);
  for (size_t j = 0; j <= m; ++j) d[0][j] = static_cast<int>(j);
  for (size_t i = 1; i <= n; ++i)
    for (size_t j = 1; j <= m; ++j) {
      const int cost = a[i - 1] == b[j - 1] ? 0 : 1;
      d[i][j] = std::min({d[i - 1][j] + 1, d[i][j - 1] + 1, d[i - 1][j - 1] + cost});
      if (i > 1 && j > 1 && a[i - 1] == b[j - 2] && a[i - 2] == b[j - 1])
        d[i][j] = std::min(d[i][j], d[i - 2][j - 2] + 1);
    }
  return d[n][m];
}

// "; did you mean 'x'?" for the closest candidate within edit distance 2, else "".
inline std::string DidYouMean(const std::string& word, const std::vector<std::string>& candidates) {
  std::string best;
  int best_distance = 3;
  for (const std::string& c : candidates) {
    const int dist = EditDistance(word, c);
    if (dist < best_distance) best = c, best_distance = dist;
  }
  return best.empty() ? "" : "; did you mean '" + best + "'?";
}

inline std::string JoinQuoted(const std::vector<std::string>& words) {
  std::string s;
  for (const std::string& w : words) s += (s.empty() ? "" : ", ") + w;
  return s;
}

// Suggestion if one is close, else the list of candidates (when short enough to be useful).
inline std::string SuggestOrList(const std::string& word, const std::vector<std::string>& candidates,
                          const std::string& what) {
  std::string s = DidYouMean(word, candidates);
  if (!s.empty()) return s;
  if (candidates.empty()) return " (there are no " + what + ")";
  if (candidates.size() <= 12) return " (" + what + ": " + JoinQuoted(candidates) + ")";
  return "";
}

inline std::string Num(double x) {
  std::ostringstream s;
  s << x;
  return s.str();
}

// ---------------------------------------------------------------------------------------------
// Context, items and errors

// One "--set key=value" after parsing: the value node is spliced into the tree.
struct OverrideSetting {
  std::string key;   // as the user wrote it
  std::string path;  // canonical key path ("bodies[bob].mass")
  YAML::Node value;
};

// A node of the scene with its key path and the line to report (the key's line for map entries).
struct Item {
  YAML::Node node;
  std::string path;
  YAML::Mark mark;
};

inline bool Contains(const YAML::Node& root, const YAML::Node& node) {
  if (root.is(node)) return true;
  if (root.IsSequence() || root.IsMap())
    for (auto it = root.begin(); it != root.end(); ++it) {
      if (root.IsSequence() && Contains(*it, node)) return true;
      if (root.IsMap() && (Contains(it->first, node) || Contains(it->second, node))) return true;
    }
  return false;
}

class Context {
 public:
  explicit Context(std::string file) : file_(std::move(file)) {}
  const std::string& file() const { return file_; }
  std::vector<OverrideSetting>& overrides() { return overrides_; }

  // Throws "FILE:LINE: PATH: reason", or "FILE: --set KEY: [PATH: ]reason" for override values.
  [[noreturn]] void Fail(const YAML::Node& node, const YAML::Mark& mark, const std::string& path,
                         const std::string& reason) const {
    for (const OverrideSetting& o : overrides_)
      if (node.IsDefined() && Contains(o.value, node))
        throw SceneError(file_ + ": --set " + o.key + ": " +
                         (path == o.path || path.empty() ? "" : path + ": ") + reason);
    std::string where = file_;
    if (mark.line >= 0) where += ":" + std::to_string(mark.line + 1);
    throw SceneError(where + ": " + (path.empty() ? "" : path + ": ") + reason);
  }
  [[noreturn]] void Fail(const Item& at, const std::string& reason) const {
    Fail(at.node, at.mark, at.path, reason);
  }
  // Errors in the override text itself: "FILE: --set KEY: reason".
  [[noreturn]] void FailOverride(const std::string& key, const std::string& reason) const {
    throw SceneError(file_ + ": --set " + key + ": " + reason);
  }

  // Whether a missing reduced-body file may be made from its reduce input (SceneLoadOptions).
  bool make_reduced_bodies() const { return make_reduced_bodies_; }
  void set_make_reduced_bodies(bool on) { make_reduced_bodies_ = on; }
  // Whether the scene's faults are left out (SceneLoadOptions::without_faults).
  bool without_faults() const { return without_faults_; }
  void set_without_faults(bool on) { without_faults_ = on; }
  // Other files the scene reads (Scene::input_files), noted by the readers as they go.
  void NoteInput(const std::string& path) const { inputs_.push_back(path); }
  const std::vector<std::string>& inputs() const { return inputs_; }

 private:
  std::string file_;
  std::vector<OverrideSetting> overrides_;
  bool make_reduced_bodies_ = false;
  bool without_faults_ = false;
  mutable std::vector<std::string> inputs_;
};

// What a node is, for "expected X, got Y".
inline std::string Describe(const YAML::Node& n) {
  switch (n.Type()) {
    case YAML::NodeType::Undefined:
    case YAML::NodeType::Null: return "nothing (null)";
    case YAML::NodeType::Scalar: {
      // At most 60 characters of a value (a binary file read as a scene is one long scalar)
      std::string value = n.Scalar();
      if (value.size() > 60) {
        value.resize(57);
        value += "...";
      }
      return n.Tag() == "!" ? "the quoted string \"" + value + "\"" : "'" + value + "'";
    }
    case YAML::NodeType::Sequence: return "a list of " + std::to_string(n.size());
    case YAML::NodeType::Map: return "a map";
  }
  return "?";
}

// The i-th element of a list.
inline Item Element(const Item& list, size_t i) {
  const YAML::Node n = list.node[i];
  return {n, list.path + "[" + std::to_string(i) + "]", n.Mark()};
}

// Unquoted scalars (numbers and booleans are never quoted in a scene).
inline bool IsPlainScalar(const YAML::Node& n) {
  return n.IsScalar() && n.Tag() != "!";
}

inline double ToNumber(const Context& ctx, const Item& it) {
  double x = 0;
  if (!IsPlainScalar(it.node) || !YAML::convert<double>::decode(it.node, x))
    ctx.Fail(it, "expected a number, got " + Describe(it.node));
  if (!std::isfinite(x)) ctx.Fail(it, "expected a finite number, got " + it.node.Scalar());
  return x;
}

inline int ToInt(const Context& ctx, const Item& it) {
  int x = 0;
  if (!IsPlainScalar(it.node) || !YAML::convert<int>::decode(it.node, x))
    ctx.Fail(it, "expected an integer, got " + Describe(it.node));
  return x;
}

inline bool ToBool(const Context& ctx, const Item& it) {
  bool x = false;
  if (!IsPlainScalar(it.node) || !YAML::convert<bool>::decode(it.node, x))
    ctx.Fail(it, "expected true or false, got " + Describe(it.node));
  return x;
}

inline std::string ToString(const Context& ctx, const Item& it) {
  if (!it.node.IsScalar() || it.node.Scalar().empty())
    ctx.Fail(it, "expected a name (a string), got " + Describe(it.node));
  return it.node.Scalar();
}

// A list of numbers; `n` >= 0 fixes its length.
inline std::vector<double> ToNumbers(const Context& ctx, const Item& it, int n) {
  const std::string expected = n == 1    ? "a list of 1 number"
                               : n >= 0  ? "a list of " + std::to_string(n) + " numbers"
                                         : "a list of numbers";
  if (!it.node.IsSequence()) ctx.Fail(it, "expected " + expected + ", got " + Describe(it.node));
  if (n >= 0 && static_cast<int>(it.node.size()) != n)
    ctx.Fail(it, "expected " + expected + ", got " + Describe(it.node));
  std::vector<double> x;
  for (size_t i = 0; i < it.node.size(); ++i) x.push_back(ToNumber(ctx, Element(it, i)));
  return x;
}

inline Vec3 ToVec3(const Context& ctx, const Item& it) {
  const std::vector<double> x = ToNumbers(ctx, it, 3);
  return Vec3(x[0], x[1], x[2]);
}

// Path of the i-th item of a list of named maps: "bodies[crank]", or "bodies[2]" without a name.
inline std::string ItemPath(const std::string& list_path, size_t i, const YAML::Node& item) {
  if (item.IsMap())
    for (auto it = item.begin(); it != item.end(); ++it)
      if (it->first.IsScalar() && it->first.Scalar() == "name" && it->second.IsScalar() &&
          !it->second.Scalar().empty())
        return list_path + "[" + it->second.Scalar() + "]";
  return list_path + "[" + std::to_string(i) + "]";
}

// The items of an optional list (null counts as empty).
inline std::vector<Item> ListItems(const Context& ctx, const std::optional<Item>& list) {
  std::vector<Item> items;
  if (!list || list->node.IsNull()) return items;
  if (!list->node.IsSequence()) ctx.Fail(*list, "expected a list, got " + Describe(list->node));
  for (size_t i = 0; i < list->node.size(); ++i) {
    const YAML::Node n = list->node[i];
    items.push_back({n, ItemPath(list->path, i, n), n.Mark()});
  }
  return items;
}

// ---------------------------------------------------------------------------------------------
// Maps with a fixed set of keys

class MapReader {
 public:
  // Checks that `item` is a map whose keys are all in `allowed` (no duplicates). `notes` explain
  // keys that are valid elsewhere but not here ("a spherical joint has no axis").
  MapReader(const Context& ctx, Item item, const std::vector<std::string>& allowed,
            const std::map<std::string, std::string>& notes = {})
      : ctx_(ctx), item_(std::move(item)) {
    if (!item_.node.IsMap()) ctx_.Fail(item_, "expected a map, got " + Describe(item_.node));
    for (auto it = item_.node.begin(); it != item_.node.end(); ++it) {
      const YAML::Node key = it->first, value = it->second;
      const std::string name = key.IsScalar() ? key.Scalar() : "?";
      const Item entry{value, Join(name), key.Mark()};
      if (!key.IsScalar()) ctx_.Fail(value, key.Mark(), item_.path, "keys must be plain names");
      if (std::find(allowed.begin(), allowed.end(), name) == allowed.end()) {
        const auto note = notes.find(name);
        if (note != notes.end()) ctx_.Fail(entry, "key not allowed here: " + note->second);
        std::string hint = DidYouMean(name, allowed);
        if (hint.empty()) hint = " (allowed: " + JoinQuoted(allowed) + ")";
        ctx_.Fail(entry, "unknown key '" + name + "'" + hint);
      }
      for (const auto& [seen, seen_item] : entries_)
        if (seen == name)
          ctx_.Fail(entry, "duplicate key '" + name + "'" +
                               (seen_item.mark.line >= 0
                                    ? " (first at line " + std::to_string(seen_item.mark.line + 1) + ")"
                                    : ""));
      entries_.emplace_back(name, entry);
    }
  }

  const Context& ctx() const { return ctx_; }
  const Item& item() const { return item_; }
  std::string Join(const std::string& key) const {
    return item_.path.empty() ? key : item_.path + "." + key;
  }

  std::optional<Item> Find(const std::string& key) const {
    for (const auto& [name, entry] : entries_)
      if (name == key) return entry;
    return std::nullopt;
  }
  bool Has(const std::string& key) const { return Find(key).has_value(); }
  // A required key; missing: "PATH.key: missing required key" at the map's line.
  Item Need(const std::string& key) const {
    if (auto it = Find(key)) return *it;
    ctx_.Fail(item_.node, item_.mark, Join(key), "missing required key '" + key + "'");
  }
  [[noreturn]] void FailMissing(const std::string& key, const std::string& reason) const {
    ctx_.Fail(item_.node, item_.mark, Join(key), reason);
  }

  // Typed reads: required, or with a default.
  double Number(const std::string& key) const { return ToNumber(ctx_, Need(key)); }
  double Number(const std::string& key, double fallback) const {
    const auto it = Find(key);
    return it ? ToNumber(ctx_, *it) : fallback;
  }
  int Int(const std::string& key, int fallback) const {
    const auto it = Find(key);
    return it ? ToInt(ctx_, *it) : fallback;
  }
  bool Bool(const std::string& key, bool fallback) const {
    const auto it = Find(key);
    return it ? ToBool(ctx_, *it) : fallback;
  }
  std::string String(const std::string& key) const { return ToString(ctx_, Need(key)); }
  Vec3 Vector(const std::string& key, const Vec3& fallback) const {
    const auto it = Find(key);
    return it ? ToVec3(ctx_, *it) : fallback;
  }

  // `key` or one of its unit-suffixed variants ("angle" / "angle_deg"): the item and the factor
  // to SI. At most one may be given.
  std::optional<std::pair<Item, double>> FindScaled(
      const std::string& key, const std::vector<std::pair<std::string, double>>& suffixes) const {
    std::optional<std::pair<Item, double>> found;
    std::string found_key;
    for (const auto& [suffix, factor] : suffixes)
      if (auto it = Find(key + suffix)) {
        if (found) ctx_.Fail(*it, "give either '" + found_key + "' or '" + key + suffix + "', not both");
        found = std::make_pair(*it, factor);
        found_key = key + suffix;
      }
    return found;
  }

  // A string that must be one of `choices`.
  std::string Choice(const std::string& key, const std::vector<std::string>& choices,
                     const std::optional<std::string>& fallback = std::nullopt) const {
    const auto it = Find(key);
    if (!it && fallback) return *fallback;
    const Item item = it ? *it : Need(key);
    const std::string value = ToString(ctx_, item);
    if (std::find(choices.begin(), choices.end(), value) == choices.end())
      ctx_.Fail(item, "unknown value '" + value + "'" + SuggestOrList(value, choices, "one of"));
    return value;
  }

 private:
  const Context& ctx_;
  Item item_;
  std::vector<std::pair<std::string, Item>> entries_;
};

// ---------------------------------------------------------------------------------------------
// Rotations, poses and functions of time

// Writes `n` to `out` as YAML text that reads back to the same node: every collection in flow
// style when `all_flow` (a one-line value for `--set key=TEXT`), else in the style each had;
// scalars tagged "!" (quoted in the source) stay quoted.
inline void EmitYaml(YAML::Emitter& out, const YAML::Node& n, bool all_flow) {
  switch (n.Type()) {
    case YAML::NodeType::Sequence:
      if (all_flow || n.Style() == YAML::EmitterStyle::Flow) out << YAML::Flow;
      out << YAML::BeginSeq;
      for (const YAML::Node& item : n) EmitYaml(out, item, all_flow);
      out << YAML::EndSeq;
      break;
    case YAML::NodeType::Map:
      if (all_flow || n.Style() == YAML::EmitterStyle::Flow) out << YAML::Flow;
      out << YAML::BeginMap;
      for (auto it = n.begin(); it != n.end(); ++it) {
        out << YAML::Key;
        EmitYaml(out, it->first, all_flow);
        out << YAML::Value;
        EmitYaml(out, it->second, all_flow);
      }
      out << YAML::EndMap;
      break;
    case YAML::NodeType::Scalar:
      if (n.Tag() == "!") out << YAML::DoubleQuoted;
      out << n.Scalar();
      break;
    default: out << YAML::Null; break;
  }
}

inline Mat3 RotX(double a) { return AxisAngle(Vec3::UnitX(), a); }
inline Mat3 RotY(double a) { return AxisAngle(Vec3::UnitY(), a); }
inline Mat3 RotZ(double a) { return AxisAngle(Vec3::UnitZ(), a); }

// ROT: {axis, angle|angle_deg} | {quaternion: [w,x,y,z]} | {rpy|rpy_deg} | 3x3 nested list.
inline Mat3 ToRotation(const Context& ctx, const Item& it) {
  // A 3x3 matrix, rows first; must be orthonormal to 1e-6 and proper, then re-orthonormalized.
  if (it.node.IsSequence()) {
    if (it.node.size() != 3 || !it.node[0].IsSequence())
      ctx.Fail(it, "expected a rotation: a 3x3 nested list (rows) or a map with axis/angle, "
                   "quaternion or rpy; got " + Describe(it.node));
    Mat3 R;
    for (int r = 0; r < 3; ++r) {
      const std::vector<double> row = ToNumbers(ctx, Element(it, r), 3);
      R.row(r) << row[0], row[1], row[2];
    }
    const double err = (R.transpose() * R - Mat3::Identity()).norm();
    if (err > 1e-6 || R.determinant() < 0)
      ctx.Fail(it, "the 3x3 matrix is not a rotation (|R^T R - I| = " + Num(err) +
                   ", det = " + Num(R.determinant()) + ")");
    const Eigen::JacobiSVD<Mat3> svd(R, Eigen::ComputeFullU | Eigen::ComputeFullV);
    return svd.matrixU() * svd.matrixV().transpose();
  }
  if (!it.node.IsMap())
    ctx.Fail(it, "expected a rotation: a map with axis/angle, quaternion or rpy, or a 3x3 nested "
                 "list; got " + Describe(it.node));
  const MapReader m(ctx, it, {"axis", "angle", "angle_deg", "quaternion", "rpy", "rpy_deg"});
  const int forms = int(m.Has("axis")) + int(m.Has("quaternion")) +
                    int(m.Has("rpy") || m.Has("rpy_deg"));
  if (forms != 1)
    ctx.Fail(it, "give exactly one of {axis, angle}, {quaternion} or {rpy}");
  // Axis and angle.
  if (m.Has("axis")) {
    const Vec3 axis = ToVec3(ctx, m.Need("axis"));
    if (!(axis.norm() > 1e-12)) ctx.Fail(m.Need("axis"), "axis has zero length");
    const auto angle = m.FindScaled("angle", {{"", 1.0}, {"_deg", kDegToRad}});
    if (!angle) m.FailMissing("angle", "missing required key 'angle' (or 'angle_deg')");
    return AxisAngle(axis.normalized(), ToNumber(ctx, angle->first) * angle->second);
  }
  if (const auto angle = m.FindScaled("angle", {{"", 1.0}, {"_deg", kDegToRad}}))
    ctx.Fail(angle->first, "an angle goes with an axis");
  // Quaternion (w, x, y, z), normalized.
  if (m.Has("quaternion")) {
    const std::vector<double> q = ToNumbers(ctx, m.Need("quaternion"), 4);
    const Quat quat(q[0], q[1], q[2], q[3]);
    if (!(quat.norm() > 1e-12)) ctx.Fail(m.Need("quaternion"), "quaternion is zero");
    return quat.normalized().toRotationMatrix();
  }
  // Roll, pitch, yaw: R = Rz(yaw) Ry(pitch) Rx(roll).
  const auto rpy = m.FindScaled("rpy", {{"", 1.0}, {"_deg", kDegToRad}});
  const Vec3 a = ToVec3(ctx, rpy->first) * rpy->second;
  return RotZ(a.z()) * RotY(a.y()) * RotX(a.x());
}

// A map entry looked up without checking the map's keys (to read a "type" that decides them).
inline std::optional<Item> RawField(const Item& map, const std::string& key) {
  if (!map.node.IsMap()) return std::nullopt;
  for (auto it = map.node.begin(); it != map.node.end(); ++it)
    if (it->first.IsScalar() && it->first.Scalar() == key)
      return Item{it->second, map.path + "." + key, it->first.Mark()};
  return std::nullopt;
}

// The "type" of a list item that must be one of `types` (aliases allowed by the caller).
inline std::string ItemType(const Context& ctx, const Item& item, const std::vector<std::string>& types) {
  if (!item.node.IsMap()) ctx.Fail(item, "expected a map, got " + Describe(item.node));
  const auto type = RawField(item, "type");
  if (!type)
    ctx.Fail(item.node, item.mark, item.path + ".type",
             "missing required key 'type' (one of: " + JoinQuoted(types) + ")");
  const std::string value = ToString(ctx, *type);
  if (std::find(types.begin(), types.end(), value) == types.end())
    ctx.Fail(*type, "unknown type '" + value + "'" + SuggestOrList(value, types, "one of"));
  return value;
}

// Units of the values of a time function: the factor to SI and the unit suffixes it accepts.
struct FunctionUnits {
  double scale = 1.0;          // scene value unit -> SI (length scale for translations, ...)
  bool angle = false;          // angular quantity: "_deg" allowed (degrees, or degrees per second)
  bool angular_speed = false;  // angular speed: "_rpm" allowed as well (rev/min)
};

// FUNC: a number (constant) or {type: constant|ramp|smooth_step|table|sine|trapezoid, ...}.
inline TimeFunction ToFunction(const Context& ctx, const Item& it, const FunctionUnits& units) {
  if (it.node.IsScalar()) return TimeFunction::Constant(ToNumber(ctx, it) * units.scale);
  if (!it.node.IsMap())
    ctx.Fail(it, "expected a function of time: a number or a map with a 'type', got " +
                     Describe(it.node));
  // The type decides the keys: time and shape parameters, and values that carry the unit.
  static const std::map<std::string, std::pair<std::vector<std::string>, std::vector<std::string>>>
      kKeys{{"constant", {{}, {"value"}}},
            {"ramp", {{"t0", "t1"}, {"v0", "v1"}}},
            {"smooth_step", {{"t0", "t1"}, {"v0", "v1"}}},
            {"table", {{"times"}, {"values"}}},
            {"sine", {{"frequency_hz", "phase", "phase_deg"}, {"amplitude", "offset"}}},
            {"trapezoid", {{"t4", "alpha1", "alpha2", "alpha3"}, {"w0", "w1", "w2"}}}};
  const std::string type =
      ItemType(ctx, it, {"constant", "ramp", "smooth_step", "table", "sine", "trapezoid"});
  const auto& [params, values] = kKeys.at(type);
  std::vector<std::pair<std::string, double>> suffixes{{"", units.scale}};
  if (units.angle) suffixes.emplace_back("_deg", kDegToRad);
  if (units.angular_speed) suffixes.emplace_back("_rpm", kRpmToRadPerS);
  std::vector<std::string> allowed{"type"};
  allowed.insert(allowed.end(), params.begin(), params.end());
  std::map<std::string, std::string> notes;
  for (const std::string& v : values) {
    for (const auto& s : suffixes) allowed.push_back(v + s.first);
    if (!units.angle) notes[v + "_deg"] = "'_deg' is only for angles and angular speeds";
    if (!units.angular_speed)
      notes[v + "_rpm"] = "'_rpm' is only for the speed of a rotational coordinate";
  }
  const MapReader m(ctx, it, allowed, notes);
  // A value key in one of its units, converted to SI.
  auto value = [&](const std::string& key) -> double {
    const auto found = m.FindScaled(key, suffixes);
    if (!found) m.FailMissing(key, "missing required key '" + key + "'");
    return ToNumber(ctx, found->first) * found->second;
  };
  auto value_or = [&](const std::string& key, double fallback) -> double {
    const auto found = m.FindScaled(key, suffixes);
    return found ? ToNumber(ctx, found->first) * found->second : fallback;
  };
  try {
    if (type == "constant") return TimeFunction::Constant(value("value"));
    if (type == "ramp")
      return TimeFunction::Ramp(m.Number("t0"), m.Number("t1"), value("v0"), value("v1"));
    if (type == "smooth_step")
      return TimeFunction::SmoothStep(m.Number("t0"), m.Number("t1"), value("v0"), value("v1"));
    if (type == "table") {
      const std::vector<double> times = ToNumbers(ctx, m.Need("times"), -1);
      const auto found = m.FindScaled("values", suffixes);
      if (!found) m.FailMissing("values", "missing required key 'values'");
      std::vector<double> v = ToNumbers(ctx, found->first, static_cast<int>(times.size()));
      for (double& x : v) x *= found->second;
      return TimeFunction::Table(times, v);
    }
    if (type == "sine") {
      const auto phase = m.FindScaled("phase", {{"", 1.0}, {"_deg", kDegToRad}});
      return TimeFunction::Sine(value("amplitude"), m.Number("frequency_hz"),
                                phase ? ToNumber(ctx, phase->first) * phase->second : 0.0,
                                value_or("offset", 0.0));
    }
    return TimeFunction::Trapezoid(value("w0"), value("w1"), value("w2"), m.Number("t4"),
                                   m.Number("alpha1"), m.Number("alpha2"), m.Number("alpha3"));
  } catch (const std::invalid_argument& e) {
    ctx.Fail(it, e.what());
  }
}


// ---------------------------------------------------------------------------------------------
// Builder errors: std::invalid_argument from ModelBuilder, placed at the key it is about

// Strips the builder's "<kind> '<name>': " prefix (the key path already names the element).
inline std::string StripElementPrefix(const std::string& message) {
  static const std::regex kPrefix("^[a-z ]+ '[^']*': ");
  return std::regex_replace(message, kPrefix, "", std::regex_constants::format_first_only);
}

// Runs a builder call; an std::invalid_argument becomes a SceneError at the first key of
// `keywords` ({word in the message, key}) that the message mentions and the map has, else at the
// element itself.
template <class F>
auto Build(const MapReader& element,
           std::initializer_list<std::pair<const char*, const char*>> keywords, F&& f) {
  try {
    return f();
  } catch (const std::invalid_argument& e) {
    const std::string reason = StripElementPrefix(e.what());
    for (const auto& [word, key] : keywords)
      if (reason.find(word) != std::string::npos)
        if (const auto it = element.Find(key)) element.ctx().Fail(*it, reason);
    element.ctx().Fail(element.item(), reason);
  }
}

}  // namespace orrery::scene_reader
