#include "import/mesh_checks.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <numbers>
#include <queue>

#include <Eigen/Geometry>

namespace orrery {
namespace {

// One use of an edge: its vertices (lo < hi), the triangle, and whether the triangle runs lo -> hi.
struct EdgeUse {
  int lo, hi, triangle;
  bool forward;
};

bool IsDegenerate(const TriangleMesh& m, const std::array<int, 3>& t) {
  if (t[0] == t[1] || t[1] == t[2] || t[0] == t[2]) return true;
  const Vec3 &a = m.vertices[t[0]], &b = m.vertices[t[1]], &c = m.vertices[t[2]];
  const double l2 = std::max({(b - a).squaredNorm(), (c - b).squaredNorm(), (a - c).squaredNorm()});
  return !((b - a).cross(c - a).norm() > 1e-12 * l2);
}

int CountDuplicates(const TriangleMesh& m) {
  std::vector<std::array<int, 3>> sorted(m.triangles);
  for (auto& t : sorted) std::sort(t.begin(), t.end());
  std::sort(sorted.begin(), sorted.end());
  int duplicates = 0;
  for (std::size_t i = 1; i < sorted.size(); ++i) duplicates += sorted[i] == sorted[i - 1];
  return duplicates;
}

// Signed volume of a set of triangles (with flips applied), sum a . (b x c) / 6.
double SignedVolume(const TriangleMesh& m, const std::vector<int>& tris, const std::vector<char>& flip) {
  double six_v = 0;
  for (int t : tris) {
    const auto& f = m.triangles[t];
    const double v = m.vertices[f[0]].dot(m.vertices[f[1]].cross(m.vertices[f[2]]));
    six_v += flip[t] ? -v : v;
  }
  return six_v / 6;
}

// Generalized winding number of point p with respect to oriented triangles (Jacobson et al. 2013).
double WindingNumber(const TriangleMesh& m, const std::vector<int>& tris, const std::vector<char>& flip, const Vec3& p) {
  double omega = 0;
  for (int t : tris) {
    const auto& f = m.triangles[t];
    Vec3 a = m.vertices[f[0]] - p, b = m.vertices[f[1]] - p, c = m.vertices[f[2]] - p;
    if (flip[t]) std::swap(b, c);
    const double la = a.norm(), lb = b.norm(), lc = c.norm();
    const double num = a.dot(b.cross(c));
    const double den = la * lb * lc + a.dot(b) * lc + b.dot(c) * la + c.dot(a) * lb;
    omega += 2 * std::atan2(num, den);
  }
  return omega / (4 * std::numbers::pi);
}

// ---- Triangle-triangle intersection (Moller 1997) ----------------------------------------------

// Index of the vertex alone on its side of the other plane; -1 if all three lie in it.
int IsolatedVertex(const double d[3]) {
  if (d[0] * d[1] > 0) return 2;
  if (d[0] * d[2] > 0) return 1;
  if (d[1] * d[2] > 0 || d[0] != 0) return 0;
  if (d[1] != 0) return 1;
  if (d[2] != 0) return 2;
  return -1;
}

// The interval of a triangle on the intersection line (projections p, signed distances d).
void LineInterval(const double p[3], const double d[3], int k, double& t0, double& t1) {
  const int i = (k + 1) % 3, j = (k + 2) % 3;
  t0 = p[k] + (p[i] - p[k]) * d[k] / (d[k] - d[i]);
  t1 = p[k] + (p[j] - p[k]) * d[k] / (d[k] - d[j]);
  if (t0 > t1) std::swap(t0, t1);
}

// 2-D orientation of c relative to segment a-b.
double Orient2(const Eigen::Vector2d& a, const Eigen::Vector2d& b, const Eigen::Vector2d& c) {
  return (b.x() - a.x()) * (c.y() - a.y()) - (b.y() - a.y()) * (c.x() - a.x());
}

bool SegmentsCross(const Eigen::Vector2d& a, const Eigen::Vector2d& b, const Eigen::Vector2d& c, const Eigen::Vector2d& d) {
  const double o1 = Orient2(a, b, c), o2 = Orient2(a, b, d), o3 = Orient2(c, d, a), o4 = Orient2(c, d, b);
  return o1 * o2 < 0 && o3 * o4 < 0;
}

bool InsideTriangle2(const Eigen::Vector2d& p, const Eigen::Vector2d t[3]) {
  const double s0 = Orient2(t[0], t[1], p), s1 = Orient2(t[1], t[2], p), s2 = Orient2(t[2], t[0], p);
  return (s0 > 0 && s1 > 0 && s2 > 0) || (s0 < 0 && s1 < 0 && s2 < 0);
}

// Coplanar triangles: project on the plane of the largest normal component, then edges crossing
// or a vertex strictly inside the other triangle.
bool CoplanarIntersect(const Vec3& n, const Vec3 a[3], const Vec3 b[3]) {
  int drop = 0;
  n.cwiseAbs().maxCoeff(&drop);
  const int u = (drop + 1) % 3, v = (drop + 2) % 3;
  Eigen::Vector2d p[3], q[3];
  for (int k = 0; k < 3; ++k) p[k] = {a[k][u], a[k][v]}, q[k] = {b[k][u], b[k][v]};
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      if (SegmentsCross(p[i], p[(i + 1) % 3], q[j], q[(j + 1) % 3])) return true;
  for (int k = 0; k < 3; ++k)
    if (InsideTriangle2(p[k], q) || InsideTriangle2(q[k], p)) return true;
  return false;
}

// ---- Bounding-volume hierarchy over triangle boxes ---------------------------------------------

struct Box {
  Vec3 lo = Vec3::Constant(INFINITY), hi = Vec3::Constant(-INFINITY);
  void Add(const Box& b) { lo = lo.cwiseMin(b.lo), hi = hi.cwiseMax(b.hi); }
  bool Overlaps(const Box& b) const { return (lo.array() <= b.hi.array()).all() && (b.lo.array() <= hi.array()).all(); }
};

struct BvhNode {
  Box box;
  int left = -1, right = -1;  // children, or -1 for a leaf
  int first = 0, count = 0;   // leaf: range in the triangle order
};

class SelfIntersectionFinder {
 public:
  SelfIntersectionFinder(const TriangleMesh& m, const std::vector<char>& degenerate, int max_pairs)
      : m_(m), max_pairs_(max_pairs) {
    for (int t = 0; t < static_cast<int>(m.triangles.size()); ++t)
      if (!degenerate[t]) order_.push_back(t);
    boxes_.resize(m.triangles.size());
    for (int t : order_)
      for (int k = 0; k < 3; ++k) boxes_[t].Add({m.vertices[m.triangles[t][k]], m.vertices[m.triangles[t][k]]});
    if (!order_.empty()) Build(0, static_cast<int>(order_.size()));
  }

