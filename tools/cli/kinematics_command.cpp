#include "tools/cli/kinematics_command.h"

#include <cmath>
#include <cstdio>
#include <exception>
#include <filesystem>
#include <limits>
#include <numbers>
#include <optional>
#include <stdexcept>

#include "import/scene.h"
#include "models/mesh_stiffness.h"
#include "models/planetary_kinematics.h"
#include "models/planetary_power_flow.h"
#include "models/tooth_fault.h"
#include "models/train_dynamics.h"
#include "tools/cli/error_message.h"
#include "tools/cli/json_writer.h"

namespace orrery::cli {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kRadToDeg = 180.0 / std::numbers::pi;
constexpr double kRadPerSToRpm = 30.0 / std::numbers::pi;

// Everything reported for one train mesh.
struct MeshReport {
  std::string name, stage, gear_1, gear_2, geometry_error;
  double mesh_frequency_hz = 0, static_force_n = 0, line_of_action_force_n = 0, normal_force_n = 0;
  bool loaded = false;
  double base_radius_1_m = kNaN, base_radius_2_m = kNaN, contact_ratio = kNaN, overlap_ratio = kNaN;
  double working_pressure_angle_deg = kNaN, face_width_m = kNaN;
  double c_prime_th = kNaN, c_prime = kNaN, c_gamma_alpha = kNaN, c_gamma_beta = kNaN;
  double tvms_mean = kNaN, tvms_min = kNaN, tvms_max = kNaN, model_stiffness = kNaN;
};

std::string Fmt(const char* format, double x) {
  if (!std::isfinite(x)) return "-";
  char buffer[64];
  std::snprintf(buffer, sizeof buffer, format, x);
  return buffer;
}

std::string Pad(const std::string& s, std::size_t width, bool left = false) {
  if (s.size() >= width) return left ? s + " " : " " + s;
  const std::string fill(width - s.size(), ' ');
  return left ? s + fill : fill + s;
}

// Train gear index of a scene fault (the reader checked the name).
int SceneFaultGear(const gears::PlanetaryTrain& t, const gears::TrainToothFault& f) {
  for (size_t i = 0; i < t.gears.size(); ++i)
    if (t.gears[i].name == f.gear) return static_cast<int>(i);
  throw std::invalid_argument("tooth fault on '" + f.gear + "': no such gear");
}

// What the report says of a gear train at the range asked for: kinematics at the operating
// point, power flow at the input torque (unit speeds at rest), and per mesh its forces, geometry
// and stiffness.
struct TrainReport {
  int range = 0;
  Eigen::VectorXd w;  // input speeds, rad/s
  gears::PlanetaryKinematics k;
  gears::PlanetaryPowerFlow p;
  bool torque_given = false;
  std::vector<MeshReport> meshes;
};

int ReportRange(const GearTrainScene& g, const KinematicsArgs& args) {
  const gears::PlanetaryTrain& t = *g.train;
  if (args.range.empty()) return g.range;
  if (!t.range_by_name.count(args.range)) {
    std::string known;
    for (const gears::GearRange& r : t.ranges) known += (known.empty() ? "" : ", ") + r.name;
    throw std::invalid_argument("--range: no gear range named '" + args.range + "' (ranges: " + known + ")");
  }
  return t.RangeIndex(args.range);
}

MeshReport MeshReportOf(const GearTrainScene& g, const TrainReport& tr, int mi) {
  const gears::PlanetaryTrain& t = *g.train;
  const gears::PlanetaryKinematics& k = tr.k;
  const gears::PlanetaryPowerFlow& p = tr.p;
  const bool torque_given = tr.torque_given;
  const int range = tr.range;
  const gears::TrainMesh& m = t.meshes[mi];
  MeshReport r;
  r.name = m.name;
  r.stage = t.stages[m.stage].name;
  r.mesh_frequency_hz = k.mesh_frequencies_hz(mi);
  r.static_force_n = torque_given ? p.mesh_tangential_forces_n(mi) : 0.0;
  r.line_of_action_force_n = torque_given ? p.mesh_line_of_action_forces_n(mi) : 0.0;
  r.normal_force_n = torque_given ? p.mesh_normal_forces_n(mi) : 0.0;
  r.loaded = torque_given && p.mesh_loaded[mi];
  const bool internal = m.kind == gears::MeshKind::kInternal;
  r.gear_1 = t.gears[internal ? m.gear_b : m.gear_a].name;
  r.gear_2 = t.gears[internal ? m.gear_a : m.gear_b].name;
  try {
    const gears::GearPair pair = gears::MakeTrainGearPair(t, mi, g.options);
    r.base_radius_1_m = pair.gear1().base_radius_m();
    r.base_radius_2_m = pair.gear2().base_radius_m();
    r.contact_ratio = pair.transverse_contact_ratio();
    r.overlap_ratio = pair.overlap_ratio();
    r.working_pressure_angle_deg = pair.working_pressure_angle_rad() * kRadToDeg;
    r.face_width_m = pair.face_width_m();
    const gears::Iso6336Stiffness iso = gears::CalcIso6336Stiffness(pair);
    r.c_prime_th = iso.c_th;
    r.c_prime = iso.c_single;
    r.c_gamma_alpha = iso.c_gamma_alpha;
    r.c_gamma_beta = iso.c_gamma_beta;
    const gears::Tvms tvms = gears::CalcTvms(pair, gears::MakeTrainTvmsOptions(t, mi, g.options));
    r.tvms_mean = tvms.mean_n_per_m;
    r.tvms_min = tvms.min_n_per_m;
    r.tvms_max = tvms.max_n_per_m;
  } catch (const std::exception& e) {
    r.geometry_error = OneLine(e.what());
  }
  if (range == g.range)
    for (const gears::TrainMeshElement& e : g.model->meshes)
      if (e.train_mesh == mi && e.branch == 0) r.model_stiffness = e.stiffness_n_per_m;
  return r;
}

TrainReport MakeTrainReport(const GearTrainScene& g, const KinematicsArgs& args) {
  const gears::PlanetaryTrain& t = *g.train;
  TrainReport tr;
  tr.range = ReportRange(g, args);
  const int ni = static_cast<int>(t.inputs.size());
  tr.w.resize(ni);
  Eigen::VectorXd w_flow = Eigen::VectorXd::Ones(ni);
  for (int i = 0; i < ni; ++i) tr.w(i) = g.input_speeds_rad_s[i];
  if (tr.w.cwiseAbs().maxCoeff() > 0) w_flow = tr.w;
  tr.k = gears::SolvePlanetaryKinematics(t, tr.range, tr.w);
  tr.p = gears::CalcPlanetaryPowerFlow(t, gears::SolvePlanetaryKinematics(t, tr.range, w_flow), t.inputs[0],
                                       g.input_torque_n_m);
  tr.torque_given = g.input_torque_n_m != 0;
  for (int mi = 0; mi < static_cast<int>(t.meshes.size()); ++mi) tr.meshes.push_back(MeshReportOf(g, tr, mi));
  return tr;
}

void WriteTrainJson(const Scene& scene, const TrainReport& tr, std::ostream& out) {
  const GearTrainScene& g = *scene.gear_train;
  const gears::PlanetaryTrain& t = *g.train;
  const gears::PlanetaryKinematics& k = tr.k;
  const gears::PlanetaryPowerFlow& p = tr.p;
  const Eigen::VectorXd& w = tr.w;
  const int range = tr.range, ni = static_cast<int>(w.size());
  const bool torque_given = tr.torque_given;
  const std::vector<MeshReport>& meshes = tr.meshes;
  JsonWriter j(out);
  j.BeginObject().Key("scene").String(scene.name).Key("kind").String("gear_train");
  j.Key("range").String(t.ranges[range].name).Key("ratio").Number(k.ratio);
  j.Key("inputs").BeginArray();
  for (int i = 0; i < ni; ++i)
    j.BeginObject().Key("member").String(t.members[t.inputs[i]].name).Key("speed_rad_s").Number(w(i)).EndObject();
  j.EndArray().Key("input_torque_n_m").Number(g.input_torque_n_m);
  j.Key("members").BeginObject();
  for (int i = 0; i < t.num_members(); ++i) {
    j.Key(t.members[i].name).BeginObject();
    j.Key("speed_rad_s").Number(k.speeds_rad_s(i)).Key("speed_rpm").Number(k.speeds_rad_s(i) * kRadPerSToRpm);
    j.Key("torque_n_m").Number(p.mesh_torques_n_m(i)).Key("external_torque_n_m").Number(p.external_torques_n_m(i));
    j.Key("loaded").Bool(torque_given && p.member_loaded[i]).EndObject();
  }
  j.EndObject().Key("planet_sets").BeginObject();
  for (size_t s = 0; s < t.planet_sets.size(); ++s) {
    const double rel = k.planet_relative_speeds_rad_s(s);
    j.Key(t.planet_sets[s].name).BeginObject().Key("speed_rad_s").Number(k.speeds_rad_s(t.num_members() + s));
    j.Key("relative_speed_rad_s").Number(rel).Key("relative_frequency_hz").Number(std::abs(rel) / (2 * std::numbers::pi));
    j.EndObject();
  }
  j.EndObject().Key("stage_mesh_frequencies_hz").BeginObject();
  for (size_t s = 0; s < t.stages.size(); ++s) j.Key(t.stages[s].name).Number(k.stage_mesh_frequencies_hz(s));
  j.EndObject().Key("meshes").BeginArray();
  for (const MeshReport& r : meshes) {
    j.BeginObject().Key("name").String(r.name).Key("stage").String(r.stage);
    j.Key("mesh_frequency_hz").Number(r.mesh_frequency_hz).Key("static_force_n").Number(r.static_force_n);
    j.Key("line_of_action_force_n").Number(r.line_of_action_force_n).Key("normal_force_n").Number(r.normal_force_n);
    j.Key("loaded").Bool(r.loaded).Key("gear_1").String(r.gear_1).Key("gear_2").String(r.gear_2);
    j.Key("base_radius_1_m").Number(r.base_radius_1_m).Key("base_radius_2_m").Number(r.base_radius_2_m);
    j.Key("contact_ratio").Number(r.contact_ratio).Key("overlap_ratio").Number(r.overlap_ratio);
    j.Key("working_pressure_angle_deg").Number(r.working_pressure_angle_deg).Key("face_width_m").Number(r.face_width_m);
    j.Key("c_prime_th").Number(r.c_prime_th).Key("c_prime").Number(r.c_prime);
    j.Key("c_gamma_alpha").Number(r.c_gamma_alpha).Key("c_gamma_beta").Number(r.c_gamma_beta);
    j.Key("tvms_mean_n_per_m").Number(r.tvms_mean).Key("tvms_min_n_per_m").Number(r.tvms_min);
    j.Key("tvms_max_n_per_m").Number(r.tvms_max).Key("tvms_range_n_per_m").Number(r.tvms_max - r.tvms_min);
    j.Key("model_stiffness_n_per_m").Number(r.model_stiffness);
    if (!r.geometry_error.empty()) j.Key("geometry_error").String(r.geometry_error);
    j.EndObject();
  }
  j.EndArray().Key("fault_frequencies_hz").BeginObject();
  for (size_t i = 0; i < t.gears.size(); ++i) j.Key(t.gears[i].name).Number(k.gear_fault_frequencies_hz(i));
  // The scene's own faults (dynamics.faults) with the rate at which each meets its partners.
  j.EndObject().Key("scene_faults").BeginArray();
  for (const gears::TrainToothFault& f : g.options.tooth_faults) {
    j.BeginObject().Key("gear").String(f.gear).Key("branch").Number(f.branch + 1);
    j.Key("kind").String(gears::KindName(f.spec.kind)).Key("tooth").Number(f.spec.tooth);
    j.Key("fault_frequency_hz").Number(k.gear_fault_frequencies_hz(SceneFaultGear(t, f))).EndObject();
  }
  j.EndArray().EndObject();
}

void WriteTrainText(const Scene& scene, const TrainReport& tr, std::ostream& out) {
  const GearTrainScene& g = *scene.gear_train;
  const gears::PlanetaryTrain& t = *g.train;
  const gears::PlanetaryKinematics& k = tr.k;
  const gears::PlanetaryPowerFlow& p = tr.p;
  const Eigen::VectorXd& w = tr.w;
  const int range = tr.range, ni = static_cast<int>(w.size());
  const std::vector<MeshReport>& meshes = tr.meshes;
  out << "scene " << scene.name << " (gear_train), range " << t.ranges[range].name << ", ratio "
      << Fmt("%.5g", k.ratio) << ", input torque " << Fmt("%g", g.input_torque_n_m) << " N m\n";
  for (int i = 0; i < ni; ++i)
    out << "input " << t.members[t.inputs[i]].name << "  " << Fmt("%.6g", w(i)) << " rad/s ("
        << Fmt("%.6g", w(i) * kRadPerSToRpm) << " rpm)\n";
  out << "\nmembers" << std::string(10, ' ') << Pad("speed rad/s", 14) << Pad("rpm", 12)
      << Pad("torque N m", 14) << Pad("external N m", 14) << '\n';
  for (int i = 0; i < t.num_members(); ++i)
    out << "  " << Pad(t.members[i].name, 15, true) << Pad(Fmt("%.6g", k.speeds_rad_s(i)), 14)
        << Pad(Fmt("%.6g", k.speeds_rad_s(i) * kRadPerSToRpm), 12) << Pad(Fmt("%.6g", p.mesh_torques_n_m(i)), 14)
        << Pad(Fmt("%.6g", p.external_torques_n_m(i)), 14) << '\n';
  out << "\nplanet sets" << std::string(6, ' ') << Pad("speed rad/s", 14) << Pad("rel. rad/s", 14)
      << Pad("rel. Hz", 12) << '\n';
  for (size_t s = 0; s < t.planet_sets.size(); ++s) {
    const double rel = k.planet_relative_speeds_rad_s(s);
    out << "  " << Pad(t.planet_sets[s].name, 15, true) << Pad(Fmt("%.6g", k.speeds_rad_s(t.num_members() + s)), 14)
        << Pad(Fmt("%.6g", rel), 14) << Pad(Fmt("%.5g", std::abs(rel) / (2 * std::numbers::pi)), 12) << '\n';
  }
  out << "\nmeshes" << std::string(13, ' ') << Pad("f_mesh Hz", 11) << Pad("F_t N", 10) << Pad("F_bt N", 10)
      << Pad("r_b1 mm", 9) << Pad("r_b2 mm", 9) << Pad("eps_a", 7) << Pad("a_wt deg", 9) << Pad("c'_th", 7)
      << Pad("c'", 7) << Pad("c_ga", 7) << Pad("c_gb", 7) << Pad("TVMS mean N/m", 14) << Pad("range N/m", 11)
      << Pad("model N/m", 11) << '\n';
  for (const MeshReport& r : meshes) {
    out << "  " << Pad(r.name, 17, true) << Pad(Fmt("%.5g", r.mesh_frequency_hz), 11)
        << Pad(Fmt("%.5g", r.static_force_n), 10) << Pad(Fmt("%.5g", r.line_of_action_force_n), 10)
        << Pad(Fmt("%.4g", r.base_radius_1_m * 1e3), 9) << Pad(Fmt("%.4g", r.base_radius_2_m * 1e3), 9)
        << Pad(Fmt("%.4f", r.contact_ratio), 7) << Pad(Fmt("%.3f", r.working_pressure_angle_deg), 9)
        << Pad(Fmt("%.2f", r.c_prime_th), 7) << Pad(Fmt("%.2f", r.c_prime), 7) << Pad(Fmt("%.2f", r.c_gamma_alpha), 7)
        << Pad(Fmt("%.2f", r.c_gamma_beta), 7) << Pad(Fmt("%.4g", r.tvms_mean), 14)
        << Pad(Fmt("%.3g", r.tvms_max - r.tvms_min), 11) << Pad(Fmt("%.4g", r.model_stiffness), 11) << '\n';
    if (!r.geometry_error.empty()) out << "    (no geometry: " << r.geometry_error << ")\n";
  }
  out << "  (c'_th, c', c_gamma_alpha, c_gamma_beta in N/(mm um); F per planet)\n";
  out << "\nfault frequencies (Hz)\n";
  for (size_t i = 0; i < t.gears.size(); ++i)
    out << "  " << Pad(t.gears[i].name, 15, true) << Pad(Fmt("%.5g", k.gear_fault_frequencies_hz(i)), 12) << '\n';
  if (!g.options.tooth_faults.empty()) out << "\nscene faults (Hz: the rate at which the tooth meets its partners)\n";
  for (const gears::TrainToothFault& f : g.options.tooth_faults) {
    const std::string where = t.gears[SceneFaultGear(t, f)].planet_set >= 0 ? f.gear + " #" + std::to_string(f.branch + 1) : f.gear;
    out << "  " << Pad(where, 15, true) << Pad(std::string(gears::KindName(f.spec.kind)) + " tooth " + std::to_string(f.spec.tooth), 22, true)
        << Pad(Fmt("%.5g", k.gear_fault_frequencies_hz(SceneFaultGear(t, f))), 12) << '\n';
  }
  out << std::flush;
}

int GearTrainReport(const Scene& scene, const KinematicsArgs& args, std::ostream& out) {
  const TrainReport tr = MakeTrainReport(*scene.gear_train, args);
  if (args.json) WriteTrainJson(scene, tr, out);
  else WriteTrainText(scene, tr, out);
  return kExitSuccess;
}

int LumpedStageReport(const Scene& scene, const KinematicsArgs& args, std::ostream& out) {
  const LumpedStageScene& s = *scene.lumped_stage;
  const LumpedStageParams& p = s.params;
  const char* dofs = p.dofs == LumpedStageParams::Dofs::kTorsional ? "torsional"
                     : p.dofs == LumpedStageParams::Dofs::kPlanar  ? "planar"
                                                                   : "spatial";
  const std::vector<std::pair<std::string, const LumpedMember*>> members{
      {"sun", &p.sun}, {"ring", &p.ring}, {"carrier", &p.carrier}, {"planet", &p.planet}};
  if (args.json) {
    JsonWriter j(out);
    j.BeginObject().Key("scene").String(scene.name).Key("kind").String("lumped_stage");
    j.Key("dofs").String(dofs).Key("planets").Int(p.planets).Key("members").BeginObject();
    for (const auto& [name, m] : members) {
      j.Key(name).BeginObject().Key("mass_kg").Number(m->mass).Key("inertia_kg_m2").Number(m->inertia);
      j.Key("radius_m").Number(m->radius).Key("bearing_stiffness_n_per_m").Number(m->bearing_stiffness);
      j.Key("torsional_stiffness_n_m_per_rad").Number(m->torsional_stiffness).Key("teeth").Int(m->teeth).EndObject();
    }
    j.EndObject().Key("meshes").BeginArray();
    j.BeginObject().Key("name").String("sun-planet").Key("stiffness_n_per_m").Number(p.mesh_stiffness_sun)
        .Key("pressure_angle_deg").Number(p.pressure_angle_sun * kRadToDeg).EndObject();
    j.BeginObject().Key("name").String("ring-planet").Key("stiffness_n_per_m").Number(p.mesh_stiffness_ring)
        .Key("pressure_angle_deg").Number(p.pressure_angle_ring * kRadToDeg).EndObject();
    j.EndArray().Key("ports").BeginArray();
    for (const LumpedStagePort& port : s.ports)
      j.BeginObject().Key("member").String(port.member)
          .Key("kind").String(port.kind == LumpedStagePort::Kind::kSpeed ? "speed" : "torque")
          .Key("role").String(port.is_load ? "load" : "input").Key("function").String(port.function.Describe())
          .EndObject();
    j.EndArray().EndObject();
    return kExitSuccess;
  }
  out << "scene " << scene.name << " (lumped_stage): " << dofs << ", " << p.planets << " planets\n\n";
  out << "members  " << Pad("mass kg", 10) << Pad("I kg m^2", 12) << Pad("radius mm", 11) << Pad("k_bearing N/m", 15)
      << Pad("k_torsion N m/rad", 19) << Pad("teeth", 6) << '\n';
  for (const auto& [name, m] : members)
    out << "  " << Pad(name, 7, true) << Pad(Fmt("%.5g", m->mass), 10) << Pad(Fmt("%.5g", m->inertia), 12)
        << Pad(Fmt("%.5g", m->radius * 1e3), 11) << Pad(Fmt("%.4g", m->bearing_stiffness), 15)
        << Pad(Fmt("%.4g", m->torsional_stiffness), 19) << Pad(std::to_string(m->teeth), 6) << '\n';
  out << "\nmeshes  sun-planet " << Fmt("%.4g", p.mesh_stiffness_sun) << " N/m at " << Fmt("%.4g", p.pressure_angle_sun * kRadToDeg)
      << " deg;  ring-planet " << Fmt("%.4g", p.mesh_stiffness_ring) << " N/m at "
      << Fmt("%.4g", p.pressure_angle_ring * kRadToDeg) << " deg\n";
  for (const LumpedStagePort& port : s.ports)
    out << (port.is_load ? "load   " : "input  ") << port.member << " "
        << (port.kind == LumpedStagePort::Kind::kSpeed ? "speed " : "torque ") << port.function.Describe() << '\n';
  out << "(no tooth counts and tooth forms: speeds, mesh frequencies and stiffnesses need a gear_train scene)\n"
      << std::flush;
  return kExitSuccess;
}

}  // namespace

int KinematicsCommand(const KinematicsArgs& args, std::ostream& out, std::ostream& err) {
  std::error_code ec;
  if (!std::filesystem::exists(args.scene_path, ec)) {
    ReportError(err, "scene file " + args.scene_path + ": no such file");
    return kExitFailure;
  }
  try {
    const Scene scene = LoadScene(args.scene_path, args.overrides);
    if (scene.kind == SceneKind::kGearTrain) return GearTrainReport(scene, args, out);
    if (!args.range.empty()) throw std::invalid_argument("--range: only gear_train scenes have gear ranges");
    if (scene.kind == SceneKind::kLumpedStage) return LumpedStageReport(scene, args, out);
    throw std::invalid_argument(args.scene_path + ": kinematics needs a gear_train or lumped_stage scene");
  } catch (const std::exception& e) {
    ReportError(err, e.what());
    return kExitFailure;
  }
}

}  // namespace orrery::cli
