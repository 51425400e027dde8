// Replays, with the normal build, every input the fuzzers start from (tools/fuzz/corpus/<reader>/)
// and every input that once broke a reader (tests/fuzz_regressions/<reader>/, kept when the bug
// was fixed) through the same code the fuzzers run (tools/fuzz/fuzz_targets.h). A reader may
// refuse an input with an exception; it must not crash, abort or hang.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "tools/fuzz/fuzz_targets.h"

namespace orrery::fuzz {
namespace {

namespace fs = std::filesystem;

void ReplayFile(const Target& target, const fs::path& file) {
  std::ifstream in(file, std::ios::binary);
  std::ostringstream bytes;
  bytes << in.rdbuf();
  const std::string data = bytes.str();
  SCOPED_TRACE(file.string());
  target.run(reinterpret_cast<const std::uint8_t*>(data.data()), data.size());
}

int Replay(const Target& target, const fs::path& dir) {
  std::error_code ec;
  if (!fs::is_directory(dir, ec)) return 0;
  int count = 0;
  for (const fs::directory_entry& entry : fs::directory_iterator(dir)) {
    if (!entry.is_regular_file()) continue;
    ReplayFile(target, entry.path());
    ++count;
  }
  return count;
}

TEST(FuzzRegressionTest, CorpusAndRegressionInputsReplayWithoutCrashing) {
  const fs::path root(ORRERY_SOURCE_DIR);
  for (const Target& target : kTargets) {
    int seeds = Replay(target, root / "tools" / "fuzz" / "corpus" / target.name);
    // The scene fuzzer starts from these ready scenes (tools/fuzz/run_fuzz.sh)
    if (std::string(target.name) == "scene")
      for (const char* scene : {"pendulum.yaml", "slider_crank.yaml", "lin_parker_1999_n3.yaml"}) {
        ReplayFile(target, root / "models" / "scenes" / scene);
        ++seeds;
      }
    const int regressions = Replay(target, root / "tests" / "fuzz_regressions" / target.name);
    std::printf("  %s: %d seeds, %d regression inputs\n", target.name, seeds, regressions);
    EXPECT_GT(seeds, 0) << target.name;
  }
}

}  // namespace
}  // namespace orrery::fuzz
