// Structured hex mesh of a generated gear (models/gear_fe_mesh.h). Oracles:
// - volume: face width x the transverse area of the gear's profile sampled finely by
//   Gear::SampleGearOutline (shoelace formula), minus the bore disc; the mesh's error is the
//   chord error of its boundary edges, O(h^2) for hex8, and must shrink under refinement;
// - quality: the Jacobian of every element at its Gauss points and corners (scaled Jacobian
//   det J / (|J_1| |J_2| |J_3|), 1 for a cube);
// - conformity: the count of a structured mesh from the division counts, no two nodes closer than
//   a small fraction of the element size, every element face shared by at most two elements and
//   every unshared face on one of the known surfaces (bore, end planes, gear outline);
// - node sets: bore radius; flank nodes on the involute of the base circle, from the closed form
//   polar angle of ISO 21771, psi(R) = psi(r) + inv(alpha_t) - inv(alpha_R), about the tooth's
//   centre line 2 pi k / z; helical flank nodes are the z = 0 ones turned by z tan(beta) / r;
//   tooth k's flank sets hold the vertices of gear_geometry's own flank surface of tooth k
//   (MakeFlankMesh, built by a different path: profile strip rotated per layer);
// - errors name the offending parameter;
// - faults: a broken tooth's mesh loses the volume of the section above the fracture chord
//   (shoelace area of the finely sampled outline) times the broken width, stays conforming
//   (faces shared by at most two elements, unshared faces on the outline, end faces or the
//   fracture set) and keeps no element above the chord inside the broken range; a crack's two
//   faces share no node (duplicated nodes at equal positions, never in one element), and it
//   opens exactly the crack row's points nearer the mouth than the depth.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <set>

#include "flex/fe_element.h"
#include "models/gear_fe_mesh.h"
#include "models/tooth_fault_geometry.h"

