#pragma once
// Lumped-parameter models of a planetary stage (the `lumped` rung of DESIGN.md): rigid sun,
// ring, carrier and planets joined by gear-mesh springs along the lines of action and by
// bearing springs, at one of three DOF sets:
//   torsional: each member turns about its axis (seed 001 eqs. 7-9, Kahraman's model);
//   planar:    3 DOF per member, x, y and rotation (Lin & Parker 1999);
//   spatial:   6 DOF per member with 6-DOF bearings (seed 002 eqs. 7-11).
// Every parameter is given explicitly (mass, inertia, base radius, bearing and torsional
// stiffness, mesh stiffness, pressure angle), so a published lumped model can be entered exactly
// as printed; the gear-train layer derives them from geometry and material.
//
// Geometry: the stage axis is world z; the carrier frame holds planet n at radius r_c and angle
// psi_n (default 2 pi (n-1)/N); planet coordinates are relative to the carrier (radial,
// tangential, rotation), central members' to the world. Sun-planet meshes engage the sun's drive
// flank (the sun driving +z) and ring-planet meshes the opposite planet flank, as in
// Lin & Parker's deflections delta_sn, delta_rn.
//
// Usage:
//   LumpedStageParams p = LinParker1999Example(3);
//   LumpedStage stage = BuildLumpedStage(p);
//   ModalResult modes = CalcModes(Linearize(*stage.model, State::Initial(*stage.model)));
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "mbd/model.h"

namespace orrery {

struct LumpedMember {
  double mass = 0;                 // kg
  double inertia = 0;              // kg m^2 about the stage axis
  double radius = 0;               // m: base radius (gears); planet-centre radius (carrier)
  double bearing_stiffness = 0;    // N/m, radial, isotropic (planets: to the carrier)
  double bearing_damping = 0;      // N s/m
  double torsional_stiffness = 0;  // N m/rad, to ground (central members; a planet's must be 0)
  double torsional_damping = 0;    // N m s/rad (central members; a planet's must be 0)
  double axial_stiffness = 0;      // N/m (spatial DOF set)
  double tilt_stiffness = 0;       // N m/rad (spatial DOF set)
  int teeth = 0;                   // gears: tooth count (mesh phase and base pitch)
};

struct LumpedStageParams {
  enum class Dofs { kTorsional, kPlanar, kSpatial } dofs = Dofs::kPlanar;
  int planets = 3;
  std::vector<double> planet_angles;  // rad; empty: equally spaced
  LumpedMember sun, ring, carrier, planet;
  double mesh_stiffness_sun = 0, mesh_stiffness_ring = 0;  // N/m
  double pressure_angle_sun = 0, pressure_angle_ring = 0;  // rad, working transverse
  double helix_angle = 0;                                  // rad, base helix (spatial)
  double mesh_damping_ratio = 0;
  bool check_centre_distance = false;  // published lumped data need not be consistent
  // Frame holding the lines of action: the carrier (it turns with the carrier; needed when the
  // carrier spins) or the world (a non-spinning carrier, as in Lin & Parker's zero carrier speed:
  // their lines of action do not turn with the carrier's vibration, which matters at first order
  // when the printed centre distance disagrees with the base radii).
  bool lines_of_action_on_carrier = true;
};

struct LumpedStage {
  std::shared_ptr<const Model> model;
  JointIndex sun = -1, ring = -1, carrier = -1;
  std::vector<JointIndex> planets;
};

// Called with the builder and the stage's joints before Finalize: add drivers, loads, output
// shafts (e.g. b.AddDriver({... .joint = stage.sun ...})).
using LumpedStageExtras = std::function<void(ModelBuilder&, const LumpedStage&)>;

// Builds the stage. Throws std::invalid_argument naming the parameter that is missing or
// non-physical.
LumpedStage BuildLumpedStage(const LumpedStageParams& params, const LumpedStageExtras& extras = {});

// The example system of Lin & Parker (1999), Table 1 (docs/validation/lin_parker_1999.md).
LumpedStageParams LinParker1999Example(int planets);

}  // namespace orrery
