#pragma once
// Quantities that a scene may spell in several units (`face_width` or `face_width_mm`, `_deg`,
// `_diameter_mm`): the small readers the gear sections share (lumped_stage_reader.cpp,
// gear_train_reader.cpp, train_dynamics_reader.cpp). Internal to import/.
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "import/scene_reader.h"

namespace orrery::scene_reader {

// One of several spellings of a quantity ({key, factor to SI}); at most one may be given.
inline std::optional<std::pair<Item, double>> FindOneOf(const MapReader& m,
                                                 const std::vector<std::pair<std::string, double>>& keys) {
  std::optional<std::pair<Item, double>> found;
  std::string found_key;
  for (const auto& [key, factor] : keys)
    if (const auto it = m.Find(key)) {
      if (found) m.ctx().Fail(*it, "give either '" + found_key + "' or '" + key + "', not both");
      found = std::make_pair(*it, factor);
      found_key = key;
    }
  return found;
}

inline std::string KeyList(const std::vector<std::pair<std::string, double>>& keys) {
  std::string s;
  for (const auto& [key, factor] : keys) s += (s.empty() ? "'" : ", '") + key + "'";
  return s;
}

// A value in SI from one of `keys`; nullopt if none is given.
inline std::optional<double> ScaledOf(const MapReader& m, const std::vector<std::pair<std::string, double>>& keys) {
  const auto found = FindOneOf(m, keys);
  if (!found) return std::nullopt;
  return ToNumber(m.ctx(), found->first) * found->second;
}

// Required, > 0 (or >= 0 with `allow_zero`), in SI.
inline double NeedScaled(const MapReader& m, const std::vector<std::pair<std::string, double>>& keys,
                  bool allow_zero = false) {
  const auto found = FindOneOf(m, keys);
  if (!found) m.FailMissing(keys.front().first, "missing required key (one of " + KeyList(keys) + ")");
  const double x = ToNumber(m.ctx(), found->first) * found->second;
  if (allow_zero ? !(x >= 0) : !(x > 0))
    m.ctx().Fail(found->first, std::string("must be ") + (allow_zero ? ">= 0" : "> 0") + ", got " +
                                   Num(ToNumber(m.ctx(), found->first)));
  return x;
}

// Optional with a default; checked >= 0 (or > 0).
inline double OptScaled(const MapReader& m, const std::vector<std::pair<std::string, double>>& keys,
                 double fallback, bool positive = false) {
  const auto found = FindOneOf(m, keys);
  if (!found) return fallback;
  const double x = ToNumber(m.ctx(), found->first) * found->second;
  if (positive ? !(x > 0) : !(x >= 0))
    m.ctx().Fail(found->first, std::string("must be ") + (positive ? "> 0" : ">= 0") + ", got " +
                                   Num(ToNumber(m.ctx(), found->first)));
  return x;
}

inline std::vector<std::pair<std::string, double>> Plain(const std::string& key) { return {{key, 1.0}}; }
inline std::vector<std::pair<std::string, double>> Angle(const std::string& key) {
  return {{key, 1.0}, {key + "_deg", kDegToRad}};
}
inline std::vector<std::pair<std::string, double>> LengthMm(const std::string& key) {
  return {{key, 1.0}, {key + "_mm", 1e-3}};
}
// A radius given as a diameter or a radius, in m or mm.
inline std::vector<std::pair<std::string, double>> RadiusKeys(const std::string& stem) {
  return {{stem + "_diameter", 0.5}, {stem + "_diameter_mm", 0.5e-3}, {stem + "_radius", 1.0},
          {stem + "_radius_mm", 1e-3}};
}
inline std::vector<std::string> Names(const std::vector<std::pair<std::string, double>>& keys) {
  std::vector<std::string> names;
  for (const auto& [key, factor] : keys) names.push_back(key);
  return names;
}
inline void Append(std::vector<std::string>& to, const std::vector<std::string>& more) {
  to.insert(to.end(), more.begin(), more.end());
}

// A list of angles (rad) from `key` or `key_deg`, `n` of them.
inline std::optional<std::vector<double>> AnglesOf(const MapReader& m, const std::string& key, int n) {
  const auto found = FindOneOf(m, Angle(key));
  if (!found) return std::nullopt;
  std::vector<double> a = ToNumbers(m.ctx(), found->first, n);
  for (double& x : a) x *= found->second;
  return a;
}

// A map or a list of maps (an entry that may repeat).
inline std::vector<Item> OneOrMany(const Context& ctx, const std::optional<Item>& item) {
  if (!item || item->node.IsNull()) return {};
  if (item->node.IsMap()) return {*item};
  return ListItems(ctx, item);
}

// Speeds: a function of time in rad/s ('_rpm' and '_deg' inside a function map).
inline FunctionUnits SpeedUnits() { return FunctionUnits{.scale = 1.0, .angle = true, .angular_speed = true}; }

// The value of largest magnitude of f over [0, end_time] (the operating point of a run-up).
inline double PeakValue(const TimeFunction& f, double end_time) {
  double best = f.Value(0.0);
  const int n = 2000;
  for (int i = 1; i <= n; ++i) {
    const double v = f.Value(end_time * i / n);
    if (std::abs(v) > std::abs(best)) best = v;
  }
  return best;
}


}  // namespace orrery::scene_reader
