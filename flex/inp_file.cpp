#include "flex/inp_file.h"

#include "mbd/file_checks.h"

#include <cctype>
#include <cerrno>
#include <charconv>
#include <cstdio>
#include <cstring>
#include <cstdlib>
#include <fstream>
#include <map>
#include <optional>
#include <stdexcept>

namespace orrery::flex {
namespace {

std::string Trim(std::string_view s) {
  std::size_t a = 0, b = s.size();
  while (a < b && std::isspace(static_cast<unsigned char>(s[a]))) ++a;
  while (b > a && std::isspace(static_cast<unsigned char>(s[b - 1]))) --b;
  return std::string(s.substr(a, b - a));
}

std::vector<std::string> SplitCommas(std::string_view line) {
  std::vector<std::string> out;
  std::size_t start = 0;
  for (;;) {
    const std::size_t comma = line.find(',', start);
    out.push_back(Trim(line.substr(start, comma == std::string_view::npos ? std::string_view::npos : comma - start)));
    if (comma == std::string_view::npos) break;
    start = comma + 1;
  }
  return out;
}

// A keyword line: "*NAME, KEY=VALUE, FLAG" (name and keys upper case, values as written).
struct Keyword {
  std::string name;
  std::map<std::string, std::string> params;
  int line = 0;
};

// Where a problem is: "file:line: *KEYWORD: "
struct Context {
  const std::string& file;
  [[noreturn]] void Fail(int line, const std::string& keyword, const std::string& reason) const {
    throw std::runtime_error(file + ":" + std::to_string(line) + ": " + (keyword.empty() ? "" : "*" + keyword + ": ") + reason);
  }
};

std::optional<long long> ParseInt(const std::string& s) {
  long long v = 0;
  const char* end = s.data() + s.size();
  const auto [p, ec] = std::from_chars(s.data(), end, v);
  if (ec != std::errc() || p != end) return std::nullopt;
  return v;
}

std::optional<double> ParseDouble(const std::string& s) {
  if (s.empty()) return std::nullopt;
  // Fortran exponents (1.0D3) are accepted as well
  std::string t = s;
  for (char& c : t)
    if (c == 'd' || c == 'D') c = 'e';
  char* end = nullptr;
  errno = 0;
  const double v = std::strtod(t.c_str(), &end);
  if (end != t.c_str() + t.size() || errno == ERANGE) return std::nullopt;
  return v;
}

// Records collected in a first pass; the mesh is built once all nodes and elements are known.
struct NodeRecord { int id; Eigen::Vector3d p; int line; };
struct ElementRecord { int id; ElementType type; std::vector<int> nodes; int line; };
struct SetRecord {  // one data line of *NSET / *ELSET, or the NSET= / ELSET= of *NODE / *ELEMENT
  bool nodes;       // node set (else element set)
  std::string name;
  std::vector<std::string> items;  // ids or set names
  bool generate = false;
  int line;
  std::string keyword;
};
struct MaterialRecord { IsotropicMaterial m; bool has_elastic = false, has_density = false; int line; };
struct SectionRecord { std::string elset, material; int line; };

// First pass over the file: keyword lines open blocks, data lines (continued by a trailing comma)
// become records. Then BuildMesh turns the records into the mesh.
class InpParser {
 public:
  InpParser(const std::string& source, InpReadResult& result) : source_(source), ctx_{source}, result_(result) {}

  void ReadLine(const std::string& line, int line_no) {
    if (line[0] == '*') {
      if (!pending_.empty()) ctx_.Fail(pending_line_, kw_.name, "data line continued with a comma but no data follows");
      ReadKeyword(line, line_no);
    } else {
      ReadDataLine(line, line_no);
    }
  }

  void Finish() {
    if (!pending_.empty()) ctx_.Fail(pending_line_, kw_.name, "data line continued with a comma but the file ends");
    AddNodesAndElements();
    AddSets();
    AssignSections();
  }

