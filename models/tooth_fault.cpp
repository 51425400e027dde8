#include "models/tooth_fault.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <sstream>
#include <stdexcept>

namespace orrery::gears {
namespace {

template <typename... Args>
[[noreturn]] void Fail(Args&&... args) {
  std::ostringstream s;
  s.precision(6);
  s << "tooth fault: ";
  (s << ... << args);
  throw std::invalid_argument(s.str());
}

void CheckFraction(const char* name, double f, bool zero_allowed = false) {
  if (!((zero_allowed ? f >= 0 : f > 0) && f <= 1)) Fail(name, " = ", f, " must lie in ", zero_allowed ? "[0, 1]" : "(0, 1]");
}

}  // namespace

double BeamRootHalfThickness(const Gear& gear) {
  const double rb = gear.base_radius_m(), rf = gear.root_radius_m();
  if (!gear.internal() && rf < rb) return rb * std::sin(gear.HalfToothAngle(rb));
  return rf * std::sin(gear.HalfToothAngle(rf));
}

double RollDistance(const Gear& gear, double radius_m) {
  const double rb = gear.base_radius_m();
  return radius_m > rb ? std::sqrt(radius_m * radius_m - rb * rb) : 0.0;
}

double BreakRadius(const Gear& gear, const ToothFaultSpec& fault) {
  const double ra = gear.tip_radius_m(), rf = gear.root_radius_m();
  return ra - fault.height_fraction * (ra - rf);
}

std::pair<double, double> FaultAxialRange(const Gear& gear, const ToothFaultSpec& fault) {
  const double b = gear.spec().face_width_m;
  switch (fault.kind) {
    case ToothFaultSpec::Kind::kSpall: return {fault.axial_start_m, fault.axial_end_m};
    case ToothFaultSpec::Kind::kBrokenTooth:
    case ToothFaultSpec::Kind::kRootCrack: {
      const double f = fault.kind == ToothFaultSpec::Kind::kBrokenTooth ? fault.face_fraction
                                                                       : fault.crack_face_fraction;
      const double length = std::min(1.0, f) * b;
      if (fault.from_face == ToothFaultSpec::FromFace::kZmin) return {0.0, length};
      return {b - length, b};
    }
  }
  return {0.0, b};
}

double CrackDepthAt(const Gear& gear, const ToothFaultSpec& fault, double z_m) {
  if (fault.kind != ToothFaultSpec::Kind::kRootCrack) return 0;
  const double b = gear.spec().face_width_m;
  const double length = fault.crack_face_fraction * b;
  // Distance from the start face; beyond L_c the tooth is whole.
  const double zp = fault.from_face == ToothFaultSpec::FromFace::kZmin ? z_m : b - z_m;
  if (zp < 0 || zp > length * (1 + 1e-12)) return 0;
  if (!fault.crack_end_depth_m) return fault.crack_depth_m;
  // Chen & Shao (2011): q^2 linear along the width (parabolic front).
  const double q0 = fault.crack_depth_m, q1 = *fault.crack_end_depth_m;
  const double t = std::clamp(zp / length, 0.0, 1.0);
  return std::sqrt(std::max(0.0, q0 * q0 + (q1 * q1 - q0 * q0) * t));
}

void ValidateToothFault(const Gear& gear, const ToothFaultSpec& f) {
  const int z = gear.teeth();
  const double b = gear.spec().face_width_m;
  if (f.tooth < 0 || f.tooth >= z) Fail(KindName(f.kind), ": tooth = ", f.tooth, " is not in [0, ", z, ")");
  switch (f.kind) {
    case ToothFaultSpec::Kind::kBrokenTooth:
      CheckFraction("broken_tooth: height_fraction", f.height_fraction, true);
      CheckFraction("broken_tooth: face_fraction", f.face_fraction, true);
      return;
    case ToothFaultSpec::Kind::kRootCrack: {
      CheckFraction("root_crack: crack_face_fraction", f.crack_face_fraction);
      if (!(f.crack_depth_m >= 0)) Fail("root_crack: crack_depth_m = ", f.crack_depth_m, " must be >= 0");
      if (f.crack_end_depth_m && !(*f.crack_end_depth_m >= 0))
        Fail("root_crack: crack_end_depth_m = ", *f.crack_end_depth_m, " must be >= 0");
      if (!(f.crack_angle_rad >= 0 && f.crack_angle_rad <= std::numbers::pi / 2))
        Fail("root_crack: crack_angle_rad = ", f.crack_angle_rad, " must lie in [0, pi/2]");
      // The cracked side must keep material up to the centre line (Chen & Shao's model).
      const double q = std::max(f.crack_depth_m, f.crack_end_depth_m.value_or(0.0));
      const double h = BeamRootHalfThickness(gear);
      if (q * std::sin(f.crack_angle_rad) >= h)
        Fail("root_crack: crack_depth_m = ", q, " at crack_angle_rad = ", f.crack_angle_rad,
             " reaches past the tooth centre line (q sin(nu) = ", q * std::sin(f.crack_angle_rad),
             " m >= root half thickness ", h, " m)");
      return;
    }
    case ToothFaultSpec::Kind::kSpall: {
      if (!(f.depth_m > 0)) Fail("spall: depth_m = ", f.depth_m, " must be > 0");
      if (!(f.roll_end_m > f.roll_start_m))
        Fail("spall: roll range [", f.roll_start_m, ", ", f.roll_end_m, "] m is empty");
      if (!(f.axial_end_m > f.axial_start_m))
        Fail("spall: axial range [", f.axial_start_m, ", ", f.axial_end_m, "] m is empty");
      const double rho_a = RollDistance(gear, gear.tip_radius_m());
      const double rho_f = RollDistance(gear, gear.form_radius_m());
      const double lo = std::min(rho_a, rho_f), hi = std::max(rho_a, rho_f);
      const double tol = 1e-9 * gear.reference_radius_m();
      if (f.roll_start_m < lo - tol || f.roll_end_m > hi + tol)
        Fail("spall: roll range [", f.roll_start_m, ", ", f.roll_end_m, "] m leaves the involute [", lo, ", ",
             hi, "] m (form circle to tip)");
      if (f.axial_start_m < -tol || f.axial_end_m > b + tol)
        Fail("spall: axial range [", f.axial_start_m, ", ", f.axial_end_m, "] m leaves the face [0, ", b, "] m");
      return;
    }
  }
}

void ValidateToothFaults(const Gear& gear, const std::vector<ToothFaultSpec>& faults) {
  for (const ToothFaultSpec& f : faults) ValidateToothFault(gear, f);
  for (size_t i = 0; i < faults.size(); ++i)
    for (size_t j = i + 1; j < faults.size(); ++j) {
      const ToothFaultSpec &a = faults[i], &b = faults[j];
      const bool geometric_a = a.kind != ToothFaultSpec::Kind::kRootCrack;
      const bool geometric_b = b.kind != ToothFaultSpec::Kind::kRootCrack;
      if (a.tooth == b.tooth && geometric_a && geometric_b)
        Fail("tooth ", a.tooth, " carries two faults that change its geometry (", KindName(a.kind), ", ",
             KindName(b.kind), "): not modelled");
      if (a.tooth == b.tooth && !geometric_a && !geometric_b)
        Fail("tooth ", a.tooth, " carries two root cracks: not modelled");
    }
}

const char* KindName(ToothFaultSpec::Kind kind) {
  switch (kind) {
    case ToothFaultSpec::Kind::kBrokenTooth: return "broken_tooth";
    case ToothFaultSpec::Kind::kRootCrack: return "root_crack";
    case ToothFaultSpec::Kind::kSpall: return "spall";
  }
  return "?";
}

const char* FlankName(ToothFaultSpec::Flank flank) {
  return flank == ToothFaultSpec::Flank::kPlus ? "plus" : "minus";
}

const char* FaceName(ToothFaultSpec::FromFace face) {
  return face == ToothFaultSpec::FromFace::kZmin ? "zmin" : "zmax";
}

ToothFaultSpec::Kind ParseFaultKind(const std::string& name) {
  for (auto k : {ToothFaultSpec::Kind::kBrokenTooth, ToothFaultSpec::Kind::kRootCrack, ToothFaultSpec::Kind::kSpall})
    if (name == KindName(k)) return k;
  Fail("kind '", name, "' is not one of broken_tooth, root_crack, spall");
}

ToothFaultSpec::Flank ParseFlank(const std::string& name) {
  if (name == "plus") return ToothFaultSpec::Flank::kPlus;
  if (name == "minus") return ToothFaultSpec::Flank::kMinus;
  Fail("flank '", name, "' is not plus or minus");
}

ToothFaultSpec::FromFace ParseFromFace(const std::string& name) {
  if (name == "zmin") return ToothFaultSpec::FromFace::kZmin;
  if (name == "zmax") return ToothFaultSpec::FromFace::kZmax;
  Fail("from_face '", name, "' is not zmin or zmax");
}

std::string DescribeToothFault(const ToothFaultSpec& f) {
  std::ostringstream s;
  s.precision(17);
  s << KindName(f.kind) << " tooth=" << f.tooth;
  switch (f.kind) {
    case ToothFaultSpec::Kind::kBrokenTooth:
      s << " height_fraction=" << f.height_fraction << " face_fraction=" << f.face_fraction
        << " from_face=" << FaceName(f.from_face);
      break;
    case ToothFaultSpec::Kind::kRootCrack:
      s << " crack_depth_m=" << f.crack_depth_m << " crack_angle_rad=" << f.crack_angle_rad
        << " crack_face_fraction=" << f.crack_face_fraction << " from_face=" << FaceName(f.from_face)
        << " flank=" << FlankName(f.flank);
      if (f.crack_end_depth_m) s << " crack_end_depth_m=" << *f.crack_end_depth_m;
      break;
    case ToothFaultSpec::Kind::kSpall:
      s << " flank=" << FlankName(f.flank) << " roll_start_m=" << f.roll_start_m << " roll_end_m=" << f.roll_end_m
        << " axial_start_m=" << f.axial_start_m << " axial_end_m=" << f.axial_end_m << " depth_m=" << f.depth_m;
      break;
  }
  return s.str();
}

}  // namespace orrery::gears