namespace orrery::gears {
namespace {

using flex::ElementType;
using flex::FeMesh;
constexpr double kPi = 3.14159265358979323846;

// Seed 001's planet (scenarios.md): 18 teeth, module 1.5 mm, pressure angle 21.3 deg, 30 mm wide.
GearSpec PlanetSpec(double helix_rad = 0) {
  return {.teeth = 18, .normal_module_m = 1.5e-3, .normal_pressure_angle_rad = 21.3 * kPi / 180,
          .helix_angle_rad = helix_rad, .face_width_m = 0.03};
}
constexpr double kBore = 7e-3;

// Transverse area of the gear outline (closed polygon, finely sampled) minus the bore disc.
double ExactTransverseArea(const Gear& g, double bore) {
  const std::vector<ProfilePoint> pts =
      g.SampleGearOutline({.root = 400, .fillet = 2000, .involute = 2000, .tip = 400});
  double twice = 0;
  for (std::size_t k = 0; k < pts.size(); ++k) {
    const Vec2& a = pts[k].p;
    const Vec2& b = pts[(k + 1) % pts.size()].p;
    twice += a.x() * b.y() - a.y() * b.x();
  }
  return 0.5 * twice - kPi * bore * bore;
}

double MeshVolume(const FeMesh& mesh) {
  double v = 0;
  for (int e = 0; e < mesh.num_elements(); ++e)
    v += flex::CalcElementVolume(mesh.elements()[e].type, mesh.ElementPositions(e));
  return v;
}

// Minimum scaled Jacobian over the Gauss points of the stiffness rule and the corner nodes.
double MinScaledJacobian(const FeMesh& mesh, double* min_det = nullptr) {
  double worst = 1e300, worst_det = 1e300;
  Eigen::VectorXd N;
  Eigen::MatrixX3d dN;
  for (int e = 0; e < mesh.num_elements(); ++e) {
    const ElementType t = mesh.elements()[e].type;
    const Eigen::MatrixX3d X = mesh.ElementPositions(e);
    std::vector<Eigen::Vector3d> pts = flex::StiffnessRule(t).points;
    const Eigen::MatrixX3d nat = flex::NaturalNodeCoordinates(t);
    for (int c = 0; c < 8; ++c) pts.push_back(nat.row(c).transpose());
    for (const Eigen::Vector3d& xi : pts) {
      flex::EvalShapeFunctions(t, xi, N, dN);
      const Eigen::Matrix3d J = dN.transpose() * X;  // rows: dx/dxi_i
      const double det = J.determinant();
      worst_det = std::min(worst_det, det);
      worst = std::min(worst, det / (J.row(0).norm() * J.row(1).norm() * J.row(2).norm()));
    }
  }
  if (min_det) *min_det = worst_det;
  return worst;
}

// Corner-node faces of a hex (fe_mesh.h order).
constexpr int kHexFaces[6][4] = {{0, 1, 2, 3}, {4, 5, 6, 7}, {0, 1, 5, 4}, {1, 2, 6, 5}, {2, 3, 7, 6}, {3, 0, 4, 7}};

std::set<int> SetOf(const std::vector<int>& v) { return {v.begin(), v.end()}; }

TEST(GearFeMeshTest, SpurHex8IsConformingAndValid) {
  const Gear g(PlanetSpec());
  const GearFeMeshSpec spec{.bore_radius_m = kBore};
  const FeMesh mesh = MakeGearFeMesh(g, spec);
  // Structured count per sector (the radial line at the next space middle belongs to the next
  // sector): rim block n_a (n_rim + 1), tooth block above r_base (n_a + 1) n_j less the n_d nodes
  // of that radial line, n_j = n_d + n_fil + n_fl; times z, times the axial levels.
  const int na = spec.tooth_divisions, nd = spec.root_layer_divisions;
  const int nj = nd + spec.fillet_divisions + spec.flank_divisions;
  const int per_sector = na * (spec.rim_divisions + 1) + (na + 1) * nj - nd;
  EXPECT_EQ(mesh.num_nodes(), per_sector * g.teeth() * (spec.face_divisions + 1));
  const int cells = na * (spec.rim_divisions + nj);
  EXPECT_EQ(mesh.num_elements(), cells * g.teeth() * spec.face_divisions);

  // No two nodes coincide (closer than 1e-3 of the smallest edge ~ 0.1 mm).
  std::map<std::pair<long long, long long>, std::vector<int>> grid;
  const double cell = 1e-5;
  for (int n = 0; n < mesh.num_nodes(); ++n) {
    const Eigen::Vector3d& p = mesh.positions()[n];
    grid[{std::llround(p.x() / cell), std::llround(p.y() / cell)}].push_back(n);
  }
  int close = 0;
  for (const auto& [key, list] : grid)
    for (int dx = -1; dx <= 1; ++dx)
      for (int dy = -1; dy <= 1; ++dy) {
        auto it = grid.find({key.first + dx, key.second + dy});
        if (it == grid.end()) continue;
        for (int a : list)
          for (int b : it->second)
            if (a < b && (mesh.positions()[a] - mesh.positions()[b]).norm() < 1e-7) ++close;
      }
  EXPECT_EQ(close, 0);

  // Faces: shared by at most two elements; unshared faces on a known surface.
  std::map<std::array<int, 4>, int> faces;
  for (const flex::FeElement& el : mesh.elements())
    for (const auto& f : kHexFaces) {
      std::array<int, 4> key{el.nodes[f[0]], el.nodes[f[1]], el.nodes[f[2]], el.nodes[f[3]]};
      std::sort(key.begin(), key.end());
      ++faces[key];
    }
  std::set<int> outline = SetOf(mesh.NodeSet("ROOT"));
  for (int k = 0; k < g.teeth(); ++k)
    for (const char* part : {"FLANK_PLUS", "FLANK_MINUS", "FILLET_PLUS", "FILLET_MINUS", "TIP"})
      for (int n : mesh.NodeSet(ToothSetName(k, part))) outline.insert(n);
  const std::set<int> bore = SetOf(mesh.NodeSet("BORE")), zmin = SetOf(mesh.NodeSet("FACE_ZMIN")),
                      zmax = SetOf(mesh.NodeSet("FACE_ZMAX"));
  int boundary = 0, shared = 0, over = 0, stray = 0;
  for (const auto& [key, count] : faces) {
    if (count > 2) ++over;
    if (count == 2) ++shared;
    if (count != 1) continue;
    ++boundary;
    bool known = false;
    for (const std::set<int>* surface : std::initializer_list<const std::set<int>*>{&bore, &zmin, &zmax, &outline})
      known |= std::all_of(key.begin(), key.end(), [&](int n) { return surface->count(n) > 0; });
    if (!known) ++stray;
  }
  EXPECT_EQ(over, 0);
  EXPECT_EQ(stray, 0);
  // Boundary faces: two end faces of every column plus the side faces of bore and outline.
  const int side_cells = g.teeth() * (na + 2 * (spec.fillet_divisions + spec.flank_divisions) + na);
  EXPECT_EQ(boundary, 2 * cells * g.teeth() + side_cells * spec.face_divisions);

  // Quality.
  double min_det = 0;
  const double sj = MinScaledJacobian(mesh, &min_det);
  std::printf("spur hex8: %d nodes, %d elements, min scaled Jacobian %.3f\n", mesh.num_nodes(), mesh.num_elements(),
              sj);
  EXPECT_GT(min_det, 0);
  EXPECT_GT(sj, 0.2);
  EXPECT_EQ(mesh.ElementSet("EALL").size(), static_cast<std::size_t>(mesh.num_elements()));
  EXPECT_EQ(mesh.NodeSet("NALL").size(), static_cast<std::size_t>(mesh.num_nodes()));
  ASSERT_EQ(mesh.materials().size(), 1u);
  EXPECT_TRUE(std::all_of(mesh.element_material().begin(), mesh.element_material().end(),
                          [](int m) { return m == 0; }));
}

TEST(GearFeMeshTest, VolumeConvergesToProfileArea) {
  const Gear g(PlanetSpec());
  const double exact = g.spec().face_width_m * ExactTransverseArea(g, kBore);
  // Boundary nodes lie on the exact curves, so the error is the gap between the curves and the
  // elements' edges: straight chords (hex8, O(h^2)) or quadratic arcs (hex20, O(h^3) or better).
  // Convex parts (flanks, tip) lose area, concave ones (fillets, bore) gain, so the signed
  // contributions partly cancel; the test asks for at least the O(h^2) rate (a factor 3 per
  // halving of h), hex20 below hex8 at every level, and 2e-6 at the finest level.
  std::map<ElementType, std::vector<double>> errors;
  for (ElementType type : {ElementType::kHex8, ElementType::kHex20})
    for (int level : {1, 2, 4}) {
      const GearFeMeshSpec spec{.bore_radius_m = kBore, .type = type, .flank_divisions = 4 * level,
                                .fillet_divisions = 4 * level, .tooth_divisions = 4 * level,
                                .root_layer_divisions = level, .rim_divisions = 2 * level, .face_divisions = 2};
      errors[type].push_back(std::abs(MeshVolume(MakeGearFeMesh(g, spec)) / exact - 1));
      std::printf("%s level %d: relative volume error %.3g\n", flex::CalculixName(type), level, errors[type].back());
    }
  for (ElementType type : {ElementType::kHex8, ElementType::kHex20}) {
    const std::vector<double>& e = errors[type];
    EXPECT_GT(e[0] / e[1], 3) << flex::CalculixName(type);
    EXPECT_GT(e[1] / e[2], 3) << flex::CalculixName(type);
    EXPECT_LT(e[2], 2e-6) << flex::CalculixName(type);
  }
  for (int k = 0; k < 3; ++k) EXPECT_LT(errors[ElementType::kHex20][k], errors[ElementType::kHex8][k]);
}

TEST(GearFeMeshTest, NodeSetsLieOnTheirSurfaces) {
  const Gear g(PlanetSpec());
  const FeMesh mesh = MakeGearFeMesh(g, {.bore_radius_m = kBore, .type = ElementType::kHex20});
  const double b = g.spec().face_width_m;
  for (int n : mesh.NodeSet("BORE")) EXPECT_NEAR(mesh.positions()[n].head<2>().norm(), kBore, 1e-12);
  EXPECT_EQ(mesh.NodeSet("BORE").size(),
            SelectNodesOnCylinder(mesh, Eigen::Vector3d::Zero(), Eigen::Vector3d::UnitZ(), kBore, 1e-9).size());
  EXPECT_EQ(SetOf(mesh.NodeSet("FACE_ZMIN")),
            SetOf(SelectNodesOnPlane(mesh, Eigen::Vector3d::Zero(), Eigen::Vector3d::UnitZ(), 1e-12)));
  EXPECT_EQ(SetOf(mesh.NodeSet("FACE_ZMAX")),
            SetOf(SelectNodesOnPlane(mesh, Eigen::Vector3d(0, 0, b), -Eigen::Vector3d::UnitZ(), 1e-12)));
  for (int n : mesh.NodeSet("ROOT")) EXPECT_NEAR(mesh.positions()[n].head<2>().norm(), g.root_radius_m(), 1e-12);
  // Involute: tooth k's plus flank at radius R has polar angle 2 pi k / z + psi(R), the minus
  // flank 2 pi k / z - psi(R), psi(R) = psi_ref + inv(alpha_t) - inv(acos(r_b / R)).
  const double r_b = g.base_radius_m();
  const double psi_ref = g.HalfToothAngle(g.reference_radius_m());
  double worst = 0;
  for (int k = 0; k < g.teeth(); ++k)
    for (int sign : {1, -1}) {
      const std::vector<int>& set = mesh.NodeSet(ToothSetName(k, sign > 0 ? "FLANK_PLUS" : "FLANK_MINUS"));
      EXPECT_EQ(set.size(), (2u * 8 + 1) * 11 + 9 * 10);  // corners on odd levels only
      for (int n : set) {
        const Eigen::Vector3d& p = mesh.positions()[n];
        const double R = p.head<2>().norm();
        const double inv_r = std::tan(std::acos(r_b / R)) - std::acos(r_b / R);
        const double inv_t = std::tan(g.transverse_pressure_angle_rad()) - g.transverse_pressure_angle_rad();
        const double psi = psi_ref + inv_t - inv_r;
        double d = std::atan2(p.y(), p.x()) - (2 * kPi * k / g.teeth() + sign * psi);
        d = std::remainder(d, 2 * kPi);
        worst = std::max(worst, std::abs(d) * R);
        EXPECT_GE(R, g.form_radius_m() - 1e-12);
        EXPECT_LE(R, g.tip_radius_m() + 1e-12);
      }
    }
  std::printf("flank nodes: max distance from the involute %.3g m\n", worst);
  EXPECT_LT(worst, 1e-10);
  // Tips: the tooth's centre line at 2 pi k / z.
  for (int k = 0; k < g.teeth(); ++k) {
    Eigen::Vector2d sum = Eigen::Vector2d::Zero();
    for (int n : mesh.NodeSet(ToothSetName(k, "TIP"))) sum += mesh.positions()[n].head<2>().normalized();
    EXPECT_NEAR(std::remainder(std::atan2(sum.y(), sum.x()) - 2 * kPi * k / g.teeth(), 2 * kPi), 0, 1e-12);
  }
  for (int n : mesh.NodeSet(ToothSetName(5, "TIP")))
    EXPECT_NEAR(mesh.positions()[n].head<2>().norm(), g.tip_radius_m(), 1e-12);
  const double sj = MinScaledJacobian(mesh);
  std::printf("spur hex20 default: %d nodes, min scaled Jacobian %.3f\n", mesh.num_nodes(), sj);
  EXPECT_GT(sj, 0.2);
}

TEST(GearFeMeshTest, HelicalFlankIsTwistedByTheLead) {
  const double beta = 15 * kPi / 180;
  for (HelixHand hand : {HelixHand::kRight, HelixHand::kLeft}) {
    GearSpec gs = PlanetSpec(beta);
    gs.hand = hand;
    const Gear g(gs);
    const FeMesh mesh = MakeGearFeMesh(g, {.bore_radius_m = kBore, .type = ElementType::kHex20, .face_divisions = 12});
    const double lead = (hand == HelixHand::kRight ? 1 : -1) * std::tan(beta) / g.reference_radius_m();
    const std::vector<int>& flank = mesh.NodeSet(ToothSetName(3, "FLANK_PLUS"));
    std::vector<Eigen::Vector3d> base;
    for (int n : flank)
      if (mesh.positions()[n].z() == 0.0) base.push_back(mesh.positions()[n]);
    ASSERT_EQ(base.size(), 17u);
    double worst = 0;
    for (int n : flank) {
      const Eigen::Vector3d& p = mesh.positions()[n];
      const double a = -lead * p.z();
      const Eigen::Vector2d back(std::cos(a) * p.x() - std::sin(a) * p.y(), std::sin(a) * p.x() + std::cos(a) * p.y());
      double nearest = 1e300;
      for (const Eigen::Vector3d& q : base) nearest = std::min(nearest, (q.head<2>() - back).norm());
      worst = std::max(worst, nearest);
    }
    EXPECT_LT(worst, 1e-12);
    // gear_geometry's flank surface of the same tooth (same profile and face divisions) has
    // its vertices on the mesh's flank nodes, for both flanks and both hands.
    for (bool plus : {true, false}) {
      const std::vector<int>& set = mesh.NodeSet(ToothSetName(3, plus ? "FLANK_PLUS" : "FLANK_MINUS"));
      const TriangleMesh surface = MakeFlankMesh(g, 3, plus, 8, 12);
      double far = 0;
      for (const Vec3& v : surface.vertices) {
        double nearest = 1e300;
        for (int n : set) nearest = std::min(nearest, (mesh.positions()[n] - v).norm());
        far = std::max(far, nearest);
      }
      EXPECT_LT(far, 1e-12) << (plus ? "plus" : "minus");
    }
    // Every transverse section keeps its area: volume = b x area, up to the profile error of
    // these divisions (spur hex20 default: 4.5e-5) and the quadratic interpolation of the helix
    // over a layer (0.05 rad).
    const double err = std::abs(MeshVolume(mesh) / (gs.face_width_m * ExactTransverseArea(g, kBore)) - 1);
    const double sj = MinScaledJacobian(mesh);
    std::printf("helical 15 deg hex20: volume error %.3g, min scaled Jacobian %.3f\n", err, sj);
    EXPECT_LT(err, 1e-4);
    EXPECT_GT(sj, 0.2);
  }
}

TEST(GearFeMeshTest, WebOmitsElementsOutsideTheWeb) {
  const Gear g(PlanetSpec());
  const GearWebSpec web{.rim_thickness_m = 3e-3, .web_thickness_m = 10e-3, .hub_radius_m = 7.5e-3};
  const GearFeMeshSpec spec{.bore_radius_m = 5e-3, .rim_divisions = 1, .face_divisions = 8, .web = web};
  const FeMesh mesh = MakeGearFeMesh(g, spec);
  const double b = g.spec().face_width_m, r_in = g.root_radius_m() - web.rim_thickness_m;
  // Volume: solid gear minus the two recesses between hub and rim.
  const double recess = kPi * (r_in * r_in - web.hub_radius_m * web.hub_radius_m) * (b - web.web_thickness_m);
  const double exact = b * ExactTransverseArea(g, spec.bore_radius_m) - recess;
  const double err = std::abs(MeshVolume(mesh) / exact - 1);
  const double sj = MinScaledJacobian(mesh);
  std::printf("web hex8: %d elements, volume error %.3g, min scaled Jacobian %.3f\n", mesh.num_elements(), err, sj);
  EXPECT_LT(err, 2e-3);  // hex8 chord error of this mesh (same order as the solid gear's)
  EXPECT_GT(sj, 0.2);
  for (int e : mesh.ElementSet("WEB")) {
    const Eigen::MatrixX3d X = mesh.ElementPositions(e);
    const Eigen::Vector3d c = X.colwise().mean();
    EXPECT_GT(c.z(), 0.5 * (b - web.web_thickness_m));
    EXPECT_LT(c.z(), 0.5 * (b + web.web_thickness_m));
  }
  // End faces hold only rim and hub nodes.
  for (int n : mesh.NodeSet("FACE_ZMIN")) {
    const double r = mesh.positions()[n].head<2>().norm();
    EXPECT_TRUE(r <= web.hub_radius_m + 1e-12 || r >= r_in - 1e-12) << r;
  }
}

TEST(GearFeMeshTest, BadInputNamesTheParameter) {
  const Gear g(PlanetSpec());
  auto message = [&](const GearFeMeshSpec& spec) {
    try {
      MakeGearFeMesh(g, spec);
    } catch (const std::invalid_argument& e) {
      return std::string(e.what());
    }
    return std::string("no exception");
  };
  EXPECT_NE(message({.bore_radius_m = 12e-3}).find("bore_radius_m"), std::string::npos);
  EXPECT_NE(message({.bore_radius_m = 0}).find("bore_radius_m"), std::string::npos);
  EXPECT_NE(message({.bore_radius_m = kBore, .flank_divisions = 0}).find("flank_divisions"), std::string::npos);
  EXPECT_NE(message({.bore_radius_m = kBore, .tooth_divisions = 0}).find("tooth_divisions"), std::string::npos);
  EXPECT_NE(message({.bore_radius_m = kBore, .face_divisions = -1}).find("face_divisions"), std::string::npos);
  EXPECT_NE(message({.bore_radius_m = kBore, .flank_bias = 0.5}).find("flank_bias"), std::string::npos);
  EXPECT_NE(message({.bore_radius_m = kBore, .type = ElementType::kTet10}).find("type"), std::string::npos);
  GearFeMeshSpec web{.bore_radius_m = kBore, .web = GearWebSpec{.rim_thickness_m = 3e-3, .web_thickness_m = 0.01,
                                                                .hub_radius_m = 6e-3}};
  EXPECT_NE(message(web).find("web.hub_radius_m"), std::string::npos);
  web.web->hub_radius_m = 8e-3;
  web.web->web_axial_divisions = 3;
  EXPECT_NE(message(web).find("web.web_axial_divisions"), std::string::npos);
  GearSpec ring = PlanetSpec();
  ring.teeth = 70;
  ring.internal = true;
  EXPECT_THROW(MakeGearFeMesh(Gear(ring), {.bore_radius_m = kBore}), std::invalid_argument);
  EXPECT_THROW(SelectNodesOnCylinder(FeMesh(), Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero(), 1, 0),
               std::invalid_argument);
}

}  // namespace
}  // namespace orrery::gears