 private:
  enum class Block { kNone, kNode, kElement, kNset, kElset, kElastic, kDensity, kSection, kSkip };

  // A keyword's parameter; "" when absent (an error if required).
  std::string Param(const char* key, bool required) const {
    const auto it = kw_.params.find(key);
    if (it == kw_.params.end() || it->second.empty()) {
      if (required) ctx_.Fail(kw_.line, kw_.name, std::string("missing parameter ") + key + "=");
      return "";
    }
    return it->second;
  }

  // "*NAME, KEY=VALUE, FLAG": the block it opens.
  void ReadKeyword(const std::string& line, int line_no) {
    const std::vector<std::string> parts = SplitCommas(std::string_view(line).substr(1));
    kw_ = Keyword{UpperName(parts[0]), {}, line_no};
    for (std::size_t i = 1; i < parts.size(); ++i) {
      if (parts[i].empty()) continue;
      const std::size_t eq = parts[i].find('=');
      if (eq == std::string::npos) kw_.params[UpperName(parts[i])] = "";
      else kw_.params[UpperName(Trim(parts[i].substr(0, eq)))] = Trim(parts[i].substr(eq + 1));
    }
    generate_ = kw_.params.contains("GENERATE");
    const std::string& name = kw_.name;
    if (name == "NODE") {
      block_ = Block::kNode;
      set_name_ = Param("NSET", false);
    } else if (name == "ELEMENT") {
      block_ = Block::kElement;
      const std::string type = Param("TYPE", true);
      element_type_ = ElementTypeFromCalculixName(type);
      if (!element_type_) ctx_.Fail(line_no, name, "element type " + type + " not supported (C3D4, C3D10, C3D8, C3D20)");
      set_name_ = Param("ELSET", false);
    } else if (name == "NSET" || name == "ELSET") {
      block_ = name == "NSET" ? Block::kNset : Block::kElset;
      set_name_ = Param(name.c_str(), true);
    } else if (name == "MATERIAL") {
      block_ = Block::kNone;
      materials_.push_back({.m = {.name = UpperName(Param("NAME", true))}, .line = line_no});
    } else if (name == "ELASTIC" || name == "DENSITY") {
      if (materials_.empty()) ctx_.Fail(line_no, name, "outside a *MATERIAL");
      const std::string type = UpperName(Param("TYPE", false));
      if (name == "ELASTIC" && !type.empty() && type != "ISO" && type != "ISOTROPIC")
        ctx_.Fail(line_no, name, "TYPE=" + type + " not supported (isotropic only)");
      block_ = name == "ELASTIC" ? Block::kElastic : Block::kDensity;
    } else if (name == "SOLID SECTION") {
      block_ = Block::kSection;
      sections_.push_back({Param("ELSET", true), UpperName(Param("MATERIAL", true)), line_no});
    } else if (name == "INCLUDE") {
      ctx_.Fail(line_no, name, "not supported (merge the included file into this one)");
    } else {
      block_ = Block::kSkip;
      result_.notes.push_back(source_ + ":" + std::to_string(line_no) + ": *" + name + " ignored");
    }
  }

  // A data line; a trailing comma continues it on the next line (an element: until it has its
  // 1 + NodeCount values, however many lines they take).
  void ReadDataLine(const std::string& line, int line_no) {
    if (block_ == Block::kSkip) return;
    if (block_ == Block::kNone) ctx_.Fail(line_no, "", "data line outside a keyword block");
    std::vector<std::string> values = SplitCommas(line);
    const bool continued = !values.empty() && values.back().empty();
    if (continued) values.pop_back();
    if (pending_.empty()) pending_line_ = line_no;
    pending_.insert(pending_.end(), values.begin(), values.end());
    if (block_ == Block::kElement) {
      const std::size_t need = 1 + NodeCount(*element_type_);
      if (pending_.size() < need) return;
      if (pending_.size() > need)
        ctx_.Fail(line_no, kw_.name, std::to_string(pending_.size() - 1) + " node ids for a " +
                                         CalculixName(*element_type_) + " element, expected " + std::to_string(need - 1));
    } else if (continued) {
      return;
    }
    values.swap(pending_);
    pending_.clear();
    StoreRecord(values, pending_line_);
  }

