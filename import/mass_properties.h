#pragma once
// Mass properties of the solid a closed triangle mesh bounds, for a uniform density: volume,
// mass, centre of mass and the inertia tensor about the centre of mass, in the mesh's axes.
//
// Method: the divergence theorem turns each volume integral int_V x^a y^b z^c dV (a + b + c <= 2)
// into a sum over the triangles of surface integrals of polynomials, which are integrated exactly
// over each flat triangle; the result is exact for the polyhedron (the only error is rounding).
// The per-triangle subexpressions are those of D. Eberly, "Polyhedral Mass Properties
// (Revisited)", Geometric Tools, 2002 (after B. Mirtich, "Fast and Accurate Computation of
// Polyhedral Mass Properties", J. Graphics Tools 1(2), 1996): with d = (p1 - p0) x (p2 - p0) and,
// per coordinate w, f1 = w0 + w1 + w2, f2 = w0^2 + w0 w1 + w1^2 + w2 f1, f3 = w0^3 + w0^2 w1 +
// ... + w2 f2 (all monomials of degree 3), g_i = f2 + w_i (f1 + w_i):
//   int 1 = sum d_x f1x / 6,  int x = sum d_x f2x / 24,  int x^2 = sum d_x f3x / 60,
//   int xy = sum d_x (y0 g0x + y1 g1x + y2 g2x) / 120   (and cyclically).
// Inertia about the centre c (tensor convention, products with a minus sign):
//   I_xx = rho (int y^2 + z^2) - m (c_y^2 + c_z^2),  I_xy = -(rho int xy - m c_x c_y), ...
// The vertices are first shifted by the centre of their bounding box, so that the sums do not
// cancel for a part far from the origin.
// Precondition: closed (watertight), consistently and outward oriented (mesh_checks.h CheckMesh,
// then OrientMesh); otherwise the sums have no meaning, which MassPropertiesOfSolid checks.
//
// Usage:
//   MeshCheckReport r = CheckMesh(mesh);  OrientMesh(mesh, r);
//   MassProperties p = MassPropertiesOfSolid(mesh, 7850, r, "gear.stl");
//   builder.AddBody("gear", p.mass_kg, p.center_of_mass_m, p.inertia_kg_m2);
#include <string>

#include "import/mesh_checks.h"
#include "mbd/spatial.h"
#include "mbd/triangle_mesh.h"

namespace orrery {

struct MassProperties {
  double volume_m3 = 0;
  double mass_kg = 0;
  Vec3 center_of_mass_m = Vec3::Zero();     // in the mesh's frame
  Mat3 inertia_kg_m2 = Mat3::Zero();        // about the centre of mass, mesh axes
  Vec3 principal_moments_kg_m2 = Vec3::Zero();  // ascending
  Mat3 principal_axes = Mat3::Identity();   // columns, right-handed
};

// The sums above for an oriented closed mesh, no checks of its topology. Throws
// std::invalid_argument for a density that is not finite and > 0.
MassProperties CalcMassProperties(const TriangleMesh& mesh, double density_kg_m3);

// CalcMassProperties after checking the report of the (already oriented) mesh. Throws
// std::runtime_error naming `source`: not watertight (boundary / non-manifold edges), a
// non-orientable component, or a volume that is not positive.
MassProperties MassPropertiesOfSolid(const TriangleMesh& mesh, double density_kg_m3, const MeshCheckReport& report,
                                     const std::string& source);

}  // namespace orrery
