#pragma once
// Tokens, lines and numbers over a file's bytes, for the text readers of import/ (STL, OBJ, gmsh
// .msh, Matrix Market, CalculiX matrices). Never reads past the end of its buffer, counts lines
// (1-based) for messages, parses numbers with std::from_chars (no locale, no exceptions).
//
// Usage:
//   TextScanner s(bytes);
//   std::string_view word;
//   while (s.NextToken(word)) { if (word == "vertex") ...; }
//   double x;  if (!ParseDouble(word, x)) throw ...;   // "1e3", "+2", "-0.5"; not "1,5"
#include <cstdint>
#include <string_view>

namespace orrery {

// A whole token as a double (a leading '+' allowed); false for anything else.
bool ParseDouble(std::string_view token, double& value);
// A whole token as a 64-bit signed integer (a leading '+' allowed); false for anything else or
// a value out of range.
bool ParseInt64(std::string_view token, std::int64_t& value);

class TextScanner {
 public:
  explicit TextScanner(std::string_view data) : data_(data) {}

  // The next whitespace-separated token (spaces, tabs, CR and LF), crossing lines; false at the end.
  bool NextToken(std::string_view& token);
  // The next token on the current line only; false at the end of the line (not consumed).
  bool NextTokenOnLine(std::string_view& token);
  // The rest of the current line (without CR / LF), and moves to the next line; false at the end.
  bool NextLine(std::string_view& line);
  // Skips to the start of the next line.
  void SkipLine();
  bool AtEnd() const { return pos_ >= data_.size(); }

  // The line of the last token or line returned (1-based).
  int line() const { return token_line_; }
  std::size_t position() const { return pos_; }
  std::size_t remaining() const { return data_.size() - pos_; }
  // Moves to byte `pos` (clamped to the size), keeping the line count right; used around binary
  // blocks.
  void Seek(std::size_t pos);
  std::string_view data() const { return data_; }

 private:
  std::string_view data_;
  std::size_t pos_ = 0;
  int line_ = 1;        // line at pos_
  int token_line_ = 1;  // line of the last token
};

}  // namespace orrery
