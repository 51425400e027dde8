#include "contact/signed_gap.h"

#include <algorithm>
#include <cmath>

namespace orrery::contact {

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
// Whether the feature of triangle `face` lies on the surface's open rim: an edge by the face's
// own flags, a vertex by the vertex's (a rim vertex is a corner of faces whose edges there are
// interior too, and which of them a tie picks must not matter).
bool OnRim(const ContactSurface& surface, int face, TriangleFeature feature) {
  const int corner = FeatureVertex(feature);
  if (corner >= 0) return surface.vertex_on_rim()[surface.triangles()[face][corner]];
  return surface.boundary_edges()[face] & FeatureEdges(feature);
}

}  // namespace

GapScratch::GapScratch(const ContactSurface& node_surface)
    : best_d2(node_surface.num_vertices(), kInf),
      best_face(node_surface.num_vertices(), -1),
      p_F(node_surface.num_vertices(), Vec3::Zero()),
      q_F(node_surface.num_vertices(), Vec3::Zero()),
      feature(node_surface.num_vertices(), TriangleFeature::kFace) {
  touched.reserve(node_surface.num_vertices());
}

NodeGap NodeGapFromClosest(const ContactSurface& face_surface, int face, const Vec3& p_F,
                           const Vec3& q_F, TriangleFeature feature) {
  return NodeGapFromClosest(face_surface, face, face_surface.face_normals()[face], p_F, q_F,
                            feature);
}

NodeGap NodeGapFromClosest(const ContactSurface& face_surface, int face, const Vec3& n,
                           const Vec3& p_F, const Vec3& q_F, TriangleFeature feature) {
  NodeGap g;
  g.face = face;
  const Vec3 d = p_F - q_F;
  const double along = d.dot(n);
  if (feature == TriangleFeature::kFace) {
    // Projection inside the face (eq. 7).
    g.gap = along;
  } else if (OnRim(face_surface, face, feature)) {
    // On the open rim: the part of P - Q across the rim edges (their outward directions m in
    // the face's plane) is how far P lies beyond the surface; the rest is signed as at an
    // interior edge or vertex (for a rim edge, the plane's gap).
    // At a vertex, the rim edges of every face around it count (P may lie beyond a
    // neighbour's rim edge rather than this face's).
    Vec3 beyond = Vec3::Zero();
    auto across = [&](int t, unsigned edges) {
      for (int k = 0; k < 3; ++k) {
        if (!(edges & (1u << k))) continue;
        const Vec3& m = face_surface.face_rim_outward()[t][k];
        const double c = (d - beyond).dot(m);
        if (c > 0) beyond += c * m;
      }
    };
    const int corner = FeatureVertex(feature);
    double fade = 0;
    if (corner < 0) {
      across(face, face_surface.boundary_edges()[face] & FeatureEdges(feature));
      fade = face_surface.face_rim_fade()[face];
    } else {
      const int v = face_surface.triangles()[face][corner];
      fade = face_surface.vertex_rim_fade()[v];
      for (int i = face_surface.vertex_face_start()[v]; i < face_surface.vertex_face_start()[v + 1]; ++i) {
        const int t = face_surface.vertex_faces()[i];
        const auto& tri = face_surface.triangles()[t];
        const int k = tri[0] == v ? 0 : tri[1] == v ? 1 : 2;
        // The two edges of t at v: k (v, next) and k - 1 (previous, v).
        across(t, face_surface.boundary_edges()[t] & ((1u << k) | (1u << ((k + 2) % 3))));
      }
    }
    const double inside = (d - beyond).norm();
    g.gap = along < 0 ? -inside : inside;
    g.rim_offset_m = beyond.norm();
    g.rim_fade_m = fade;
    g.weight = g.rim_offset_m < fade ? 1.0 - g.rim_offset_m / fade : 0.0;
    g.on_surface = g.weight > 0;
  } else {
    // Interior edge or vertex: the distance, signed by the side of the face.
    g.gap = along < 0 ? -d.norm() : d.norm();
  }
  return g;
}

