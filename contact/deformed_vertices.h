#pragma once
// The deformed vertices of a flexible contact surface made on first read within one evaluation,
// their deformation rates made on first read within one pass over the contact points, and the
// reader the gap passes take for a surface's vertices (own or deformed).
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

// The deformation rates of a flexible contact surface's vertices in the world axes,
//   v_v = R_WB Phi_v q_f-dot      (flexible_contact_surface.h VertexShapeTimes),
// made on first read within one pass over the contact points (flexible_contact_element.h): a
// face vertex is read by every contact point on the faces around it, and a node of one pass is
// a face vertex of the other, so the points of one evaluation read each vertex's rate about
// twice on average (four 3 x nf products per point pair before this cache). The same expression
// as a direct product: the numbers are the same to the last bit. Stamped per vertex with the
// epoch of the Begin() that made it (a rate made at an earlier Begin() is never returned).
// Sized once (no allocation in Begin() or a read).
//
// Usage:
//   VertexRates rates(surface);                       // once
//   rates.Begin(&q_f_dot, X_WB.R);                    // per pass over the contact points
//   const Vec3& v = rates[vertex];                    // made on first read
class VertexRates {
 public:
  VertexRates() = default;  // no surface: Begin() must not be called
  // Keeps a reference to the surface, which must outlive it.
  explicit VertexRates(const FlexibleContactSurface& surface);

  // Starts a pass at the modal rates *q_f_dot (nf, kept by pointer until the next Begin()) and
  // the body's rotation R_WB.
  void Begin(const Eigen::VectorXd* q_f_dot, const Mat3& R_WB);
  // R_WB Phi_v q_f-dot of vertex v (world), made on its first read since Begin().
  const Vec3& operator[](int v) { return stamp_[v] == epoch_ ? rate_[v] : Make(v); }
  // Rates made since Begin() (statistics, tests).
  int made() const { return made_; }

 private:
  const Vec3& Make(int v);

  const FlexibleContactSurface* surface_ = nullptr;
  const Eigen::VectorXd* q_f_dot_ = nullptr;
  Mat3 R_WB_ = Mat3::Identity();
  std::vector<Vec3> rate_;   // #V: the rate of vertex v as of stamp_[v]
  std::vector<long> stamp_;  // #V: epoch_ at which rate_[v] was made
  long epoch_ = 0;
  int made_ = 0;
};

// A surface's vertices as a gap pass reads them: a vector (a rigid surface's own, or deformed
// vertices made beforehand) or deformed on first read.
struct SurfaceVertices {
  const std::vector<Vec3>* own = nullptr;
  DeformedVertices* deformed = nullptr;  // when set, `own` is not read
  const Vec3& operator[](int v) const { return deformed ? (*deformed)[v] : (*own)[v]; }
};

}  // namespace orrery::contact
