#include "import/obj_reader.h"

#include <map>
#include <set>
#include <stdexcept>

#include "import/text_scanner.h"

namespace orrery {
namespace {

class ObjParser {
 public:
  ObjParser(std::string_view bytes, const std::string& source) : s_(bytes), source_(source) {}

  RawSurface Parse() {
    raw_.format = "OBJ";
    std::string_view line;
    while (s_.NextLine(line)) ParseLine(line);
    if (raw_.triangles.empty()) throw std::runtime_error(source_ + ": the OBJ file holds no faces");
    if (raw_.region_names.empty()) raw_.region_names.push_back("");
    return std::move(raw_);
  }

 private:
  [[noreturn]] void Fail(const std::string& what) const {
    throw std::runtime_error(source_ + ":" + std::to_string(line_) + ": " + what);
  }
  static std::string Show(std::string_view tok) { return std::string(tok.substr(0, 40)); }

  void ParseLine(std::string_view line) {
    line_ = s_.line();
    if (const std::size_t hash = line.find('#'); hash != std::string_view::npos) line = line.substr(0, hash);
    TextScanner words(line);
    std::string_view keyword;
    if (!words.NextToken(keyword)) return;
    if (keyword == "v") return Vertex(words);
    if (keyword == "f") return Face(words);
    if (keyword == "g" || keyword == "o") return Region(keyword, words);
    if (skipped_.insert(std::string(keyword.substr(0, 16))).second)
      raw_.notes.push_back(source_ + ":" + std::to_string(line_) + ": '" + Show(keyword) + "' statements ignored");
  }

  void Vertex(TextScanner& words) {
    double x[3];
    for (double& c : x) {
      std::string_view tok;
      if (!words.NextToken(tok)) Fail("a vertex needs three coordinates");
      if (!ParseDouble(tok, c)) Fail("expected a coordinate, got '" + Show(tok) + "'");
    }
    raw_.vertices.emplace_back(x[0], x[1], x[2]);
  }

  // A corner "i[/t[/n]]": the vertex index, resolved and checked.
  int Corner(std::string_view tok) const {
    const std::string_view index = tok.substr(0, tok.find('/'));
    std::int64_t i = 0;
    if (!ParseInt64(index, i)) Fail("expected a vertex index, got '" + Show(tok) + "'");
    const auto n = static_cast<std::int64_t>(raw_.vertices.size());
    const std::int64_t resolved = i > 0 ? i - 1 : n + i;
    if (i == 0 || resolved < 0 || resolved >= n)
      Fail("face refers to vertex " + std::to_string(i) + ", but " + std::to_string(n) + " are defined so far");
    return static_cast<int>(resolved);
  }

  void Face(TextScanner& words) {
    corners_.clear();
    for (std::string_view tok; words.NextToken(tok);) corners_.push_back(Corner(tok));
    if (corners_.size() < 3) Fail("a face needs at least 3 vertices, got " + std::to_string(corners_.size()));
    if (region_ < 0) region_ = RegionIndex("");
    for (std::size_t k = 1; k + 1 < corners_.size(); ++k) {
      raw_.triangles.push_back({corners_[0], corners_[k], corners_[k + 1]});
      raw_.triangle_region.push_back(region_);
    }
  }

  // "g a b" names the group "a b"; a group, once named, keeps its region index.
  void Region(std::string_view keyword, TextScanner& words) {
    std::string name;
    for (std::string_view tok; words.NextToken(tok);) {
      if (!name.empty()) name += ' ';
      name.append(tok.substr(0, 256));
    }
    if (keyword == "o" && name.empty()) return;
    region_ = RegionIndex(name);
  }

  int RegionIndex(const std::string& name) {
    const auto [it, added] = regions_.emplace(name, static_cast<int>(raw_.region_names.size()));
    if (added) raw_.region_names.push_back(name);
    return it->second;
  }

  TextScanner s_;
  const std::string& source_;
  RawSurface raw_;
  int line_ = 0;
  int region_ = -1;  // none yet
  std::map<std::string, int> regions_;
  std::set<std::string> skipped_;
  std::vector<int> corners_;
};

}  // namespace

RawSurface ParseObj(std::string_view bytes, const std::string& source) { return ObjParser(bytes, source).Parse(); }

}  // namespace orrery
