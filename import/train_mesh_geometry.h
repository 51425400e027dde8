#pragma once
// Involute geometry of the meshes of a planetary train (planetary_train.h) for reports and the
// mesh-stiffness models of mesh_stiffness.h: one GearPair per train mesh from the tooth forms of
// its gears, the face width and the blank radii that BuildTrainModel (train_dynamics.h) derives
// its bodies from, so ISO 6336 / TVMS stiffnesses and the lumped bodies describe the same gears.
//
// Conventions: gear 1 of the pair is the external gear of the mesh that is not a planet (the sun)
// for a central-planet mesh, the planet for a ring-planet mesh (gear 2 the ring, internal), and
// gear_a for a planet-planet mesh. Reference gears (no profile shift) at their zero-backlash centre
// distance: a train whose printed centre distances imply profile shift (seed 000 stage 1) gets the
// unshifted values. External helical pairs take opposite hands, internal pairs the same hand.
//
// Usage:
//   gears::GearPair pair = MakeTrainMeshPair(train, train.MeshIndex("S1.sun-planet"), options);
//   gears::Iso6336Stiffness iso = gears::CalcIso6336Stiffness(pair);
//   gears::Tvms k = gears::CalcTvms(pair, TrainMeshTvmsOptions(train, mesh, options));
#include "models/gear_geometry.h"
#include "models/mesh_stiffness.h"
#include "models/planetary_train.h"
#include "models/train_dynamics.h"

namespace orrery {

// Face width of a train mesh: the smaller of its two gears' (member / planet-set override
// face_width_m, else options.face_width_m).
double TrainMeshFaceWidth(const gears::PlanetaryTrain& train, int mesh,
                          const gears::TrainModelOptions& options);

// The pair of mesh `mesh` (conventions above). Throws std::invalid_argument if a gear has no tooth
// form, the face width is not > 0, or the geometry is invalid (undercut, interference,
// eps_alpha < 1; the message comes from Gear / GearPair).
gears::GearPair MakeTrainMeshPair(const gears::PlanetaryTrain& train, int mesh,
                                  const gears::TrainModelOptions& options);

// TVMS options for that pair: bore radii of external gears (override bore_radius_m, else
// options.bore_to_pitch_ratio times the pitch radius) and the ring's outer radius (override
// outer_radius_m, else pitch radius + options.ring_rim_modules m_n); steel, default sampling.
gears::TvmsOptions TrainMeshTvmsOptions(const gears::PlanetaryTrain& train, int mesh,
                                        const gears::TrainModelOptions& options);

}  // namespace orrery
