#include "import/stl_reader.h"

#include <algorithm>
#include <cctype>
#include <cstdint>
#include <cstring>
#include <stdexcept>

#include "import/text_scanner.h"

namespace orrery {
namespace {

constexpr std::size_t kHeaderBytes = 84;
constexpr std::size_t kRecordBytes = 50;

std::uint32_t ReadU32(const char* p) {
  const auto* b = reinterpret_cast<const unsigned char*>(p);
  return std::uint32_t{b[0]} | std::uint32_t{b[1]} << 8 | std::uint32_t{b[2]} << 16 | std::uint32_t{b[3]} << 24;
}

float ReadF32(const char* p) {
  const std::uint32_t bits = ReadU32(p);
  float f;
  std::memcpy(&f, &bits, sizeof f);
  return f;
}

bool EqualsNoCase(std::string_view a, std::string_view b) {
  return a.size() == b.size() && std::equal(a.begin(), a.end(), b.begin(), [](char x, char y) {
           return std::tolower(static_cast<unsigned char>(x)) == std::tolower(static_cast<unsigned char>(y));
         });
}

bool StartsWithSolid(std::string_view bytes) {
  std::size_t i = 0;
  while (i < bytes.size() && std::isspace(static_cast<unsigned char>(bytes[i]))) ++i;
  return bytes.size() - i >= 5 && EqualsNoCase(bytes.substr(i, 5), "solid");
}

// Text has no control bytes other than whitespace in its first 512 bytes (a binary header
// that begins with "solid" is followed by float data).
bool LooksLikeText(std::string_view bytes) {
  const std::string_view head = bytes.substr(0, 512);
  return std::none_of(head.begin(), head.end(), [](char c) {
    const auto u = static_cast<unsigned char>(c);
    return u < 32 && !std::isspace(u);
  });
}

RawSurface ParseBinary(std::string_view bytes) {
  RawSurface raw;
  raw.format = "STL (binary)";
  const std::uint32_t n = ReadU32(bytes.data() + 80);
  raw.vertices.resize(std::size_t{3} * n);
  raw.triangles.resize(n);
  for (std::uint32_t t = 0; t < n; ++t) {
    const char* rec = bytes.data() + kHeaderBytes + kRecordBytes * t;
    for (int k = 0; k < 3; ++k) {
      const char* v = rec + 12 + 12 * k;  // after the normal
      raw.vertices[3 * t + k] = Vec3(ReadF32(v), ReadF32(v + 4), ReadF32(v + 8));
    }
    const int first = static_cast<int>(3 * t);
    raw.triangles[t] = {first, first + 1, first + 2};
  }
  raw.triangle_region.assign(n, 0);
  raw.region_names = {""};
  return raw;
}

// ASCII: a small state machine over the keywords; `where` gives "file:line: " for errors.
class AsciiParser {
 public:
  AsciiParser(std::string_view bytes, const std::string& source) : s_(bytes), source_(source) {}

  RawSurface Parse() {
    raw_.format = "STL (ASCII)";
    std::string_view tok;
    if (!s_.NextToken(tok) || !EqualsNoCase(tok, "solid")) Fail("expected 'solid'");
    for (;;) {
      ParseSolid();
      if (!s_.NextToken(tok)) break;  // end of file after endsolid
      if (!EqualsNoCase(tok, "solid")) Fail("expected 'solid' or the end of the file, got '" + Show(tok) + "'");
    }
    if (raw_.triangles.empty()) throw std::runtime_error(source_ + ": the STL file holds no triangles");
    return std::move(raw_);
  }

 private:
  [[noreturn]] void Fail(const std::string& what) const {
    throw std::runtime_error(source_ + ":" + std::to_string(s_.line()) + ": " + what);
  }
  static std::string Show(std::string_view tok) { return std::string(tok.substr(0, 40)); }