  int AsInt(const std::string& s, const char* what, int at) const {
    const std::optional<long long> v = ParseInt(s);
    if (!v || *v < 1 || *v > 2147483647) ctx_.Fail(at, kw_.name, std::string(what) + " '" + s + "' is not a positive integer");
    return static_cast<int>(*v);
  }
  double AsDouble(const std::string& s, const char* what, int at) const {
    const std::optional<double> v = ParseDouble(s);
    if (!v) ctx_.Fail(at, kw_.name, std::string(what) + " '" + s + "' is not a number");
    return *v;
  }

  // One complete data record of the open block, first line `at`.
  void StoreRecord(const std::vector<std::string>& values, int at) {
    switch (block_) {
      case Block::kNode: {
        if (values.size() < 2 || values.size() > 4) ctx_.Fail(at, kw_.name, "expected id, x, y, z");
        Eigen::Vector3d p = Eigen::Vector3d::Zero();
        for (std::size_t i = 1; i < values.size(); ++i)
          p(i - 1) = values[i].empty() ? 0.0 : AsDouble(values[i], "coordinate", at);
        nodes_.push_back({AsInt(values[0], "node id", at), p, at});
        if (!set_name_.empty()) sets_.push_back({true, set_name_, {values[0]}, false, at, kw_.name});
        break;
      }
      case Block::kElement: {
        ElementRecord e{AsInt(values[0], "element id", at), *element_type_, {}, at};
        for (std::size_t i = 1; i < values.size(); ++i) e.nodes.push_back(AsInt(values[i], "node id", at));
        if (!set_name_.empty()) sets_.push_back({false, set_name_, {values[0]}, false, at, kw_.name});
        elements_.push_back(std::move(e));
        break;
      }
      case Block::kNset:
      case Block::kElset: {
        std::vector<std::string> items;
        for (const std::string& v : values)
          if (!v.empty()) items.push_back(v);
        if (generate_ && (items.size() < 2 || items.size() > 3))
          ctx_.Fail(at, kw_.name, "GENERATE expects first, last[, increment]");
        sets_.push_back({block_ == Block::kNset, set_name_, items, generate_, at, kw_.name});
        break;
      }
      case Block::kElastic: {
        if (values.size() < 2) ctx_.Fail(at, kw_.name, "expected E, nu");
        if (values.size() > 2 && !values[2].empty()) ctx_.Fail(at, kw_.name, "temperature-dependent data not supported");
        materials_.back().m.youngs_modulus_pa = AsDouble(values[0], "E", at);
        materials_.back().m.poissons_ratio = AsDouble(values[1], "nu", at);
        materials_.back().has_elastic = true;
        block_ = Block::kSkip;  // one line only
        break;
      }
      case Block::kDensity: {
        if (values.empty() || (values.size() > 1 && !values[1].empty())) ctx_.Fail(at, kw_.name, "expected rho");
        materials_.back().m.density_kg_m3 = AsDouble(values[0], "density", at);
        materials_.back().has_density = true;
        block_ = Block::kSkip;
        break;
      }
      case Block::kSection: block_ = Block::kSkip; break;  // thickness line: not used by solids
      case Block::kNone:
      case Block::kSkip: break;
    }
  }

  void AddNodesAndElements() {
    FeMesh& mesh = result_.mesh;
    for (const NodeRecord& n : nodes_) {
      try {
        mesh.AddNode(n.id, n.p);
      } catch (const std::invalid_argument& e) {
        ctx_.Fail(n.line, "NODE", e.what());
      }
    }
    for (const ElementRecord& e : elements_) {
      try {
        mesh.AddElement(e.id, e.type, e.nodes);
      } catch (const std::invalid_argument& ex) {
        ctx_.Fail(e.line, "ELEMENT", ex.what());
      }
    }
  }

