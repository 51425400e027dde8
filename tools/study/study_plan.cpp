#include "tools/study/study_plan.h"

#include <charconv>
#include <cmath>
#include <filesystem>
#include <random>
#include <stdexcept>
#include <system_error>

#include "import/scene.h"

namespace orrery::study {
namespace {

// Shortest text that reads back as the same double
std::string ShortestText(double value) {
  char buffer[64];
  const auto [end, ec] = std::to_chars(buffer, buffer + sizeof buffer, value);
  return ec == std::errc() ? std::string(buffer, end) : std::to_string(value);
}

// The entries of one block: each a list of values for the block's keys
struct BlockEntries {
  std::vector<std::string> keys, at;
  std::vector<std::vector<std::string>> entries;
};

BlockEntries AxisEntries(const StudyBlock& block) {
  BlockEntries e;
  for (const StudyAxis& axis : block.axes) {
    e.keys.push_back(axis.key);
    e.at.push_back(axis.at);
  }
  // Zipped axes have equal lengths (checked by the reader)
  const std::size_t n = block.axes.front().values.size();
  for (std::size_t i = 0; i < n; ++i) {
    std::vector<std::string>& entry = e.entries.emplace_back();
    for (const StudyAxis& axis : block.axes) entry.push_back(axis.values[i]);
  }
  return e;
}

BlockEntries RandomEntries(const StudyBlock& block) {
  BlockEntries e;
  for (const StudyRandomKey& k : block.keys) {
    e.keys.push_back(k.key);
    e.at.push_back(k.at);
  }
  std::mt19937_64 engine(block.seed);
  auto draw = [&engine] { return static_cast<double>(engine() >> 11) * 0x1.0p-53; };
  for (int s = 0; s < block.samples; ++s) {
    std::vector<std::string>& entry = e.entries.emplace_back();
    for (const StudyRandomKey& k : block.keys) {
      const double u = draw();
      switch (k.distribution) {
        case StudyDistribution::kUniform:
          entry.push_back(ShortestText(k.low + (k.high - k.low) * u));
          break;
        case StudyDistribution::kLogUniform:
          entry.push_back(
              ShortestText(std::exp(std::log(k.low) + (std::log(k.high) - std::log(k.low)) * u)));
          break;
        case StudyDistribution::kChoice: {
          const auto i = static_cast<std::size_t>(u * static_cast<double>(k.choices.size()));
          entry.push_back(k.choices[std::min(i, k.choices.size() - 1)]);
          break;
        }
      }
    }
  }
  return e;
}

}  // namespace

std::vector<std::string> StudyPlan::Overrides(const RunSpec& run) const {
  std::vector<std::string> overrides;
  for (const StudySetting& s : study.settings) overrides.push_back(s.key + "=" + s.value);
  for (std::size_t i = 0; i < parameters.size(); ++i)
    overrides.push_back(parameters[i] + "=" + run.values[i]);
  return overrides;
}

StudyPlan MakeStudyPlan(StudyDescription study) {
  StudyPlan plan;
  // Entries of every block and the number of runs
  std::vector<BlockEntries> blocks;
  long long runs = 1;
  for (const StudyBlock& block : study.blocks) {
    blocks.push_back(block.kind == StudyBlock::Kind::kRandom ? RandomEntries(block)
                                                             : AxisEntries(block));
    runs *= static_cast<long long>(blocks.back().entries.size());
    if (runs > kMaxStudyRuns)
      throw std::runtime_error(study.file + ": axes: the study has more than " +
                               std::to_string(kMaxStudyRuns) + " runs");
    plan.parameters.insert(plan.parameters.end(), blocks.back().keys.begin(),
                           blocks.back().keys.end());
    plan.parameter_at.insert(plan.parameter_at.end(), blocks.back().at.begin(),
                             blocks.back().at.end());
  }
  // Cartesian product, the last block fastest
  plan.runs.resize(static_cast<std::size_t>(runs));
  for (long long r = 0; r < runs; ++r) {
    RunSpec& run = plan.runs[static_cast<std::size_t>(r)];
    run.index = static_cast<int>(r);
    run.values.resize(plan.parameters.size());
    long long rest = r;
    std::size_t column = plan.parameters.size();
    for (std::size_t b = blocks.size(); b-- > 0;) {
      const auto n = static_cast<long long>(blocks[b].entries.size());
      const std::vector<std::string>& entry = blocks[b].entries[static_cast<std::size_t>(rest % n)];
      rest /= n;
      column -= entry.size();
      std::copy(entry.begin(), entry.end(),
                run.values.begin() + static_cast<std::ptrdiff_t>(column));
    }
  }
  plan.study = std::move(study);
  return plan;
}

void CheckStudyScene(const StudyPlan& plan) {
  const StudyDescription& s = plan.study;
  std::error_code ec;
  if (!std::filesystem::is_regular_file(s.scene_path, ec))
    throw std::runtime_error(s.scene_at + ": no scene file " + s.scene_path);
  const std::vector<std::string> overrides = plan.Overrides(plan.runs.front());
  try {
    LoadScene(s.scene_path, overrides);
  } catch (const std::exception& e) {
    // The setting or axis the scene's message names ("FILE: --set KEY: reason"), else the scene
    const std::string message = e.what();
    std::vector<std::pair<std::string, std::string>> keys;
    for (const StudySetting& setting : s.settings) keys.emplace_back(setting.key, setting.at);
    for (std::size_t i = 0; i < plan.parameters.size(); ++i)
      keys.emplace_back(plan.parameters[i], plan.parameter_at[i]);
    for (const auto& [key, at] : keys)
      if (message.find(": --set " + key + ": ") != std::string::npos)
        throw std::runtime_error(at + ": " + message);
    throw std::runtime_error(s.scene_at + ": " + message);
  }
}

}  // namespace orrery::study
