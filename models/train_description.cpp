#include "models/train_description.h"

#include <algorithm>
#include <stdexcept>

namespace orrery::gears {
namespace {

// Member suffixes, planet-set suffixes and mesh suffixes of each stage type, in builder order.
struct StageNames {
  std::vector<std::string> members, planet_sets, meshes;
};

const StageNames& NamesOf(const StageSpec& stage) {
  static const StageNames kSingle{{"sun", "ring", "carrier"}, {"planet"}, {"sun-planet", "ring-planet"}};
  static const StageNames kDouble{{"sun", "ring", "carrier"}, {"inner", "outer"},
                                  {"sun-inner", "inner-outer", "ring-outer"}};
  static const StageNames kRavigneaux{{"sun1", "sun2", "ring", "carrier"}, {"short", "long"},
                                      {"sun1-short", "short-long", "sun2-long", "ring-long"}};
  if (std::holds_alternative<SinglePlanetStageSpec>(stage)) return kSingle;
  if (std::holds_alternative<DoublePlanetStageSpec>(stage)) return kDouble;
  return kRavigneaux;
}

std::vector<std::string> Prefixed(const StageSpec& stage, const std::vector<std::string>& suffixes) {
  std::vector<std::string> out;
  for (const std::string& s : suffixes) out.push_back(StageName(stage) + "." + s);
  return out;
}

}  // namespace

const std::string& StageName(const StageSpec& stage) {
  return std::visit([](const auto& s) -> const std::string& { return s.name; }, stage);
}

int StagePlanetCount(const StageSpec& stage) {
  return std::visit([](const auto& s) { return s.num_planets; }, stage);
}

std::vector<std::string> StageMemberNames(const StageSpec& stage) { return Prefixed(stage, NamesOf(stage).members); }
std::vector<std::string> StagePlanetSetNames(const StageSpec& stage) {
  return Prefixed(stage, NamesOf(stage).planet_sets);
}
std::vector<std::string> StageMeshNames(const StageSpec& stage) { return Prefixed(stage, NamesOf(stage).meshes); }

std::shared_ptr<const PlanetaryTrain> BuildPlanetaryTrain(const PlanetaryTrainDescription& d) {
  PlanetaryTrainBuilder b;
  for (const StageSpec& stage : d.stages) {
    if (const auto* s = std::get_if<SinglePlanetStageSpec>(&stage)) b.AddSinglePlanetStage(*s);
    else if (const auto* s2 = std::get_if<DoublePlanetStageSpec>(&stage)) b.AddDoublePlanetStage(*s2);
    else b.AddRavigneauxStage(std::get<RavigneauxStageSpec>(stage));
  }
  for (const CouplingSpec& c : d.connections) b.AddConnection(c.name, c.member_a, c.member_b);
  for (const CouplingSpec& c : d.clutches) b.AddClutch(c.name, c.member_a, c.member_b);
  for (const BrakeSpec& br : d.brakes) b.AddBrake(br.name, br.member);
  for (const RangeSpec& r : d.ranges) b.AddRange(r.name, r.engaged);
  for (const std::string& in : d.inputs) b.AddInput(in);
  b.SetOutput(d.output);
  return std::move(b).Finalize();
}

TrainModelOptions WithStageFaceWidths(const PlanetaryTrain& train, const PlanetaryTrainDescription& d,
                                      TrainModelOptions o) {
  for (const Stage& stage : train.stages) {
    const auto it = d.stage_face_widths_m.find(stage.name);
    if (it == d.stage_face_widths_m.end()) continue;
    if (o.face_width_m == 0) o.face_width_m = it->second;
    for (int mi : stage.members)
      if (!o.members[train.members[mi].name].face_width_m) o.members[train.members[mi].name].face_width_m = it->second;
    for (int ps : stage.planet_sets)
      if (!o.members[train.planet_sets[ps].name].face_width_m)
        o.members[train.planet_sets[ps].name].face_width_m = it->second;
  }
  return o;
}

GearTrainAssembly AssembleGearTrain(const GearTrainDescription& d) {
  GearTrainAssembly a;
  a.train = BuildPlanetaryTrain(d.train);
  if (!d.range.empty() && !a.train->range_by_name.count(d.range))
    throw std::invalid_argument("gear range '" + d.range + "': no such range");
  a.range = d.range.empty() ? 0 : a.train->RangeIndex(d.range);
  a.options = WithStageFaceWidths(*a.train, d.train, d.options);
  a.model = BuildTrainModel(*a.train, a.range, a.options);
  return a;
}

}  // namespace orrery::gears
