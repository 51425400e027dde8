#pragma once
// A cloud of point masses, each moved by all kModes modes along its own random directions (every
// I5_kl a full 3 x 3 matrix), with its inertia invariants as the sums over the particles that the
// volume integrals of flexible_body.h become. Drawn with std::rand from `seed`: the particles'
// masses, positions and shapes, in that order. For flexible_body_test.cpp (the particles are the
// oracle of the modal sums) and flexible_tangents_test.cpp (a body with full invariants).
#include <cstdlib>
#include <memory>
#include <vector>

#include <Eigen/Core>

#include "mbd/flexible_body.h"
#include "mbd/spatial.h"

namespace orrery::test_support {

struct ParticleCloud {
  static constexpr int kModes = 7, kPoints = 11;
  std::vector<double> mass;
  std::vector<Vec3> x;
  std::vector<Eigen::Matrix<double, 3, kModes>> phi;

  explicit ParticleCloud(unsigned seed = 7) {
    std::srand(seed);
    auto uniform = [] { return 2.0 * std::rand() / RAND_MAX - 1.0; };
    for (int p = 0; p < kPoints; ++p) {
      mass.push_back(0.2 + 0.5 * (uniform() + 1));
      x.push_back(0.3 * Vec3(uniform(), uniform(), uniform()));
      Eigen::Matrix<double, 3, kModes> shapes;
      for (int i = 0; i < 3; ++i)
        for (int k = 0; k < kModes; ++k) shapes(i, k) = uniform();
      phi.push_back(shapes);
    }
  }

  std::shared_ptr<FlexibleBodyModes> Modes() const {
    auto m = std::make_shared<FlexibleBodyModes>();
    const int n = kModes;
    m->nf = n;
    m->I2 = Eigen::Matrix<double, 3, Eigen::Dynamic>::Zero(3, n);
    m->I4.assign(n, Mat3::Zero());
    m->I5.assign(n * n, Mat3::Zero());
    for (int p = 0; p < kPoints; ++p) {
      m->mass += mass[p];
      m->I1 += mass[p] * x[p];
      m->I3 += mass[p] * x[p] * x[p].transpose();
      m->I2 += mass[p] * phi[p];
      for (int k = 0; k < n; ++k) {
        m->I4[k] += mass[p] * x[p] * phi[p].col(k).transpose();
        for (int l = 0; l < n; ++l)
          m->I5[k * n + l] += mass[p] * phi[p].col(k) * phi[p].col(l).transpose();
      }
    }
    m->stiffness = Eigen::MatrixXd::Zero(n, n);
    return m;
  }
};

}  // namespace orrery::test_support
