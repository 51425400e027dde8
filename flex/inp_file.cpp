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

}  // namespace

InpReadResult ParseInp(std::istream& in, const std::string& source) {
  const Context ctx{source};
  InpReadResult result;
  std::vector<NodeRecord> nodes;
  std::vector<ElementRecord> elements;
  std::vector<SetRecord> sets;  // in file order
  std::vector<MaterialRecord> materials;
  std::vector<SectionRecord> sections;

  enum class Block { kNone, kNode, kElement, kNset, kElset, kElastic, kDensity, kSection, kSkip };
  Block block = Block::kNone;
  Keyword kw;
  std::optional<ElementType> element_type;
  std::string set_name;
  bool generate = false;
  std::vector<std::string> pending;  // values of a continued data line
  int pending_line = 0;

  std::string raw;
  int line_no = 0;
  while (std::getline(in, raw)) {
    ++line_no;
    if (!raw.empty() && raw.back() == '\r') raw.pop_back();
    const std::string line = Trim(raw);
    if (line.empty() || line.rfind("**", 0) == 0) continue;

    if (line[0] == '*') {
      if (!pending.empty()) ctx.Fail(pending_line, kw.name, "data line continued with a comma but no data follows");
      // Keyword line
      const std::vector<std::string> parts = SplitCommas(std::string_view(line).substr(1));
      kw = Keyword{UpperName(parts[0]), {}, line_no};
      for (std::size_t i = 1; i < parts.size(); ++i) {
        if (parts[i].empty()) continue;
        const std::size_t eq = parts[i].find('=');
        if (eq == std::string::npos) kw.params[UpperName(parts[i])] = "";
        else kw.params[UpperName(Trim(parts[i].substr(0, eq)))] = Trim(parts[i].substr(eq + 1));
      }
      auto param = [&](const char* key, bool required) -> std::string {
        const auto it = kw.params.find(key);
        if (it == kw.params.end() || it->second.empty()) {
          if (required) ctx.Fail(line_no, kw.name, std::string("missing parameter ") + key + "=");
          return "";
        }
        return it->second;
      };
      generate = kw.params.contains("GENERATE");
      if (kw.name == "NODE") {
        block = Block::kNode;
        set_name = param("NSET", false);
      } else if (kw.name == "ELEMENT") {
        block = Block::kElement;
        const std::string type = param("TYPE", true);
        element_type = ElementTypeFromCalculixName(type);
        if (!element_type)
          ctx.Fail(line_no, kw.name, "element type " + type + " not supported (C3D4, C3D10, C3D8, C3D20)");
        set_name = param("ELSET", false);
      } else if (kw.name == "NSET") {
        block = Block::kNset;
        set_name = param("NSET", true);
      } else if (kw.name == "ELSET") {
        block = Block::kElset;
        set_name = param("ELSET", true);
      } else if (kw.name == "MATERIAL") {
        block = Block::kNone;
        materials.push_back({.m = {.name = UpperName(param("NAME", true))}, .line = line_no});
      } else if (kw.name == "ELASTIC" || kw.name == "DENSITY") {
        if (materials.empty()) ctx.Fail(line_no, kw.name, "outside a *MATERIAL");
        const std::string type = UpperName(param("TYPE", false));
        if (kw.name == "ELASTIC" && !type.empty() && type != "ISO" && type != "ISOTROPIC")
          ctx.Fail(line_no, kw.name, "TYPE=" + type + " not supported (isotropic only)");
        block = kw.name == "ELASTIC" ? Block::kElastic : Block::kDensity;
      } else if (kw.name == "SOLID SECTION") {
        block = Block::kSection;
        sections.push_back({param("ELSET", true), UpperName(param("MATERIAL", true)), line_no});
      } else if (kw.name == "INCLUDE") {
        ctx.Fail(line_no, kw.name, "not supported (merge the included file into this one)");
      } else {
        block = Block::kSkip;
        result.notes.push_back(source + ":" + std::to_string(line_no) + ": *" + kw.name + " ignored");
      }
      continue;
    }

    // Data line; a trailing comma continues it on the next line
    if (block == Block::kSkip) continue;
    if (block == Block::kNone) ctx.Fail(line_no, "", "data line outside a keyword block");
    std::vector<std::string> values = SplitCommas(line);
    const bool continued = !values.empty() && values.back().empty();
    if (continued) values.pop_back();
    if (pending.empty()) pending_line = line_no;
    pending.insert(pending.end(), values.begin(), values.end());
    if (block == Block::kElement) {
      // An element needs 1 + NodeCount values, however many lines they take
      const std::size_t need = 1 + NodeCount(*element_type);
      if (pending.size() < need) continue;
      if (pending.size() > need)
        ctx.Fail(line_no, kw.name, std::to_string(pending.size() - 1) + " node ids for a " +
                                       CalculixName(*element_type) + " element, expected " + std::to_string(need - 1));
    } else if (continued) {
      continue;
    }
    values.swap(pending);
    pending.clear();
    const int at = pending_line;

    auto as_int = [&](const std::string& s, const char* what) {
      const std::optional<long long> v = ParseInt(s);
      if (!v || *v < 1 || *v > 2147483647) ctx.Fail(at, kw.name, std::string(what) + " '" + s + "' is not a positive integer");
      return static_cast<int>(*v);
    };
    auto as_double = [&](const std::string& s, const char* what) {
      const std::optional<double> v = ParseDouble(s);
      if (!v) ctx.Fail(at, kw.name, std::string(what) + " '" + s + "' is not a number");
      return *v;
    };
    switch (block) {
      case Block::kNode: {
        if (values.size() < 2 || values.size() > 4) ctx.Fail(at, kw.name, "expected id, x, y, z");
        Eigen::Vector3d p = Eigen::Vector3d::Zero();
        for (std::size_t i = 1; i < values.size(); ++i) p(i - 1) = values[i].empty() ? 0.0 : as_double(values[i], "coordinate");
        nodes.push_back({as_int(values[0], "node id"), p, at});
        if (!set_name.empty()) sets.push_back({true, set_name, {values[0]}, false, at, kw.name});
        break;
      }
      case Block::kElement: {
        ElementRecord e{as_int(values[0], "element id"), *element_type, {}, at};
        for (std::size_t i = 1; i < values.size(); ++i) e.nodes.push_back(as_int(values[i], "node id"));
        if (!set_name.empty()) sets.push_back({false, set_name, {values[0]}, false, at, kw.name});
        elements.push_back(std::move(e));
        break;
      }
      case Block::kNset:
      case Block::kElset: {
        std::vector<std::string> items;
        for (const std::string& v : values)
          if (!v.empty()) items.push_back(v);
        if (generate && (items.size() < 2 || items.size() > 3))
          ctx.Fail(at, kw.name, "GENERATE expects first, last[, increment]");
        sets.push_back({block == Block::kNset, set_name, items, generate, at, kw.name});
        break;
      }
      case Block::kElastic: {
        if (values.size() < 2) ctx.Fail(at, kw.name, "expected E, nu");
        if (values.size() > 2 && !values[2].empty()) ctx.Fail(at, kw.name, "temperature-dependent data not supported");
        materials.back().m.youngs_modulus_pa = as_double(values[0], "E");
        materials.back().m.poissons_ratio = as_double(values[1], "nu");
        materials.back().has_elastic = true;
        block = Block::kSkip;  // one line only
        break;
      }
      case Block::kDensity: {
        if (values.empty() || (values.size() > 1 && !values[1].empty())) ctx.Fail(at, kw.name, "expected rho");
        materials.back().m.density_kg_m3 = as_double(values[0], "density");
        materials.back().has_density = true;
        block = Block::kSkip;
        break;
      }
      case Block::kSection: block = Block::kSkip; break;  // thickness line: not used by solids
      case Block::kNone:
      case Block::kSkip: break;
    }
  }
  if (!pending.empty()) ctx.Fail(pending_line, kw.name, "data line continued with a comma but the file ends");

  // Build the mesh: nodes, elements, sets in file order, materials, sections
  FeMesh& mesh = result.mesh;
  for (const NodeRecord& n : nodes) {
    try {
      mesh.AddNode(n.id, n.p);
    } catch (const std::invalid_argument& e) {
      ctx.Fail(n.line, "NODE", e.what());
    }
  }
  for (const ElementRecord& e : elements) {
    try {
      mesh.AddElement(e.id, e.type, e.nodes);
    } catch (const std::invalid_argument& ex) {
      ctx.Fail(e.line, "ELEMENT", ex.what());
    }
  }
  for (const SetRecord& s : sets) {
    std::vector<int> indices;
    auto add_id = [&](long long id) {
      const std::optional<int> i = s.nodes ? mesh.FindNode(static_cast<int>(id)) : mesh.FindElement(static_cast<int>(id));
      if (!i) ctx.Fail(s.line, s.keyword, std::string(s.nodes ? "unknown node " : "unknown element ") + std::to_string(id));
      indices.push_back(*i);
    };
    if (s.generate) {
      const std::optional<long long> a = ParseInt(s.items[0]), b = ParseInt(s.items[1]),
                                     step = s.items.size() > 2 ? ParseInt(s.items[2]) : std::optional<long long>(1);
      if (!a || !b || !step || *step < 1 || *b < *a) ctx.Fail(s.line, s.keyword, "bad GENERATE range");
      for (long long id = *a; id <= *b; id += *step) add_id(id);
    } else {
      for (const std::string& item : s.items) {
        if (const std::optional<long long> id = ParseInt(item)) {
          add_id(*id);
          continue;
        }
        // A set name: its members
        const auto& existing = s.nodes ? mesh.node_sets() : mesh.element_sets();
        const auto it = existing.find(UpperName(item));
        if (it == existing.end()) ctx.Fail(s.line, s.keyword, "'" + item + "' is neither an id nor a known set");
        indices.insert(indices.end(), it->second.begin(), it->second.end());
      }
    }
    if (s.nodes) mesh.AddToNodeSet(s.name, indices);
    else mesh.AddToElementSet(s.name, indices);
  }
  for (const SectionRecord& sec : sections) {
    const MaterialRecord* m = nullptr;
    for (const MaterialRecord& r : materials)
      if (r.m.name == sec.material) m = &r;
    if (!m) ctx.Fail(sec.line, "SOLID SECTION", "unknown material " + sec.material);
    if (!m->has_elastic || !m->has_density)
      ctx.Fail(m->line, "MATERIAL", m->m.name + ": needs *ELASTIC and *DENSITY for modes");
    try {
      mesh.AssignMaterial(sec.elset, m->m);
    } catch (const std::invalid_argument& e) {
      ctx.Fail(sec.line, "SOLID SECTION", e.what());
    }
  }
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
