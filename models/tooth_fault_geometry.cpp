#include "models/tooth_fault_geometry.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <numbers>
#include <sstream>
#include <stdexcept>
#include <tuple>
#include <unordered_map>

namespace orrery::gears {
namespace {

constexpr double kPi = std::numbers::pi;

template <typename... Args>
[[noreturn]] void Fail(Args&&... args) {
  std::ostringstream s;
  s.precision(6);
  s << "faulty tooth geometry: ";
  (s << ... << args);
  throw std::invalid_argument(s.str());
}

Vec2 Rotate(const Vec2& p, double a) {
  const double c = std::cos(a), s = std::sin(a);
  return {c * p.x() - s * p.y(), s * p.x() + c * p.y()};
}

// Triangle mesh whose vertices at bit-identical positions are one vertex; zero-area triangles
// are dropped.
class WeldedMesh {
 public:
  explicit WeldedMesh(double length_scale) : min_area2_(1e-20 * length_scale * length_scale * length_scale * length_scale) {}
  int Vertex(const Vec3& p) {
    Key k;
    std::memcpy(k.v, p.data(), sizeof(k.v));
    auto [it, fresh] = index_.try_emplace(k, static_cast<int>(mesh_.vertices.size()));
    if (fresh) mesh_.vertices.push_back(p);
    return it->second;
  }
  // Adds (a, b, c), flipped if its normal points against `towards` (zero: keep the order).
  void Triangle(int a, int b, int c, const Vec3& towards = Vec3::Zero()) {
    if (a == b || b == c || a == c) return;
    const Vec3 n = (mesh_.vertices[b] - mesh_.vertices[a]).cross(mesh_.vertices[c] - mesh_.vertices[a]);
    if (n.squaredNorm() <= min_area2_) return;
    if (n.dot(towards) < 0) std::swap(b, c);
    mesh_.triangles.push_back({a, b, c});
  }
  TriangleMesh Take() { return std::move(mesh_); }

