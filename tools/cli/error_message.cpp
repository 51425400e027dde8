#include "tools/cli/error_message.h"

namespace orrery::cli {

std::string OneLine(std::string_view text) {
  std::string line;
  line.reserve(text.size());
  bool pending_space = false;
  for (const char c : text) {
    // Any blank (line breaks included) becomes at most one space between words
    if (c == ' ' || c == '\n' || c == '\r' || c == '\t' || c == '\v' || c == '\f') {
      pending_space = !line.empty();
      continue;
    }
    if (pending_space) line.push_back(' ');
    pending_space = false;
    line.push_back(c);
  }
  return line.empty() ? std::string("unknown error") : line;
}

void ReportError(std::ostream& err, std::string_view reason) {
  err << "orrery: error: " << OneLine(reason) << '\n' << std::flush;
}

}  // namespace orrery::cli
