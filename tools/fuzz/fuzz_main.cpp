// The libFuzzer entry point of one fuzzer program: ORRERY_FUZZ_TARGET (set by tools/fuzz/CMake) is
// the index of its reader in kTargets (fuzz_targets.h).
#include <cstddef>
#include <cstdint>

#include "tools/fuzz/fuzz_targets.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  orrery::fuzz::kTargets[ORRERY_FUZZ_TARGET].run(data, size);
  return 0;
}
