#pragma once
// Discrete Fourier transforms of real sequences, through KissFFT (the C++ template kissfft.hh of
// Debian's libkissfft-dev, instantiated in double precision). This file's .cpp is the only place
// in the project that includes a KissFFT header.
//
// Forward transform, no scaling (the usual DFT definition):
//   X_k = sum_{n=0}^{N-1} x_n exp(-2 pi i k n / N),   k = 0 .. N/2   (floor(N/2) + 1 values)
// The other half follows from X_{N-k} = conj(X_k). Inverse transform of such a half spectrum:
//   x_n = (1/N) sum_{k=0}^{N-1} X_k exp(+2 pi i k n / N)
//
// Cost: KissFFT is mixed-radix, O(N sum p_i) for N = prod p_i; lengths whose prime factors are
// 2, 3 and 5 are fast, a large prime factor p costs O(N p). FastFftLength picks such a length.
// Even N use KissFFT's real transform on N/2 complex points, odd N a complex transform.
//
// Usage:
//   RealFft fft(x.size());
//   std::vector<std::complex<double>> X(fft.bins());
//   fft.Forward(x.data(), X.data());
#include <complex>
#include <memory>

namespace orrery::signal {

class RealFft {
 public:
  // A transform of length n. Throws std::invalid_argument for n < 1.
  explicit RealFft(int n);
  ~RealFft();
  RealFft(RealFft&&) noexcept;
  RealFft& operator=(RealFft&&) noexcept;

  int size() const;  // N
  int bins() const;  // N/2 + 1 (floor): the non-negative frequencies 0 .. floor(N/2)

  // X[0 .. bins()-1] = DFT of x[0 .. N-1] (see above). Uses internal scratch: not thread-safe on
  // one object; allocation-free.
  void Forward(const double* x, std::complex<double>* X);
  // x[0 .. N-1] from the half spectrum X[0 .. bins()-1] (imaginary parts of X_0 and, for even N,
  // X_{N/2} are ignored, as a real sequence cannot have them). Allocation-free.
  void Inverse(const std::complex<double>* X, double* x);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// The largest even length n' <= n whose prime factors are 2, 3 and 5 only (n >= 2), for records
// that may be shortened slightly to transform fast: n' >= 0.937 n for n >= 1000, n' >= 0.948 n
// for n >= 10^4 (checked up to 2·10^6). Throws std::invalid_argument for n < 2.
int FastFftLength(int n);

}  // namespace orrery::signal
