#pragma once
// Helpers of the tests that run the `orrery` program or read its JSON output: a shell command's
// output and exit status, and the numbers of a JSON array or field (the flat JSON of
// tools/cli/json_writer.h; a key missing gives an empty array / NaN, which the tests' checks
// then reject).
#include <sys/wait.h>

#include <array>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <string>
#include <utility>
#include <vector>

namespace orrery::test_support {

// Output (stdout and stderr) and exit status of a shell command.
inline std::pair<std::string, int> RunCommand(const std::string& command) {
  std::string out;
  FILE* p = popen((command + " 2>&1").c_str(), "r");
  if (p == nullptr) return {"popen failed", -1};
  std::array<char, 4096> buf;
  while (std::fgets(buf.data(), buf.size(), p)) out += buf.data();
  const int status = pclose(p);
  return {out, WIFEXITED(status) ? WEXITSTATUS(status) : -1};
}

// The numbers of the JSON array at "key": [ ... ].
inline std::vector<double> JsonArray(const std::string& json, const std::string& key) {
  std::string pattern = "\"";
  pattern += key;
  pattern += "\"";
  std::vector<double> v;
  std::size_t at = json.find(pattern);
  if (at == std::string::npos) return v;
  at = json.find('[', at + pattern.size());
  if (at == std::string::npos) return v;
  const char* p = json.c_str() + at + 1;
  for (;;) {
    while (*p == ' ' || *p == '\n' || *p == ',') ++p;
    if (*p == ']' || *p == '\0') return v;
    char* end = nullptr;
    v.push_back(std::strtod(p, &end));
    if (end == p) return v;
    p = end;
  }
}

// The number of the JSON field "key": value.
inline double JsonNumber(const std::string& json, const std::string& key) {
  std::string pattern = "\"";
  pattern += key;
  pattern += "\"";
  const std::size_t at = json.find(pattern);
  if (at == std::string::npos) return std::numeric_limits<double>::quiet_NaN();
  const std::size_t colon = json.find(':', at + pattern.size());
  if (colon == std::string::npos) return std::numeric_limits<double>::quiet_NaN();
  return std::strtod(json.c_str() + colon + 1, nullptr);
}

}  // namespace orrery::test_support
