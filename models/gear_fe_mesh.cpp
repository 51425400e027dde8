#include "models/gear_fe_mesh.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <sstream>
#include <stdexcept>
#include <unordered_map>
#include <utility>

#include "models/tooth_fault_geometry.h"

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
  const Vec2& at(int i, int j) const { return p[Index(i, j)]; }
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

namespace {

// Counts and distributions shared by every tooth block (q lattice points per element edge).
struct ToothLayout {
  int q = 1;
  int root_layer = 0, fillet = 0, flank = 0;  // element divisions of the side pieces
  double r_base = 0, half_pitch = 0;
  std::vector<double> across, layer;         // (q ni + 1), (q root_layer + 1)
  int smoothing = 0;
};

// Arc length of the profile over s in [0, 3] (minus side: space middle to the tip), sampled
// finely, and its inverse: nodes are spaced evenly in arc length along the root curve.
class ProfileLength {
 public:
  explicit ProfileLength(const Gear& gear) : gear_(gear), length_(kSamples + 1, 0.0) {
    for (int k = 1; k <= kSamples; ++k)
      length_[k] = length_[k - 1] + (gear.ProfileAt(S(k)).p - gear.ProfileAt(S(k - 1)).p).norm();
  }
  double At(double s) const {
    const double x = std::clamp(s / 3.0 * kSamples, 0.0, double(kSamples));
    const int k = std::min(static_cast<int>(x), kSamples - 1);
    return length_[k] + (x - k) * (length_[k + 1] - length_[k]);
  }
  // s at arc length l.
  double Parameter(double l) const {
    const int k = std::clamp(static_cast<int>(std::lower_bound(length_.begin(), length_.end(), l) - length_.begin()), 1,
                             kSamples);
    const double w = std::clamp((l - length_[k - 1]) / (length_[k] - length_[k - 1]), 0.0, 1.0);
    return S(k - 1) + w * (S(k) - S(k - 1));
  }

