#include "tools/cli/mesh_stiffness_command.h"

#include <cstdio>
#include <exception>
#include <stdexcept>

#include "models/gear_contact.h"
#include "import/scene.h"
#include "models/mesh_stiffness.h"
#include "tools/cli/error_message.h"
#include "tools/cli/flexible_mesh_stiffness.h"
#include "tools/cli/json_writer.h"
#include "tools/cli/mesh_stiffness_faults.h"

namespace orrery::cli {

void WriteSweepPoints(JsonWriter& w, const std::vector<gears::MeshSweepPoint>& points) {
  auto array = [&](const char* key, auto value) {
    w.Key(key).BeginArray();
    for (const gears::MeshSweepPoint& p : points) w.Number(value(p));
    w.EndArray();
  };
  array("roll_angle_rad", [](const auto& p) { return p.roll_angle_rad; });
  array("transmission_error_m", [](const auto& p) { return p.transmission_error_m; });
  array("stiffness_n_per_m", [](const auto& p) { return p.stiffness_n_per_m; });
  array("normal_force_n", [](const auto& p) { return p.normal_force_n; });
  array("contact_points", [](const auto& p) { return double(p.contact_points); });
  array("teeth_in_contact", [](const auto& p) { return double(p.teeth_in_contact); });
}

int MeshStiffnessCommand(const MeshStiffnessArgs& args, std::ostream& out, std::ostream& err) {
  if (args.flexible) return FlexibleMeshStiffnessCommand(args, out, err);
  try {
    const Scene scene = LoadScene(args.scene_path, args.overrides);
    if (scene.kind != SceneKind::kGearTrain)
      throw std::runtime_error("mesh-stiffness needs a gear_train scene, '" + args.scene_path +
                               "' is not one");
    const GearTrainScene& gt = *scene.gear_train;
    int mesh = -1, branch = 0;
    const MeshFaults faults = SelectMeshFaults(gt, args.mesh, args.faults, &mesh, &branch);
    // The pair and the oracles of the lumped models.
    const gears::GearPair pair = gears::MakeTrainGearPair(*gt.train, mesh, gt.options);
    const gears::Iso6336Stiffness iso = gears::CalcIso6336Stiffness(pair);
    const gears::TvmsOptions tvms_options = gears::MakeTrainTvmsOptions(*gt.train, mesh, gt.options);
    const gears::Tvms tvms = gears::CalcTvms(pair, tvms_options);
    // Rigid tooth contact calibrated at the load (a crack's stiffness ratio on the train's blanks).
    gears::GearContactOptions options;
    options.calibration_load_n = args.load_n;
    options.rim_radius1_m = tvms_options.bore_radius1_m;
    options.rim_radius2_m = tvms_options.rim_radius2_m;
    options.material = tvms_options.material1;
    if (!faults.empty()) {
      // Healthy and faulty over the first fault's engagement, against the TVMS.
      const auto level = [&](const MeshFaults& f, const gears::MeshSweepRange& range) {
        gears::GearContactOptions o = options;
        o.faults1 = f.gear1, o.faults2 = f.gear2;
        std::vector<double> k;
        for (const gears::MeshSweepPoint& p : gears::SweepGearMesh(pair, o, args.load_n, args.points, range).points)
          k.push_back(p.stiffness_n_per_m);
        return k;
      };
      WriteFaultSweep({.scene = scene.name, .mesh = args.mesh, .surfaces = "rigid tooth contact", .load_n = args.load_n,
                       .points = args.points, .json = args.json},
                      "rigid contact", pair, tvms_options, faults, level, out);
      return kExitSuccess;
    }
    // Swept over one mesh period.
    const gears::MeshSweep sweep = gears::SweepGearMesh(pair, options, args.load_n, args.points);

    if (args.json) {
      JsonWriter w(out);
      w.BeginObject().Key("scene").String(scene.name).Key("mesh").String(args.mesh);
      w.Key("load_n").Number(args.load_n);
      WriteSweepPoints(w, sweep.points);
      w.Key("mean_stiffness_n_per_m").Number(sweep.mean_stiffness_n_per_m);
      w.Key("te_peak_to_peak_m").Number(sweep.te_peak_to_peak_m);
      w.Key("iso6336_single_pair_n_per_m").Number(iso.c_single_n_per_m);
      w.Key("iso6336_c_gamma_alpha_n_per_m").Number(iso.c_gamma_alpha_n_per_m);
      w.Key("tvms_mean_n_per_m").Number(tvms.mean_n_per_m);
      w.Key("penalty_stiffness_per_area").Number(sweep.calibration.stiffness_per_area);
      w.EndObject();
      return kExitSuccess;
    }
    char line[256];
    std::snprintf(line, sizeof line, "scene %s, mesh %s, load %.6g N along the line of action\n",
                  scene.name.c_str(), args.mesh.c_str(), args.load_n);
    out << line;
    out << "roll rad     TE um   k N/um  points teeth  contact on gear 1 (roll distance, mm)\n";
    for (const gears::MeshSweepPoint& p : sweep.points) {
      std::snprintf(line, sizeof line, "%8.5f %9.4f %8.1f %7d %5d ", p.roll_angle_rad,
                    p.transmission_error_m * 1e6, p.stiffness_n_per_m * 1e-6, p.contact_points,
                    p.teeth_in_contact);
      out << line;
      for (int k = 0; k < p.teeth_in_contact && k < 3; ++k) {
        std::snprintf(line, sizeof line, " [%.3f, %.3f]", p.pattern_min_m[k] * 1e3,
                      p.pattern_max_m[k] * 1e3);
        out << line;
      }
      out << "\n";
    }
    std::snprintf(line, sizeof line,
                  "mean stiffness %.1f N/um, TE peak to peak %.4f um\n"
                  "ISO 6336 c' b %.1f N/um, c_gamma_alpha b %.1f N/um; TVMS mean %.1f N/um\n",
                  sweep.mean_stiffness_n_per_m * 1e-6, sweep.te_peak_to_peak_m * 1e6,
                  iso.c_single_n_per_m * 1e-6, iso.c_gamma_alpha_n_per_m * 1e-6,
                  tvms.mean_n_per_m * 1e-6);
    out << line;
    return kExitSuccess;
  } catch (const std::exception& e) {
    ReportError(err, e.what());
    return kExitFailure;
  }
}

}  // namespace orrery::cli
