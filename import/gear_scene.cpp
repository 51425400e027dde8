// The gear_train section of a scene: read (gear_train_reader.cpp, train_dynamics_reader.cpp),
// load the flexible bodies' reduced-body files, assemble (models/train_description.h), with the
// assembly's errors reported at the key they are about.
#include "import/gear_scene.h"

#include <algorithm>
#include <filesystem>
#include <map>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "flex/reduced_body_file.h"
#include "import/gear_train_reader.h"
#include "import/reduce_input.h"
#include "import/sensor_reader.h"

namespace orrery::scene_reader {
namespace {

// An error of the train builder within one stage: at the key it mentions (the builder's words).
[[noreturn]] void FailInStage(const MapReader& stage, const std::string& reason) {
  static const std::vector<std::pair<const char*, const char*>> kKeywords{
      {"planet angles", "planet_angles_deg"}, {"planet angles", "planet_angles"}, {"planet ", "planet_angles_deg"},
      {"spacing", "planets"}, {"overlap", "planets"}, {"num_planets", "planets"}, {"ring teeth", "ring"},
      {"module", "module_mm"}, {"pressure angle", "pressure_angle_deg"}, {"helix", "helix_angle_deg"},
      {"stage name", "name"}, {"duplicate stage", "name"}, {"pin radii", "inner_planet"}, {"equally", "planets"}};
  for (const auto& [word, key] : kKeywords)
    if (reason.find(word) != std::string::npos)
      if (const auto it = stage.Find(key)) stage.ctx().Fail(*it, reason);
  stage.ctx().Fail(stage.item(), reason);
}

// A gear's geometry refused by the assembler ("gear 'S1.planet': undercut: ..."): at the gear's
// key in its stage (its tip key when the reason is about a given tip), or the stage.
void FailAtGear(const MapReader& stage, const std::string& gear_suffix, const std::string& what) {
  static const std::map<std::string, std::string> kKeys{{"inner", "inner_planet"}, {"outer", "outer_planet"},
                                                        {"sun1", "small_sun"},   {"sun2", "large_sun"},
                                                        {"short", "short_planet"}, {"long", "long_planet"}};
  const auto key = kKeys.find(gear_suffix);
  const auto gear = stage.Find(key == kKeys.end() ? gear_suffix : key->second);
  if (!gear) stage.ctx().Fail(stage.item(), what);
  if (gear->node.IsMap() && what.find("tip") != std::string::npos)
    for (auto it = gear->node.begin(); it != gear->node.end(); ++it)
      if (it->first.Scalar().rfind("tip_", 0) == 0)
        stage.ctx().Fail(Item{it->second, gear->path + "." + it->first.Scalar(), it->first.Mark()}, what);
  stage.ctx().Fail(*gear, what);
}

bool Mentions(const std::string& what, const std::string& name) {
  return what.find("'" + name + "'") != std::string::npos || what.find("'" + name + ".") != std::string::npos ||
         what.find("'" + name + "#") != std::string::npos;
}

// The scene's tooth faults on one flexible body ("S.planet1": set S.planet, branch 0; "S.sun").
std::vector<gears::ToothFaultSpec> BodyFaults(const gears::GearTrainDescription& d, const std::string& body) {
  std::vector<gears::ToothFaultSpec> faults;
  for (const gears::TrainToothFault& f : d.options.tooth_faults)
    if (f.gear == body || f.gear + std::to_string(f.branch + 1) == body) faults.push_back(f.spec);
  return faults;
}

// The faulty twin's file of a reduced body: "<stem>.fault-<16 hex digits of the faults' text>.h5"
// beside it (the healthy file keeps its name).
std::string FaultyBodyPath(const std::string& reduced_body, const std::string& faults_text) {
  const std::filesystem::path p(reduced_body);
  const std::string hash = flex::Fnv1a64Hex(faults_text);
  return (p.parent_path() / (p.stem().string() + ".fault-" + hash.substr(hash.size() - 16) + ".h5")).string();
}

// A reduced-body file: read and checked against its reduce input (a stale file is refused with
// the reasons); made from the reduce input when missing. With scene faults on the body, the
// reduce input's mesh takes them too and the file is its faulty twin (FaultyBodyPath); without a
// reduce input the file's provenance must record exactly those faults.
std::shared_ptr<const FlexibleBodyModes> LoadReducedBody(const Context& ctx, FlexibleBodyFile f,
                                                         const std::vector<gears::ToothFaultSpec>& faults,
                                                         std::string* source) {
  std::optional<flex::ReducedBodyProvenance> expected;
  std::optional<GearReduction> job;
  const std::string given_path = f.reduced_body;
  if (f.reduce_input_item) {
    try {
      ReduceInput input = LoadReduceInput(f.reduce_input);
      if (!faults.empty()) {
        const gears::Gear gear(input.gear);
        for (const gears::ToothFaultSpec& fault : faults) input.mesh.faults.push_back(fault);
        try {
          gears::ValidateToothFaults(gear, input.mesh.faults);
        } catch (const std::invalid_argument& e) {
          throw std::invalid_argument(std::string("the scene's faults on ") + f.body + " with the reduce input's: " +
                                      e.what());
        }
        f.reduced_body = FaultyBodyPath(f.reduced_body, DescribeGearFaults(input.mesh.faults));
      }
      job = PrepareGearReduction(input);
      expected = flex::MakeReducedBodyProvenance(job->mesh, job->cb_options, job->interfaces, job->outputs, "",
                                                 job->faults);
      expected->source = "the reduce input " + f.reduce_input + (faults.empty() ? "" : " with the scene's faults");
    } catch (const std::exception& e) {
      ctx.Fail(*f.reduce_input_item, e.what());
    }
  }
  const std::string remake = f.reduce_input.empty()
                                 ? "make it with `orrery reduce INPUT -o " + f.reduced_body + "`"
                                 : faults.empty() ? "make it with `orrery reduce " + f.reduce_input + " -o " + f.reduced_body + "`"
                                                  : "delete it: `orrery run` makes it from " + f.reduce_input + " and the scene's faults";
  ctx.NoteInput(f.reduced_body);
  if (!f.reduce_input.empty()) ctx.NoteInput(f.reduce_input);
  // A missing file is made from the reduce input (once; later runs reuse it), by `orrery run` only.
  if (!std::filesystem::exists(f.reduced_body)) {
    if (!job) ctx.Fail(*f.reduced_body_item, "no reduced-body file " + f.reduced_body + "; " + remake + ", or name its reduce_input");
    if (!ctx.make_reduced_bodies())
      ctx.Fail(*f.reduced_body_item, "no reduced-body file " + f.reduced_body + " (this command writes no files); " +
                                         remake + ", or let `orrery run` make it");
    try {
      flex::WriteReducedBody(f.reduced_body, ReduceBody(job->mesh, job->interfaces, job->cb_options, job->outputs,
                                                        job->source, job->faults).body);
    } catch (const std::exception& e) {
      ctx.Fail(*f.reduced_body_item, "could not make " + f.reduced_body + " from " + f.reduce_input + ": " + e.what());
    }
  }
  try {
    flex::ReducedBody body = flex::ReadReducedBody(f.reduced_body, expected ? &*expected : nullptr);
    // Without a reduce input: the file must carry the scene's faults (and nothing else). A body
    // reduced from a mesh file (faults unknown: its geometry is the file's, damaged or not) serves
    // a scene that gives it none; faults cannot be added to it.
    const std::string want = DescribeGearFaults(faults);
    if (!job && body.provenance.faults.empty() && !faults.empty())
      ctx.Fail(*f.reduced_body_item, given_path + " was reduced from a mesh file (its geometry as the file has it) but the scene gives " +
                                         f.body + " faults '" + want + "'; model the fault in the part's geometry, or reduce a generated gear (reduce_input)");
    if (!job && !body.provenance.faults.empty() && body.provenance.faults != want)
      ctx.Fail(*f.reduced_body_item, given_path + " was reduced with faults '" + body.provenance.faults +
                                         "' but the scene gives " + f.body + " '" + want +
                                         "'; name its reduce_input so that the scene makes the body with its faults");
    *source = body.provenance.source;
    return std::make_shared<FlexibleBodyModes>(std::move(body.modes));
  } catch (const flex::StaleReducedBodyError& e) {
    ctx.Fail(*f.reduced_body_item, std::string(e.what()) + "; " + (faults.empty() ? "re" + remake : remake));
  } catch (const SceneError&) {
    throw;
  } catch (const std::exception& e) {
    ctx.Fail(*f.reduced_body_item, e.what());
  }
}

// The flexible bodies' modes, and the options that need them checked against the file.
void LoadFlexibleBodies(const Context& ctx, GearTrainRead& r) {
  for (const FlexibleBodyFile& f : r.flexible_files) {
    gears::TrainFlexibleBody& b = r.description.options.flexible_bodies.at(f.body);
    b.modes = LoadReducedBody(ctx, f, BodyFaults(r.description, f.body), &b.source);
    if (!b.mesh_interface.empty()) {
      const auto set = b.modes->node_sets.find(b.mesh_interface);
      if (set == b.modes->node_sets.end() || set->second.size() != 1)
        ctx.Fail(*f.mesh_interface_item, "'" + b.mesh_interface + "' is not an interface of " + f.reduced_body);
    }
    if (b.options.geometric_stiffening && b.modes->geometric_stiffness.empty())
      ctx.Fail(*f.geometric_stiffening_item,
               f.reduced_body + " has no geometric stiffness (reduce with outputs.geometric_stiffness: true)");
    for (const std::string& set : b.options.record_node_sets)
      if (!b.modes->node_sets.count(set))
        ctx.Fail(*f.record_node_sets_item, "no node set '" + set + "' in " + f.reduced_body +
                                               " (export it with outputs.export_node_sets when reducing)");
  }
}

}  // namespace

void FailAtSource(const Context& ctx, const GearTrainSources& s, const std::string& what, bool kinematics_error) {
  const std::string reason = StripElementPrefix(what);
  // The shared gear geometry check's (CheckTrainGearGeometry): at the gear in its stage.
  for (const auto& [name, stage] : s.stages) {
    const std::string gear = "train model: gear '" + name + ".";
    if (what.rfind(gear, 0) == 0 && what.find("gear geometry:") != std::string::npos)
      FailAtGear(stage, what.substr(gear.size(), what.find('\'', gear.size()) - gear.size()),
                 what.substr(std::string("train model: ").size()));
  }
  // The sensors stage's: at the sensor it names.
  for (const auto& [name, item] : s.sensors)
    if (what.find("sensor '" + name + "'") != std::string::npos) ctx.Fail(item, what);
  // The train builder's: a stage (by name or one of its gears), a coupling, a range, a port.
  for (const auto& [name, stage] : s.stages)
    if (Mentions(what, name) && what.find("train model:") == std::string::npos) FailInStage(stage, reason);
  for (const auto& [name, item] : s.couplings)
    if (Mentions(what, name)) ctx.Fail(item, reason);
  for (const auto& [name, item] : s.ranges)
    if (Mentions(what, name)) ctx.Fail(item, what);
  if (what.find("input") == 0 && s.inputs) ctx.Fail(*s.inputs, what);
  if (what.find("output") != std::string::npos && s.output && what.find("train model:") == std::string::npos)
    ctx.Fail(*s.output, what);
  if (kinematics_error) ctx.Fail(s.range.value_or(s.section), what);
  // The model's: a dynamics entry it names, the mesh stiffness, the dynamics map.
  for (const auto& [name, item] : s.dynamics_entries)
    if (Mentions(what, name)) ctx.Fail(item, what);
  if (s.mesh_stiffness) ctx.Fail(*s.mesh_stiffness, what);
  ctx.Fail(s.dynamics.value_or(s.section), what);
}

void ReadGearTrain(const Context& ctx, const Item& section, const std::optional<Item>& sensors, Scene& scene) {
  GearTrainRead r = ReadGearTrainDescription(ctx, section, scene.simulation.end_time);
  r.description.options.sensors = ReadTrainSensors(ctx, sensors, r.sources.sensors);
  // The healthy twin (SceneLoadOptions::without_faults): before any body is loaded or assembled
  if (ctx.without_faults()) r.description.options.tooth_faults.clear();
  LoadFlexibleBodies(ctx, r);
  gears::GearTrainAssembly a;
  try {
    a = gears::AssembleGearTrain(r.description);
  } catch (const std::invalid_argument& e) {
    FailAtSource(ctx, r.sources, e.what(), false);
  } catch (const std::runtime_error& e) {
    FailAtSource(ctx, r.sources, e.what(), true);
  }
  auto g = std::make_shared<GearTrainScene>();
  g->description = r.description;
  g->train = a.train;
  g->range = a.range;
  g->input_speed_functions = r.input_speed_functions;
  g->input_speeds_rad_s = r.input_speeds_rad_s;
  g->input_torque_n_m = a.model.input_torque_n_m;
  g->mesh_stiffness = r.mesh_stiffness;
  g->options = a.options;
  g->model = std::make_shared<const gears::TrainModel>(std::move(a.model));
  for (const gears::TrainContactMesh& c : g->model->contacts) g->contact_meshes.push_back(c.name);
  scene.kind = SceneKind::kGearTrain;
  scene.model = g->model->model;
  scene.gear_train = g;
}

}  // namespace orrery::scene_reader