 private:
  static constexpr int kSamples = 6000;
  static double S(int k) { return 3.0 * k / kSamples; }
  const Gear& gear_;
  std::vector<double> length_;
};

// The minus side of a tooth block from the space middle at r_base up to the tip: points and
// tags, with the row of a fault point (-1: none).
struct SideCurve {
  std::vector<Vec2> points;
  std::vector<std::uint8_t> tags;
  int fault_row = -1;
};

std::uint8_t MinusTag(double s) {
  if (s < 1 - 1e-12) return kRoot;
  if (std::abs(s - 2) < 1e-9) return kFlankMinus | kFilletMinus;
  if (s < 2) return kFilletMinus;
  return kFlankMinus;
}

// Side curve: radial root layer, then pieces of the profile [0, 2] (root curve, even in arc
// length) with `fillet` elements and [2, 3] (involute, even in s) with `flank` elements. A fault
// point s_f splits the piece it lies in, in proportion to arc length (at least one element each;
// a one-element piece becomes two).
SideCurve MakeSideCurve(const Gear& gear, const ToothLayout& L, const ProfileLength& len, double s_fault) {
  SideCurve side;
  const double r_f = gear.root_radius_m();
  for (int j = 0; j <= L.q * L.root_layer; ++j) {
    side.points.push_back(Polar(L.r_base + (r_f - L.r_base) * L.layer[j], -L.half_pitch));
    side.tags.push_back(j == L.q * L.root_layer ? kRoot : 0);
  }
  struct Piece { double s0, s1; int elements; bool by_length; };
  std::vector<Piece> pieces = {{0, 2, L.fillet, true}, {2, 3, L.flank, false}};
  if (s_fault >= 0) {
    for (size_t k = 0; k < pieces.size(); ++k) {
      Piece p = pieces[k];
      if (!(s_fault > p.s0 + 1e-9 && s_fault < p.s1 - 1e-9)) continue;
      const int n = std::max(2, p.elements);
      const double f = p.by_length ? (len.At(s_fault) - len.At(p.s0)) / (len.At(p.s1) - len.At(p.s0))
                                   : (s_fault - p.s0) / (p.s1 - p.s0);
      // Within 0.3 of an element of an inner piece boundary: that boundary's row (no sliver).
      if (f * p.elements < 0.3 && p.s0 > 0) {
        s_fault = p.s0;
        break;
      }
      if ((1 - f) * p.elements < 0.3) {
        if (p.s1 >= 3) Fail("a fault point within 0.3 of an element of the tip: refine flank_divisions");
        s_fault = p.s1;
        break;
      }
      const int n_low = std::clamp(static_cast<int>(std::lround(n * f)), 1, n - 1);
      pieces[k] = {p.s0, s_fault, n_low, p.by_length};
      pieces.insert(pieces.begin() + k + 1, Piece{s_fault, p.s1, n - n_low, p.by_length});
      break;
    }
  }
  for (const Piece& p : pieces) {
    if (s_fault >= 0 && std::abs(p.s0 - s_fault) < 1e-9) side.fault_row = static_cast<int>(side.points.size()) - 1;
    const int m = L.q * p.elements;
    for (int j = 1; j <= m; ++j) {
      const double t = static_cast<double>(j) / m;
      const double sv = p.by_length ? len.Parameter(len.At(p.s0) + t * (len.At(p.s1) - len.At(p.s0)))
                                    : p.s0 + t * (p.s1 - p.s0);
      const double s_node = j == m ? p.s1 : sv;
      side.points.push_back(gear.ProfileAt(s_node).p);
      side.tags.push_back(MinusTag(s_node));
    }
  }
  if (s_fault >= 0 && side.fault_row < 0) side.fault_row = static_cast<int>(side.points.size()) - 1;
  return side;
}

// Coons patch of a block's four sides (already in place), then Winslow smoothing.
void FillBlock(Block& b, const std::vector<double>& across, int smoothing, double tol) {
  std::vector<double> eta(b.nj + 1, 0.0);
  for (int j = 1; j <= b.nj; ++j) eta[j] = eta[j - 1] + (b.at(0, j) - b.at(0, j - 1)).norm();
  for (double& e : eta) e /= eta.back();
  const Vec2 c00 = b.at(0, 0), c10 = b.at(b.ni, 0), c01 = b.at(0, b.nj), c11 = b.at(b.ni, b.nj);
  for (int j = 1; j < b.nj; ++j)
    for (int i = 1; i < b.ni; ++i) {
      const double u = across[i], v = eta[j];
      b.at(i, j) = (1 - u) * b.at(0, j) + u * b.at(b.ni, j) + (1 - v) * b.at(i, 0) + v * b.at(i, b.nj) -
                   ((1 - u) * (1 - v) * c00 + u * (1 - v) * c10 + (1 - u) * v * c01 + u * v * c11);
    }
  Winslow(b, across, eta, smoothing, tol);
}

// The fault row of a tooth block: its points from the minus side (i = 0) to the plus side.
// Broken tooth: the chord between the two break points. Crack (from the minus side): the
// straight crack from the side point A to the tip C = A + q d, d = (-cos nu, sin nu) (towards
// the root and the centre line), then straight on to the plus side's point; the crack tip is the
// element corner nearest to |AC| / (|AC| + |CB|) of the across distribution (crack_tip_column).
std::vector<Vec2> FaultRow(const Vec2& a, const Vec2& b, const ToothFaultSpec& fault, const std::vector<double>& across,
                           int q, int* crack_tip_column) {
  const int ni = static_cast<int>(across.size()) - 1;
  std::vector<Vec2> row(ni + 1);
  if (fault.kind != ToothFaultSpec::Kind::kRootCrack) {
    for (int i = 0; i <= ni; ++i) row[i] = a + across[i] * (b - a);
    return row;
  }
  const double q_max = std::max(fault.crack_depth_m, fault.crack_end_depth_m.value_or(0.0));
  const Vec2 c = a + q_max * Vec2(-std::cos(fault.crack_angle_rad), std::sin(fault.crack_angle_rad));
  const double f = (c - a).norm() / ((c - a).norm() + (b - c).norm());
  int best = q;
  for (int i = q; i < ni; i += q)
    if (std::abs(across[i] - f) < std::abs(across[best] - f)) best = i;
  *crack_tip_column = best;
  for (int i = 0; i <= ni; ++i)
    row[i] = i <= best ? a + across[i] / across[best] * (c - a)
                       : c + (across[i] - across[best]) / (1 - across[best]) * (b - c);
  return row;
}

// A faulted tooth block: one lattice whose row side.fault_row is the fault row, the parts below
// and above filled separately.
Block MakeFaultedToothBlock(const SideCurve& side, const Block& healthy_bottom_top, const std::vector<Vec2>& row,
                            const ToothLayout& L, double tol) {
  const int ni = healthy_bottom_top.ni, nj = static_cast<int>(side.points.size()) - 1, jf = side.fault_row;
  Block lower(ni, jf), upper(ni, nj - jf);
  for (int j = 0; j <= jf; ++j) {
    lower.at(0, j) = side.points[j];
    lower.at(ni, j) = Vec2(side.points[j].x(), -side.points[j].y());
  }
  for (int j = jf; j <= nj; ++j) {
    upper.at(0, j - jf) = side.points[j];
    upper.at(ni, j - jf) = Vec2(side.points[j].x(), -side.points[j].y());
  }
  for (int i = 0; i <= ni; ++i) {
    lower.at(i, 0) = healthy_bottom_top.at(i, 0);
    lower.at(i, jf) = upper.at(i, 0) = row[i];
    upper.at(i, nj - jf) = healthy_bottom_top.at(i, healthy_bottom_top.nj);
  }
  FillBlock(lower, L.across, L.smoothing, tol);
  FillBlock(upper, L.across, L.smoothing, tol);
  Block b(ni, nj);
  for (int j = 0; j <= nj; ++j)
    for (int i = 0; i <= ni; ++i) b.at(i, j) = j <= jf ? lower.at(i, j) : upper.at(i, j - jf);
  return b;
}

// Tags of a tooth block's sides (minus side's tags mirrored to the plus side) and tip row.
void TagToothBlock(Block& b, const std::vector<std::uint8_t>& left_tags) {
  for (int j = 0; j <= b.nj; ++j) {
    const std::uint8_t t = left_tags[j];
    b.tag[b.Index(0, j)] = t;
    b.tag[b.Index(b.ni, j)] = (t & kRoot) | (t & kFlankMinus ? kFlankPlus : 0) | (t & kFilletMinus ? kFilletPlus : 0);
  }
  for (int i = 0; i <= b.ni; ++i) b.tag[b.Index(i, b.nj)] |= kTip;
}

// Mirror image y -> -y of a block (i reversed), tags swapped minus <-> plus.
Block MirrorBlock(const Block& b) {
  Block m(b.ni, b.nj);
  auto swap_tag = [](std::uint8_t t) {
    std::uint8_t o = t & (kBore | kRoot | kTip);
    if (t & kFlankMinus) o |= kFlankPlus;
    if (t & kFlankPlus) o |= kFlankMinus;
    if (t & kFilletMinus) o |= kFilletPlus;
    if (t & kFilletPlus) o |= kFilletMinus;
    return o;
  };
  for (int j = 0; j <= b.nj; ++j)
    for (int i = 0; i <= b.ni; ++i) {
      const Vec2 p = b.p[b.Index(b.ni - i, j)];
      m.at(i, j) = Vec2(p.x(), -p.y());
      m.tag[m.Index(i, j)] = swap_tag(b.tag[b.Index(b.ni - i, j)]);
    }
  return m;
}

// The tooth block of one tooth (healthy: fault == nullptr). For a fault: the row index of the
// fault row and, for a crack, the lattice points of the crack (column i, row fault_row) from the
// mouth (i = 0 on the damaged side) to the tip with their distance from the mouth.
struct ToothBlock {
  Block block{0, 0};
  int fault_row = -1;
  std::vector<int> crack_columns;     // lattice columns of the crack, mouth first
  std::vector<double> crack_distance; // m from the mouth
};

ToothBlock MakeToothBlock(const Gear& gear, const ToothLayout& L, const ProfileLength& len,
                          const ToothFaultSpec* fault) {
  const double tol = 1e-13 * gear.root_radius_m();
  // The fault point on the minus side: the break radius, or the crack's mouth on the fillet at
  // the tooth beam's root half thickness (mesh_stiffness.h).
  double s_fault = -1;
  if (fault && fault->kind == ToothFaultSpec::Kind::kBrokenTooth) s_fault = ProfileParameterAtRadius(gear, BreakRadius(gear, *fault), false);
  if (fault && fault->kind == ToothFaultSpec::Kind::kRootCrack) {
    const double h = BeamRootHalfThickness(gear);
    double a = 1.0, b = 2.0;
    auto f = [&](double s) { return -gear.ProfileAt(s).p.y() - h; };
    if (f(a) * f(b) > 0) {
      s_fault = std::abs(f(a)) < std::abs(f(b)) ? 1.0 : 2.0;
    } else {
      for (int it = 0; it < 100; ++it) (f(0.5 * (a + b)) * f(a) > 0 ? a : b) = 0.5 * (a + b);
      s_fault = 0.5 * (a + b);
    }
  }
  const SideCurve side = MakeSideCurve(gear, L, len, s_fault);
  const int ni = static_cast<int>(L.across.size()) - 1, nj = static_cast<int>(side.points.size()) - 1;
  Block frame(ni, nj);  // bottom (r_base arc) and top (tip arc) rows
  for (int i = 0; i <= ni; ++i) {
    frame.at(i, 0) = Polar(L.r_base, -L.half_pitch + 2 * L.half_pitch * L.across[i]);
    frame.at(i, nj) = gear.ProfileAt(3 + L.across[i]).p;
  }
  ToothBlock out;
  if (fault == nullptr) {
    out.block = frame;
    for (int j = 0; j <= nj; ++j) {
      out.block.at(0, j) = side.points[j];
      out.block.at(ni, j) = Vec2(side.points[j].x(), -side.points[j].y());
    }
    FillBlock(out.block, L.across, L.smoothing, tol);
  } else {
    const Vec2 a = side.points[side.fault_row], b(a.x(), -a.y());
    int tip = -1;
    const std::vector<Vec2> row = FaultRow(a, b, *fault, L.across, L.q, &tip);
    out.block = MakeFaultedToothBlock(side, frame, row, L, tol);
    out.fault_row = side.fault_row;
    for (int i = 0; tip >= 0 && i <= tip; ++i) {
      out.crack_columns.push_back(i);
      out.crack_distance.push_back((row[i] - row[0]).norm());
    }
  }
  TagToothBlock(out.block, side.tags);
  // A crack on the plus flank: the mirror image (columns counted from the plus side).
  if (fault && fault->kind == ToothFaultSpec::Kind::kRootCrack && fault->flank == ToothFaultSpec::Flank::kPlus) {
    out.block = MirrorBlock(out.block);
    for (int& i : out.crack_columns) i = ni - i;
  }
  return out;
}

// Folded cells (corner cross products of both signs) of a block: the fault did not fit the mesh.
bool BlockFolds(const Block& b, int q) {
  for (int cj = 0; cj < b.nj / q; ++cj)
    for (int ci = 0; ci < b.ni / q; ++ci) {
      const Vec2 p[4] = {b.p[b.Index(q * ci, q * cj)], b.p[b.Index(q * ci + q, q * cj)],
                         b.p[b.Index(q * ci + q, q * cj + q)], b.p[b.Index(q * ci, q * cj + q)]};
      int pos = 0, neg = 0;
      for (int k = 0; k < 4; ++k) {
        const Vec2 u = p[(k + 1) % 4] - p[k], v = p[(k + 3) % 4] - p[k];
        const double c = u.x() * v.y() - u.y() * v.x();
        (c > 0 ? pos : neg) += 1;
      }
      if (pos && neg) return true;
    }
  return false;
}

}  // namespace

