#pragma once
// The deformed vertices of a flexible contact surface made on first read within one evaluation,
// and the reader the gap passes take for a surface's vertices (own or deformed).
//
// Why: the tracked gaps (tracked_gaps.h) read the vertices of the awake nodes and of the faces
// those nodes end on and walk over: a few hundred per evaluation, against the ~7 700 vertices of
// the ~10 tracked teeth of seed 003's flexible planet per contact element. Forming all of them
// (every FE node of every tracked tooth times 24 modes, then the interpolation) was half of the
// flexible run. Here a vertex is formed when it is first read after Begin(): x_v = s_v + u_v,
//   u_v = sum_k w_k u_b(k),   u_b = Phi_b q_f   (flexible_contact_surface.h, embedded surfaces:
// the FE nodes b the vertex hangs on, barycentric weights w), each base's u_b on first read too,
// by FlexibleContactSurface::DeformVertex (the expression DeformParts used: the same numbers).
// Stamps (one per vertex and base, the epoch of the evaluation that made it) say what is current.
// Sized once (no allocation in Begin() or a read).
//
// Usage:
//   DeformedVertices deformed(surface);               // once
//   deformed.Begin(&q_f, &vertices);                  // per evaluation
//   const Vec3& x = deformed[v];                      // made on first read
#include <vector>

#include <Eigen/Core>

#include "mbd/spatial.h"

namespace orrery::contact {

class FlexibleContactSurface;

class DeformedVertices {
 public:
  DeformedVertices() = default;  // no surface: Begin() must not be called
  // Keeps a reference to the surface, which must outlive it.
  explicit DeformedVertices(const FlexibleContactSurface& surface);

  // Starts an evaluation at the modal coordinates *q_f (nf) writing into *vertices (#V of the
  // surface): both are kept by pointer until the next Begin(). Entries of *vertices not read
  // since keep older positions.
  void Begin(const Eigen::VectorXd* q_f, std::vector<Vec3>* vertices);
  // The deformed position of vertex v (body frame), made on its first read in this evaluation.
  const Vec3& operator[](int v) { return vertex_stamp_[v] == epoch_ ? (*vertices_)[v] : Make(v); }
  // Vertices and bases made in this evaluation (statistics, tests).
  int vertices_made() const { return vertices_made_; }
  int bases_made() const { return bases_made_; }

 private:
  const Vec3& Make(int v);

  const FlexibleContactSurface* surface_ = nullptr;
  const Eigen::VectorXd* q_f_ = nullptr;
  std::vector<Vec3>* vertices_ = nullptr;
  std::vector<long> vertex_stamp_;       // #V: epoch_ at which (*vertices_)[v] was made
  std::vector<Vec3> base_displacement_;  // #bases: Phi_b q_f
  std::vector<long> base_stamp_;         // #bases
  long epoch_ = 0;
  int vertices_made_ = 0, bases_made_ = 0;
};

// A surface's vertices as a gap pass reads them: a vector (a rigid surface's own, or deformed
// vertices made beforehand) or deformed on first read.
struct SurfaceVertices {
  const std::vector<Vec3>* own = nullptr;
  DeformedVertices* deformed = nullptr;  // when set, `own` is not read
  const Vec3& operator[](int v) const { return deformed ? (*deformed)[v] : (*own)[v]; }
};

}  // namespace orrery::contact
