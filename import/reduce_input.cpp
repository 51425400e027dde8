#include "import/reduce_input.h"

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <set>
#include <sstream>

#include "flex/fe_assembly.h"
#include "import/scene_reader.h"
#include "import/tooth_fault_reader.h"
#include "mbd/file_checks.h"

namespace orrery {
namespace {

using namespace scene_reader;

constexpr double kMm = 1e-3;

// "FILE:LINE: PATH" of an item, for errors found after reading.
std::string Where(const Context& ctx, const Item& it) {
  std::string w = ctx.file();
  if (it.mark.line >= 0) {
    w += ':';
    w += std::to_string(it.mark.line + 1);
  }
  w += ": ";
  w += it.path;
  return w;
}

// A length given as `key` (m) or `key_mm`; required.
double Length(const MapReader& m, const std::string& key) {
  const auto found = m.FindScaled(key, {{"", 1.0}, {"_mm", kMm}});
  if (!found) m.FailMissing(key, "missing required key '" + key + "' (or '" + key + "_mm')");
  const double v = ToNumber(m.ctx(), found->first) * found->second;
  if (!(v > 0)) m.ctx().Fail(found->first, "must be > 0, got " + found->first.node.Scalar());
  return v;
}

// An angle given as `key` (rad) or `key_deg`, with a default.
double Angle(const MapReader& m, const std::string& key, double fallback_rad) {
  const auto found = m.FindScaled(key, {{"", 1.0}, {"_deg", kDegToRad}});
  return found ? ToNumber(m.ctx(), found->first) * found->second : fallback_rad;
}

// A count >= `lo`, with a default.
int Count(const MapReader& m, const std::string& key, int fallback, int lo) {
  const auto it = m.Find(key);
  if (!it) return fallback;
  const int v = ToInt(m.ctx(), *it);
  if (v < lo) m.ctx().Fail(*it, "must be >= " + std::to_string(lo) + ", got " + std::to_string(v));
  return v;
}

// A number with a lower bound (strict or not), with a default.
double Bounded(const MapReader& m, const std::string& key, double fallback, double lo, bool strict) {
  const auto it = m.Find(key);
  if (!it) return fallback;
  const double v = ToNumber(m.ctx(), *it);
  if (strict ? !(v > lo) : !(v >= lo))
    m.ctx().Fail(*it, std::string("must be ") + (strict ? "> " : ">= ") + Num(lo) + ", got " + it->node.Scalar());
  return v;
}

ReduceInput Read(const Context& ctx, const YAML::Node& root) {
  ReduceInput in;
  in.file = ctx.file();
  const MapReader top(ctx, {root, "", root.Mark()},
                      {"gear", "mesh", "material", "interfaces", "reduction", "outputs", "fault"});

  // gear: the geometry, checked by building it
  {
    const Item item = top.Need("gear");
    const MapReader g(ctx, item,
                      {"teeth", "module", "module_mm", "pressure_angle", "pressure_angle_deg", "helix_angle",
                       "helix_angle_deg", "hand", "face_width", "face_width_mm", "profile_shift", "bore_diameter",
                       "bore_diameter_mm"});
    const Item teeth = g.Need("teeth");
    in.gear.teeth = ToInt(ctx, teeth);
    if (in.gear.teeth < 1) ctx.Fail(teeth, "must be >= 1, got " + teeth.node.Scalar());
    in.gear.normal_module_m = Length(g, "module");
    in.gear.normal_pressure_angle_rad = Angle(g, "pressure_angle", in.gear.normal_pressure_angle_rad);
    in.gear.helix_angle_rad = Angle(g, "helix_angle", 0);
    in.gear.hand = g.Choice("hand", {"right", "left"}, "right") == "right" ? gears::HelixHand::kRight
                                                                           : gears::HelixHand::kLeft;
    in.gear.face_width_m = Length(g, "face_width");
    in.gear.profile_shift = g.Number("profile_shift", 0);
    in.mesh.bore_radius_m = Length(g, "bore_diameter") / 2;
    try {
      const gears::Gear gear(in.gear);
      if (!(in.mesh.bore_radius_m < gear.root_radius_m()))
        ctx.Fail(g.FindScaled("bore_diameter", {{"", 1.0}, {"_mm", kMm}})->first,
                 "the bore (radius " + Num(in.mesh.bore_radius_m) + " m) must lie inside the root circle (radius " +
                     Num(gear.root_radius_m()) + " m)");
    } catch (const std::invalid_argument& e) {
      ctx.Fail(item, e.what());
    }
  }

  // mesh: element type and divisions (defaults of GearFeMeshSpec)
  if (const auto item = top.Find("mesh")) {
    const MapReader m(ctx, *item,
                      {"element", "flank_divisions", "fillet_divisions", "tooth_divisions",
                       "root_layer_divisions", "rim_divisions", "face_divisions", "smoothing_iterations",
                       "root_layer_depth_coef", "flank_bias", "rim_bias"});
    in.mesh.type = m.Choice("element", {"hex8", "hex20"}, "hex20") == "hex8" ? flex::ElementType::kHex8
                                                                            : flex::ElementType::kHex20;
    gears::GearFeMeshSpec& s = in.mesh;
    s.flank_divisions = Count(m, "flank_divisions", s.flank_divisions, 1);
    s.fillet_divisions = Count(m, "fillet_divisions", s.fillet_divisions, 1);
    s.tooth_divisions = Count(m, "tooth_divisions", s.tooth_divisions, 1);
    s.root_layer_divisions = Count(m, "root_layer_divisions", s.root_layer_divisions, 1);
    s.rim_divisions = Count(m, "rim_divisions", s.rim_divisions, 1);
    s.face_divisions = Count(m, "face_divisions", s.face_divisions, 1);
    s.smoothing_iterations = Count(m, "smoothing_iterations", s.smoothing_iterations, 0);
    s.root_layer_depth_coef = Bounded(m, "root_layer_depth_coef", s.root_layer_depth_coef, 0, true);
    s.flank_bias = Bounded(m, "flank_bias", s.flank_bias, 1, false);
    s.rim_bias = Bounded(m, "rim_bias", s.rim_bias, 0, true);
  } else {
    in.mesh.type = flex::ElementType::kHex20;
  }

  // fault: one tooth fault or a list (tooth_fault_reader.h), checked against the gear
  if (const auto item = top.Find("fault")) {
    const gears::Gear gear(in.gear);
    in.mesh.faults = ReadToothFaults(ctx, item);
    const std::vector<Item> items = item->node.IsMap() ? std::vector<Item>{*item} : ListItems(ctx, item);
    for (size_t i = 0; i < items.size(); ++i) CheckToothFault(ctx, items[i], gear, in.mesh.faults[i]);
    try {
      gears::ValidateToothFaults(gear, in.mesh.faults);
    } catch (const std::invalid_argument& e) {
      ctx.Fail(*item, e.what());
    }
  }

  // material: E, nu, rho (SI)
  {
    const Item item = top.Need("material");
    const MapReader m(ctx, item, {"name", "E", "nu", "rho"});
    flex::IsotropicMaterial& mat = in.mesh.material;
    mat.name = m.Has("name") ? m.String("name") : "MATERIAL";
    const Item e = m.Need("E"), nu = m.Need("nu"), rho = m.Need("rho");
    mat.youngs_modulus_pa = ToNumber(ctx, e);
    mat.poissons_ratio = ToNumber(ctx, nu);
    mat.density_kg_m3 = ToNumber(ctx, rho);
    if (!(mat.youngs_modulus_pa > 0)) ctx.Fail(e, "Young's modulus must be > 0 (Pa), got " + e.node.Scalar());
    if (!(mat.poissons_ratio > -1 && mat.poissons_ratio < 0.5))
      ctx.Fail(nu, "Poisson's ratio must lie in (-1, 0.5), got " + nu.node.Scalar());
    if (!(mat.density_kg_m3 > 0)) ctx.Fail(rho, "density must be > 0 (kg/m^3), got " + rho.node.Scalar());
  }

  // interfaces: at least one, unique names
  {
    const Item list = top.Need("interfaces");
    const std::vector<Item> items = ListItems(ctx, list);
    if (items.empty()) ctx.Fail(list, "needs at least one interface (the body frame sits on the first)");
    std::set<std::string> names;
    for (const Item& item : items) {
      const MapReader m(ctx, item, {"name", "node_set", "kind"});
      ReduceInput::Interface& f = in.interfaces.emplace_back();
      f.name = m.String("name");
      if (!names.insert(f.name).second) ctx.Fail(m.Need("name"), "duplicate interface name '" + f.name + "'");
      const Item set = m.Need("node_set");
      f.node_set = ToString(ctx, set);
      f.node_set_at = Where(ctx, set);
      f.rbe3 = m.Choice("kind", {"rbe2", "rbe3"}, "rbe2") == "rbe3";
    }
  }

  // reduction: modes, cutoff, reference interface
  if (const auto item = top.Find("reduction")) {
    const MapReader m(ctx, *item, {"modes", "cutoff_hz", "reference", "inertial_load_modes"});
    in.modes = Count(m, "modes", in.modes, 0);
    in.inertial_load_modes = m.Bool("inertial_load_modes", false);
    in.cutoff_hz = Bounded(m, "cutoff_hz", 0, 0, false);
    if (const auto ref = m.Find("reference")) {
      const std::string name = ToString(ctx, *ref);
      std::vector<std::string> known;
      for (const ReduceInput::Interface& f : in.interfaces) known.push_back(f.name);
      const auto at = std::find(known.begin(), known.end(), name);
      if (at == known.end())
        ctx.Fail(*ref, "unknown interface '" + name + "'" + SuggestOrList(name, known, "interfaces"));
      in.reference_interface = static_cast<int>(at - known.begin());
    }
  }

  // outputs
  if (const auto item = top.Find("outputs")) {
    const MapReader m(ctx, *item, {"stress_modes", "geometric_stiffness", "export_node_sets"});
    in.stress_modes = m.Bool("stress_modes", true);
    in.geometric_stiffness = m.Bool("geometric_stiffness", true);
    for (const Item& set : ListItems(ctx, m.Find("export_node_sets"))) in.export_node_sets.push_back(ToString(ctx, set));
  }
  return in;
}

}  // namespace

ReduceInput ParseReduceInput(const std::string& text, const std::string& file) {
  YAML::Node root;
  try {
    root = YAML::Load(text);
  } catch (const YAML::ParserException& e) {
    throw SceneError(file + ":" + std::to_string(e.mark.line + 1) + ": YAML syntax error: " + e.msg);
  } catch (const YAML::Exception& e) {
    throw SceneError(file + ": YAML error: " + e.msg);
  }
  if (root.IsNull()) throw SceneError(file + ": the input is empty");
  if (!root.IsMap()) throw SceneError(file + ":1: the input must be a map of sections, got " + Describe(root));
  const Context ctx(file);
  return Read(ctx, root);
}

ReduceInput LoadReduceInput(const std::string& path) {
  std::string text;
  try {
    text = ReadInputFile(path, "reduce input", kMaxTextInputBytes);
  } catch (const std::runtime_error& e) {
    throw SceneError(e.what());
  }
  return ParseReduceInput(text, path);
}

GearReduction PrepareGearReduction(const ReduceInput& in) {
  GearReduction job;
  const gears::Gear gear(in.gear);
  try {
    job.mesh = gears::MakeGearFeMesh(gear, in.mesh);
  } catch (const std::invalid_argument& e) {
    throw std::runtime_error(in.file + ": mesh: " + e.what());
  }
  for (const ReduceInput::Interface& f : in.interfaces) {
    try {
      job.interfaces.push_back(flex::MakeInterface(job.mesh, f.node_set, f.rbe3 ? flex::InterfaceKind::kRbe3
                                                                                 : flex::InterfaceKind::kRbe2));
    } catch (const std::invalid_argument& e) {
      throw std::runtime_error(f.node_set_at + ": " + e.what());
    }
    job.interfaces.back().name = f.name;
    job.interface_sets.push_back(f.node_set);
  }
  for (const std::string& set : in.export_node_sets) {
    try {
      job.mesh.NodeSet(set);
    } catch (const std::invalid_argument& e) {
      throw std::runtime_error(in.file + ": outputs.export_node_sets: " + e.what());
    }
  }
  job.cb_options = {.num_modes = in.modes, .cutoff_hz = in.cutoff_hz, .reference_interface = in.reference_interface,
                    .inertial_load_modes = in.inertial_load_modes};
  job.outputs = {.export_node_sets = in.export_node_sets,
                 .stress_modes = in.stress_modes,
                 .geometric_stiffness = in.geometric_stiffness};
  const gears::GearSpec& g = in.gear;
  constexpr double kDeg = 180 / std::numbers::pi;
  job.source = "gear z=" + std::to_string(g.teeth) + ", m_n=" + Num(g.normal_module_m) + " m, alpha_n=" +
               Num(g.normal_pressure_angle_rad * kDeg) + " deg, beta=" + Num(g.helix_angle_rad * kDeg) +
               " deg, b=" + Num(g.face_width_m) + " m, x=" + Num(g.profile_shift) + ", bore radius " +
               Num(in.mesh.bore_radius_m) + " m; " + flex::CalculixName(in.mesh.type) + " mesh (" + in.file + ")";
  job.faults = DescribeGearFaults(in.mesh.faults);
  if (!in.mesh.faults.empty()) job.source += "; faults: " + job.faults;
  return job;
}

std::string DescribeGearFaults(const std::vector<gears::ToothFaultSpec>& faults) {
  if (faults.empty()) return "none";
  std::string s;
  for (const gears::ToothFaultSpec& f : faults) s += (s.empty() ? "" : "; ") + gears::DescribeToothFault(f);
  return s;
}

Reduction ReduceBody(const flex::FeMesh& mesh, std::span<const flex::FeInterface> interfaces,
                     const flex::CraigBamptonOptions& cb_options, const flex::FlexibleBodyModesOptions& outputs,
                     const std::string& source, const std::string& faults) {
  const auto start = std::chrono::steady_clock::now();
  flex::FeSystem system = flex::AssembleFeSystem(mesh);
  const double assembly_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  Reduction r = ReduceAssembledBody(mesh, std::move(system), interfaces, cb_options, outputs, source, faults);
  r.assembly_s = assembly_s;
  return r;
}

Reduction ReduceAssembledBody(const flex::FeMesh& mesh, flex::FeSystem system,
                              std::span<const flex::FeInterface> interfaces, const flex::CraigBamptonOptions& cb_options,
                              const flex::FlexibleBodyModesOptions& outputs, const std::string& source,
                              const std::string& faults) {
  using Clock = std::chrono::steady_clock;
  auto since = [](Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); };
  Reduction r;
  r.system = std::move(system);
  auto start = Clock::now();
  r.cb = flex::ReduceCraigBampton(mesh, r.system, interfaces, cb_options);
  r.reduction_s = since(start);
  start = Clock::now();
  flex::ReducedBody& body = r.body;
  body.modes = flex::MakeFlexibleBodyModes(mesh, r.system, r.cb, interfaces, outputs);
  r.modes_s = since(start);
  body.K = r.cb.K;
  body.M = r.cb.M;
  body.reduced_frequencies_hz = r.cb.frequencies_hz;
  body.full_model_boundary = "not computed";
  for (const flex::FeInterface& i : interfaces) body.interfaces.push_back(flex::DescribeInterface(mesh, i));
  body.reference_interface = cb_options.reference_interface;
  body.provenance = flex::MakeReducedBodyProvenance(mesh, cb_options, interfaces, outputs, source, faults);
  return r;
}

}  // namespace orrery
