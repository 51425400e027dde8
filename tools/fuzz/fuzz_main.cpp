// The libFuzzer entry point of one fuzzer program: ORRERY_FUZZ_TARGET (set by tools/fuzz/CMake) is
// the index of its reader in kTargets (fuzz_targets.h).
#include <cstddef>
#include <cstdint>

#include "tools/fuzz/fuzz_targets.h"

// The reader chosen at compile time: only its code is referenced, so a reader's program links
// without the rest of the engine (tools/fuzz/CMakeLists.txt).
constexpr auto kRun = orrery::fuzz::kTargets[ORRERY_FUZZ_TARGET].run;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  kRun(data, size);
  return 0;
}