  void Expect(std::string_view keyword) {
    std::string_view tok;
    if (!s_.NextToken(tok)) Fail("expected '" + std::string(keyword) + "', got the end of the file");
    if (!EqualsNoCase(tok, keyword)) Fail("expected '" + std::string(keyword) + "', got '" + Show(tok) + "'");
  }

  double Number(const char* what) {
    std::string_view tok;
    double v = 0;
    if (!s_.NextToken(tok)) Fail(std::string("expected ") + what + ", got the end of the file");
    if (!ParseDouble(tok, v)) Fail(std::string("expected ") + what + ", got '" + Show(tok) + "'");
    return v;
  }

  // After "solid": the name (rest of the line), then facets up to "endsolid".
  void ParseSolid() {
    std::string_view name;
    s_.NextLine(name);
    while (!name.empty() && std::isspace(static_cast<unsigned char>(name.front()))) name.remove_prefix(1);
    while (!name.empty() && std::isspace(static_cast<unsigned char>(name.back()))) name.remove_suffix(1);
    const int region = static_cast<int>(raw_.region_names.size());
    raw_.region_names.emplace_back(name.substr(0, 256));
    std::string_view tok;
    for (;;) {
      if (!s_.NextToken(tok)) Fail("expected 'facet' or 'endsolid', got the end of the file");
      if (EqualsNoCase(tok, "endsolid")) {
        s_.SkipLine();  // optional name
        return;
      }
      if (!EqualsNoCase(tok, "facet")) Fail("expected 'facet' or 'endsolid', got '" + Show(tok) + "'");
      ParseFacet(region);
    }
  }

  void ParseFacet(int region) {
    Expect("normal");
    for (const char* c : {"the normal's x", "the normal's y", "the normal's z"}) Number(c);
    Expect("outer");
    Expect("loop");
    const int first = static_cast<int>(raw_.vertices.size());
    std::string_view tok;
    for (;;) {
      if (!s_.NextToken(tok)) Fail("expected 'vertex' or 'endloop', got the end of the file");
      if (EqualsNoCase(tok, "endloop")) break;
      if (!EqualsNoCase(tok, "vertex")) Fail("expected 'vertex' or 'endloop', got '" + Show(tok) + "'");
      const double x = Number("a coordinate"), y = Number("a coordinate"), z = Number("a coordinate");
      raw_.vertices.emplace_back(x, y, z);
    }
    const int count = static_cast<int>(raw_.vertices.size()) - first;
    if (count < 3) Fail("a facet needs at least 3 vertices, got " + std::to_string(count));
    for (int k = 1; k + 1 < count; ++k) {
      raw_.triangles.push_back({first, first + k, first + k + 1});
      raw_.triangle_region.push_back(region);
    }
    Expect("endfacet");
  }

  TextScanner s_;
  const std::string& source_;
  RawSurface raw_;
};

}  // namespace

bool IsBinaryStl(std::string_view bytes) {
  if (bytes.size() < kHeaderBytes) return false;
  const std::uint64_t n = ReadU32(bytes.data() + 80);
  return bytes.size() == kHeaderBytes + kRecordBytes * n;
}

RawSurface ParseStl(std::string_view bytes, const std::string& source) {
  if (IsBinaryStl(bytes)) {
    RawSurface raw = ParseBinary(bytes);
    if (raw.triangles.empty()) throw std::runtime_error(source + ": the binary STL file holds no triangles");
    return raw;
  }
  if (StartsWithSolid(bytes) && LooksLikeText(bytes)) return AsciiParser(bytes, source).Parse();
  if (bytes.size() < kHeaderBytes)
    throw std::runtime_error(source + ": not an STL file (" + std::to_string(bytes.size()) +
                             " bytes: shorter than a binary STL header and not ASCII 'solid ...')");
  const std::uint64_t n = ReadU32(bytes.data() + 80);
  throw std::runtime_error(source + ": binary STL header says " + std::to_string(n) + " triangles (" +
                           std::to_string(kHeaderBytes + kRecordBytes * n) + " bytes) but the file has " +
                           std::to_string(bytes.size()) + " bytes");
}

}  // namespace orrery
