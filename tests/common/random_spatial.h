#pragma once
// Random rotations, rigid-body inertias and frames for the mbd tests that check the pipeline on
// arbitrary trees (tests/mbd/jacobian_test.cpp, tests/mbd/articulated_solve_test.cpp). Drawn
// from a caller's std::mt19937, so each test's sequence is its own and repeatable.
#include <random>

#include "mbd/spatial.h"

namespace orrery::test_support {

// A rotation by an angle uniform in [-max_angle, max_angle] rad about a random axis.
inline Mat3 RandomRotation(std::mt19937& rng, double max_angle) {
  std::uniform_real_distribution<double> u(-1, 1);
  const Vec3 axis(u(rng), u(rng), u(rng));
  return AxisAngle(axis.normalized(), max_angle * u(rng));
}

// A physically valid central inertia (kg m^2, about 0.1 to 0.3) in turned axes: principal
// moments from positive "second moments" a, b, c as (b + c, a + c, a + b), which always satisfy
// the triangle inequality.
inline Mat3 RandomInertia(std::mt19937& rng) {
  std::uniform_real_distribution<double> u(0.05, 0.15);
  const double a = u(rng), b = u(rng), c = u(rng);
  const Vec3 d(b + c, a + c, a + b);
  const Mat3 R = RandomRotation(rng, 3.0);
  return R * d.asDiagonal() * R.transpose();
}

// A frame turned by up to 1 rad, offset by up to `reach` m along each axis.
inline Transform RandomFrame(std::mt19937& rng, double reach) {
  std::uniform_real_distribution<double> u(-reach, reach);
  return Transform(RandomRotation(rng, 1.0), Vec3(u(rng), u(rng), u(rng)));
}

}  // namespace orrery::test_support
