#pragma once
// The two-mesh gear model of the contact tests (parallel_contacts_test.cpp,
// warm_start_test.cpp): a pinion (18 teeth, seed 001's sun) on a revolute joint about z, meshing
// by tooth contact with two 34-tooth gears on revolute joints across from each other: two
// contact elements of the same weight, "mesh1" and "mesh2".
#include <memory>
#include <string>
#include <utility>

#include "contact/contact_element.h"
#include "mbd/model.h"
#include "models/gear_contact.h"

namespace orrery::contact::test_scenes {

// An 18/34 spur pair (seed 001's sun and planet) on revolute joints about z, "j1" (the pinion,
// at the origin) and "j2" (the gear, across the centre distance on x, turned half a tooth so that
// teeth meet gaps), added to `b` (no_allocation_test.cpp, contact_point_record_test.cpp).
struct SpurPair {
  gears::GearPair pair;
  BodyIndex pinion, gear;
  JointIndex pinion_joint;
};

inline SpurPair AddSpurPair(ModelBuilder& b) {
  constexpr double kPi = 3.14159265358979323846;
  gears::GearSpec s1{.teeth = 18,
                     .normal_module_m = 1.5e-3,
                     .normal_pressure_angle_rad = 21.3 * kPi / 180,
                     .face_width_m = 0.03};
  gears::GearSpec s2 = s1;
  s2.teeth = 34;
  gears::GearPair pair{gears::Gear(s1), gears::Gear(s2)};
  const Mat3 I = Mat3::Identity() * 1e-4;
  const BodyIndex g1 = b.AddBody("pinion", 0.3, Vec3::Zero(), I);
  const BodyIndex g2 = b.AddBody("gear", 1.0, Vec3::Zero(), I);
  JointSpec j1;
  j1.name = "j1", j1.type = JointType::kRevolute, j1.parent = kWorldBody, j1.child = g1;
  JointSpec j2 = j1;
  j2.name = "j2", j2.child = g2;
  j2.X_PF = Transform(AxisAngle(Vec3::UnitZ(), kPi * (1 + 1.0 / 34)),
                      Vec3(pair.center_distance_m(), 0, 0));
  const JointIndex ji1 = b.AddJoint(j1);
  b.AddJoint(j2);
  return {std::move(pair), g1, g2, ji1};
}

inline std::shared_ptr<const Model> TwoMeshModel() {
  constexpr double kPi = 3.14159265358979323846;
  const double deg = kPi / 180;
  gears::GearSpec s1{.teeth = 18, .normal_module_m = 1.5e-3,
                     .normal_pressure_angle_rad = 21.3 * deg, .face_width_m = 0.03};
  gears::GearSpec s2 = s1;
  s2.teeth = 34;
  const gears::GearPair pair{gears::Gear(s1), gears::Gear(s2)};
  ModelBuilder b;
  const Mat3 I = Mat3::Identity() * 1e-4;
  const BodyIndex pinion = b.AddBody("pinion", 0.3, Vec3::Zero(), I);
  JointSpec jp;
  jp.name = "pinion", jp.type = JointType::kRevolute, jp.parent = kWorldBody, jp.child = pinion;
  b.AddJoint(jp);
  gears::GearContactOptions o;
  o.involute_intervals = 16;
  o.face_intervals = 2;
  for (int k = 0; k < 2; ++k) {
    const std::string name = "gear" + std::to_string(k + 1);
    const BodyIndex gear = b.AddBody(name, 1.0, Vec3::Zero(), I);
    JointSpec jg = jp;
    jg.name = name, jg.child = gear;
    // Across from each other; the gear turned half a tooth so that teeth meet gaps.
    const double side = k == 0 ? 0.0 : kPi;
    jg.X_PF = Transform(AxisAngle(Vec3::UnitZ(), side + kPi * (1 + 1.0 / 34)),
                        AxisAngle(Vec3::UnitZ(), side) * Vec3(pair.center_distance_m(), 0, 0));
    b.AddJoint(jg);
    b.AddExternalForce(std::make_shared<ContactElement>(
        gears::MakeGearContactSpec("mesh" + std::to_string(k + 1), pair, pinion, gear, o)));
  }
  return std::move(b).Finalize();
}

}  // namespace orrery::contact::test_scenes
