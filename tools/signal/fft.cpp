#include "tools/signal/fft.h"

#include <kissfft.hh>

#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

namespace orrery::signal {

using Complex = std::complex<double>;

struct RealFft::Impl {
  int n = 0;
  std::optional<kissfft<double>> half_forward;  // even n: real transform on n/2 complex points
  std::optional<kissfft<double>> full_forward;  // odd n: complex transform of n points
  kissfft<double> full_inverse;
  std::vector<Complex> in, out;  // scratch, n each

  explicit Impl(int size) : n(size), full_inverse(static_cast<std::size_t>(size), true), in(size), out(size) {
    if (n % 2 == 0)
      half_forward.emplace(static_cast<std::size_t>(n / 2), false);
    else
      full_forward.emplace(static_cast<std::size_t>(n), false);
  }
};

RealFft::RealFft(int n) {
  if (n < 1) throw std::invalid_argument("RealFft: length must be >= 1, got " + std::to_string(n));
  impl_ = std::make_unique<Impl>(n);
}
RealFft::~RealFft() = default;
RealFft::RealFft(RealFft&&) noexcept = default;
RealFft& RealFft::operator=(RealFft&&) noexcept = default;

int RealFft::size() const { return impl_->n; }
int RealFft::bins() const { return impl_->n / 2 + 1; }

void RealFft::Forward(const double* x, Complex* X) {
  Impl& m = *impl_;
  if (m.n == 1) {
    X[0] = Complex(x[0], 0.0);
    return;
  }
  // Even length: KissFFT packs X_0 and X_{N/2} (both real) into its first output
  if (m.half_forward) {
    const int half = m.n / 2;
    m.half_forward->transform_real(x, X);
    const double nyquist = X[0].imag();
    X[0] = Complex(X[0].real(), 0.0);
    X[half] = Complex(nyquist, 0.0);
    return;
  }
  // Odd length: complex transform, keep the non-negative frequencies
  for (int i = 0; i < m.n; ++i) m.in[i] = Complex(x[i], 0.0);
  m.full_forward->transform(m.in.data(), m.out.data());
  for (int k = 0; k < bins(); ++k) X[k] = m.out[k];
}

void RealFft::Inverse(const Complex* X, double* x) {
  Impl& m = *impl_;
  const int n = m.n;
  // Hermitian extension of the half spectrum
  m.in[0] = Complex(X[0].real(), 0.0);
  for (int k = 1; k < bins(); ++k) m.in[k] = X[k];
  if (n % 2 == 0) m.in[n / 2] = Complex(X[n / 2].real(), 0.0);
  for (int k = bins(); k < n; ++k) m.in[k] = std::conj(m.in[n - k]);
  m.full_inverse.transform(m.in.data(), m.out.data());
  const double scale = 1.0 / n;
  for (int i = 0; i < n; ++i) x[i] = m.out[i].real() * scale;
}

int FastFftLength(int n) {
  if (n < 2) throw std::invalid_argument("FastFftLength: length must be >= 2, got " + std::to_string(n));
  for (int m = n - (n % 2); m >= 2; m -= 2) {
    int r = m;
    for (int p : {2, 3, 5})
      while (r % p == 0) r /= p;
    if (r == 1) return m;
  }
  return 2;
}

}  // namespace orrery::signal