  // Sets in file order: ids, GENERATE ranges, or the members of sets defined before.
  void AddSets() {
    FeMesh& mesh = result_.mesh;
    for (const SetRecord& s : sets_) {
      std::vector<int> indices;
      auto add_id = [&](long long id) {
        const std::optional<int> i = s.nodes ? mesh.FindNode(static_cast<int>(id)) : mesh.FindElement(static_cast<int>(id));
        if (!i) ctx_.Fail(s.line, s.keyword, std::string(s.nodes ? "unknown node " : "unknown element ") + std::to_string(id));
        indices.push_back(*i);
      };
      if (s.generate) {
        const std::optional<long long> a = ParseInt(s.items[0]), b = ParseInt(s.items[1]),
                                       step = s.items.size() > 2 ? ParseInt(s.items[2]) : std::optional<long long>(1);
        if (!a || !b || !step || *step < 1 || *b < *a) ctx_.Fail(s.line, s.keyword, "bad GENERATE range");
        for (long long id = *a; id <= *b; id += *step) add_id(id);
      } else {
        for (const std::string& item : s.items) {
          if (const std::optional<long long> id = ParseInt(item)) {
            add_id(*id);
            continue;
          }
          const auto& existing = s.nodes ? mesh.node_sets() : mesh.element_sets();
          const auto it = existing.find(UpperName(item));
          if (it == existing.end()) ctx_.Fail(s.line, s.keyword, "'" + item + "' is neither an id nor a known set");
          indices.insert(indices.end(), it->second.begin(), it->second.end());
        }
      }
      if (s.nodes) mesh.AddToNodeSet(s.name, indices);
      else mesh.AddToElementSet(s.name, indices);
    }
  }

  void AssignSections() {
    for (const SectionRecord& sec : sections_) {
      const MaterialRecord* m = nullptr;
      for (const MaterialRecord& r : materials_)
        if (r.m.name == sec.material) m = &r;
      if (!m) ctx_.Fail(sec.line, "SOLID SECTION", "unknown material " + sec.material);
      if (!m->has_elastic || !m->has_density)
        ctx_.Fail(m->line, "MATERIAL", m->m.name + ": needs *ELASTIC and *DENSITY for modes");
      try {
        result_.mesh.AssignMaterial(sec.elset, m->m);
      } catch (const std::invalid_argument& e) {
        ctx_.Fail(sec.line, "SOLID SECTION", e.what());
      }
    }
  }