 private:
  struct Key {
    double v[3];
    bool operator==(const Key& o) const { return std::memcmp(v, o.v, sizeof(v)) == 0; }
  };
  struct KeyHash {
    size_t operator()(const Key& k) const {
      size_t h = 1469598103934665603ULL;
      const unsigned char* b = reinterpret_cast<const unsigned char*>(k.v);
      for (size_t i = 0; i < sizeof(k.v); ++i) h = (h ^ b[i]) * 1099511628211ULL;
      return h;
    }
  };
  double min_area2_;
  TriangleMesh mesh_;
  std::unordered_map<Key, int, KeyHash> index_;
};

// A transverse section point at height z on the helix: p (tooth-0 frame) turned by angle + twist z.
Vec3 At(const Vec2& p, double angle, double twist, double z) {
  const Vec2 q = Rotate(p, angle + twist * z);
  return {q.x(), q.y(), z};
}

// One tooth's transverse outline: healthy, and with its geometric fault (if any), plus the
// sub-polylines where the two differ (for the steps between segments).
struct ToothProfiles {
  std::vector<Vec2> healthy, faulty;
  std::vector<Vec2> healthy_part, faulty_part;  // same end points
  double z0 = 0, z1 = 0;                        // the fault's axial range
  bool faulted = false;
};

// Inserts s into the sorted parameters unless one is within 1e-12.
void InsertParameter(std::vector<double>& s, double value) {
  auto it = std::lower_bound(s.begin(), s.end(), value);
  if (it != s.end() && std::abs(*it - value) < 1e-12) return;
  if (it != s.begin() && std::abs(*(it - 1) - value) < 1e-12) return;
  s.insert(it, value);
}

// Profile parameter of the involute point with roll distance rho on one flank.
double InvoluteParameter(const Gear& gear, double rho, bool plus_side) {
  const double r = std::hypot(gear.base_radius_m(), rho);
  return ProfileParameterAtRadius(gear, r, plus_side);
}

ToothProfiles MakeToothProfiles(const Gear& gear, const ProfileResolution& res, bool open_end,
                                const ToothFaultSpec* fault) {
  std::vector<double> s;
  for (const ProfilePoint& q : gear.SampleToothOutline(res)) s.push_back(q.s);
  if (open_end) s.push_back(7.0);
  ToothProfiles out;
  auto points = [&](double a, double b) {
    std::vector<Vec2> p;
    for (double v : s)
      if (v >= a - 1e-12 && v <= b + 1e-12) p.push_back(gear.ProfileAt(v).p);
    return p;
  };
  if (fault == nullptr || fault->kind == ToothFaultSpec::Kind::kRootCrack ||
      (fault->kind == ToothFaultSpec::Kind::kBrokenTooth && (fault->height_fraction <= 0 || fault->face_fraction <= 0))) {
    out.healthy = points(-1, 8);
    return out;
  }
  out.faulted = true;
  std::tie(out.z0, out.z1) = FaultAxialRange(gear, *fault);
  double sa = 0, sb = 0;
  if (fault->kind == ToothFaultSpec::Kind::kBrokenTooth) {
    const double rbreak = BreakRadius(gear, *fault);
    sa = ProfileParameterAtRadius(gear, rbreak, false);
    sb = ProfileParameterAtRadius(gear, rbreak, true);
  } else {
    const bool plus = fault->flank == ToothFaultSpec::Flank::kPlus;
    const double a = InvoluteParameter(gear, fault->roll_start_m, plus);
    const double b = InvoluteParameter(gear, fault->roll_end_m, plus);
    sa = std::min(a, b), sb = std::max(a, b);
  }
  InsertParameter(s, sa);
  InsertParameter(s, sb);
  out.healthy = points(-1, 8);
  out.healthy_part = points(sa, sb);
  // The faulty part: the chord of the fracture, or the depressed flank with its walls.
  if (fault->kind == ToothFaultSpec::Kind::kBrokenTooth) {
    const Vec2 pa = gear.ProfileAt(sa).p, pb = gear.ProfileAt(sb).p;
    const int n = res.tip + 2;
    out.faulty_part.push_back(pa);
    for (int j = 1; j < n; ++j) out.faulty_part.push_back(pa + (pb - pa) * (static_cast<double>(j) / n));
    out.faulty_part.push_back(pb);
  } else {
    out.faulty_part.push_back(gear.ProfileAt(sa).p);
    for (double v : s)
      if (v >= sa - 1e-12 && v <= sb + 1e-12) {
        const ProfilePoint q = gear.ProfileAt(v);
        out.faulty_part.push_back(q.p - fault->depth_m * q.n);
      }
    out.faulty_part.push_back(gear.ProfileAt(sb).p);
  }
  const std::vector<Vec2> before = points(-1, sa), after = points(sb, 8);
  out.faulty.assign(before.begin(), before.end() - 1);
  out.faulty.insert(out.faulty.end(), out.faulty_part.begin(), out.faulty_part.end());
  out.faulty.insert(out.faulty.end(), after.begin() + 1, after.end());
  return out;
}

// Ruled strip of a transverse polyline over z_levels (open or closed), oriented as
// gear_geometry.h's strips (outward normal = tangent x z when the material is inside).
void AddStrip(WeldedMesh& mesh, const std::vector<Vec2>& profile, bool closed, double angle, double twist,
              const std::vector<double>& z_levels, bool material_inside) {
  const int n = static_cast<int>(profile.size());
  std::vector<int> lower(n), upper(n);
  for (int i = 0; i < n; ++i) lower[i] = mesh.Vertex(At(profile[i], angle, twist, z_levels[0]));
  for (size_t k = 1; k < z_levels.size(); ++k) {
    for (int i = 0; i < n; ++i) upper[i] = mesh.Vertex(At(profile[i], angle, twist, z_levels[k]));
    for (int i = 0; i < (closed ? n : n - 1); ++i) {
      const int a = lower[i], b = lower[(i + 1) % n], c = upper[(i + 1) % n], d = upper[i];
      if (material_inside) {
        mesh.Triangle(a, b, c);
        mesh.Triangle(a, c, d);
      } else {
        mesh.Triangle(a, c, b);
        mesh.Triangle(a, d, c);
      }
    }
    lower.swap(upper);
  }
}

// Planar step at height z between two polylines with common end points, zipped by arc length,
// normal along `normal_z` (+1 or -1) z.
void AddStep(WeldedMesh& mesh, const std::vector<Vec2>& a, const std::vector<Vec2>& b, double angle, double twist,
             double z, double normal_z) {
  auto fractions = [](const std::vector<Vec2>& p) {
    std::vector<double> f(p.size(), 0.0);
    for (size_t i = 1; i < p.size(); ++i) f[i] = f[i - 1] + (p[i] - p[i - 1]).norm();
    for (double& v : f) v /= std::max(f.back(), 1e-300);
    return f;
  };
  const std::vector<double> fa = fractions(a), fb = fractions(b);
  const Vec3 towards(0, 0, normal_z);
  auto v = [&](const Vec2& p) { return mesh.Vertex(At(p, angle, twist, z)); };
  size_t i = 0, j = 0;
  while (i + 1 < a.size() || j + 1 < b.size()) {
    if (j + 1 == b.size() || (i + 1 < a.size() && fa[i + 1] <= fb[j + 1])) {
      mesh.Triangle(v(a[i]), v(a[i + 1]), v(b[j]), towards);
      ++i;
    } else {
      mesh.Triangle(v(a[i]), v(b[j]), v(b[j + 1]), towards);
      ++j;
    }
  }
}

// z levels of [z0, z1] with n intervals.
std::vector<double> Levels(double z0, double z1, int n) {
  std::vector<double> z;
  for (int k = 0; k <= n; ++k) z.push_back(k == n ? z1 : z0 + (z1 - z0) * k / n);
  return z;
}

// The geometric fault of tooth t among `faults` (validated: at most one).
const ToothFaultSpec* GeometricFault(const std::vector<ToothFaultSpec>& faults, int t) {
  for (const ToothFaultSpec& f : faults)
    if (f.tooth == t && f.kind != ToothFaultSpec::Kind::kRootCrack) return &f;
  return nullptr;
}

// Segment boundaries: 0, b and the axial limits of every faulted profile.
std::vector<double> SegmentEdges(double b, const std::vector<const ToothProfiles*>& teeth) {
  std::vector<double> z = {0.0, b};
  for (const ToothProfiles* t : teeth)
    if (t->faulted) z.insert(z.end(), {std::clamp(t->z0, 0.0, b), std::clamp(t->z1, 0.0, b)});
  std::sort(z.begin(), z.end());
  std::vector<double> out;
  for (double v : z)
    if (out.empty() || v - out.back() > 1e-12 * b) out.push_back(v);
  return out;
}

int Intervals(int n_face, double width, double b) {
  return std::max(1, static_cast<int>(std::lround(n_face * width / b)));
}

bool FaultyIn(const ToothProfiles& t, double z_mid) { return t.faulted && z_mid > t.z0 && z_mid < t.z1; }

// Steps of one tooth at every inner boundary where its state changes.
void AddToothSteps(WeldedMesh& mesh, const ToothProfiles& t, const std::vector<double>& edges, double angle,
                   double twist) {
  for (size_t k = 1; k + 1 < edges.size(); ++k) {
    const bool below = FaultyIn(t, 0.5 * (edges[k - 1] + edges[k]));
    const bool above = FaultyIn(t, 0.5 * (edges[k] + edges[k + 1]));
    if (below == above) continue;
    // The region between the profiles is material on the healthy side: it faces the other.
    AddStep(mesh, t.healthy_part, t.faulty_part, angle, twist, edges[k], below ? -1.0 : 1.0);
  }
}

}  // namespace

double ProfileParameterAtRadius(const Gear& gear, double radius_m, bool plus_side) {
  const double rf = gear.root_radius_m(), ra = gear.tip_radius_m();
  const double lo_r = std::min(rf, ra), hi_r = std::max(rf, ra);
  if (!(radius_m >= lo_r * (1 - 1e-12) && radius_m <= hi_r * (1 + 1e-12)))
    Fail("radius ", radius_m, " m is outside the tooth [", lo_r, ", ", hi_r, "] m");
  // Minus side: s in [1, 3] from the fillet's root end to the tip; plus side: [4, 6].
  double a = plus_side ? 4.0 : 1.0, b = plus_side ? 6.0 : 3.0;
  auto f = [&](double s) { return gear.ProfileAt(s).p.norm() - radius_m; };
  double fa = f(a);
  for (int it = 0; it < 200 && b - a > 1e-15; ++it) {
    const double m = 0.5 * (a + b), fm = f(m);
    if ((fm < 0) == (fa < 0)) {
      a = m;
      fa = fm;
    } else {
      b = m;
    }
  }
  return 0.5 * (a + b);
}

TriangleMesh MakeFaultyToothSurfaceMesh(const Gear& gear, int tooth, const ProfileResolution& res, int n_face,
                                        const std::vector<ToothFaultSpec>& faults) {
  if (n_face < 1) Fail("n_face = ", n_face, " must be >= 1");
  ValidateToothFaults(gear, faults);
  const ToothProfiles t = MakeToothProfiles(gear, res, true, GeometricFault(faults, tooth));
  const double b = gear.spec().face_width_m, twist = gear.twist_per_length();
  const double angle = 2 * kPi * tooth / gear.teeth();
  const std::vector<double> edges = SegmentEdges(b, {&t});
  WeldedMesh mesh(gear.tip_radius_m());
  for (size_t k = 0; k + 1 < edges.size(); ++k) {
    const bool faulty = FaultyIn(t, 0.5 * (edges[k] + edges[k + 1]));
    AddStrip(mesh, faulty ? t.faulty : t.healthy, false, angle, twist,
             Levels(edges[k], edges[k + 1], Intervals(n_face, edges[k + 1] - edges[k], b)), !gear.internal());
  }
  AddToothSteps(mesh, t, edges, angle, twist);
  return mesh.Take();
}

namespace {

// Annulus between the closed outline (all teeth) and the rim circle at height z (end faces).
void AddEndFace(WeldedMesh& mesh, const std::vector<Vec2>& outline, const std::vector<Vec2>& circle, double twist,
                double z, bool top, bool internal) {
  auto unwrapped = [](const std::vector<Vec2>& p, double start) {
    std::vector<double> a;
    for (const Vec2& q : p) {
      double v = std::atan2(q.y(), q.x());
      const double prev = a.empty() ? start : a.back();
      while (v < prev - kPi) v += 2 * kPi;
      while (v > prev + kPi) v -= 2 * kPi;
      if (!a.empty() && !(v > prev))
        throw std::logic_error("faulty gear mesh: outline polar angle not increasing (not star-shaped)");
      a.push_back(v);
    }
    return a;
  };
  const double start = std::atan2(outline[0].y(), outline[0].x()) - 1e-9;
  const std::vector<double> ao = unwrapped(outline, start), ac = unwrapped(circle, start);
  const std::vector<Vec2>& outer = internal ? circle : outline;
  const std::vector<Vec2>& inner = internal ? outline : circle;
  const std::vector<double>& a_out = internal ? ac : ao;
  const std::vector<double>& a_in = internal ? ao : ac;
  const int no = static_cast<int>(outer.size()), ni = static_cast<int>(inner.size());
  auto angle = [&](const std::vector<double>& a, int i) { return i < static_cast<int>(a.size()) ? a[i] : a[0] + 2 * kPi; };
  auto v = [&](const Vec2& p) { return mesh.Vertex(At(p, 0.0, twist, z)); };
  const Vec3 towards(0, 0, top ? 1.0 : -1.0);
  int i = 0, j = 0;
  while (i < no || j < ni) {
    if (j == ni || (i < no && angle(a_out, i + 1) <= angle(a_in, j + 1))) {
      mesh.Triangle(v(outer[i]), v(outer[(i + 1) % no]), v(inner[j % ni]), towards);
      ++i;
    } else {
      mesh.Triangle(v(inner[j]), v(outer[i % no]), v(inner[(j + 1) % ni]), towards);
      ++j;
    }
  }
}

}  // namespace

TriangleMesh MakeFaultyGearMesh(const Gear& gear, const ProfileResolution& res, int n_face, double rim_radius_m,
                                const std::vector<ToothFaultSpec>& faults) {
  if (n_face < 1) Fail("n_face = ", n_face, " must be >= 1");
  const bool internal = gear.internal();
  if (!internal && !(rim_radius_m > 0 && rim_radius_m < gear.root_radius_m()))
    Fail("bore radius ", rim_radius_m, " m must lie in (0, r_f = ", gear.root_radius_m(), " m)");
  if (internal && !(rim_radius_m > gear.root_radius_m()))
    Fail("rim radius ", rim_radius_m, " m must exceed the internal root radius ", gear.root_radius_m(), " m");
  ValidateToothFaults(gear, faults);
  const double b = gear.spec().face_width_m, twist = gear.twist_per_length();
  for (const ToothFaultSpec& f : faults)
    if (f.kind == ToothFaultSpec::Kind::kSpall && (f.axial_start_m <= 0 || f.axial_end_m >= b))
      Fail("spall on tooth ", f.tooth, " reaches an end face (axial range [", f.axial_start_m, ", ", f.axial_end_m,
           "] m of [0, ", b, "] m): the closed gear mesh needs star-shaped end faces");
  // Tooth outlines (each from -pi/z, the next tooth's start excluded) and the segments.
  const int z = gear.teeth();
  std::vector<ToothProfiles> teeth;
  std::vector<const ToothProfiles*> pointers;
  // Each tooth's profiles turned to its place once, so that strips and steps share vertices.
  for (int t = 0; t < z; ++t) {
    ToothProfiles p = MakeToothProfiles(gear, res, false, GeometricFault(faults, t));
    for (std::vector<Vec2>* line : {&p.healthy, &p.faulty, &p.healthy_part, &p.faulty_part})
      for (Vec2& q : *line) q = Rotate(q, 2 * kPi * t / z);
    teeth.push_back(std::move(p));
  }
  for (const ToothProfiles& t : teeth) pointers.push_back(&t);
  const std::vector<double> edges = SegmentEdges(b, pointers);
  auto outline_at = [&](double z_mid) {
    std::vector<Vec2> o;
    for (int t = 0; t < z; ++t)
      for (const Vec2& p : FaultyIn(teeth[t], z_mid) ? teeth[t].faulty : teeth[t].healthy) o.push_back(p);
    return o;
  };
  WeldedMesh mesh(gear.tip_radius_m());
  // Outline strips per segment, steps per tooth, the rim and both end faces.
  for (size_t k = 0; k + 1 < edges.size(); ++k)
    AddStrip(mesh, outline_at(0.5 * (edges[k] + edges[k + 1])), true, 0.0, twist,
             Levels(edges[k], edges[k + 1], Intervals(n_face, edges[k + 1] - edges[k], b)), !internal);
  for (int t = 0; t < z; ++t) AddToothSteps(mesh, teeth[t], edges, 0.0, twist);
  const std::vector<Vec2> first = outline_at(0.5 * (edges[0] + edges[1]));
  const std::vector<Vec2> last = outline_at(0.5 * (edges[edges.size() - 2] + edges.back()));
  const int m = std::max(3 * z, static_cast<int>(first.size()) / 3);
  std::vector<Vec2> circle;
  const double angle0 = -kPi / z;
  for (int j = 0; j < m; ++j) circle.push_back(rim_radius_m * Vec2(std::cos(angle0 + 2 * kPi * j / m), std::sin(angle0 + 2 * kPi * j / m)));
  AddStrip(mesh, circle, true, 0.0, twist, Levels(0, b, n_face), internal);
  AddEndFace(mesh, first, circle, twist, 0.0, false, internal);
  AddEndFace(mesh, last, circle, twist, b, true, internal);
  return mesh.Take();
}

}  // namespace orrery::gears
