#pragma once
// Which BLAS kernels the sparse factorizations of flex/ run on (CHOLMOD's supernodal Cholesky
// spends most of its time in BLAS 3). Debian 12's OpenBLAS 0.3.21 does not know CPU models newer
// than it (Intel family 6 model 207, for one) and falls back to its generic SSE3 ("Prescott")
// kernels, about 2.3 times slower on the 92k-DOF factorization of docs/performance.md than the
// AVX-512 ("SkylakeX") ones the same CPU runs with OPENBLAS_CORETYPE set. OpenBLAS reads that
// variable when it is loaded, so a process cannot change it for itself: the programs say so.

#include <string>

namespace orrery::flex {

// The OpenBLAS kernel set this process runs ("SkylakeX", "Haswell", "Prescott", ...), empty when
// the BLAS is not OpenBLAS (found at run time, openblas_get_corename; no OpenBLAS header needed).
std::string BlasKernelName();

// One line of advice when OpenBLAS runs its generic kernels on a CPU with AVX-512 or AVX2 and
// OPENBLAS_CORETYPE is unset, naming the setting that selects the CPU's kernels; empty otherwise.
std::string BlasKernelAdvice();

}  // namespace orrery::flex