  int Run() {
    if (nodes_.empty()) return 0;
    // Self-traversal with an explicit stack of node pairs
    std::vector<std::pair<int, int>> stack = {{0, 0}};
    while (!stack.empty()) {
      const auto [a, b] = stack.back();
      stack.pop_back();
      const BvhNode &na = nodes_[a], &nb = nodes_[b];
      if (a == b) {
        if (na.left < 0) {
          LeafPairs(na, na, true);
        } else {
          stack.push_back({na.left, na.left});
          stack.push_back({na.right, na.right});
          stack.push_back({na.left, na.right});
        }
        continue;
      }
      if (!na.box.Overlaps(nb.box)) continue;
      if (na.left < 0 && nb.left < 0) {
        LeafPairs(na, nb, false);
      } else if (nb.left < 0 || (na.left >= 0 && na.count >= nb.count)) {
        stack.push_back({na.left, b});
        stack.push_back({na.right, b});
      } else {
        stack.push_back({a, nb.left});
        stack.push_back({a, nb.right});
      }
    }
    return count_;
  }

  std::vector<std::pair<int, int>> examples;

 private:
  int Build(int first, int count) {
    const int index = static_cast<int>(nodes_.size());
    nodes_.emplace_back();
    Box box;
    for (int i = first; i < first + count; ++i) box.Add(boxes_[order_[i]]);
    nodes_[index].box = box;
    nodes_[index].first = first;
    nodes_[index].count = count;
    if (count <= 4) return index;
    // Median split of the box centres along the longest axis
    int axis = 0;
    (box.hi - box.lo).maxCoeff(&axis);
    const int mid = first + count / 2;
    std::nth_element(order_.begin() + first, order_.begin() + mid, order_.begin() + first + count, [&](int s, int t) {
      return boxes_[s].lo[axis] + boxes_[s].hi[axis] < boxes_[t].lo[axis] + boxes_[t].hi[axis];
    });
    const int left = Build(first, mid - first);
    const int right = Build(mid, first + count - mid);
    nodes_[index].left = left;
    nodes_[index].right = right;
    return index;
  }

