#include "models/planetary_scenes.h"

#include <numbers>

namespace orrery::gears {
namespace {

constexpr double kDeg = std::numbers::pi / 180.0;

ToothForm Spur(double module_m, double pressure_angle_deg) {
  return ToothForm{.normal_module_m = module_m, .normal_pressure_angle_rad = pressure_angle_deg * kDeg};
}

}  // namespace

std::shared_ptr<const PlanetaryTrain> MakeSeed000HoistTrain() {
  PlanetaryTrainBuilder b;
  // Stages of Table 1 (pressure angle assumed 20 deg).
  b.AddSinglePlanetStage({.name = "S1", .sun = {25}, .planet = {34}, .ring = {95},
                          .num_planets = 3, .tooth_form = Spur(0.010, 20.0)});
  b.AddSinglePlanetStage({.name = "S2", .sun = {21}, .planet = {25}, .ring = {71},
                          .num_planets = 4, .tooth_form = Spur(0.016, 20.0)});
  // Stage-1 carrier drives the stage-2 sun; both rings fixed in the housing.
  b.AddConnection("S1.carrier-S2.sun", "S1.carrier", "S2.sun");
  b.AddBrake("B1", "S1.ring");
  b.AddBrake("B2", "S2.ring");
  b.AddRange("hoist", {"B1", "B2"});
  b.AddInput("S1.sun");
  b.SetOutput("S2.carrier");
  return std::move(b).Finalize();
}

std::shared_ptr<const PlanetaryTrain> MakeSeed001AutomaticTransmission() {
  PlanetaryTrainBuilder b;
  // Three identical gear sets (Table 1): outside diameters as tip radii, pin circle 78 mm.
  const ToothForm form = Spur(0.0015, 21.3);
  const TrainGearSpec sun{.teeth = 34, .tip_radius_m = 0.5 * 0.05274};
  const TrainGearSpec planet{.teeth = 18, .tip_radius_m = 0.5 * 0.0305};
  const TrainGearSpec ring{.teeth = 70};
  const std::vector<double> three = AssemblablePlanetAngles(34 + 70, 3);
  b.AddSinglePlanetStage({.name = "S1", .sun = sun, .planet = planet, .ring = ring,
                          .num_planets = 4, .tooth_form = form, .pin_radius_m = 0.039});
  b.AddSinglePlanetStage({.name = "S2", .sun = sun, .planet = planet, .ring = ring,
                          .num_planets = 3, .tooth_form = form, .planet_angles_rad = three,
                          .pin_radius_m = 0.039});
  b.AddSinglePlanetStage({.name = "S3", .sun = sun, .planet = planet, .ring = ring,
                          .num_planets = 3, .tooth_form = form, .planet_angles_rad = three,
                          .pin_radius_m = 0.039});
  // Series chain S1 -> S3 -> S2: ring in, carrier out.
  b.AddConnection("S1.carrier-S3.ring", "S1.carrier", "S3.ring");
  b.AddConnection("S3.carrier-S2.ring", "S3.carrier", "S2.ring");
  // Sun brakes and lock-up clutches.
  b.AddBrake("B1", "S1.sun");
  b.AddBrake("B2", "S2.sun");
  b.AddBrake("B3", "S3.sun");
  b.AddClutch("K1", "S1.ring", "S1.carrier");
  b.AddClutch("K2", "S2.ring", "S2.carrier");
  b.AddClutch("K3", "S3.ring", "S3.carrier");
  // Clutching schedule.
  b.AddRange("1st", {"B1", "B2", "B3"});
  b.AddRange("2nd", {"K1", "B2", "B3"});
  b.AddRange("3rd", {"K1", "K3", "B2"});
  b.AddRange("4th", {"K1", "K3", "K2"});
  b.AddInput("S1.ring");
  b.SetOutput("S2.carrier");
  return std::move(b).Finalize();
}

std::shared_ptr<const PlanetaryTrain> MakeSeed002WindTurbineStage() {
  PlanetaryTrainBuilder b;
  b.AddSinglePlanetStage({.name = "S", .sun = {19}, .planet = {34}, .ring = {89},
                          .num_planets = 3,
                          .tooth_form = ToothForm{.normal_module_m = 0.016,
                                                  .normal_pressure_angle_rad = 20.0 * kDeg,
                                                  .helix_angle_rad = 7.0 * kDeg}});
  b.AddBrake("B", "S.ring");
  b.AddRange("run", {"B"});
  b.AddInput("S.carrier");
  b.SetOutput("S.sun");
  return std::move(b).Finalize();
}

GearTrainDescription MakeSeed003StageDescription(double sun_speed_rad_s) {
  GearTrainDescription d;
  d.train.stages.push_back(SinglePlanetStageSpec{
      .name = "S", .sun = {22}, .planet = {14}, .ring = {50}, .num_planets = 3,
      .tooth_form = Spur(4e-3, 22.5)});
  d.train.stage_face_widths_m["S"] = 0.04;
  d.train.ranges = {{.name = "steer"}};
  d.train.inputs = {"S.ring", "S.sun"};
  d.train.output = "S.carrier";
  d.range = "steer";
  TrainModelOptions& o = d.options;
  o.input = TrainModelOptions::Input::kSpeed;
  o.input_speed_functions = {TimeFunction::Constant(80.6), TimeFunction::Constant(sun_speed_rad_s)};
  o.output_port_torque_n_m = -6000;
  o.operating_speeds_rad_s = {80.6, sun_speed_rad_s};
  return d;
}

std::shared_ptr<const PlanetaryTrain> MakeSeed003SteeringDifferential() {
  PlanetaryTrainBuilder b;
  b.AddSinglePlanetStage({.name = "S", .sun = {22}, .planet = {14}, .ring = {50},
                          .num_planets = 3});
  b.AddRange("steer", {});
  b.AddInput("S.ring");
  b.AddInput("S.sun");
  b.SetOutput("S.carrier");
  return std::move(b).Finalize();
}

}  // namespace orrery::gears
