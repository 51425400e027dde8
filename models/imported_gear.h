#pragma once
// A gear whose body comes from a mesh file (an STL, OBJ, STEP, ... read by import/, for example a
// gear the project's own STL writer exported, models/stl.h) instead of being generated: its mass
// properties and its tooth-contact surface are the file's, its involute geometry (base radius,
// pressure angle, tooth count) still the train's gear it stands for.
//
// Frame (precondition, checked): the file is in the gear frame G the generated gears use
// (models/gear_geometry.h MakeGearMesh): axis z, tooth 0 centred on +x, faces at z = 0 and
// z = b. The planet of a train turns G in its body as the rigid builder's planet
// (models/train_contact.h, "Gear frames and tooth phasing").
//
// Contact surface (SplitImportedGearTeeth): the triangles of the toothed boundary, i.e. those
// whose vertices all lie beyond r_f - m_n / 4 (inside the root circle r_f, outside any bore or
// web) and whose normals lean less than 60 degrees from the transverse plane (|n_z| < 1/2: not
// the end faces; a helical flank leans by its base helix angle), split into one part per tooth,
// the sector of half-width pi / z about tooth k's centre 2 pi k / z, turned by the helix at the
// triangle centroid's height (tooth parts from root middle to root middle, as
// MakeToothSurfaceMesh's). The parts are the imported triangles, unchanged.
//
// Checks (std::invalid_argument naming the source and what is off): the largest radius must be
// the gear's tip radius and the faces at 0 and b within kImportedGearTolerance m_n (a wrong unit
// or a part outside the gear frame); every tooth sector must hold triangles, and the points of
// the toothed surface above the reference circle must lie within 0.4 of a pitch of their tooth
// centre (a tooth's half-thickness there is at most (pi / 2 + 2 x tan alpha) / z, 0.31 of a pitch
// for a profile shift x = 0.5; a part turned by half a pitch has points half a pitch from the
// centres).
//
// Usage:
//   SolidMesh s = ReadSolidMesh("planet.stl", {.unit = LengthUnit::kMillimetre}, 7850);
//   auto teeth = SplitImportedGearTeeth(s.surface.mesh, planet, "planet.stl");
//   GearContactOptions o;
//   o.imported_teeth2 = std::make_shared<const std::vector<TriangleMesh>>(teeth);
#include <string>
#include <vector>

#include "mbd/triangle_mesh.h"
#include "models/gear_geometry.h"

namespace orrery::gears {

// Tolerance of the radius and face checks, in normal modules (a tenth: far above a faceted
// outline's float rounding, far below a unit mix-up).
inline constexpr double kImportedGearTolerance = 0.1;

// The tooth-contact parts of a closed gear mesh (header): #teeth meshes, part k tooth k, gear
// frame. Throws std::invalid_argument as described in the header.
std::vector<TriangleMesh> SplitImportedGearTeeth(const TriangleMesh& mesh, const Gear& gear,
                                                 const std::string& source);

}  // namespace orrery::gears