void ComputeNodeGaps(const ContactSurface& node_surface, const Transform& X_WN,
                     const ContactSurface& face_surface, const Transform& X_WF,
                     const std::vector<TrianglePair>& pairs, bool nodes_are_a,
                     double search_distance_m, GapScratch* scratch, std::vector<NodeGap>* gaps) {
  GapScratch& s = *scratch;
  gaps->clear();
  const Transform X_FN = X_WF.Inverse() * X_WN;
  const auto& node_tris = node_surface.triangles();
  const auto& face_tris = face_surface.triangles();
  const auto& fv = face_surface.vertices();
  // Closest candidate face of every node of the candidate triangles (eq. 6).
  for (const TrianglePair& pair : pairs) {
    const int node_tri = nodes_are_a ? pair.a : pair.b;
    const int face = nodes_are_a ? pair.b : pair.a;
    const auto& ft = face_tris[face];
    for (int k = 0; k < 3; ++k) {
      const int node = node_tris[node_tri][k];
      if (s.best_face[node] < 0 && s.best_d2[node] == kInf) {
        s.p_F[node] = X_FN * node_surface.vertices()[node];
        s.touched.push_back(node);
        s.best_d2[node] = std::numeric_limits<double>::max();
      }
      const ClosestPoint c = ClosestPointOnTriangle(s.p_F[node], fv[ft[0]], fv[ft[1]], fv[ft[2]]);
      const double d2 = (s.p_F[node] - c.point).squaredNorm();
      if (d2 < s.best_d2[node] || (d2 == s.best_d2[node] && face < s.best_face[node])) {
        s.best_d2[node] = d2;
        s.best_face[node] = face;
        s.q_F[node] = c.point;
        s.feature[node] = c.feature;
      }
    }
  }
  // Signed gaps of the nodes within the search distance (eqs. 7-9), in node order; reset the
  // scratch for the next pass.
  std::sort(s.touched.begin(), s.touched.end());
  const double d2_max = search_distance_m * search_distance_m;
  for (const int node : s.touched) {
    if (s.best_d2[node] <= d2_max) {
      NodeGap g = NodeGapFromClosest(face_surface, s.best_face[node], s.p_F[node], s.q_F[node],
                                     s.feature[node]);
      g.node = node;
      g.p_W = X_WF * s.p_F[node];
      g.q_W = X_WF * s.q_F[node];
      const auto& ft = face_tris[g.face];
      g.n_W = X_WF.R * (!InContact(g)
                            ? face_surface.face_normals()[g.face]
                            : ForceNormal(face_surface, g.face, s.q_F[node], fv[ft[0]], fv[ft[1]],
                                          fv[ft[2]], /*deformed=*/false, [&](int f) -> const Vec3& {
                                            return face_surface.face_normals()[f];
                                          }));
      gaps->push_back(g);
    }
    s.best_d2[node] = kInf;
    s.best_face[node] = -1;
  }
  s.touched.clear();
}

void ListNodeFaceCandidates(const ContactSurface& node_surface,
                            const std::vector<TrianglePair>& pairs, bool nodes_are_a,
                            GapScratch* scratch, std::vector<NodeFaceCandidate>* out) {
  GapScratch& s = *scratch;  // best_face: -1 for untouched nodes, used as count, then offset
  const auto& node_tris = node_surface.triangles();
  // Count the entries of every node.
  for (const TrianglePair& pair : pairs) {
    const int node_tri = nodes_are_a ? pair.a : pair.b;
    for (int k = 0; k < 3; ++k) {
      const int node = node_tris[node_tri][k];
      if (s.best_face[node] < 0) {
        s.best_face[node] = 0;
        s.touched.push_back(node);
      }
      ++s.best_face[node];
    }
  }
  // Offsets in node order.
  std::sort(s.touched.begin(), s.touched.end());
  int offset = 0;
  for (const int node : s.touched) {
    const int count = s.best_face[node];
    s.best_face[node] = offset;
    offset += count;
  }
  out->resize(offset);
  // Scatter; afterwards best_face[node] is the end of the node's range.
  for (const TrianglePair& pair : pairs) {
    const int node_tri = nodes_are_a ? pair.a : pair.b;
    const int face = nodes_are_a ? pair.b : pair.a;
    for (int k = 0; k < 3; ++k) {
      const int node = node_tris[node_tri][k];
      (*out)[s.best_face[node]++] = {node, face};
    }
  }
  // Sort each node's faces, drop repeats, compact; reset the scratch.
  auto write = out->begin();
  auto begin = out->begin();
  for (const int node : s.touched) {
    const auto end = out->begin() + s.best_face[node];
    std::sort(begin, end);
    const auto last = std::unique(begin, end);
    write = std::move(begin, last, write);
    begin = end;
    s.best_face[node] = -1;
  }
  out->erase(write, out->end());
  s.touched.clear();
}

