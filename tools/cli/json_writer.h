#pragma once
// A small JSON writer for the machine-readable output of the `orrery` commands (--json). No JSON
// library is packaged; this one writes RFC 8259 text with two-space indentation:
//   - strings escaped (", \, control characters as \n, \t, ... or \u00XX; other bytes, UTF-8
//     included, pass through);
//   - numbers in the shortest form that reads back as the same double; NaN and infinities, which
//     JSON cannot hold, become null;
//   - commas and nesting tracked by the writer; misuse (a value where a key is due, unbalanced
//     End*) throws std::logic_error.
//
// Usage:
//   JsonWriter w(std::cout);
//   w.BeginObject().Key("frequencies_hz").BeginArray().Number(0).Number(743.2).EndArray();
//   w.Key("scene").String("lin_parker").EndObject();   // then a final newline is written
#include <ostream>
#include <string>
#include <string_view>
#include <vector>

namespace orrery::cli {

// `text` as a JSON string literal, quotes included.
std::string JsonString(std::string_view text);
// `x` as a JSON number (shortest round-trip form), "null" if not finite.
std::string JsonNumber(double x);

class JsonWriter {
 public:
  explicit JsonWriter(std::ostream& out) : out_(out) {}

  JsonWriter& BeginObject();
  JsonWriter& EndObject();
  JsonWriter& BeginArray();
  JsonWriter& EndArray();
  JsonWriter& Key(std::string_view key);  // inside an object, before each value
  JsonWriter& String(std::string_view value);
  JsonWriter& Number(double value);       // null if not finite
  JsonWriter& Int(long long value);
  JsonWriter& Bool(bool value);
  JsonWriter& Null();

 private:
  struct Level {
    bool object = false;
    int count = 0;
  };
  void BeforeValue();
  void Open(char c, bool object);
  void Close(char c, bool object);
  void Newline();

  std::ostream& out_;
  std::vector<Level> stack_;
  bool after_key_ = false;
};

}  // namespace orrery::cli
