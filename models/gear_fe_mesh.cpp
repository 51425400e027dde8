#include "models/gear_fe_mesh.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <sstream>
#include <stdexcept>
#include <unordered_map>
#include <utility>

namespace orrery::gears {
namespace {

constexpr double kPi = 3.14159265358979323846;

template <typename... Args>
[[noreturn]] void Fail(Args&&... args) {
  std::ostringstream s;
  s << "MakeGearFeMesh: ";
  (s << ... << args);
  throw std::invalid_argument(s.str());
}

Vec2 Polar(double r, double a) { return {r * std::cos(a), r * std::sin(a)}; }
Vec2 Rotate(const Vec2& p, double a) {
  const double c = std::cos(a), s = std::sin(a);
  return {c * p.x() - s * p.y(), s * p.x() + c * p.y()};
}

// Surface tags of transverse points (bit flags); the per-tooth ones refer to the point's sector.
enum Tag : std::uint8_t {
  kBore = 1, kRoot = 2, kFlankPlus = 4, kFlankMinus = 8, kFilletPlus = 16, kFilletMinus = 32, kTip = 64
};
constexpr int kToothParts = 5;
constexpr Tag kToothTags[kToothParts] = {kFlankPlus, kFlankMinus, kFilletPlus, kFilletMinus, kTip};
constexpr const char* kToothPartNames[kToothParts] = {"FLANK_PLUS", "FLANK_MINUS", "FILLET_PLUS", "FILLET_MINUS",
                                                       "TIP"};

// ---- 1-D node distributions on [0, 1] ----

// n elements whose sizes grow geometrically from the 0 end to the 1 end by last/first = ratio.
std::vector<double> Geometric(int n, double ratio) {
  const double rho = n > 1 ? std::pow(ratio, 1.0 / (n - 1)) : 1.0;
  std::vector<double> x(n + 1, 0.0);
  double size = 1;
  for (int k = 0; k < n; ++k, size *= rho) x[k + 1] = x[k] + size;
  for (double& v : x) v /= x[n];
  return x;
}

// n elements, smallest at both ends, middle / end size = bias (geometric towards the middle).
std::vector<double> Symmetric(int n, double bias) {
  const int half = (n - 1) / 2;
  const double rho = half > 0 ? std::pow(bias, 1.0 / half) : 1.0;
  std::vector<double> x(n + 1, 0.0);
  for (int k = 0; k < n; ++k) x[k + 1] = x[k] + std::pow(rho, std::min(k, n - 1 - k));
  for (double& v : x) v /= x[n];
  return x;
}

// Inserts q - 1 equally spaced parameters into every interval (q = 1: unchanged).
std::vector<double> Refine(const std::vector<double>& x, int q) {
  std::vector<double> out;
  for (std::size_t k = 0; k + 1 < x.size(); ++k)
    for (int s = 0; s < q; ++s) out.push_back(x[k] + (x[k + 1] - x[k]) * s / q);
  out.push_back(x.back());
  return out;
}

// Concatenates distributions of consecutive intervals [a_k, a_k+1] (values mapped into them).
std::vector<double> Concat(const std::vector<std::pair<std::vector<double>, std::pair<double, double>>>& parts) {
  std::vector<double> out;
  for (const auto& [x, range] : parts)
    for (std::size_t k = out.empty() ? 0 : 1; k < x.size(); ++k)
      out.push_back(range.first + (range.second - range.first) * x[k]);
  return out;
}

// ---- Transverse structured blocks ----

// A (ni + 1) x (nj + 1) lattice of points of one block (q points per element edge).
struct Block {
  int ni = 0, nj = 0;
  std::vector<Vec2> p;
  std::vector<std::uint8_t> tag;
  std::vector<std::uint8_t> web_row;  // per element row (j / q): 1 inside the web's radial range
  Block(int ni_, int nj_) : ni(ni_), nj(nj_), p((ni_ + 1) * (nj_ + 1)), tag((ni_ + 1) * (nj_ + 1), 0) {}
  int Index(int i, int j) const { return j * (ni + 1) + i; }
  Vec2& at(int i, int j) { return p[Index(i, j)]; }
};

// Polar block: angles (ni + 1) x radii (nj + 1).
Block PolarBlock(const std::vector<double>& angles, const std::vector<double>& radii) {
  Block b(static_cast<int>(angles.size()) - 1, static_cast<int>(radii.size()) - 1);
  for (int j = 0; j <= b.nj; ++j)
    for (int i = 0; i <= b.ni; ++i) b.at(i, j) = Polar(radii[j], angles[i]);
  return b;
}

// Winslow smoothing of the interior points of `b` on computational coordinates xi (ni + 1) and
// eta (nj + 1): Gauss-Seidel on a x_xixi - 2 b x_xieta + c x_etaeta = 0 with
// a = |x_eta|^2, b = x_xi . x_eta, c = |x_xi|^2, central differences on the non-uniform grid.
void Winslow(Block& b, const std::vector<double>& xi, const std::vector<double>& eta, int iterations, double tol) {
  for (int it = 0; it < iterations; ++it) {
    double max_move = 0;
    for (int j = 1; j < b.nj; ++j)
      for (int i = 1; i < b.ni; ++i) {
        const double hp = xi[i + 1] - xi[i], hm = xi[i] - xi[i - 1];
        const double kp = eta[j + 1] - eta[j], km = eta[j] - eta[j - 1];
        const Vec2 x_xi = (b.at(i + 1, j) - b.at(i - 1, j)) / (hp + hm);
        const Vec2 x_eta = (b.at(i, j + 1) - b.at(i, j - 1)) / (kp + km);
        const Vec2 x_xieta = (b.at(i + 1, j + 1) - b.at(i - 1, j + 1) - b.at(i + 1, j - 1) + b.at(i - 1, j - 1)) /
                             ((hp + hm) * (kp + km));
        const double alpha = x_eta.squaredNorm(), beta = x_xi.dot(x_eta), gamma = x_xi.squaredNorm();
        const double ap = 2 / (hp * (hp + hm)), am = 2 / (hm * (hp + hm));
        const double bp = 2 / (kp * (kp + km)), bm = 2 / (km * (kp + km));
        const Vec2 next = (alpha * (ap * b.at(i + 1, j) + am * b.at(i - 1, j)) +
                           gamma * (bp * b.at(i, j + 1) + bm * b.at(i, j - 1)) - 2 * beta * x_xieta) /
                          (alpha * (ap + am) + gamma * (bp + bm));
        max_move = std::max(max_move, (next - b.at(i, j)).norm());
        b.at(i, j) = next;
      }
    if (max_move < tol) break;
  }
}

// Merges points closer than a tolerance (shared lines of blocks and sectors) by a hash grid.
class PointMerger {
 public:
  explicit PointMerger(double tol) : tol_(tol) {}
  int Add(const Vec2& p, std::uint8_t tag, int tooth) {
    const long long cx = std::llround(p.x() / tol_), cy = std::llround(p.y() / tol_);
    for (long long dx = -1; dx <= 1; ++dx)
      for (long long dy = -1; dy <= 1; ++dy) {
        auto it = grid_.find(Key(cx + dx, cy + dy));
        if (it != grid_.end() && (points_[it->second] - p).norm() <= tol_) {
          tags_[it->second] |= tag;
          if (tag & ~(kBore | kRoot)) tooth_[it->second] = tooth;
          return it->second;
        }
      }
    const int index = static_cast<int>(points_.size());
    points_.push_back(p);
    tags_.push_back(tag);
    tooth_.push_back(tooth);
    grid_.emplace(Key(cx, cy), index);
    return index;
  }
  const std::vector<Vec2>& points() const { return points_; }
  const std::vector<std::uint8_t>& tags() const { return tags_; }
  const std::vector<int>& tooth() const { return tooth_; }