void ComputeNodeGapsFromCandidates(const ContactSurface& node_surface, const Transform& X_WN,
                                   const ContactSurface& face_surface, const Transform& X_WF,
                                   const std::vector<NodeFaceCandidate>& candidates,
                                   double search_distance_m, std::vector<NodeGap>* gaps) {
  ComputeNodeGapsFromCandidates(node_surface, node_surface.vertices(), X_WN, face_surface,
                                face_surface.vertices(), face_surface.face_normals(), X_WF,
                                candidates, search_distance_m, gaps);
}

void ComputeNodeGapsFromCandidates(const ContactSurface& /*node_surface*/,
                                   const std::vector<Vec3>& node_vertices_N, const Transform& X_WN,
                                   const ContactSurface& face_surface,
                                   const std::vector<Vec3>& face_vertices_F,
                                   const std::vector<Vec3>& face_normals_F, const Transform& X_WF,
                                   const std::vector<NodeFaceCandidate>& candidates,
                                   double search_distance_m, std::vector<NodeGap>* gaps) {
  gaps->clear();
  const Transform X_FN = X_WF.Inverse() * X_WN;
  const auto& face_tris = face_surface.triangles();
  const auto& fv = face_vertices_F;
  const double d2_max = search_distance_m * search_distance_m;
  const size_t n = candidates.size();
  size_t i = 0;
  while (i < n) {
    // One node: its position in the face frame, then the closest of its faces (eq. 6); faces
    // come in increasing order, so a strict < keeps the lowest index on ties.
    const int node = candidates[i].node;
    const Vec3 p_F = X_FN * node_vertices_N[node];
    double best_d2 = std::numeric_limits<double>::max();
    int best_face = -1;
    ClosestPoint best;
    for (; i < n && candidates[i].node == node; ++i) {
      const int face = candidates[i].face;
      const auto& ft = face_tris[face];
      const ClosestPoint c = ClosestPointOnTriangle(p_F, fv[ft[0]], fv[ft[1]], fv[ft[2]]);
      const double d2 = (p_F - c.point).squaredNorm();
      if (d2 < best_d2) {
        best_d2 = d2;
        best_face = face;
        best = c;
      }
    }
    // Signed gap (eqs. 7-9) of a node within the search distance.
    if (best_d2 > d2_max) continue;
    NodeGap g = NodeGapFromClosest(face_surface, best_face, face_normals_F[best_face], p_F,
                                   best.point, best.feature);
    g.node = node;
    g.p_W = X_WF * p_F;
    g.q_W = X_WF * best.point;
    const auto& ft = face_tris[g.face];
    g.n_W = X_WF.R * (!InContact(g)
                          ? face_normals_F[g.face]
                          : ForceNormal(face_surface, g.face, best.point, fv[ft[0]], fv[ft[1]],
                                        fv[ft[2]], &face_normals_F != &face_surface.face_normals(),
                                        [&](int f) -> const Vec3& { return face_normals_F[f]; }));
    gaps->push_back(g);
  }
}

}  // namespace orrery::contact