namespace {

// Nodes, elements and sets of the extruded mesh (cells x layers). Faulted teeth: cells above the
// fault row are left out inside a break's axial range; across a crack (the lattice points of the
// crack row nearer the mouth than the local depth q(z), inside the crack's axial range) they use
// duplicated nodes, so the two faces of the crack share no node and carry no stiffness across.
flex::FeMesh AssembleGearFeMesh(const Gear& gear, const GearFeMeshSpec& s, const PointMerger& merger,
                                const std::vector<Cell>& cells, const std::vector<int>& cell_tooth,
                                const std::vector<std::uint8_t>& cell_above,
                                const std::vector<std::vector<std::pair<int, double>>>& crack_points,
                                const std::vector<std::vector<int>>& fracture_points,
                                const std::vector<const ToothFaultSpec*>& tooth_fault, const std::vector<double>& z_levels,
                                const std::vector<std::uint8_t>& web_layer, int q) {
  const int z_teeth = gear.teeth(), n_levels = static_cast<int>(z_levels.size());
  const double b_face = gear.spec().face_width_m, tol = 1e-9 * b_face;
  flex::FeMesh mesh;
  const std::vector<Vec2>& points = merger.points();
  const double twist = gear.twist_per_length();
  std::vector<int> node_of(points.size() * n_levels, -1);
  std::vector<int> face_min, face_max, bore, root;
  std::vector<std::vector<int>> tooth_sets(static_cast<std::size_t>(z_teeth) * kToothParts);
  // Registers a new node at (point p, level) in the sets its point belongs to.
  auto add_node = [&](int p, int level) {
    const double z = z_levels[level];
    const Vec2 xy = Rotate(points[p], twist * z);
    const int index = mesh.AddNode(mesh.num_nodes() + 1, Eigen::Vector3d(xy.x(), xy.y(), z));
    if (level == 0) face_min.push_back(index);
    if (level == n_levels - 1) face_max.push_back(index);
    const std::uint8_t tag = merger.tags()[p];
    if (tag & kBore) bore.push_back(index);
    if (tag & kRoot) root.push_back(index);
    for (int part = 0; part < kToothParts; ++part)
      if (tag & kToothTags[part]) tooth_sets[merger.tooth()[p] * kToothParts + part].push_back(index);
    return index;
  };
  auto node = [&](int p, int level) {
    int& id = node_of[static_cast<std::size_t>(p) * n_levels + level];
    if (id < 0) id = add_node(p, level) + 1;
    return id;
  };
  // Crack faces: the open points per tooth, and their duplicates.
  std::vector<std::unordered_map<int, double>> crack_distance(z_teeth);
  for (int k = 0; k < z_teeth; ++k)
    for (const auto& [p, d] : crack_points[k]) crack_distance[k][p] = d;
  std::unordered_map<long long, int> duplicate;
  std::vector<std::vector<int>> crack_sets(z_teeth), fracture_sets(z_teeth);
  auto open_crack = [&](int k, int p, int level) {
    const ToothFaultSpec* f = tooth_fault[k];
    if (f == nullptr || f->kind != ToothFaultSpec::Kind::kRootCrack) return false;
    auto it = crack_distance[k].find(p);
    if (it == crack_distance[k].end()) return false;
    // Inside the crack's axial range (its edges are crack fronts unless they are end faces).
    const double z = z_levels[level];
    const auto [za, zb] = FaultAxialRange(gear, *f);
    const bool inside = (z > za + tol || za <= tol) && (z < zb - tol || zb >= b_face - tol);
    return inside && it->second < CrackDepthAt(gear, *f, std::clamp(z, za, zb)) - tol;
  };
  auto upper_node = [&](int k, int p, int level) {
    if (!open_crack(k, p, level)) return node(p, level);
    auto [it, fresh] = duplicate.try_emplace(static_cast<long long>(p) * n_levels + level, 0);
    if (fresh) {
      const int original = node(p, level) - 1;
      it->second = add_node(p, level) + 1;
      crack_sets[k].insert(crack_sets[k].end(), {original, it->second - 1});
    }
    return it->second;
  };
  const int n_el = flex::NodeCount(s.type);
  const int n_layers = (n_levels - 1) / q;
  std::vector<int> ids(n_el), web_elements;
  for (int layer_index = 0; layer_index < n_layers; ++layer_index) {
    const double z_mid = 0.5 * (z_levels[q * layer_index] + z_levels[q * layer_index + q]);
    for (std::size_t ci = 0; ci < cells.size(); ++ci) {
      const Cell& c = cells[ci];
      if (c.web && !web_layer[layer_index]) continue;
      const int k = cell_tooth[ci];
      const ToothFaultSpec* f = k >= 0 ? tooth_fault[k] : nullptr;
      if (f && cell_above[ci] && f->kind == ToothFaultSpec::Kind::kBrokenTooth) {
        const auto [za, zb] = FaultAxialRange(gear, *f);
        if (z_mid > za && z_mid < zb && f->height_fraction > 0) continue;  // the broken part
      }
      const bool across_crack = f && cell_above[ci] && f->kind == ToothFaultSpec::Kind::kRootCrack;
      for (int a = 0; a < n_el; ++a) {
        const int p = c.p[kHexOffsets[a][0] * q / 2][kHexOffsets[a][1] * q / 2];
        const int level = q * layer_index + kHexOffsets[a][2] * q / 2;
        ids[a] = across_crack ? upper_node(k, p, level) : node(p, level);
      }
      const int e = mesh.AddElement(mesh.num_elements() + 1, s.type, ids);
      if (c.web) web_elements.push_back(e);
    }
  }
  // Fracture surfaces: the fault row's nodes that exist inside the broken axial range.
  for (int k = 0; k < z_teeth; ++k) {
    if (!tooth_fault[k] || tooth_fault[k]->kind != ToothFaultSpec::Kind::kBrokenTooth) continue;
    const auto [za, zb] = FaultAxialRange(gear, *tooth_fault[k]);
    for (int p : fracture_points[k])
      for (int level = 0; level < n_levels; ++level) {
        const int id = node_of[static_cast<std::size_t>(p) * n_levels + level];
        if (id > 0 && z_levels[level] >= za - tol && z_levels[level] <= zb + tol) fracture_sets[k].push_back(id - 1);
      }
  }

  // Sets and material.
  std::vector<int> all(mesh.num_nodes());
  for (int n = 0; n < mesh.num_nodes(); ++n) all[n] = n;
  mesh.AddToNodeSet("NALL", all);
  mesh.AddToNodeSet("BORE", bore);
  mesh.AddToNodeSet("ROOT", root);
  mesh.AddToNodeSet("FACE_ZMIN", face_min);
  mesh.AddToNodeSet("FACE_ZMAX", face_max);
  for (int k = 0; k < z_teeth; ++k) {
    for (int part = 0; part < kToothParts; ++part)
      mesh.AddToNodeSet(ToothSetName(k, kToothPartNames[part]), tooth_sets[k * kToothParts + part]);
    if (!crack_sets[k].empty()) mesh.AddToNodeSet(ToothSetName(k, "CRACK"), crack_sets[k]);
    if (!fracture_sets[k].empty()) mesh.AddToNodeSet(ToothSetName(k, "FRACTURE"), fracture_sets[k]);
  }
  if (s.web) mesh.AddToElementSet("WEB", web_elements);
  mesh.AssignMaterialToAll(s.material);
  return mesh;
}

}  // namespace

