#include "import/text_scanner.h"

#include <charconv>

namespace orrery {
namespace {

bool IsSpace(char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\n' || c == '\v' || c == '\f'; }

}  // namespace

bool ParseDouble(std::string_view token, double& value) {
  if (!token.empty() && token.front() == '+') token.remove_prefix(1);
  if (token.empty() || token.front() == '+' || (token.front() == '-' && token.size() > 1 && token[1] == '+'))
    return false;
  const auto [end, ec] = std::from_chars(token.data(), token.data() + token.size(), value);
  return ec == std::errc() && end == token.data() + token.size();
}

bool ParseInt64(std::string_view token, std::int64_t& value) {
  if (!token.empty() && token.front() == '+') token.remove_prefix(1);
  if (token.empty() || token.front() == '+') return false;
  const auto [end, ec] = std::from_chars(token.data(), token.data() + token.size(), value);
  return ec == std::errc() && end == token.data() + token.size();
}

bool TextScanner::NextToken(std::string_view& token) {
  // Skip whitespace, counting new lines
  while (pos_ < data_.size() && IsSpace(data_[pos_])) {
    if (data_[pos_] == '\n') ++line_;
    ++pos_;
  }
  if (pos_ >= data_.size()) return false;
  const std::size_t start = pos_;
  while (pos_ < data_.size() && !IsSpace(data_[pos_])) ++pos_;
  token = data_.substr(start, pos_ - start);
  token_line_ = line_;
  return true;
}

bool TextScanner::NextTokenOnLine(std::string_view& token) {
  while (pos_ < data_.size() && IsSpace(data_[pos_]) && data_[pos_] != '\n') ++pos_;
  if (pos_ >= data_.size() || data_[pos_] == '\n') return false;
  return NextToken(token);
}

bool TextScanner::NextLine(std::string_view& line) {
  if (pos_ >= data_.size()) return false;
  const std::size_t start = pos_;
  while (pos_ < data_.size() && data_[pos_] != '\n') ++pos_;
  std::size_t end = pos_;
  if (end > start && data_[end - 1] == '\r') --end;
  line = data_.substr(start, end - start);
  token_line_ = line_;
  if (pos_ < data_.size()) {
    ++pos_;
    ++line_;
  }
  return true;
}

void TextScanner::SkipLine() {
  std::string_view ignored;
  NextLine(ignored);
}

void TextScanner::Seek(std::size_t pos) {
  if (pos > data_.size()) pos = data_.size();
  if (pos < pos_) pos_ = 0, line_ = 1;  // backwards: count again from the start
  for (std::size_t i = pos_; i < pos; ++i)
    if (data_[i] == '\n') ++line_;
  pos_ = pos;
}

}  // namespace orrery