  const std::string& source_;
  const Context ctx_;
  InpReadResult& result_;
  std::vector<NodeRecord> nodes_;
  std::vector<ElementRecord> elements_;
  std::vector<SetRecord> sets_;  // in file order
  std::vector<MaterialRecord> materials_;
  std::vector<SectionRecord> sections_;
  Block block_ = Block::kNone;
  Keyword kw_;
  std::optional<ElementType> element_type_;
  std::string set_name_;
  bool generate_ = false;
  std::vector<std::string> pending_;  // values of a continued data line
  int pending_line_ = 0;
};

}  // namespace

InpReadResult ParseInp(std::istream& in, const std::string& source) {
  InpReadResult result;
  InpParser parser(source, result);
  std::string raw;
  int line_no = 0;
  while (std::getline(in, raw)) {
    ++line_no;
    if (!raw.empty() && raw.back() == '\r') raw.pop_back();
    const std::string line = Trim(raw);
    if (line.empty() || line.rfind("**", 0) == 0) continue;
    parser.ReadLine(line, line_no);
  }
  parser.Finish();
  return result;
}

InpReadResult ReadInp(const std::filesystem::path& path) {
  // A regular file only: a device or FIFO (/dev/zero) would be read without end
  CheckRegularInput(path.string(), "mesh file");
  std::ifstream in(path);
  if (!in) throw std::runtime_error(path.string() + ": cannot open");
  return ParseInp(in, path.string());
}

namespace {

// Shortest of the round-trip form and what CalculiX can read: ccx takes at most 20 characters per
// field, which %.17g exceeds for small magnitudes ("-3.8867686406668911e-16"); precision is then
// lowered until the field fits (14 digits at worst).
std::string Num(double x) {
  char b[40];
  for (int digits = 17; digits >= 14; --digits) {
    std::snprintf(b, sizeof b, "%.*g", digits, x);
    if (std::strlen(b) <= 20) break;
  }
  return b;
}

// Ids, 16 per line.
void WriteIds(std::ostream& out, const std::vector<int>& ids) {
  for (std::size_t i = 0; i < ids.size(); ++i)
    out << ids[i] << ((i + 1) % 16 == 0 || i + 1 == ids.size() ? "\n" : ", ");
}

}  // namespace

void WriteInp(std::ostream& out, const FeMesh& mesh, const InpWriteOptions& options) {
  out << "*HEADING\n" << options.heading << "\n";
  out << "*NODE\n";
  for (int i = 0; i < mesh.num_nodes(); ++i) {
    const Eigen::Vector3d& p = mesh.positions()[i];
    out << mesh.node_ids()[i] << ", " << Num(p(0)) << ", " << Num(p(1)) << ", " << Num(p(2)) << "\n";
  }
  // Elements, one block per run of equal types; at most 16 entries on a line
  const std::vector<FeElement>& els = mesh.elements();
  for (std::size_t i = 0; i < els.size(); ++i) {
    if (i == 0 || els[i].type != els[i - 1].type) out << "*ELEMENT, TYPE=" << CalculixName(els[i].type) << "\n";
    out << els[i].id;
    const int n = NodeCount(els[i].type);
    for (int k = 0; k < n; ++k) out << (k == 15 ? ",\n" : ", ") << mesh.node_ids()[els[i].nodes[k]];
    out << "\n";
  }
  for (const auto& [name, items] : mesh.node_sets()) {
    std::vector<int> ids;
    for (int i : items) ids.push_back(mesh.node_ids()[i]);
    out << "*NSET, NSET=" << name << "\n";
    WriteIds(out, ids);
  }
  for (const auto& [name, items] : mesh.element_sets()) {
    std::vector<int> ids;
    for (int i : items) ids.push_back(els[i].id);
    out << "*ELSET, ELSET=" << name << "\n";
    WriteIds(out, ids);
  }
  for (std::size_t m = 0; m < mesh.materials().size(); ++m) {
    const IsotropicMaterial& mat = mesh.materials()[m];
    out << "*MATERIAL, NAME=" << (mat.name.empty() ? "MAT" + std::to_string(m + 1) : mat.name) << "\n";
    out << "*ELASTIC\n" << Num(mat.youngs_modulus_pa) << ", " << Num(mat.poissons_ratio) << "\n";
    out << "*DENSITY\n" << Num(mat.density_kg_m3) << "\n";
  }
  for (const auto& [elset, m] : mesh.sections()) {
    const IsotropicMaterial& mat = mesh.materials()[m];
    out << "*SOLID SECTION, ELSET=" << elset
        << ", MATERIAL=" << (mat.name.empty() ? "MAT" + std::to_string(m + 1) : mat.name) << "\n";
  }
  for (const std::string& set : options.fixed_node_sets) {
    mesh.NodeSet(set);  // throws for an unknown set
    out << "*BOUNDARY\n" << UpperName(set) << ", 1, 3\n";
  }
  if (options.num_frequencies > 0)
    out << "*STEP\n*FREQUENCY\n" << options.num_frequencies << "\n*END STEP\n";
}

void WriteInpFile(const std::filesystem::path& path, const FeMesh& mesh, const InpWriteOptions& options) {
  std::ofstream out(path);
  if (!out) throw std::runtime_error(path.string() + ": cannot write");
  WriteInp(out, mesh, options);
  out.close();
  if (!out) throw std::runtime_error(path.string() + ": write failed");
}

}  // namespace orrery::flex
