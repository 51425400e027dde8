#include "flex/blas_kernels.h"

#include <dlfcn.h>

#include <cstdlib>

namespace orrery::flex {

std::string BlasKernelName() {
  using CoreName = char* (*)();
  const auto name = reinterpret_cast<CoreName>(dlsym(RTLD_DEFAULT, "openblas_get_corename"));
  if (name == nullptr) return "";
  const char* core = name();
  return core != nullptr ? core : "";
}

std::string BlasKernelAdvice() {
  if (std::getenv("OPENBLAS_CORETYPE") != nullptr) return "";
  const std::string core = BlasKernelName();
  if (core != "Prescott" && core != "Core2" && core != "Nehalem") return "";
  const char* better = __builtin_cpu_supports("avx512f")  ? "SkylakeX"
                       : __builtin_cpu_supports("avx2") ? "Haswell"
                                                        : nullptr;
  if (better == nullptr) return "";
  return std::string("OpenBLAS runs its generic '") + core +
         "' kernels on this CPU (a model newer than the installed OpenBLAS); run with "
         "OPENBLAS_CORETYPE=" + better +
         " for its vector kernels (the sparse factorizations run about 2 times faster, "
         "docs/performance.md)";
}

}  // namespace orrery::flex
