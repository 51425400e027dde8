#include "tools/cli/flexible_mesh_stiffness.h"

#include <cstdio>
#include <exception>
#include <stdexcept>

#include "models/flexible_gear_mesh.h"
#include "import/scene.h"
#include "models/mesh_stiffness.h"
#include "tools/cli/error_message.h"
#include "tools/cli/json_writer.h"
#include "tools/cli/mesh_stiffness_faults.h"

namespace orrery::cli {

int FlexibleMeshStiffnessCommand(const MeshStiffnessArgs& args, std::ostream& out, std::ostream& err) {
  try {
    const int fe_level = args.fe_level;
    if (fe_level < 1) throw std::invalid_argument("--fe-level must be >= 1");
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
    // Flexible gears on the lumped models' blanks.
    gears::FlexibleGearMeshOptions o;
    o.bore_radius1_m = tvms_options.bore_radius1_m;
    o.bore_radius2_m = tvms_options.rim_radius2_m;
    o.fe.flank_divisions *= fe_level, o.fe.tooth_divisions *= fe_level;
    o.fe.fillet_divisions *= fe_level, o.fe.root_layer_divisions *= fe_level;
    o.fe.rim_divisions *= fe_level, o.fe.face_divisions *= fe_level;
    if (!faults.empty()) {
      // Healthy and faulty over the first fault's engagement, against the TVMS.
      const auto level = [&](const MeshFaults& f, const gears::MeshSweepRange& range) {
        gears::FlexibleGearMeshOptions fo = o;
        fo.faults1 = f.gear1, fo.faults2 = f.gear2;
        std::vector<double> k;
        for (const gears::MeshSweepPoint& p : gears::SweepFlexibleGearMesh(pair, fo, args.load_n, args.points, range).points)
          k.push_back(p.stiffness_n_per_m);
        return k;
      };
      WriteFaultSweep({.scene = scene.name, .mesh = args.mesh, .surfaces = "flexible gears (hex20)", .load_n = args.load_n,
                       .points = args.points, .json = args.json},
                      "flexible FE contact", pair, tvms_options, faults, level, out);
      return kExitSuccess;
    }
    const gears::FlexibleMeshSweep sweep =
        gears::SweepFlexibleGearMesh(pair, o, args.load_n, args.points);

    if (args.json) {
      JsonWriter w(out);
      w.BeginObject().Key("scene").String(scene.name).Key("mesh").String(args.mesh);
      w.Key("load_n").Number(args.load_n);
      WriteSweepPoints(w, sweep.points);
      w.Key("predicted_pairs").BeginArray();
      for (int n : sweep.predicted_pairs) w.Number(n);
      w.EndArray();
      w.Key("mean_stiffness_n_per_m").Number(sweep.mean_stiffness_n_per_m);
      w.Key("single_zone_stiffness_n_per_m").Number(sweep.single_zone_stiffness_n_per_m);
      w.Key("double_zone_stiffness_n_per_m").Number(sweep.double_zone_stiffness_n_per_m);
      w.Key("te_peak_to_peak_m").Number(sweep.te_peak_to_peak_m);
      w.Key("iso6336_single_pair_n_per_m").Number(iso.c_single_n_per_m);
      w.Key("iso6336_c_gamma_alpha_n_per_m").Number(iso.c_gamma_alpha_n_per_m);
      w.Key("tvms_mean_n_per_m").Number(tvms.mean_n_per_m);
      w.Key("tvms_min_n_per_m").Number(tvms.min_n_per_m);
      w.Key("tvms_max_n_per_m").Number(tvms.max_n_per_m);
      w.Key("hertz_stiffness_n_per_m").Number(sweep.hertz_stiffness_n_per_m);
      w.Key("penalty_stiffness_per_area").Number(sweep.stiffness_per_area);
      w.Key("modes_gear1").Number(sweep.nf1).Key("modes_gear2").Number(sweep.nf2);
      w.Key("fe_nodes_gear1").Number(sweep.fe_nodes1).Key("fe_nodes_gear2").Number(sweep.fe_nodes2);
      w.Key("reduce_seconds").Number(sweep.reduce_seconds);
      w.Key("sweep_seconds").Number(sweep.sweep_seconds);
      w.EndObject();
      return kExitSuccess;
    }
    char line[768];
    std::snprintf(line, sizeof line,
                  "scene %s, mesh %s, load %.6g N along the line of action, flexible gears "
                  "(hex20, %d + %d FE nodes, %d + %d modes)\n",
                  scene.name.c_str(), args.mesh.c_str(), args.load_n, sweep.fe_nodes1,
                  sweep.fe_nodes2, sweep.nf1, sweep.nf2);
    out << line;
    out << "roll rad     TE um   k N/um  points teeth (path)  contact on gear 1 (roll distance, mm)\n";
    for (size_t i = 0; i < sweep.points.size(); ++i) {
      const gears::MeshSweepPoint& p = sweep.points[i];
      std::snprintf(line, sizeof line, "%8.5f %9.4f %8.1f %7d %5d (%d)  ", p.roll_angle_rad,
                    p.transmission_error_m * 1e6, p.stiffness_n_per_m * 1e-6, p.contact_points,
                    p.teeth_in_contact, sweep.predicted_pairs[i]);
      out << line;
      for (int k = 0; k < p.teeth_in_contact && k < 3; ++k) {
        std::snprintf(line, sizeof line, " [%.3f, %.3f]", p.pattern_min_m[k] * 1e3,
                      p.pattern_max_m[k] * 1e3);
        out << line;
      }
      out << "\n";
    }
    std::snprintf(line, sizeof line,
                  "path of contact %.3f..%.3f mm (eps_alpha %.3f)\n"
                  "mean stiffness %.1f N/um (single-pair zone %.1f, double-pair zone %.1f), TE peak "
                  "to peak %.4f um\n"
                  "ISO 6336 c' b %.1f N/um, c_gamma_alpha b %.1f N/um; TVMS mean %.1f N/um "
                  "(min %.1f, max %.1f)\n"
                  "penalty: Hertz line contact %.1f N/um; reduction %.1f s, sweep %.1f s\n",
                  pair.contact_start_m() * 1e3, pair.contact_end_m() * 1e3,
                  pair.transverse_contact_ratio(), sweep.mean_stiffness_n_per_m * 1e-6,
                  sweep.single_zone_stiffness_n_per_m * 1e-6,
                  sweep.double_zone_stiffness_n_per_m * 1e-6, sweep.te_peak_to_peak_m * 1e6,
                  iso.c_single_n_per_m * 1e-6, iso.c_gamma_alpha_n_per_m * 1e-6,
                  tvms.mean_n_per_m * 1e-6, tvms.min_n_per_m * 1e-6, tvms.max_n_per_m * 1e-6,
                  sweep.hertz_stiffness_n_per_m * 1e-6, sweep.reduce_seconds, sweep.sweep_seconds);
    out << line;
    return kExitSuccess;
  } catch (const std::exception& e) {
    ReportError(err, e.what());
    return kExitFailure;
  }
}

}  // namespace orrery::cli
