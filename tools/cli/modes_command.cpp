#include "tools/cli/modes_command.h"

#include <cmath>
#include <cstdio>
#include <exception>
#include <filesystem>
#include <limits>
#include <numbers>
#include <optional>

#include "mbd/linearization.h"
#include "models/modal_analysis.h"
#include "tools/cli/error_message.h"
#include "tools/cli/json_writer.h"

namespace orrery::cli {
namespace {

constexpr double kEigenSafety = 1e3;       // as modal_analysis.cpp
constexpr double kCentralEnergyShare = 1e-6;

std::string ClassName(gears::ModeClass c) {
  switch (c) {
    case gears::ModeClass::kRigidBody: return "rigid_body";
    case gears::ModeClass::kRotational: return "rotational";
    case gears::ModeClass::kTranslational: return "translational";
    case gears::ModeClass::kPlanet: return "planet";
    case gears::ModeClass::kMixed: return "mixed";
  }
  return "mixed";
}

const char* KindName(SceneKind k) {
  switch (k) {
    case SceneKind::kMultibody: return "multibody";
    case SceneKind::kLumpedStage: return "lumped_stage";
    case SceneKind::kGearTrain: return "gear_train";
  }
  return "?";
}

// Modes of the model at rest in its initial configuration, grouped; `classify` names mode i.
template <class Classify>
SceneModes GroupedModes(const Model& model, Classify classify) {
  const State op{0.0, model.q_initial, Eigen::VectorXd::Zero(model.nv)};
  const LinearModel lin = Linearize(model, op);
  const ModalResult modal = CalcModes(lin);
  const int n = static_cast<int>(modal.frequencies_hz.size());
  std::vector<double> lambda(n);
  double lambda_max = 0;
  for (int i = 0; i < n; ++i) {
    const double w = 2 * std::numbers::pi * modal.frequencies_hz[i];
    lambda[i] = (modal.frequencies_hz[i] < 0 ? -1.0 : 1.0) * w * w;
    lambda_max = std::max(lambda_max, std::abs(lambda[i]));
  }
  const double tol = kEigenSafety * model.nv * std::numeric_limits<double>::epsilon() * lambda_max;
  SceneModes r;
  int first = 0;
  for (int i = 0; i < n; ++i) {
    const bool rigid = std::abs(lambda[i]) <= tol;
    r.frequencies_hz.push_back(rigid ? 0.0 : modal.frequencies_hz[i]);
    if (i > 0 && SameEigenvalue(lambda[i], lambda[first], tol)) {
      ++r.groups.back().multiplicity;
      continue;
    }
    first = i;
    r.groups.push_back({r.frequencies_hz.back(), rigid ? std::string("rigid_body")
                                                       : classify(lin, modal.shapes.col(i)), 1});
  }
  return r;
}

// Lin & Parker classes from the central members' kinetic energy in spin and translation.
SceneModes LumpedStageModes(const LumpedStageScene& s) {
  const Model& m = *s.stage.model;
  const bool torsional = s.params.dofs == LumpedStageParams::Dofs::kTorsional;
  auto classify = [&](const LinearModel& lin, const Eigen::VectorXd& x) -> std::string {
    const Eigen::VectorXd Mx = lin.M * x;
    const double kinetic = x.dot(Mx);
    double e_rot = 0, e_trans = 0;
    for (JointIndex j : {s.stage.sun, s.stage.ring, s.stage.carrier}) {
      const Joint& joint = m.joints[j];
      Eigen::VectorXd rot = Eigen::VectorXd::Zero(x.size()), trans = rot;
      for (int k = 0; k < joint.nv; ++k)
        (k == s.rotation_coordinate ? rot : trans)(joint.v_start + k) = x(joint.v_start + k);
      e_rot = std::max(e_rot, rot.dot(lin.M * rot) / kinetic);
      e_trans = std::max(e_trans, trans.dot(lin.M * trans) / kinetic);
    }
    const bool still_rot = e_rot < kCentralEnergyShare, still_trans = e_trans < kCentralEnergyShare;
    if (still_rot && still_trans) return "planet";
    if (torsional || still_trans) return "rotational";
    if (still_rot) return "translational";
    return "mixed";
  };
  return GroupedModes(m, classify);
}

SceneModes GearTrainModes(const GearTrainScene& g) {
  const gears::TrainModes modes = gears::CalcTrainModes(*g.model);
  SceneModes r;
  for (const gears::TrainMode& mode : modes.modes)
    r.frequencies_hz.push_back(mode.mode_class == gears::ModeClass::kRigidBody ? 0.0 : mode.frequency_hz);
  for (const gears::ModeGroup& grp : modes.groups)
    r.groups.push_back({grp.mode_class == gears::ModeClass::kRigidBody ? 0.0 : grp.frequency_hz,
                        ClassName(grp.mode_class), grp.multiplicity});
  return r;
}

}  // namespace

SceneModes CalcSceneModes(const Scene& scene) {
  switch (scene.kind) {
    case SceneKind::kLumpedStage: return LumpedStageModes(*scene.lumped_stage);
    case SceneKind::kGearTrain: return GearTrainModes(*scene.gear_train);
    case SceneKind::kMultibody: break;
  }
  return GroupedModes(*scene.model, [](const LinearModel&, const Eigen::VectorXd&) { return std::string("mode"); });
}

int ModesCommand(const ModesArgs& args, std::ostream& out, std::ostream& err) {
  std::error_code ec;
  if (!std::filesystem::exists(args.scene_path, ec)) {
    ReportError(err, "scene file " + args.scene_path + ": no such file");
    return kExitFailure;
  }
  std::optional<Scene> scene;
  SceneModes modes;
  try {
    scene = LoadScene(args.scene_path, args.overrides);
    modes = CalcSceneModes(*scene);
  } catch (const std::exception& e) {
    ReportError(err, e.what());
    return kExitFailure;
  }
  if (args.json) {
    JsonWriter w(out);
    w.BeginObject().Key("scene").String(scene->name).Key("kind").String(KindName(scene->kind));
    w.Key("frequencies_hz").BeginArray();
    for (double f : modes.frequencies_hz) w.Number(f);
    w.EndArray().Key("modes").BeginArray();
    for (const ModeGroupEntry& g : modes.groups)
      w.BeginObject().Key("frequency_hz").Number(g.frequency_hz).Key("class").String(g.mode_class)
          .Key("multiplicity").Int(g.multiplicity).EndObject();
    w.EndArray().EndObject();
    return kExitSuccess;
  }
  out << "scene " << scene->name << " (" << KindName(scene->kind) << "): " << modes.frequencies_hz.size()
      << " modes, " << modes.groups.size() << " distinct\n";
  char line[128];
  std::snprintf(line, sizeof line, "%16s  %-14s %s\n", "frequency (Hz)", "class", "multiplicity");
  out << line;
  for (const ModeGroupEntry& g : modes.groups) {
    std::snprintf(line, sizeof line, "%16.4f  %-14s %d\n", g.frequency_hz, g.mode_class.c_str(), g.multiplicity);
    out << line;
  }
  out << std::flush;
  return kExitSuccess;
}

}  // namespace orrery::cli
