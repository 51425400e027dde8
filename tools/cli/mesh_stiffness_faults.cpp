#include "tools/cli/mesh_stiffness_faults.h"

#include <algorithm>
#include <cstdio>
#include <cmath>
#include <limits>
#include <numbers>
#include <optional>
#include <stdexcept>

#include "import/scene.h"
#include "import/tooth_fault_reader.h"
#include "models/train_assembly.h"
#include "tools/cli/json_writer.h"

namespace orrery::cli {

MeshFaults SelectMeshFaults(const GearTrainScene& gt, const std::string& mesh_name,
                            const std::vector<std::string>& cli_faults, int* mesh, int* branch) {
  // "NAME#k": branch k (1-based) of the mesh.
  const size_t hash = mesh_name.find('#');
  *mesh = gt.train->MeshIndex(mesh_name.substr(0, hash));
  const gears::TrainMesh& m = gt.train->meshes.at(*mesh);
  const auto [g1, g2] = gears::TrainSpecGears(m);
  const int planet_gear = gt.train->gears[g2].planet_set >= 0 ? g2 : g1;
  const int planets = static_cast<int>(gt.train->planet_sets[gt.train->gears[planet_gear].planet_set].angles_rad.size());
  *branch = 0;
  if (hash != std::string::npos) {
    const std::string k = mesh_name.substr(hash + 1);
    char* end = nullptr;
    const long b = std::strtol(k.c_str(), &end, 10);
    if (k.empty() || *end != '\0' || b < 1 || b > planets)
      throw std::runtime_error("--mesh " + mesh_name + ": the branch after '#' must be in 1.." + std::to_string(planets));
    *branch = static_cast<int>(b) - 1;
  }
  std::vector<gears::TrainToothFault> all = gt.options.tooth_faults;
  for (const std::string& text : cli_faults) all.push_back(ReadTrainToothFaultArgument(text, *gt.train));
  MeshFaults out;
  for (const gears::TrainToothFault& f : all) {
    for (int side : {1, 2}) {
      const gears::TrainGear& tg = gt.train->gears[side == 1 ? g1 : g2];
      if (tg.name != f.gear || (tg.planet_set >= 0 && f.branch != *branch)) continue;
      (side == 1 ? out.gear1 : out.gear2).push_back(f.spec);
      const char* kinds[] = {"broken_tooth", "root_crack", "spall"};
      out.names.push_back(f.gear + (tg.planet_set >= 0 ? "#" + std::to_string(f.branch + 1) : "") + " tooth " +
                          std::to_string(f.spec.tooth) + " " + kinds[static_cast<int>(f.spec.kind)]);
    }
  }
  return out;
}

gears::MeshSweepRange FaultEngagement(const gears::GearPair& pair, const MeshFaults& faults) {
  const gears::TvmsSweepFrame frame = gears::MakeTvmsSweepFrame(pair);
  const bool on1 = !faults.gear1.empty();
  const int e = frame.MeshTooth(on1 ? 1 : 2, on1 ? faults.gear1[0].tooth : faults.gear2[0].tooth);
  const double p = 2 * std::numbers::pi / pair.gear1().teeth();
  return {.start_rad = e * p - frame.theta_offset_rad - 0.25 * p,
          .span_rad = (pair.transverse_contact_ratio() + 0.5) * p};
}

std::vector<double> TvmsSecantAt(const gears::GearPair& pair, gears::TvmsOptions options, const MeshFaults& faults,
                                 const std::vector<double>& angles, double load_n) {
  options.samples_per_period = 400;
  options.load_n = load_n;
  options.faults = gears::TvmsFaultsInSweepFrame(pair, faults.gear1, faults.gear2);
  const gears::Tvms t = gears::CalcTvms(pair, options);
  const double offset = gears::MakeTvmsSweepFrame(pair).theta_offset_rad;
  std::vector<double> k;
  for (double a : angles) k.push_back(load_n / gears::InterpolateTvms(t, t.loaded_te_m, a + offset));
  return k;
}

FaultDrop CompareFaultDrop(const std::string& level, const std::vector<double>& angles,
                           const std::vector<double>& healthy, const std::vector<double>& faulty,
                           const std::vector<double>& tvms_healthy, const std::vector<double>& tvms_faulty,
                           bool engagement) {
  // Zones of r below 1 - half the largest drop (or 0.995 over an engagement).
  auto zone = [&](const std::vector<double>& h, const std::vector<double>& f) {
    double max_drop = 0;
    for (size_t i = 0; i < h.size(); ++i) max_drop = std::max(max_drop, 1 - f[i] / h[i]);
    std::vector<char> z;
    for (size_t i = 0; i < h.size(); ++i) z.push_back(f[i] / h[i] < (engagement ? 0.995 : 1 - 0.5 * max_drop));
    return z;
  };
  const std::vector<char> zl = zone(healthy, faulty), zt = zone(tvms_healthy, tvms_faulty);
  FaultDrop d{.level = level, .first_rad = std::numeric_limits<double>::quiet_NaN(),
              .last_rad = std::numeric_limits<double>::quiet_NaN()};
  int n = 0;
  for (size_t i = 0; i < angles.size(); ++i) {
    if (zl[i]) {
      if (!(d.first_rad <= angles[i])) d.first_rad = angles[i];
      d.last_rad = angles[i];
    }
    if (!zt[i]) continue;
    d.mean_drop += 1 - faulty[i] / healthy[i];
    d.tvms_mean_drop += 1 - tvms_faulty[i] / tvms_healthy[i];
    ++n;
  }
  if (n > 0) d.mean_drop /= n, d.tvms_mean_drop /= n;
  return d;
}

void WriteFaultReport(const std::string& level, const gears::GearPair& pair, const gears::TvmsOptions& tvms_options,
                      const MeshFaults& faults, double load_n, const gears::MeshSweepRange& range, int points,
                      const std::function<std::vector<double>(const MeshFaults&)>& sweep, JsonWriter* json,
                      std::ostream& out) {
  std::vector<double> angles;
  for (int i = 0; i < points; ++i) angles.push_back(range.start_rad + range.span_rad * i / points);
  const std::vector<double> healthy = sweep(MeshFaults{}), faulty = sweep(faults);
  gears::TvmsOptions hertz = tvms_options, slices = tvms_options;
  slices.spall_model = gears::TvmsOptions::SpallModel::kSlices;
  const std::vector<double> th = TvmsSecantAt(pair, hertz, MeshFaults{}, angles, load_n);
  const std::vector<double> tf = TvmsSecantAt(pair, hertz, faults, angles, load_n);
  // A spall: both TVMS models; a crack acts over the whole engagement.
  bool spall = false, crack = false;
  for (const auto* list : {&faults.gear1, &faults.gear2})
    for (const gears::ToothFaultSpec& f : *list) {
      spall |= f.kind == gears::ToothFaultSpec::Kind::kSpall;
      crack |= f.kind == gears::ToothFaultSpec::Kind::kRootCrack;
    }
  std::vector<FaultDrop> rows = {CompareFaultDrop("lumped TVMS", angles, th, tf, th, tf, crack),
                                 CompareFaultDrop(level, angles, healthy, faulty, th, tf, crack)};
  if (spall) {
    const std::vector<double> ts = TvmsSecantAt(pair, slices, faults, angles, load_n);
    rows.push_back(CompareFaultDrop("lumped TVMS (lost slices)", angles, th, ts, th, ts, false));
    rows.push_back(CompareFaultDrop(level + " vs lost slices", angles, healthy, faulty, th, ts, false));
  }
  constexpr double kDeg = 180 / std::numbers::pi;
  if (json) {
    JsonWriter& w = *json;
    w.Key("faults").BeginArray();
    for (const std::string& n : faults.names) w.String(n);
    w.EndArray();
    auto array = [&](const char* key, const std::vector<double>& v) {
      w.Key(key).BeginArray();
      for (double x : v) w.Number(x);
      w.EndArray();
    };
    array("roll_angle_rad", angles);
    array("healthy_stiffness_n_per_m", healthy);
    array("faulty_stiffness_n_per_m", faulty);
    array("tvms_healthy_n_per_m", th);
    array("tvms_faulty_n_per_m", tf);
    w.Key("levels").BeginArray();
    for (const FaultDrop& d : rows) {
      w.BeginObject().Key("level").String(d.level);
      w.Key("drop_zone_start_rad").Number(d.first_rad).Key("drop_zone_end_rad").Number(d.last_rad);
      w.Key("mean_drop").Number(d.mean_drop).Key("tvms_mean_drop").Number(d.tvms_mean_drop);
      w.EndObject();
    }
    w.EndArray();
    return;
  }
  char line[256];
  out << "faults:";
  for (const std::string& n : faults.names) out << " " << n << ";";
  out << "\nroll deg   k healthy  k faulty  ratio   TVMS healthy  TVMS faulty  ratio  (N/um)\n";
  for (size_t i = 0; i < angles.size(); ++i) {
    std::snprintf(line, sizeof line, "%8.3f %10.1f %9.1f %6.3f %14.1f %12.1f %6.3f\n", angles[i] * kDeg,
                  healthy[i] * 1e-6, faulty[i] * 1e-6, faulty[i] / healthy[i], th[i] * 1e-6, tf[i] * 1e-6,
                  tf[i] / th[i]);
    out << line;
  }
  out << "| level | drop zone (deg) | mean drop | TVMS drop | diff |\n";
  for (const FaultDrop& d : rows) {
    std::snprintf(line, sizeof line, "| %s | %.2f .. %.2f | %.1f %% | %.1f %% | %+.1f %% |\n", d.level.c_str(),
                  d.first_rad * kDeg, d.last_rad * kDeg, 100 * d.mean_drop, 100 * d.tvms_mean_drop,
                  100 * (d.mean_drop - d.tvms_mean_drop));
    out << line;
  }
}

void WriteFaultSweep(const FaultSweepHead& head, const std::string& level, const gears::GearPair& pair,
                     const gears::TvmsOptions& tvms_options, const MeshFaults& faults,
                     const std::function<std::vector<double>(const MeshFaults&, const gears::MeshSweepRange&)>& sweep,
                     std::ostream& out) {
  const gears::MeshSweepRange range = FaultEngagement(pair, faults);
  const auto level_sweep = [&](const MeshFaults& f) { return sweep(f, range); };
  std::optional<JsonWriter> w;
  if (head.json) {
    w.emplace(out);
    w->BeginObject().Key("scene").String(head.scene).Key("mesh").String(head.mesh);
    w->Key("load_n").Number(head.load_n);
  } else {
    out << "scene " << head.scene << ", mesh " << head.mesh << ", load " << head.load_n
        << " N along the line of action, " << head.surfaces << "\n";
  }
  WriteFaultReport(level, pair, tvms_options, faults, head.load_n, range, head.points, level_sweep,
                   w ? &*w : nullptr, out);
  if (w) w->EndObject();
}

}  // namespace orrery::cli
