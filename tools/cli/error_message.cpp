#include "tools/cli/error_message.h"

#include <cstdio>

namespace orrery::cli {
namespace {

// Length of the valid UTF-8 sequence starting at text[i] (2 to 4), or 0 when it is not one.
std::size_t Utf8Length(std::string_view text, std::size_t i) {
  const auto byte = [&](std::size_t k) { return static_cast<unsigned char>(text[k]); };
  const unsigned char c = byte(i);
  std::size_t n = 0;
  if (c >= 0xC2 && c <= 0xDF) n = 2;
  else if (c >= 0xE0 && c <= 0xEF) n = 3;
  else if (c >= 0xF0 && c <= 0xF4) n = 4;
  if (n == 0 || i + n > text.size()) return 0;
  for (std::size_t k = 1; k < n; ++k)
    if ((byte(i + k) & 0xC0) != 0x80) return 0;
  return n;
}

}  // namespace

std::string OneLine(std::string_view text) {
  std::string line;
  line.reserve(text.size());
  bool pending_space = false;
  for (std::size_t i = 0; i < text.size(); ++i) {
    const char c = text[i];
    // Any blank (line breaks included) becomes at most one space between words
    if (c == ' ' || c == '\n' || c == '\r' || c == '\t' || c == '\v' || c == '\f') {
      pending_space = !line.empty();
      continue;
    }
    if (pending_space) line.push_back(' ');
    pending_space = false;
    // Printable ASCII and valid UTF-8 as they are; control and stray bytes escaped
    const auto byte = static_cast<unsigned char>(c);
    if (byte >= 0x20 && byte < 0x7F) {
      line.push_back(c);
    } else if (const std::size_t n = byte >= 0x80 ? Utf8Length(text, i) : 0; n > 0) {
      line.append(text.substr(i, n));
      i += n - 1;
    } else {
      char escaped[8];
      std::snprintf(escaped, sizeof escaped, "\\x%02X", byte);
      line += escaped;
    }
  }
  return line.empty() ? std::string("unknown error") : line;
}

std::string Sanitized(std::string_view text, std::size_t max_chars) {
  std::string line = OneLine(text);
  if (line.size() <= max_chars) return line;
  // Cut at a character boundary (not inside a UTF-8 sequence)
  std::size_t cut = max_chars;
  while (cut > 0 && (static_cast<unsigned char>(line[cut]) & 0xC0) == 0x80) --cut;
  const std::size_t more = line.size() - cut;
  line.resize(cut);
  line += "... (" + std::to_string(more) + " more characters)";
  return line;
}

void ReportError(std::ostream& err, std::string_view reason) {
  err << "orrery: error: " << Sanitized(reason) << '\n' << std::flush;
}

}  // namespace orrery::cli