  void LeafPairs(const BvhNode& a, const BvhNode& b, bool same) {
    for (int i = a.first; i < a.first + a.count; ++i)
      for (int j = same ? i + 1 : b.first; j < b.first + b.count; ++j) Test(order_[i], order_[j]);
  }

  void Test(int s, int t) {
    if (!boxes_[s].Overlaps(boxes_[t])) return;
    const auto &f = m_.triangles[s], &g = m_.triangles[t];
    for (int i : f)
      for (int j : g)
        if (i == j) return;  // neighbours: not tested
    const Vec3* v = m_.vertices.data();
    if (!TrianglesIntersect(v[f[0]], v[f[1]], v[f[2]], v[g[0]], v[g[1]], v[g[2]])) return;
    ++count_;
    if (static_cast<int>(examples.size()) < max_pairs_) examples.push_back({std::min(s, t), std::max(s, t)});
  }

  const TriangleMesh& m_;
  int max_pairs_;
  std::vector<int> order_;
  std::vector<Box> boxes_;
  std::vector<BvhNode> nodes_;
  int count_ = 0;
};

// Orientation walk: flips that make each component consistent, component ids, conflicts.
struct OrientationWalk {
  std::vector<char> flip;
  std::vector<int> component;
  std::vector<char> non_orientable;  // per component
  int components = 0;
};

OrientationWalk WalkOrientation(int nt, const std::vector<EdgeUse>& uses, const std::vector<int>& manifold_pair_of) {
  OrientationWalk w;
  w.flip.assign(nt, 0);
  w.component.assign(nt, -1);
  // Neighbours through manifold edges: for each triangle, up to 3 (neighbour, same direction)
  std::vector<std::array<std::pair<int, bool>, 3>> nb(nt);
  std::vector<int> nb_count(nt, 0);
  for (std::size_t u = 0; u < uses.size(); ++u) {
    const int other = manifold_pair_of[u];
    if (other < 0) continue;
    const int t = uses[u].triangle;
    if (nb_count[t] < 3) nb[t][nb_count[t]++] = {uses[other].triangle, uses[u].forward == uses[other].forward};
  }
  std::queue<int> queue;
  for (int seed = 0; seed < nt; ++seed) {
    if (w.component[seed] >= 0) continue;
    const int c = w.components++;
    w.non_orientable.push_back(0);
    w.component[seed] = c;
    queue.push(seed);
    while (!queue.empty()) {
      const int t = queue.front();
      queue.pop();
      for (int k = 0; k < nb_count[t]; ++k) {
        const auto [s, same_direction] = nb[t][k];
        // Consistent neighbours run the shared edge in opposite directions
        const char want = static_cast<char>(w.flip[t] ^ same_direction);
        if (w.component[s] < 0) {
          w.component[s] = c;
          w.flip[s] = want;
          queue.push(s);
        } else if (w.flip[s] != want) {
          w.non_orientable[c] = 1;
        }
      }
    }
  }
  return w;
}

}  // namespace

bool TrianglesIntersect(const Vec3& a0, const Vec3& a1, const Vec3& a2, const Vec3& b0, const Vec3& b1, const Vec3& b2) {
  const Vec3 a[3] = {a0, a1, a2}, b[3] = {b0, b1, b2};
  const double scale = std::max({(a1 - a0).norm(), (a2 - a0).norm(), (b1 - b0).norm(), (b2 - b0).norm()});
  // Signed distances of a's vertices to b's plane; all on one side: apart
  const Vec3 nb = (b1 - b0).cross(b2 - b0), na = (a1 - a0).cross(a2 - a0);
  const double eps_b = 1e-12 * nb.norm() * scale, eps_a = 1e-12 * na.norm() * scale;
  double da[3], db[3];
  for (int k = 0; k < 3; ++k) {
    da[k] = nb.dot(a[k] - b0);
    if (std::abs(da[k]) < eps_b) da[k] = 0;
    db[k] = na.dot(b[k] - a0);
    if (std::abs(db[k]) < eps_a) db[k] = 0;
  }
  if ((da[0] > 0 && da[1] > 0 && da[2] > 0) || (da[0] < 0 && da[1] < 0 && da[2] < 0)) return false;
  if ((db[0] > 0 && db[1] > 0 && db[2] > 0) || (db[0] < 0 && db[1] < 0 && db[2] < 0)) return false;
  const int ka = IsolatedVertex(da), kb = IsolatedVertex(db);
  if (ka < 0 || kb < 0) return CoplanarIntersect(nb, a, b);
  // Intervals on the intersection line, projected on its largest coordinate axis
  const Vec3 line = na.cross(nb);
  int axis = 0;
  line.cwiseAbs().maxCoeff(&axis);
  const double pa[3] = {a0[axis], a1[axis], a2[axis]}, pb[3] = {b0[axis], b1[axis], b2[axis]};
  double a_lo, a_hi, b_lo, b_hi;
  LineInterval(pa, da, ka, a_lo, a_hi);
  LineInterval(pb, db, kb, b_lo, b_hi);
  const double overlap = std::min(a_hi, b_hi) - std::max(a_lo, b_lo);
  return overlap > 1e-12 * scale;
}

bool MeshCheckReport::valid_solid() const {
  return watertight() && non_orientable_components == 0 && degenerate_triangles == 0 && duplicate_triangles == 0 &&
         self_intersections <= 0;
}

std::vector<std::string> MeshCheckReport::Problems() const {
  std::vector<std::string> p;
  const auto add = [&](int n, const std::string& what) {
    if (n > 0) p.push_back(std::to_string(n) + " " + what);
  };
  add(boundary_edges, "boundary edges: the mesh is open (not watertight)");
  add(non_manifold_edges, "non-manifold edges (used by three or more triangles)");
  add(degenerate_triangles, "degenerate triangles (no area)");
  add(duplicate_triangles, "duplicate triangles");
  add(non_orientable_components, "non-orientable components (left as they were)");
  add(self_intersections, "pairs of intersecting triangles");
  add(static_cast<int>(flipped.size()), "triangles re-oriented (consistent, outward)");
  if (!nesting_checked) p.push_back("more than 64 closed components: cavities not detected, all oriented outward");
  return p;
}

MeshCheckReport CheckMesh(const TriangleMesh& mesh, const MeshCheckOptions& options) {
  MeshCheckReport r;
  const int nt = static_cast<int>(mesh.triangles.size());
  r.triangles = nt;
  r.vertices = static_cast<int>(mesh.vertices.size());

  // Degenerate and duplicate triangles
  std::vector<char> degenerate(nt, 0);
  for (int t = 0; t < nt; ++t) r.degenerate_triangles += degenerate[t] = IsDegenerate(mesh, mesh.triangles[t]);
  r.duplicate_triangles = CountDuplicates(mesh);

  // Edge uses, grouped by edge
  std::vector<EdgeUse> uses;
  uses.reserve(3 * static_cast<std::size_t>(nt));
  for (int t = 0; t < nt; ++t)
    for (int k = 0; k < 3; ++k) {
      const int u = mesh.triangles[t][k], v = mesh.triangles[t][(k + 1) % 3];
      if (u != v) uses.push_back({std::min(u, v), std::max(u, v), t, u < v});
    }
  std::sort(uses.begin(), uses.end(),
            [](const EdgeUse& a, const EdgeUse& b) { return a.lo != b.lo ? a.lo < b.lo : a.hi != b.hi ? a.hi < b.hi : a.triangle < b.triangle; });
  std::vector<int> pair_of(uses.size(), -1);  // the other use of a manifold edge
  std::vector<char> open_component_mark(nt, 0);  // triangle touches a boundary or non-manifold edge
  for (std::size_t i = 0; i < uses.size();) {
    std::size_t j = i;
    while (j < uses.size() && uses[j].lo == uses[i].lo && uses[j].hi == uses[i].hi) ++j;
    const std::size_t count = j - i;
    if (count == 1) ++r.boundary_edges;
    if (count > 2) ++r.non_manifold_edges;
    if (count == 2) {
      pair_of[i] = static_cast<int>(i + 1);
      pair_of[i + 1] = static_cast<int>(i);
      r.inconsistent_edges += uses[i].forward == uses[i + 1].forward;
    } else {
      for (std::size_t k = i; k < j; ++k) open_component_mark[uses[k].triangle] = 1;
    }
    i = j;
  }

  // Consistent orientation per component
  OrientationWalk w = WalkOrientation(nt, uses, pair_of);
  r.components = w.components;
  std::vector<std::vector<int>> members(w.components);
  for (int t = 0; t < nt; ++t) members[w.component[t]].push_back(t);
  std::vector<char> closed(w.components, 1);
  for (int t = 0; t < nt; ++t)
    if (open_component_mark[t]) closed[w.component[t]] = 0;
  for (int c = 0; c < w.components; ++c) {
    r.non_orientable_components += w.non_orientable[c];
    r.closed_components += closed[c] && !w.non_orientable[c];
  }

  // Outward: closed components by volume and nesting depth, open ones by the majority
  std::vector<int> closed_list;
  for (int c = 0; c < w.components; ++c)
    if (closed[c] && !w.non_orientable[c]) {
      if (SignedVolume(mesh, members[c], w.flip) < 0)
        for (int t : members[c]) w.flip[t] ^= 1;
      closed_list.push_back(c);
    }
  r.nesting_checked = closed_list.size() <= 64;
  if (r.nesting_checked && closed_list.size() > 1) {
    std::vector<char> cavity(w.components, 0);
    for (int c : closed_list) {
      const Vec3 p = mesh.vertices[mesh.triangles[members[c].front()][0]];
      int depth = 0;
      for (int d : closed_list)
        if (d != c && WindingNumber(mesh, members[d], w.flip, p) > 0.5) ++depth;
      cavity[c] = depth % 2;
    }
    for (int c : closed_list)
      if (cavity[c])
        for (int t : members[c]) w.flip[t] ^= 1;
  }
  for (int c = 0; c < w.components; ++c) {
    if (w.non_orientable[c]) {
      for (int t : members[c]) w.flip[t] = 0;
    } else if (!closed[c]) {
      const auto flips = std::count_if(members[c].begin(), members[c].end(), [&](int t) { return w.flip[t] != 0; });
      if (2 * static_cast<std::size_t>(flips) > members[c].size())
        for (int t : members[c]) w.flip[t] ^= 1;
    }
  }
  for (int t = 0; t < nt; ++t)
    if (w.flip[t]) r.flipped.push_back(t);
  std::vector<int> all(nt);
  for (int t = 0; t < nt; ++t) all[t] = t;
  r.signed_volume_m3 = SignedVolume(mesh, all, w.flip);

  // Self-intersections
  if (options.self_intersections) {
    SelfIntersectionFinder finder(mesh, degenerate, options.max_reported_pairs);
    r.self_intersections = finder.Run();
    r.intersecting_pairs = finder.examples;
  }
  return r;
}

void OrientMesh(TriangleMesh& mesh, const MeshCheckReport& report) {
  for (int t : report.flipped) std::swap(mesh.triangles[t][1], mesh.triangles[t][2]);
}

}  // namespace orrery