 private:
  static long long Key(long long x, long long y) { return x * 2147483647LL + y; }
  double tol_;
  std::unordered_map<long long, int> grid_;
  std::vector<Vec2> points_;
  std::vector<std::uint8_t> tags_;
  std::vector<int> tooth_;
};

// A transverse element: its (q + 1) x (q + 1) lattice points (first index along `a`, then `b`,
// counter-clockwise) and whether it lies in the web's radial range.
struct Cell {
  std::array<std::array<int, 3>, 3> p{};
  bool web = false;
};

// Lattice offsets (0..2) of the hex20 nodes: natural coordinate + 1 (fe_mesh.h order); the first
// 8 are the hex8 corners.
constexpr int kHexOffsets[20][3] = {
    {0, 0, 0}, {2, 0, 0}, {2, 2, 0}, {0, 2, 0}, {0, 0, 2}, {2, 0, 2}, {2, 2, 2}, {0, 2, 2}, {1, 0, 0}, {2, 1, 0},
    {1, 2, 0}, {0, 1, 0}, {1, 0, 2}, {2, 1, 2}, {1, 2, 2}, {0, 1, 2}, {0, 0, 1}, {2, 0, 1}, {2, 2, 1}, {0, 2, 1}};

void CheckDivisions(int n, const char* name) {
  if (n < 1) Fail(name, " = ", n, " must be >= 1");
}

}  // namespace

std::string ToothSetName(int tooth, std::string_view part) {
  return "TOOTH" + std::to_string(tooth) + "_" + flex::UpperName(part);
}

flex::FeMesh MakeGearFeMesh(const Gear& gear, const GearFeMeshSpec& s) {
  using flex::ElementType;
  // Validate.
  if (gear.internal()) Fail("internal gears are not supported (external spur and helical gears only)");
  if (s.type != ElementType::kHex8 && s.type != ElementType::kHex20) Fail("type must be kHex8 or kHex20");
  CheckDivisions(s.flank_divisions, "flank_divisions");
  CheckDivisions(s.fillet_divisions, "fillet_divisions");
  CheckDivisions(s.tooth_divisions, "tooth_divisions");
  CheckDivisions(s.root_layer_divisions, "root_layer_divisions");
  CheckDivisions(s.rim_divisions, "rim_divisions");
  CheckDivisions(s.face_divisions, "face_divisions");
  if (!(s.flank_bias >= 1) || !std::isfinite(s.flank_bias)) Fail("flank_bias = ", s.flank_bias, " must be >= 1");
  if (!(s.rim_bias > 0) || !std::isfinite(s.rim_bias)) Fail("rim_bias = ", s.rim_bias, " must be > 0");
  if (s.smoothing_iterations < 0) Fail("smoothing_iterations = ", s.smoothing_iterations, " must be >= 0");
  if (!(s.root_layer_depth_coef > 0)) Fail("root_layer_depth_coef = ", s.root_layer_depth_coef, " must be > 0");
  flex::ValidateMaterial(s.material);

  const int z_teeth = gear.teeth();
  const double mn = gear.spec().normal_module_m, b_face = gear.spec().face_width_m;
  const double r_f = gear.root_radius_m();
  const double r_base = r_f - s.root_layer_depth_coef * mn;
  const double half_pitch = kPi / z_teeth;
  if (!(s.bore_radius_m > 0 && s.bore_radius_m < r_base))
    Fail("bore_radius_m = ", s.bore_radius_m, " m must lie in (0, r_base = r_f - root_layer_depth_coef m_n = ", r_base,
         " m); root radius r_f = ", r_f, " m");

  // Web geometry: radii of the rim's inner edge and of the hub; axial web faces.
  const int q = s.type == ElementType::kHex20 ? 2 : 1;
  int n_side = 0;
  double r_rim_in = 0, z_web0 = 0, z_web1 = 0;
  if (s.web) {
    const GearWebSpec& w = *s.web;
    CheckDivisions(w.web_radial_divisions, "web.web_radial_divisions");
    CheckDivisions(w.hub_radial_divisions, "web.hub_radial_divisions");
    CheckDivisions(w.web_axial_divisions, "web.web_axial_divisions");
    r_rim_in = r_f - w.rim_thickness_m;
    if (!(w.rim_thickness_m > r_f - r_base))
      Fail("web.rim_thickness_m = ", w.rim_thickness_m, " m must exceed the root layer depth ", r_f - r_base, " m");
    if (!(w.hub_radius_m > s.bore_radius_m && w.hub_radius_m < r_rim_in))
      Fail("web.hub_radius_m = ", w.hub_radius_m, " m must lie in (bore_radius_m = ", s.bore_radius_m,
           " m, r_f - web.rim_thickness_m = ", r_rim_in, " m)");
    if (!(w.web_thickness_m > 0 && w.web_thickness_m < b_face))
      Fail("web.web_thickness_m = ", w.web_thickness_m, " m must lie in (0, face width ", b_face, " m)");
    const int rest = s.face_divisions - w.web_axial_divisions;
    if (rest < 2 || rest % 2 != 0)
      Fail("face_divisions - web.web_axial_divisions = ", rest,
           " must be even and >= 2 (divisions on both sides of the web)");
    n_side = rest / 2;
    z_web0 = 0.5 * (b_face - w.web_thickness_m);
    z_web1 = 0.5 * (b_face + w.web_thickness_m);
  }

  // 1-D distributions (q points per element edge).
  const std::vector<double> across = Refine(Symmetric(s.tooth_divisions, s.flank_bias), q);
  const std::vector<double> layer = Refine(Geometric(s.root_layer_divisions, 1.0), q);  // r_base -> r_f
  std::vector<double> radii;  // bore -> r_base
  int web_row0 = 0, web_row1 = 0;  // element rows of the web in the rim block
  if (!s.web) {
    for (double t : Refine(Geometric(s.rim_divisions, 1.0 / s.rim_bias), q))
      radii.push_back(s.bore_radius_m + (r_base - s.bore_radius_m) * t);
  } else {
    const GearWebSpec& w = *s.web;
    radii = Concat({{Refine(Geometric(w.hub_radial_divisions, 1.0), q), {s.bore_radius_m, w.hub_radius_m}},
                    {Refine(Geometric(w.web_radial_divisions, 1.0), q), {w.hub_radius_m, r_rim_in}},
                    {Refine(Geometric(s.rim_divisions, 1.0 / s.rim_bias), q), {r_rim_in, r_base}}});
    web_row0 = w.hub_radial_divisions;
    web_row1 = web_row0 + w.web_radial_divisions;
  }

  // Root curve of the minus side, space middle (profile parameter 0) to the form circle (2):
  // half root arc and fillet, tangent to each other; nodes are spaced evenly in arc length, found
  // on a fine sampling and evaluated exactly at the interpolated profile parameter.
  constexpr int kSamples = 4000;
  std::vector<double> root_length(kSamples + 1, 0.0);
  for (int k = 1; k <= kSamples; ++k)
    root_length[k] = root_length[k - 1] +
                     (gear.ProfileAt(2.0 * k / kSamples).p - gear.ProfileAt(2.0 * (k - 1) / kSamples).p).norm();
  auto root_parameter = [&](double fraction) {
    const double target = fraction * root_length.back();
    const int k = std::clamp(static_cast<int>(std::lower_bound(root_length.begin(), root_length.end(), target) -
                                              root_length.begin()),
                             1, kSamples);
    const double w = (target - root_length[k - 1]) / (root_length[k] - root_length[k - 1]);
    return 2.0 * (k - 1 + w) / kSamples;
  };

  // Tooth block T: minus side i = 0, plus side i = ni (the mirror image); j from r_base up to the
  // tip: radial segment at the space middle (-+pi/z), root curve, involute.
  const int j_root = q * s.root_layer_divisions, j_flank = j_root + q * s.fillet_divisions;
  Block tooth(q * s.tooth_divisions, j_flank + q * s.flank_divisions);
  std::vector<Vec2> left(tooth.nj + 1), right(tooth.nj + 1);
  std::vector<std::uint8_t> left_tag(tooth.nj + 1, 0);
  for (int j = 0; j <= tooth.nj; ++j) {
    if (j <= j_root) {
      left[j] = Polar(r_base + (r_f - r_base) * layer[j], -half_pitch);
      if (j == j_root) left_tag[j] = kRoot;
    } else if (j < j_flank) {
      const double profile_s = root_parameter(static_cast<double>(j - j_root) / (j_flank - j_root));
      left[j] = gear.ProfileAt(profile_s).p;
      left_tag[j] = profile_s < 1 ? kRoot : kFilletMinus;
    } else {
      left[j] = gear.ProfileAt(2 + static_cast<double>(j - j_flank) / (tooth.nj - j_flank)).p;
      left_tag[j] = j == j_flank ? kFlankMinus | kFilletMinus : kFlankMinus;
    }
    right[j] = Vec2(left[j].x(), -left[j].y());
  }
  std::vector<Vec2> bottom(tooth.ni + 1), top(tooth.ni + 1);
  std::vector<double> base_angles(tooth.ni + 1);
  for (int i = 0; i <= tooth.ni; ++i) {
    base_angles[i] = -half_pitch + 2 * half_pitch * across[i];
    bottom[i] = Polar(r_base, base_angles[i]);
    top[i] = gear.ProfileAt(3 + across[i]).p;
  }
  // Computational coordinate along the sides: normalized arc length.
  std::vector<double> eta(tooth.nj + 1, 0.0);
  for (int j = 1; j <= tooth.nj; ++j) eta[j] = eta[j - 1] + (left[j] - left[j - 1]).norm();
  for (double& e : eta) e /= eta.back();
  // Coons patch of the four sides, then Winslow smoothing.
  for (int j = 0; j <= tooth.nj; ++j)
    for (int i = 0; i <= tooth.ni; ++i) {
      const double u = across[i], v = eta[j];
      tooth.at(i, j) = (1 - u) * left[j] + u * right[j] + (1 - v) * bottom[i] + v * top[i] -
                       ((1 - u) * (1 - v) * bottom[0] + u * (1 - v) * bottom[tooth.ni] + (1 - u) * v * top[0] +
                        u * v * top[tooth.ni]);
    }
  for (int j = 0; j <= tooth.nj; ++j) tooth.at(0, j) = left[j], tooth.at(tooth.ni, j) = right[j];
  for (int i = 0; i <= tooth.ni; ++i) tooth.at(i, 0) = bottom[i], tooth.at(i, tooth.nj) = top[i];
  Winslow(tooth, across, eta, s.smoothing_iterations, 1e-13 * r_f);
  // Mirror the side tags (minus -> plus); the tip.
  for (int j = 0; j <= tooth.nj; ++j) {
    const std::uint8_t t = left_tag[j];
    tooth.tag[tooth.Index(0, j)] = t;
    tooth.tag[tooth.Index(tooth.ni, j)] =
        (t & kRoot) | (t & kFlankMinus ? kFlankPlus : 0) | (t & kFilletMinus ? kFilletPlus : 0);
  }
  for (int i = 0; i <= tooth.ni; ++i) tooth.tag[tooth.Index(i, tooth.nj)] |= kTip;

  // Rim block R (polar, bore..r_base), matching T's base.
  std::vector<Block> blocks = {tooth, PolarBlock(base_angles, radii)};
  Block& rim = blocks[1];
  for (int i = 0; i <= rim.ni; ++i) rim.tag[rim.Index(i, 0)] |= kBore;
  rim.web_row.assign(rim.nj / q, 0);
  if (s.web)
    for (int r = web_row0; r < web_row1; ++r) rim.web_row[r] = 1;

  // Transverse mesh of the whole gear: rotated sector copies, points on shared lines merged.
  PointMerger merger(1e-9 * r_f);
  std::vector<Cell> cells;
  for (int k = 0; k < z_teeth; ++k) {
    const double angle = 2 * kPi * k / z_teeth;
    for (const Block& blk : blocks) {
      std::vector<int> index(blk.p.size());
      for (std::size_t n = 0; n < blk.p.size(); ++n) index[n] = merger.Add(Rotate(blk.p[n], angle), blk.tag[n], k);
      for (int cj = 0; cj < blk.nj / q; ++cj)
        for (int ci = 0; ci < blk.ni / q; ++ci) {
          Cell c;
          c.web = !blk.web_row.empty() && blk.web_row[cj];
          // Counter-clockwise (a, b) axes: i, j or swapped, from the signed area of the corners.
          const Vec2 d_i = blk.p[blk.Index(q * ci + q, q * cj)] - blk.p[blk.Index(q * ci, q * cj)];
          const Vec2 d_j = blk.p[blk.Index(q * ci, q * cj + q)] - blk.p[blk.Index(q * ci, q * cj)];
          const bool swap = d_i.x() * d_j.y() - d_i.y() * d_j.x() < 0;
          for (int a = 0; a <= q; ++a)
            for (int bb = 0; bb <= q; ++bb)
              c.p[a][bb] = swap ? index[blk.Index(q * ci + bb, q * cj + a)] : index[blk.Index(q * ci + a, q * cj + bb)];
          cells.push_back(c);
        }
    }
  }

  // Axial levels (q per element layer) and which element layers belong to the web.
  std::vector<double> z_levels;
  std::vector<std::uint8_t> web_layer;
  if (!s.web) {
    for (double t : Refine(Geometric(s.face_divisions, 1.0), q)) z_levels.push_back(b_face * t);
    web_layer.assign(s.face_divisions, 1);
  } else {
    z_levels = Concat({{Refine(Geometric(n_side, 1.0), q), {0.0, z_web0}},
                       {Refine(Geometric(s.web->web_axial_divisions, 1.0), q), {z_web0, z_web1}},
                       {Refine(Geometric(n_side, 1.0), q), {z_web1, b_face}}});
    web_layer.assign(s.face_divisions, 0);
    for (int l = n_side; l < n_side + s.web->web_axial_divisions; ++l) web_layer[l] = 1;
  }
  const int n_levels = static_cast<int>(z_levels.size());

  // Nodes (created on first use, ids 1, 2, ...) and elements.
  flex::FeMesh mesh;
  const std::vector<Vec2>& points = merger.points();
  const double twist = gear.twist_per_length();
  std::vector<int> node_of(points.size() * n_levels, -1);
  std::vector<int> face_min, face_max, bore, root;
  std::vector<std::vector<int>> tooth_sets(static_cast<std::size_t>(z_teeth) * kToothParts);
  auto node = [&](int p, int level) {
    int& id = node_of[static_cast<std::size_t>(p) * n_levels + level];
    if (id < 0) {
      const double z = z_levels[level];
      const Vec2 xy = Rotate(points[p], twist * z);
      const int index = mesh.AddNode(mesh.num_nodes() + 1, Eigen::Vector3d(xy.x(), xy.y(), z));
      id = index + 1;
      if (level == 0) face_min.push_back(index);
      if (level == n_levels - 1) face_max.push_back(index);
      const std::uint8_t tag = merger.tags()[p];
      if (tag & kBore) bore.push_back(index);
      if (tag & kRoot) root.push_back(index);
      for (int part = 0; part < kToothParts; ++part)
        if (tag & kToothTags[part]) tooth_sets[merger.tooth()[p] * kToothParts + part].push_back(index);
    }
    return id;
  };
  const int n_el = flex::NodeCount(s.type);
  std::vector<int> ids(n_el), web_elements;
  for (int layer_index = 0; layer_index < s.face_divisions; ++layer_index)
    for (const Cell& c : cells) {
      if (c.web && !web_layer[layer_index]) continue;
      for (int a = 0; a < n_el; ++a)
        ids[a] = node(c.p[kHexOffsets[a][0] * q / 2][kHexOffsets[a][1] * q / 2],
                      q * layer_index + kHexOffsets[a][2] * q / 2);
      const int e = mesh.AddElement(mesh.num_elements() + 1, s.type, ids);
      if (c.web) web_elements.push_back(e);
    }

  // Sets and material.
  std::vector<int> all(mesh.num_nodes());
  for (int n = 0; n < mesh.num_nodes(); ++n) all[n] = n;
  mesh.AddToNodeSet("NALL", all);
  mesh.AddToNodeSet("BORE", bore);
  mesh.AddToNodeSet("ROOT", root);
  mesh.AddToNodeSet("FACE_ZMIN", face_min);
  mesh.AddToNodeSet("FACE_ZMAX", face_max);
  for (int k = 0; k < z_teeth; ++k)
    for (int part = 0; part < kToothParts; ++part)
      mesh.AddToNodeSet(ToothSetName(k, kToothPartNames[part]), tooth_sets[k * kToothParts + part]);
  if (s.web) mesh.AddToElementSet("WEB", web_elements);
  mesh.AssignMaterialToAll(s.material);
  return mesh;
}

std::vector<int> SelectNodesOnCylinder(const flex::FeMesh& mesh, const Eigen::Vector3d& p_axis_m,
                                       const Eigen::Vector3d& axis, double radius_m, double tolerance_m) {
  if (!(axis.norm() > 0)) throw std::invalid_argument("SelectNodesOnCylinder: axis must be nonzero");
  if (!(radius_m >= 0) || !(tolerance_m >= 0))
    throw std::invalid_argument("SelectNodesOnCylinder: radius_m and tolerance_m must be >= 0");
  const Eigen::Vector3d a = axis.normalized();
  std::vector<int> out;
  for (int n = 0; n < mesh.num_nodes(); ++n)
    if (std::abs((mesh.positions()[n] - p_axis_m).cross(a).norm() - radius_m) <= tolerance_m) out.push_back(n);
  return out;
}

std::vector<int> SelectNodesOnPlane(const flex::FeMesh& mesh, const Eigen::Vector3d& p_plane_m,
                                    const Eigen::Vector3d& normal, double tolerance_m) {
  if (!(normal.norm() > 0)) throw std::invalid_argument("SelectNodesOnPlane: normal must be nonzero");
  if (!(tolerance_m >= 0)) throw std::invalid_argument("SelectNodesOnPlane: tolerance_m must be >= 0");
  const Eigen::Vector3d nrm = normal.normalized();
  std::vector<int> out;
  for (int n = 0; n < mesh.num_nodes(); ++n)
    if (std::abs((mesh.positions()[n] - p_plane_m).dot(nrm)) <= tolerance_m) out.push_back(n);
  return out;
}

}  // namespace orrery::gears
