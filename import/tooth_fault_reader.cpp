#include "import/tooth_fault_reader.h"

#include <stdexcept>

namespace orrery {
namespace {

using namespace scene_reader;

// Keys of each kind (lengths without their unit suffix).
const std::vector<std::string> kBrokenKeys = {"height_fraction", "face_fraction", "from_face"};
const std::vector<std::string> kCrackKeys = {"crack_depth", "crack_angle", "crack_face_fraction", "crack_end_depth",
                                             "flank", "from_face"};
const std::vector<std::string> kSpallKeys = {"flank", "roll_start", "roll_end", "axial_start", "axial_end", "depth"};
const std::vector<std::string> kLengthKeys = {"crack_depth", "crack_end_depth", "roll_start", "roll_end",
                                              "axial_start", "axial_end", "depth"};

bool IsLength(const std::string& key) {
  return std::find(kLengthKeys.begin(), kLengthKeys.end(), key) != kLengthKeys.end();
}

// Every spelling of a key: lengths with _mm, _um; angles with _deg.
std::vector<std::string> Spellings(const std::string& key) {
  if (IsLength(key)) return {key, key + "_mm", key + "_um"};
  if (key == "crack_angle") return {key, key + "_deg"};
  return {key};
}

std::optional<double> Length(const MapReader& m, const std::string& key) {
  const auto found = m.FindScaled(key, {{"", 1.0}, {"_mm", 1e-3}, {"_um", 1e-6}});
  if (!found) return std::nullopt;
  return ToNumber(m.ctx(), found->first) * found->second;
}

}  // namespace

gears::ToothFaultSpec ReadToothFault(const Context& ctx, const Item& item, const std::vector<std::string>& extra_keys) {
  using gears::ToothFaultSpec;
  // Every key of every kind is known, so that a key of another kind gets a clear note.
  std::vector<std::string> allowed = {"kind", "tooth"};
  allowed.insert(allowed.end(), extra_keys.begin(), extra_keys.end());
  for (const auto* list : {&kBrokenKeys, &kCrackKeys, &kSpallKeys})
    for (const std::string& k : *list)
      for (const std::string& s : Spellings(k))
        if (std::find(allowed.begin(), allowed.end(), s) == allowed.end()) allowed.push_back(s);
  const MapReader m(ctx, item, allowed);
  ToothFaultSpec f;
  const std::string kind = m.Choice("kind", {"broken_tooth", "root_crack", "spall"});
  f.kind = gears::ParseFaultKind(kind);
  const Item tooth = m.Need("tooth");
  f.tooth = ToInt(ctx, tooth);
  // Keys of the other kinds.
  const std::vector<std::string>& own = f.kind == ToothFaultSpec::Kind::kBrokenTooth ? kBrokenKeys
                                        : f.kind == ToothFaultSpec::Kind::kRootCrack ? kCrackKeys
                                                                                     : kSpallKeys;
  for (const auto* list : {&kBrokenKeys, &kCrackKeys, &kSpallKeys})
    for (const std::string& k : *list)
      if (std::find(own.begin(), own.end(), k) == own.end())
        for (const std::string& s : Spellings(k))
          if (const auto it = m.Find(s)) ctx.Fail(*it, "'" + s + "' does not apply to a " + kind);
  switch (f.kind) {
    case ToothFaultSpec::Kind::kBrokenTooth:
      f.height_fraction = m.Number("height_fraction", 1.0);
      f.face_fraction = m.Number("face_fraction", 1.0);
      f.from_face = gears::ParseFromFace(m.Choice("from_face", {"zmin", "zmax"}, "zmin"));
      break;
    case ToothFaultSpec::Kind::kRootCrack: {
      const auto depth = Length(m, "crack_depth");
      if (!depth) m.FailMissing("crack_depth", "missing required key 'crack_depth' (or '_mm', '_um')");
      f.crack_depth_m = *depth;
      const auto angle = m.FindScaled("crack_angle", {{"", 1.0}, {"_deg", kDegToRad}});
      if (!angle) m.FailMissing("crack_angle", "missing required key 'crack_angle' (or 'crack_angle_deg')");
      f.crack_angle_rad = ToNumber(ctx, angle->first) * angle->second;
      f.crack_face_fraction = m.Number("crack_face_fraction", 1.0);
      f.crack_end_depth_m = Length(m, "crack_end_depth");
      f.flank = gears::ParseFlank(m.Choice("flank", {"plus", "minus"}, "plus"));
      f.from_face = gears::ParseFromFace(m.Choice("from_face", {"zmin", "zmax"}, "zmin"));
      break;
    }
    case ToothFaultSpec::Kind::kSpall: {
      f.flank = gears::ParseFlank(m.Choice("flank", {"plus", "minus"}, "plus"));
      auto need = [&](const std::string& key) {
        const auto v = Length(m, key);
        if (!v) m.FailMissing(key, "missing required key '" + key + "' (or '" + key + "_mm', '" + key + "_um')");
        return *v;
      };
      f.roll_start_m = need("roll_start");
      f.roll_end_m = need("roll_end");
      f.axial_start_m = need("axial_start");
      f.axial_end_m = need("axial_end");
      f.depth_m = need("depth");
      break;
    }
  }
  return f;
}

std::vector<gears::ToothFaultSpec> ReadToothFaults(const Context& ctx, const std::optional<Item>& item,
                                                   const std::vector<std::string>& extra_keys) {
  std::vector<gears::ToothFaultSpec> out;
  if (!item || item->node.IsNull()) return out;
  const std::vector<Item> items = item->node.IsMap() ? std::vector<Item>{*item} : ListItems(ctx, item);
  for (const Item& it : items) out.push_back(ReadToothFault(ctx, it, extra_keys));
  return out;
}

void CheckToothFault(const Context& ctx, const Item& item, const gears::Gear& gear, const gears::ToothFaultSpec& f) {
  try {
    gears::ValidateToothFault(gear, f);
  } catch (const std::invalid_argument& e) {
    ctx.Fail(item, e.what());
  }
}

gears::TrainToothFault ReadTrainToothFaultArgument(const std::string& text, const gears::PlanetaryTrain& train) {
  const Context ctx("--fault '" + text + "'");
  // KEY=VALUE pairs into a map, each value read as YAML (a number, a word).
  YAML::Node map(YAML::NodeType::Map);
  size_t start = 0;
  while (start <= text.size()) {
    const size_t comma = std::min(text.find(',', start), text.size());
    const std::string pair = text.substr(start, comma - start);
    const size_t eq = pair.find('=');
    if (eq == std::string::npos || eq == 0)
      throw SceneError(ctx.file() + ": expected KEY=VALUE pairs separated by commas, got '" + pair + "'");
    try {
      map[pair.substr(0, eq)] = YAML::Load(pair.substr(eq + 1));
    } catch (const YAML::Exception& e) {
      throw SceneError(ctx.file() + ": " + pair.substr(0, eq) + ": cannot read the value: " + e.msg);
    }
    start = comma + 1;
  }
  const Item item{map, "", YAML::Mark::null_mark()};
  const gears::ToothFaultSpec spec = ReadToothFault(ctx, item, {"gear", "branch"});
  std::vector<std::string> keys;
  for (auto k = map.begin(); k != map.end(); ++k) keys.push_back(k->first.Scalar());
  const MapReader m(ctx, item, keys);
  gears::TrainToothFault f{.gear = m.String("gear"), .branch = 0, .spec = spec};
  // The gear, its branch (planets) and the tooth index, as in a scene.
  std::vector<std::string> names;
  int gear = -1;
  for (size_t g = 0; g < train.gears.size(); ++g) {
    names.push_back(train.gears[g].name);
    if (train.gears[g].name == f.gear) gear = static_cast<int>(g);
  }
  if (gear < 0) ctx.Fail(m.Need("gear"), "no gear named '" + f.gear + "'" + SuggestOrList(f.gear, names, "gears"));
  const gears::TrainGear& tg = train.gears[gear];
  if (tg.planet_set >= 0) {
    const int n = static_cast<int>(train.planet_sets[tg.planet_set].angles_rad.size());
    if (!m.Has("branch")) ctx.Fail(item, "a planet's fault needs 'branch' (1.." + std::to_string(n) + ")");
    const int branch = m.Int("branch", 1);
    if (branch < 1 || branch > n) ctx.Fail(m.Need("branch"), "must be in 1.." + std::to_string(n) + " (the planet of the set)");
    f.branch = branch - 1;
  } else if (m.Has("branch")) {
    ctx.Fail(m.Need("branch"), "a branch is for planets; '" + f.gear + "' is a central gear");
  }
  if (spec.tooth < 0 || spec.tooth >= tg.teeth)
    ctx.Fail(m.Need("tooth"), "tooth index " + std::to_string(spec.tooth) + " is not in 0.." + std::to_string(tg.teeth - 1));
  return f;
}

}  // namespace orrery
