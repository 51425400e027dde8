#include "models/gear_pair_model.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace orrery::gears {
namespace {

constexpr double kPi = 3.14159265358979323846;

// Solid disc (external gear, pitch radius r, bore r_in) or ring (inner radius r, rim r_out):
// mass and polar moment of an annulus of the face width.
struct DiscProps {
  double mass = 0, polar = 0;
};
DiscProps Annulus(double r_in, double r_out, double width, double density) {
  const double m = density * kPi * (r_out * r_out - r_in * r_in) * width;
  return {m, 0.5 * m * (r_out * r_out + r_in * r_in)};
}

}  // namespace

GearPairModel BuildGearPairModel(const GearPair& pair, const GearPairModelOptions& o) {
  auto fail = [](const std::string& m) { throw std::invalid_argument("gear pair model: " + m); };
  if (o.input_speed && o.input_torque) fail("give an input speed or an input torque, not both");
  const Gear& g1 = pair.gear1();
  const Gear& g2 = pair.gear2();
  if (g1.spec().internal) fail("gear 1 must be the external gear (pinion or planet)");
  const bool internal = g2.spec().internal;
  // Blanks: gear 1 a disc to its reference radius with a bore; gear 2 the same, or a ring from
  // its reference radius out to its rim.
  const DiscProps d1 = Annulus(o.bore_radius1_m, g1.reference_radius_m(), g1.spec().face_width_m, o.density_kg_m3);
  DiscProps d2;
  if (internal) {
    if (!(o.bore_radius2_m > g2.root_radius_m())) fail("an internal gear 2 needs a rim radius beyond its root circle");
    d2 = Annulus(g2.reference_radius_m(), o.bore_radius2_m, g2.spec().face_width_m, o.density_kg_m3);
  } else {
    d2 = Annulus(o.bore_radius2_m, g2.reference_radius_m(), g2.spec().face_width_m, o.density_kg_m3);
  }
  GearPairModel out;
  out.inertia1 = d1.polar;
  out.inertia2 = d2.polar;
  out.ratio = (internal ? 1.0 : -1.0) * double(g1.spec().teeth) / g2.spec().teeth;

  ModelBuilder mb;
  auto inertia = [](const DiscProps& d) { return Vec3(0.5 * d.polar, 0.5 * d.polar, d.polar).asDiagonal().toDenseMatrix(); };
  const BodyIndex body1 = mb.AddBody("gear1", d1.mass, Vec3::Zero(), inertia(d1));
  const BodyIndex body2 = mb.AddBody("gear2", d2.mass, Vec3::Zero(), inertia(d2));
  const double a = pair.center_distance_m();
  out.shaft1 = mb.AddJoint({.name = "shaft1", .type = JointType::kRevolute, .parent = kWorldBody,
                            .child = body1, .axis = Vec3::UnitZ()});
  out.shaft2 = mb.AddJoint({.name = "shaft2", .type = JointType::kRevolute, .parent = kWorldBody,
                            .child = body2, .X_PF = Transform::Translation(Vec3(internal ? -a : a, 0, 0)),
                            .axis = Vec3::UnitZ()});
  mb.SetJointVelocity(out.shaft1, Eigen::VectorXd::Constant(1, o.initial_speed1));
  mb.SetJointVelocity(out.shaft2, Eigen::VectorXd::Constant(1, out.ratio * o.initial_speed1));
  // Helix: gear 1's hand decides the sign of the axial force on gear 2.
  const double beta_b = g1.base_helix_angle_rad() * (g1.spec().hand == HelixHand::kRight ? 1.0 : -1.0);
  if (o.mesh_model == GearPairModelOptions::MeshModel::kKinematic) {
    mb.AddGearConstraint({.name = "mesh", .gear_a = mb.body_frame(body1), .gear_b = mb.body_frame(body2),
                          .teeth_a = g1.spec().teeth, .teeth_b = g2.spec().teeth,
                          .base_radius_a = g1.base_radius_m(), .base_radius_b = g2.base_radius_m(),
                          .working_pressure_angle = pair.working_pressure_angle_rad(),
                          .base_helix_angle = beta_b, .internal_b = internal});
  } else {
    GearMeshSpec mesh{.name = "mesh", .gear_a = mb.body_frame(body1), .gear_b = mb.body_frame(body2),
                      .teeth_a = g1.spec().teeth, .teeth_b = g2.spec().teeth,
                      .base_radius_a = g1.base_radius_m(), .base_radius_b = g2.base_radius_m(),
                      .working_pressure_angle = pair.working_pressure_angle_rad(),
                      .base_helix_angle = beta_b, .internal_b = internal, .contact = o.contact};
    mesh.backlash = std::isnan(o.backlash_m) ? pair.transverse_backlash_m() : o.backlash_m;
    if (o.contact != GearMeshSpec::Contact::kTwoSided) mesh.backlash = 0;
    mesh.damping_ratio = o.damping_ratio;
    switch (o.stiffness) {
      case GearPairModelOptions::Stiffness::kGiven:
        if (!(o.given_stiffness_n_per_m > 0)) fail("given stiffness must be > 0");
        mesh.stiffness = o.given_stiffness_n_per_m;
        break;
      case GearPairModelOptions::Stiffness::kIso6336:
        mesh.stiffness = CalcIso6336Stiffness(pair).c_gamma_alpha_n_per_m;
        break;
      case GearPairModelOptions::Stiffness::kTvms: {
        TvmsOptions t;
        t.material1 = o.material1;
        t.material2 = o.material2;
        t.bore_radius1_m = o.bore_radius1_m > 0 ? o.bore_radius1_m : 0.3 * g1.root_radius_m();
        t.rim_radius2_m = o.bore_radius2_m > 0 ? o.bore_radius2_m : 0.3 * g2.root_radius_m();
        t.samples_per_period = o.tvms_samples_per_period;
        t.faults = o.faults;
        t.load_n = o.tvms_load_n;
        Tvms k = CalcTvms(pair, t);
        mesh.stiffness_table = k.stiffness_n_per_m;
        // Samples cover one mesh period, or a revolution of the faulty gear.
        mesh.table_cycles = std::max<int>(1, k.stiffness_n_per_m.size() / o.tvms_samples_per_period);
        if (std::any_of(k.no_load_te_m.begin(), k.no_load_te_m.end(), [](double e) { return e != 0; })) {
          mesh.ste_table_m = k.no_load_te_m;
          mesh.ste_table_cycles = mesh.table_cycles;
        }
        out.tvms = std::move(k);
        break;
      }
    }
    if (o.stiffness != GearPairModelOptions::Stiffness::kTvms && !o.faults.empty())
      fail("tooth faults need the time-varying stiffness");
    mb.AddGearMesh(mesh);
  }
  // Loads.
  if (o.input_speed)
    mb.AddDriver({.name = "input", .joint = out.shaft1, .coordinate = 0, .mode = DriverSpec::Mode::kSpeed,
                  .function = *o.input_speed});
  if (o.input_torque)
    mb.AddJointLoad({.name = "input", .joint = out.shaft1, .coordinate = 0, .function = *o.input_torque});
  if (o.load_torque)
    mb.AddJointLoad({.name = "load", .joint = out.shaft2, .coordinate = 0, .function = *o.load_torque});
  out.model = std::move(mb).Finalize();
  for (const GearMesh& m : out.model->gear_meshes) out.mesh_stiffness_mean_n_per_m = m.k_mean;
  return out;
}

}  // namespace orrery::gears