namespace {

// Validates the spec (MakeGearFeMesh's header) and its faults.
void ValidateFeSpec(const Gear& gear, const GearFeMeshSpec& s) {
  using flex::ElementType;
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
  ValidateToothFaults(gear, s.faults);
  for (size_t i = 0; i < s.faults.size(); ++i)
    for (size_t j = i + 1; j < s.faults.size(); ++j)
      if (s.faults[i].tooth == s.faults[j].tooth && s.faults[i].kind != ToothFaultSpec::Kind::kSpall &&
          s.faults[j].kind != ToothFaultSpec::Kind::kSpall)
        Fail("tooth ", s.faults[i].tooth, " carries a broken part and a crack: not modelled in the FE mesh");
  const double r_base = gear.root_radius_m() - s.root_layer_depth_coef * gear.spec().normal_module_m;
  if (!(s.bore_radius_m > 0 && s.bore_radius_m < r_base))
    Fail("bore_radius_m = ", s.bore_radius_m, " m must lie in (0, r_base = r_f - root_layer_depth_coef m_n = ", r_base,
         " m); root radius r_f = ", gear.root_radius_m(), " m");
}

// Radial and axial layout below the teeth: the rim block's radii (bore to r_base, q points per
// element edge) with the web's element rows, and the web's axial faces.
struct RimLayout {
  std::vector<double> radii;
  int web_row0 = 0, web_row1 = 0;
  double z_web0 = 0, z_web1 = 0;
};

RimLayout MakeRimLayout(const Gear& gear, const GearFeMeshSpec& s, double r_base, int q) {
  RimLayout out;
  const double r_f = gear.root_radius_m(), b_face = gear.spec().face_width_m;
  if (!s.web) {
    for (double t : Refine(Geometric(s.rim_divisions, 1.0 / s.rim_bias), q))
      out.radii.push_back(s.bore_radius_m + (r_base - s.bore_radius_m) * t);
    return out;
  }
  const GearWebSpec& w = *s.web;
  CheckDivisions(w.web_radial_divisions, "web.web_radial_divisions");
  CheckDivisions(w.hub_radial_divisions, "web.hub_radial_divisions");
  CheckDivisions(w.web_axial_divisions, "web.web_axial_divisions");
  const double r_rim_in = r_f - w.rim_thickness_m;
  if (!(w.rim_thickness_m > r_f - r_base))
    Fail("web.rim_thickness_m = ", w.rim_thickness_m, " m must exceed the root layer depth ", r_f - r_base, " m");
  if (!(w.hub_radius_m > s.bore_radius_m && w.hub_radius_m < r_rim_in))
    Fail("web.hub_radius_m = ", w.hub_radius_m, " m must lie in (bore_radius_m = ", s.bore_radius_m,
         " m, r_f - web.rim_thickness_m = ", r_rim_in, " m)");
  if (!(w.web_thickness_m > 0 && w.web_thickness_m < b_face))
    Fail("web.web_thickness_m = ", w.web_thickness_m, " m must lie in (0, face width ", b_face, " m)");
  const int rest = s.face_divisions - w.web_axial_divisions;
  if (rest < 2 || rest % 2 != 0)
    Fail("face_divisions - web.web_axial_divisions = ", rest, " must be even and >= 2 (divisions on both sides of the web)");
  out.z_web0 = 0.5 * (b_face - w.web_thickness_m);
  out.z_web1 = 0.5 * (b_face + w.web_thickness_m);
  out.radii = Concat({{Refine(Geometric(w.hub_radial_divisions, 1.0), q), {s.bore_radius_m, w.hub_radius_m}},
                      {Refine(Geometric(w.web_radial_divisions, 1.0), q), {w.hub_radius_m, r_rim_in}},
                      {Refine(Geometric(s.rim_divisions, 1.0 / s.rim_bias), q), {r_rim_in, r_base}}});
  out.web_row0 = w.hub_radial_divisions;
  out.web_row1 = out.web_row0 + w.web_radial_divisions;
  return out;
}

// The transverse mesh of the whole gear: rotated sector copies of the tooth and rim blocks,
// points on shared lines merged; cells of a faulted tooth above its fault row marked, the crack's
// and the fracture's lattice points noted.
struct TransverseMesh {
  PointMerger merger{1.0};
  std::vector<Cell> cells;
  std::vector<int> cell_tooth;           // sector of the cell's faulted tooth block (-1: other)
  std::vector<std::uint8_t> cell_above;  // above the fault row
  std::vector<std::vector<std::pair<int, double>>> crack_points;  // (merged point, distance)
  std::vector<std::vector<int>> fracture_points;
};

TransverseMesh MakeTransverseMesh(const Gear& gear, const ToothBlock& healthy, const std::vector<ToothBlock>& faulted,
                                  const std::vector<const ToothFaultSpec*>& tooth_fault, const Block& rim, int q) {
  const int z_teeth = gear.teeth();
  TransverseMesh t;
  t.merger = PointMerger(1e-9 * gear.root_radius_m());
  t.crack_points.resize(z_teeth);
  t.fracture_points.resize(z_teeth);
  for (int k = 0; k < z_teeth; ++k) {
    const double angle = 2 * kPi * k / z_teeth;
    const ToothBlock& tb = tooth_fault[k] ? faulted[k] : healthy;
    for (const Block* blk : std::array<const Block*, 2>{&tb.block, &rim}) {
      std::vector<int> index(blk->p.size());
      for (std::size_t n = 0; n < blk->p.size(); ++n) index[n] = t.merger.Add(Rotate(blk->p[n], angle), blk->tag[n], k);
      const bool tooth_block = blk == &tb.block && tooth_fault[k] != nullptr;
      if (tooth_block) {
        for (std::size_t c = 0; c < tb.crack_columns.size(); ++c)
          t.crack_points[k].push_back({index[blk->Index(tb.crack_columns[c], tb.fault_row)], tb.crack_distance[c]});
        if (tooth_fault[k]->kind == ToothFaultSpec::Kind::kBrokenTooth)
          for (int i = 0; i <= blk->ni; ++i) t.fracture_points[k].push_back(index[blk->Index(i, tb.fault_row)]);
      }
      for (int cj = 0; cj < blk->nj / q; ++cj)
        for (int ci = 0; ci < blk->ni / q; ++ci) {
          Cell c;
          c.web = !blk->web_row.empty() && blk->web_row[cj];
          // Counter-clockwise (a, b) axes: i, j or swapped, from the signed area of the corners.
          const Vec2 d_i = blk->p[blk->Index(q * ci + q, q * cj)] - blk->p[blk->Index(q * ci, q * cj)];
          const Vec2 d_j = blk->p[blk->Index(q * ci, q * cj + q)] - blk->p[blk->Index(q * ci, q * cj)];
          const bool swap = d_i.x() * d_j.y() - d_i.y() * d_j.x() < 0;
          for (int a = 0; a <= q; ++a)
            for (int bb = 0; bb <= q; ++bb)
              c.p[a][bb] = swap ? index[blk->Index(q * ci + bb, q * cj + a)] : index[blk->Index(q * ci + a, q * cj + bb)];
          t.cells.push_back(c);
          t.cell_tooth.push_back(tooth_block ? k : -1);
          t.cell_above.push_back(tooth_block && q * cj >= tb.fault_row);
        }
    }
  }
  return t;
}

// Axial levels (q per element layer): uniform face divisions (with a web: the web's layers
// centred), split at the faulted teeth's axial limits; which layers belong to the web.
std::pair<std::vector<double>, std::vector<std::uint8_t>> MakeAxialLevels(
    const Gear& gear, const GearFeMeshSpec& s, const RimLayout& rim, const std::vector<const ToothFaultSpec*>& tooth_fault,
    int q) {
  const double b_face = gear.spec().face_width_m;
  std::vector<double> z_edges;
  if (!s.web) {
    for (double t : Geometric(s.face_divisions, 1.0)) z_edges.push_back(b_face * t);
  } else {
    const int n_side = (s.face_divisions - s.web->web_axial_divisions) / 2;
    z_edges = Concat({{Geometric(n_side, 1.0), {0.0, rim.z_web0}},
                      {Geometric(s.web->web_axial_divisions, 1.0), {rim.z_web0, rim.z_web1}},
                      {Geometric(n_side, 1.0), {rim.z_web1, b_face}}});
  }
  for (const ToothFaultSpec* f : tooth_fault) {
    if (f == nullptr) continue;
    const auto [za, zb] = FaultAxialRange(gear, *f);
    z_edges.insert(z_edges.end(), {za, zb});
  }
  std::sort(z_edges.begin(), z_edges.end());
  z_edges.erase(std::unique(z_edges.begin(), z_edges.end(), [&](double x, double y) { return y - x < 1e-9 * b_face; }),
                z_edges.end());
  z_edges.back() = b_face;
  const int n_layers = static_cast<int>(z_edges.size()) - 1;
  std::vector<std::uint8_t> web_layer(n_layers, 1);
  if (s.web)
    for (int l = 0; l < n_layers; ++l) {
      const double zm = 0.5 * (z_edges[l] + z_edges[l + 1]);
      web_layer[l] = zm > rim.z_web0 && zm < rim.z_web1;
    }
  std::vector<double> z_levels;
  for (int l = 0; l < n_layers; ++l)
    for (int k = (l == 0 ? 0 : 1); k <= q; ++k) z_levels.push_back(z_edges[l] + (z_edges[l + 1] - z_edges[l]) * k / q);
  return {z_levels, web_layer};
}

}  // namespace

