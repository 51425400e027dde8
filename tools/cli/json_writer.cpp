#include "tools/cli/json_writer.h"

#include <charconv>
#include <cmath>
#include <cstdio>
#include <stdexcept>

namespace orrery::cli {

std::string JsonString(std::string_view text) {
  std::string s = "\"";
  for (const char c : text) {
    switch (c) {
      case '"': s += "\\\""; break;
      case '\\': s += "\\\\"; break;
      case '\b': s += "\\b"; break;
      case '\f': s += "\\f"; break;
      case '\n': s += "\\n"; break;
      case '\r': s += "\\r"; break;
      case '\t': s += "\\t"; break;
      default:
        // Other control characters as \u00XX; everything else (UTF-8 included) as is
        if (static_cast<unsigned char>(c) < 0x20) {
          char buffer[8];
          std::snprintf(buffer, sizeof buffer, "\\u%04x", static_cast<unsigned>(static_cast<unsigned char>(c)));
          s += buffer;
        } else {
          s += c;
        }
    }
  }
  return s + "\"";
}

std::string JsonNumber(double x) {
  if (!std::isfinite(x)) return "null";
  if (x == 0) return "0";  // no "-0"
  char buffer[64];
  const auto [end, ec] = std::to_chars(buffer, buffer + sizeof buffer, x);
  if (ec != std::errc()) return "null";
  return std::string(buffer, end);
}

void JsonWriter::Newline() {
  out_ << '\n' << std::string(2 * stack_.size(), ' ');
}

// Comma and line break before a value (or, in an object, before its key)
void JsonWriter::BeforeValue() {
  if (after_key_) {
    after_key_ = false;
    return;
  }
  if (!stack_.empty()) {
    if (stack_.back().object) throw std::logic_error("JsonWriter: a value inside an object needs a key");
    if (stack_.back().count++ > 0) out_ << ',';
    Newline();
  }
}

void JsonWriter::Open(char c, bool object) {
  BeforeValue();
  out_ << c;
  stack_.push_back({object, 0});
}

void JsonWriter::Close(char c, bool object) {
  if (stack_.empty() || stack_.back().object != object || after_key_)
    throw std::logic_error("JsonWriter: unbalanced End");
  const bool empty = stack_.back().count == 0;
  stack_.pop_back();
  if (!empty) Newline();
  out_ << c;
  if (stack_.empty()) out_ << '\n' << std::flush;
}

JsonWriter& JsonWriter::BeginObject() { Open('{', true); return *this; }
JsonWriter& JsonWriter::EndObject() { Close('}', true); return *this; }
JsonWriter& JsonWriter::BeginArray() { Open('[', false); return *this; }
JsonWriter& JsonWriter::EndArray() { Close(']', false); return *this; }

JsonWriter& JsonWriter::Key(std::string_view key) {
  if (stack_.empty() || !stack_.back().object || after_key_)
    throw std::logic_error("JsonWriter: a key outside an object");
  if (stack_.back().count++ > 0) out_ << ',';
  Newline();
  out_ << JsonString(key) << ": ";
  after_key_ = true;
  return *this;
}

JsonWriter& JsonWriter::String(std::string_view value) { BeforeValue(); out_ << JsonString(value); return *this; }
JsonWriter& JsonWriter::Number(double value) { BeforeValue(); out_ << JsonNumber(value); return *this; }
JsonWriter& JsonWriter::Int(long long value) { BeforeValue(); out_ << value; return *this; }
JsonWriter& JsonWriter::Bool(bool value) { BeforeValue(); out_ << (value ? "true" : "false"); return *this; }
JsonWriter& JsonWriter::Null() { BeforeValue(); out_ << "null"; return *this; }

}  // namespace orrery::cli