namespace orrery::gears {
namespace {

// Unshared element faces whose corner nodes are not all in one surface; a surface is the union
// of a group of node sets.
int StrayBoundaryFaces(const FeMesh& mesh, const std::vector<std::vector<std::string>>& surfaces) {
  std::map<std::array<int, 4>, int> faces;
  for (const flex::FeElement& el : mesh.elements())
    for (const auto& f : kHexFaces) {
      std::array<int, 4> key{el.nodes[f[0]], el.nodes[f[1]], el.nodes[f[2]], el.nodes[f[3]]};
      std::sort(key.begin(), key.end());
      ++faces[key];
    }
  std::vector<std::set<int>> sets;
  for (const std::vector<std::string>& group : surfaces) {
    std::set<int> u;
    for (const std::string& name : group)
      for (int n : mesh.NodeSet(name)) u.insert(n);
    sets.push_back(u);
  }
  int stray = 0;
  for (const auto& [key, count] : faces) {
    EXPECT_LE(count, 2);
    if (count != 1) continue;
    bool known = false;
    for (const std::set<int>& surface : sets)
      known |= std::all_of(key.begin(), key.end(), [&](int n) { return surface.count(n) > 0; });
    if (!known && stray < 3) {
      std::printf("stray face:");
      for (int n : key) std::printf(" (%.5f %.5f %.5f)", mesh.positions()[n].x(), mesh.positions()[n].y(), mesh.positions()[n].z());
      std::printf("\n");
    }
    stray += !known;
  }
  return stray;
}

TEST(GearFeMeshFaults, BrokenToothRemovesItsPart) {
  const Gear g(PlanetSpec());
  const double b = g.spec().face_width_m;
  const GearFeMeshSpec healthy_spec{.bore_radius_m = kBore, .type = ElementType::kHex20, .flank_divisions = 4,
                                    .fillet_divisions = 2, .tooth_divisions = 4, .root_layer_divisions = 1,
                                    .rim_divisions = 2, .face_divisions = 3};
  for (const double height : {0.5, 1.0}) {
    GearFeMeshSpec spec = healthy_spec;
    const ToothFaultSpec broken{.kind = ToothFaultSpec::Kind::kBrokenTooth, .tooth = 4, .height_fraction = height,
                                .face_fraction = 0.5};
    spec.faults = {broken};
    const FeMesh h = MakeGearFeMesh(g, healthy_spec), f = MakeGearFeMesh(g, spec);
    // Removed section: the outline above the chord, finely sampled, times the broken width.
    const double rbreak = BreakRadius(g, broken);
    const double sa = ProfileParameterAtRadius(g, rbreak, false), sb = ProfileParameterAtRadius(g, rbreak, true);
    double twice = 0;
    const int n = 20000;
    Vec2 prev = g.ProfileAt(sa).p;
    for (int k = 1; k <= n; ++k) {
      const Vec2 p = g.ProfileAt(sa + (sb - sa) * k / n).p;
      twice += prev.x() * p.y() - prev.y() * p.x();
      prev = p;
    }
    const Vec2 a = g.ProfileAt(sa).p;
    twice += prev.x() * a.y() - prev.y() * a.x();
    const double removed = 0.5 * twice * 0.5 * b;
    const double drop = MeshVolume(h) - MeshVolume(f);
    // The healthy mesh of these divisions misses 4.5e-5 of the gear's volume (hex20 default
    // profile error, VolumeConvergesToProfileArea), about 1e-3 of one tooth: the same bound here.
    std::printf("broken at %.1f height: FE volume drop %.5e m^3, removed section x width %.5e m^3 (%+.2e)\n", height,
                drop, removed, drop / removed - 1);
    EXPECT_NEAR(drop / removed, 1, 2e-3);
    // No element node above the chord inside the broken range; the partial width keeps the tip.
    double far = 0;
    for (const flex::FeElement& el : f.elements())
      for (int c = 0; c < flex::NodeCount(el.type); ++c) {
        const Eigen::Vector3d& p = f.positions()[el.nodes[c]];
        const double polar = std::remainder(std::atan2(p.y(), p.x()) - 2 * kPi * 4 / g.teeth(), 2 * kPi);
        if (std::abs(polar) < kPi / g.teeth() && p.z() < 0.5 * b - 1e-9) far = std::max(far, p.head<2>().norm());
      }
    EXPECT_LE(far, rbreak * (1 + 1e-9));
    EXPECT_FALSE(f.NodeSet(ToothSetName(4, "TIP")).empty());
    EXPECT_FALSE(f.NodeSet(ToothSetName(4, "FRACTURE")).empty());
    // Conforming, closed: unshared faces on the known surfaces (the fracture's end face at
    // z = b/2 lies on the upper elements' faces: all its nodes are tooth-4 outline or fracture
    // nodes, or interior nodes of the remaining half: listed by the node set of that plane).
    std::vector<std::string> outline = {"ROOT", ToothSetName(4, "FRACTURE")};
    for (int k = 0; k < g.teeth(); ++k)
      for (const char* part : {"FLANK_PLUS", "FLANK_MINUS", "FILLET_PLUS", "FILLET_MINUS", "TIP"})
        outline.push_back(ToothSetName(k, part));
    FeMesh copy = f;
    copy.AddToNodeSet("MID_PLANE", SelectNodesOnPlane(f, Eigen::Vector3d(0, 0, 0.5 * b), Eigen::Vector3d::UnitZ(), 1e-12));
    const std::vector<std::vector<std::string>> surfaces = {{"BORE"}, {"FACE_ZMIN"}, {"FACE_ZMAX"}, outline, {"MID_PLANE"}};
    EXPECT_EQ(StrayBoundaryFaces(copy, surfaces), 0);
    double min_det = 0;
    EXPECT_GT(MinScaledJacobian(f, &min_det), 0.1);
    EXPECT_GT(min_det, 0);
  }
}

TEST(GearFeMeshFaults, RootCrackSeparatesItsFaces) {
  const Gear g(PlanetSpec());
  for (const auto flank : {ToothFaultSpec::Flank::kMinus, ToothFaultSpec::Flank::kPlus}) {
    const ToothFaultSpec crack{.kind = ToothFaultSpec::Kind::kRootCrack, .tooth = 2, .crack_depth_m = 0.6e-3,
                               .crack_angle_rad = 45 * kPi / 180, .crack_face_fraction = 1.0, .flank = flank};
    GearFeMeshSpec spec{.bore_radius_m = kBore, .type = ElementType::kHex20, .flank_divisions = 4,
                        .fillet_divisions = 2, .tooth_divisions = 6, .root_layer_divisions = 1, .rim_divisions = 2,
                        .face_divisions = 2};
    const FeMesh healthy = MakeGearFeMesh(g, spec);
    spec.faults = {crack};
    const FeMesh m = MakeGearFeMesh(g, spec);
    const std::vector<int>& set = m.NodeSet(ToothSetName(2, "CRACK"));
    ASSERT_FALSE(set.empty());
    ASSERT_EQ(set.size() % 2, 0u);
    // Pairs (original, copy) at equal positions; never in one element.
    std::map<int, int> partner;
    for (std::size_t i = 0; i < set.size(); i += 2) {
      EXPECT_EQ((m.positions()[set[i]] - m.positions()[set[i + 1]]).norm(), 0.0);
      partner[set[i]] = set[i + 1];
    }
    for (const flex::FeElement& el : m.elements()) {
      std::set<int> nodes(el.nodes.begin(), el.nodes.begin() + flex::NodeCount(el.type));
      for (const auto& [a, b] : partner) EXPECT_FALSE(nodes.count(a) && nodes.count(b));
    }
    // Same elements, extra nodes only on the crack; the mouth on the damaged side's fillet.
    EXPECT_EQ(m.num_elements(), healthy.num_elements());
    EXPECT_EQ(m.num_nodes(), healthy.num_nodes() + static_cast<int>(set.size() / 2));
    const std::set<int> fillet = SetOf(m.NodeSet(ToothSetName(2, flank == ToothFaultSpec::Flank::kPlus ? "FILLET_PLUS"
                                                                                                     : "FILLET_MINUS")));
    int mouth = 0;
    for (const auto& [a, b] : partner) mouth += fillet.count(a) && fillet.count(b);
    EXPECT_EQ(mouth, 2 * 2 + 1);  // one mouth node per level of two hex20 layers
    // Crack length: the open points reach about q from the mouth (within one element edge).
    double reach = 0;
    Eigen::Vector3d mouth_point = Eigen::Vector3d::Zero();
    for (const auto& [a, b] : partner)
      if (fillet.count(a) && m.positions()[a].z() == 0) mouth_point = m.positions()[a];
    for (const auto& [a, b] : partner)
      if (m.positions()[a].z() == 0) reach = std::max(reach, (m.positions()[a] - mouth_point).norm());
    std::printf("crack on the %s flank: %zu open node pairs, reach %.3f mm of q = 0.6 mm\n",
                flank == ToothFaultSpec::Flank::kPlus ? "plus" : "minus", set.size() / 2, reach * 1e3);
    EXPECT_LT(reach, 0.6e-3);
    EXPECT_GT(reach, 0.2e-3);
    double min_det = 0;
    EXPECT_GT(MinScaledJacobian(m, &min_det), 0.1);
    EXPECT_GT(min_det, 0);
  }
}

}  // namespace
}  // namespace orrery::gears