flex::FeMesh MakeGearFeMesh(const Gear& gear, const GearFeMeshSpec& s) {
  ValidateFeSpec(gear, s);
  const int z_teeth = gear.teeth(), q = s.type == flex::ElementType::kHex20 ? 2 : 1;
  const double r_base = gear.root_radius_m() - s.root_layer_depth_coef * gear.spec().normal_module_m;
  const RimLayout rim_layout = MakeRimLayout(gear, s, r_base, q);

  // 1-D distributions (q points per element edge) of the tooth blocks.
  ToothLayout L;
  L.q = q;
  L.root_layer = s.root_layer_divisions;
  L.fillet = s.fillet_divisions;
  L.flank = s.flank_divisions;
  L.r_base = r_base;
  L.half_pitch = kPi / z_teeth;
  L.across = Refine(Symmetric(s.tooth_divisions, s.flank_bias), q);
  L.layer = Refine(Geometric(s.root_layer_divisions, 1.0), q);  // r_base -> r_f
  L.smoothing = s.smoothing_iterations;

  // Tooth blocks T: the healthy one, and one per tooth with a break or a crack (minus side
  // i = 0, plus side i = ni; j from r_base up to the tip: radial segment at the space middle,
  // root curve, involute). Breaks and cracks change the mesh (a zero break or crack does not;
  // spalls, tens of micrometres deep, belong to the contact surface: gear_fe_mesh.h).
  const ProfileLength len(gear);
  const ToothBlock healthy = MakeToothBlock(gear, L, len, nullptr);
  std::vector<const ToothFaultSpec*> tooth_fault(z_teeth, nullptr);
  for (const ToothFaultSpec& f : s.faults) {
    const bool broken = f.kind == ToothFaultSpec::Kind::kBrokenTooth && f.height_fraction > 0 && f.face_fraction > 0;
    const bool cracked = f.kind == ToothFaultSpec::Kind::kRootCrack &&
                         std::max(f.crack_depth_m, f.crack_end_depth_m.value_or(0.0)) > 0;
    if (cracked && s.tooth_divisions < 2) Fail("a root crack needs tooth_divisions >= 2 (got ", s.tooth_divisions, ")");
    if (broken || cracked) tooth_fault[f.tooth] = &f;
  }
  std::vector<ToothBlock> faulted(z_teeth);
  for (int k = 0; k < z_teeth; ++k)
    if (tooth_fault[k]) {
      faulted[k] = MakeToothBlock(gear, L, len, tooth_fault[k]);
      if (BlockFolds(faulted[k].block, q))
        Fail("the ", KindName(tooth_fault[k]->kind), " on tooth ", k, " folds the tooth's elements (",
             DescribeToothFault(*tooth_fault[k]), "): refine the mesh or change the fault");
    }
  // Rim block R (polar, bore..r_base), matching T's base.
  std::vector<double> base_angles(healthy.block.ni + 1);
  for (int i = 0; i <= healthy.block.ni; ++i) base_angles[i] = -L.half_pitch + 2 * L.half_pitch * L.across[i];
  Block rim = PolarBlock(base_angles, rim_layout.radii);
  for (int i = 0; i <= rim.ni; ++i) rim.tag[rim.Index(i, 0)] |= kBore;
  rim.web_row.assign(rim.nj / q, 0);
  if (s.web)
    for (int r = rim_layout.web_row0; r < rim_layout.web_row1; ++r) rim.web_row[r] = 1;

  // The transverse mesh, the axial levels, then nodes, elements and sets.
  const TransverseMesh t = MakeTransverseMesh(gear, healthy, faulted, tooth_fault, rim, q);
  const auto [z_levels, web_layer] = MakeAxialLevels(gear, s, rim_layout, tooth_fault, q);
  return AssembleGearFeMesh(gear, s, t.merger, t.cells, t.cell_tooth, t.cell_above, t.crack_points, t.fracture_points,
                            tooth_fault, z_levels, web_layer, q);
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
