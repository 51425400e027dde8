#pragma once
// A synthetic gear vibration with closed-form spectrum, the oracle of the sideband and
// condition-indicator tests.
//
// Over the member's angle θ (one revolution = 2π), a gear of Z teeth with three mesh harmonics,
// amplitude-modulated (index m) and phase-modulated (index β at the fundamental, k β at harmonic
// k, as a phase modulation of the mesh itself) once per revolution:
//
//   x(θ) = sum_{k=1}^{3} A_k (1 + m cos θ) cos(k Z θ + k β sin θ)
//
// Jacobi-Anger: cos(φ + z sin θ) = sum_n J_n(z) cos(φ + n θ), and (1 + m cos θ) cos(φ + n θ) =
// cos(φ + n θ) + (m/2) [cos(φ + (n+1) θ) + cos(φ + (n-1) θ)], so x is a cosine series
//
//   x(θ) = sum_k sum_n c_{k,n} cos((k Z + n) θ),
//   c_{k,n} = A_k [ J_n(k β) + (m/2) (J_{n-1}(k β) + J_{n+1}(k β)) ],   J_{-n}(z) = (-1)^n J_n(z)
//
// For β k <= 1.8 the terms beyond |n| = 13 are below 1e-11 A_k, and with Z = 28 the sidebands of
// neighbouring harmonics (|n| <= 13) do not meet: every order q = k Z + n has one coefficient.
#include <cmath>
#include <map>

namespace orrery::signal::test {

inline double BesselJ(int n, double z) {
  if (n < 0) return (n % 2 ? -1.0 : 1.0) * std::cyl_bessel_j(-n, z);
  return std::cyl_bessel_j(n, z);
}

struct GearSignal {
  int teeth = 28;                      // Z
  double amplitude[3] = {1.0, 0.5, 0.25};  // A_k
  double am = 0.3;                     // m
  double pm = 0.6;                     // β
  static constexpr int kMaxSideband = 13;

  double Value(double theta) const {
    double x = 0;
    for (int k = 1; k <= 3; ++k)
      x += amplitude[k - 1] * (1 + am * std::cos(theta)) * std::cos(k * teeth * theta + k * pm * std::sin(theta));
    return x;
  }
  double Coefficient(int k, int n) const {
    const double z = k * pm;
    return amplitude[k - 1] * (BesselJ(n, z) + 0.5 * am * (BesselJ(n - 1, z) + BesselJ(n + 1, z)));
  }
  // Order -> cosine amplitude, for |n| in [min_sideband, kMaxSideband]
  std::map<int, double> Series(int min_sideband) const {
    std::map<int, double> a;
    for (int k = 1; k <= 3; ++k)
      for (int n = -kMaxSideband; n <= kMaxSideband; ++n)
        if (std::abs(n) >= min_sideband) a[k * teeth + n] = Coefficient(k, n);
    return a;
  }
};

// Mean square and mean fourth power over a period of d(θ) = sum_q a_q cos(q θ) (q >= 1): the
// square d^2 = sum_p b_p cos(p θ) with b_{|q1-q2|} and b_{q1+q2} each receiving a_{q1} a_{q2} / 2
// for every ordered pair; then mean d^2 = b_0 and mean d^4 = b_0^2 + (1/2) sum_{p>=1} b_p^2.
struct Moments {
  double m2 = 0, m4 = 0;
  double Kurtosis() const { return m4 / (m2 * m2); }
};
inline Moments CosineSeriesMoments(const std::map<int, double>& a) {
  std::map<int, double> b;
  for (const auto& [q1, a1] : a)
    for (const auto& [q2, a2] : a) {
      b[std::abs(q1 - q2)] += 0.5 * a1 * a2;
      b[q1 + q2] += 0.5 * a1 * a2;
    }
  Moments m;
  m.m2 = b[0];
  m.m4 = b[0] * b[0];
  for (const auto& [p, bp] : b)
    if (p > 0) m.m4 += 0.5 * bp * bp;
  return m;
}

}  // namespace orrery::signal::test
