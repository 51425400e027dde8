#include "import/msh_reader.h"

#include <algorithm>
#include <climits>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <map>
#include <optional>
#include <set>
#include <stdexcept>
#include <unordered_map>

#include "import/text_scanner.h"

namespace orrery {
namespace {

// gmsh element types (reference manual, "MSH file format"): node count, dimension, name.
struct TypeInfo {
  int nodes = 0;
  int dim = 0;
  const char* name = "";
};

std::optional<TypeInfo> GmshType(std::int64_t type) {
  switch (type) {
    case 1: return TypeInfo{2, 1, "2-node line"};
    case 2: return TypeInfo{3, 2, "3-node triangle"};
    case 3: return TypeInfo{4, 2, "4-node quadrangle"};
    case 4: return TypeInfo{4, 3, "4-node tetrahedron"};
    case 5: return TypeInfo{8, 3, "8-node hexahedron"};
    case 6: return TypeInfo{6, 3, "6-node prism"};
    case 7: return TypeInfo{5, 3, "5-node pyramid"};
    case 8: return TypeInfo{3, 1, "3-node line"};
    case 9: return TypeInfo{6, 2, "6-node triangle"};
    case 10: return TypeInfo{9, 2, "9-node quadrangle"};
    case 11: return TypeInfo{10, 3, "10-node tetrahedron"};
    case 12: return TypeInfo{27, 3, "27-node hexahedron"};
    case 13: return TypeInfo{18, 3, "18-node prism"};
    case 14: return TypeInfo{14, 3, "14-node pyramid"};
    case 15: return TypeInfo{1, 0, "point"};
    case 16: return TypeInfo{8, 2, "8-node quadrangle"};
    case 17: return TypeInfo{20, 3, "20-node hexahedron"};
    case 18: return TypeInfo{15, 3, "15-node prism"};
    case 19: return TypeInfo{13, 3, "13-node pyramid"};
    case 20: return TypeInfo{9, 2, "9-node incomplete triangle"};
    case 21: return TypeInfo{10, 2, "10-node triangle"};
    case 22: return TypeInfo{12, 2, "12-node incomplete triangle"};
    case 23: return TypeInfo{15, 2, "15-node triangle"};
    case 24: return TypeInfo{15, 2, "15-node incomplete triangle"};
    case 25: return TypeInfo{21, 2, "21-node triangle"};
    case 26: return TypeInfo{4, 1, "4-node line"};
    case 27: return TypeInfo{5, 1, "5-node line"};
    case 28: return TypeInfo{6, 1, "6-node line"};
    case 29: return TypeInfo{20, 3, "20-node tetrahedron"};
    case 30: return TypeInfo{35, 3, "35-node tetrahedron"};
    case 31: return TypeInfo{56, 3, "56-node tetrahedron"};
    case 92: return TypeInfo{64, 3, "64-node hexahedron"};
    case 93: return TypeInfo{125, 3, "125-node hexahedron"};
    default: return std::nullopt;
  }
}

std::string Num(double x) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%g", x);
  return buf;
}

// CalculiX node k = gmsh node kFrom[k] (header).
constexpr int kTet10FromGmsh[10] = {0, 1, 2, 3, 4, 5, 6, 7, 9, 8};
constexpr int kHex20FromGmsh[20] = {0, 1, 2, 3, 4, 5, 6, 7, 8, 11, 13, 9, 16, 18, 19, 17, 10, 12, 14, 15};

std::optional<flex::ElementType> FeType(int gmsh_type) {
  switch (gmsh_type) {
    case 4: return flex::ElementType::kTet4;
    case 11: return flex::ElementType::kTet10;
    case 5: return flex::ElementType::kHex8;
    case 17: return flex::ElementType::kHex20;
    default: return std::nullopt;
  }
}

// An element as read: gmsh type, tag, its geometric entity and (2.2) physical tag, nodes (tags).
struct RawElement {
  int type = 0;
  int tag = 0;
  int entity_dim = -1, entity_tag = 0;
  int physical = 0;        // 2.2 only (0: none)
  std::size_t first = 0;   // into the node-tag buffer
};

class MshParser {
 public:
  MshParser(std::string_view bytes, const std::string& source, const GmshReadOptions& options)
      : s_(bytes), source_(source), options_(options) {}

  GmshMesh Parse();

 private:
  [[noreturn]] void Fail(const std::string& what) const {
    std::string where = source_;
    if (!binary_ && !building_) where += ":" + std::to_string(s_.line());
    throw std::runtime_error(where + ": " + (section_.empty() ? "" : section_ + ": ") + what);
  }
  static std::string Show(std::string_view t) { return std::string(t.substr(0, 40)); }

  // ASCII values
  std::int64_t Int(const char* what) {
    std::string_view t;
    std::int64_t v = 0;
    if (!s_.NextToken(t)) Fail(std::string("expected ") + what + ", got the end of the file");
    if (!ParseInt64(t, v)) Fail(std::string("expected ") + what + " (an integer), got '" + Show(t) + "'");
    return v;
  }
  int Tag(const char* what) {
    const std::int64_t v = Int(what);
    if (v < INT_MIN || v > INT_MAX) Fail(std::string(what) + " " + std::to_string(v) + " does not fit in an int");
    return static_cast<int>(v);
  }
  double Real(const char* what) {
    std::string_view t;
    double v = 0;
    if (!s_.NextToken(t)) Fail(std::string("expected ") + what + ", got the end of the file");
    if (!ParseDouble(t, v)) Fail(std::string("expected ") + what + " (a number), got '" + Show(t) + "'");
    return v;
  }
  std::int64_t Count(const char* what) {
    const std::int64_t n = Int(what);
    if (n < 0) Fail(std::string(what) + " is negative: " + std::to_string(n));
    return n;
  }

  // Binary values (little-endian, bounds-checked)
  template <typename T>
  T Bin() {
    if (s_.remaining() < sizeof(T)) Fail("unexpected end of the file in binary data");
    T v;
    std::memcpy(&v, s_.data().data() + s_.position(), sizeof(T));
    s_.Seek(s_.position() + sizeof(T));
    return v;
  }
  int BinTag(const char* what) {
    const std::uint64_t v = Bin<std::uint64_t>();
    if (v > INT_MAX) Fail(std::string(what) + " " + std::to_string(v) + " does not fit in an int");
    return static_cast<int>(v);
  }
  // Checks that `count` items of `bytes` each are left (before a loop over a count from a header).
  void NeedBytes(std::uint64_t count, std::uint64_t bytes) {
    if (bytes != 0 && count > s_.remaining() / bytes)
      Fail("header says " + std::to_string(count) + " items, more than the " + std::to_string(s_.remaining()) +
           " bytes left can hold");
  }

  void ReadFormat();
  void ReadPhysicalNames();
  void ReadEntities();
  void ReadNodes2();
  void ReadNodes4();
  void ReadElements2();
  void ReadElements4();
  void EndSection(const std::string& name);
  void SkipSection(const std::string& name);
  void AddNode(std::int64_t tag, double x, double y, double z);
  void AddElement(int tag, int type, int entity_dim, int entity_tag, int physical);
  GmshMesh Build();
  std::vector<std::string> PhysicalGroupsOf(const RawElement& e) const;
  std::string GroupName(int dim, int tag) const;

  TextScanner s_;
  const std::string& source_;
  GmshReadOptions options_;
  std::string section_;
  bool binary_ = false;
  bool building_ = false;  // after the sections: errors name no line
  int major_ = 0;
  GmshMesh out_;
  std::map<std::pair<int, int>, std::string> physical_names_;               // (dim, tag) -> name
  std::map<std::pair<int, int>, std::vector<int>> entity_physicals_;        // (dim, entity) -> tags
  std::vector<int> node_tags_;
  std::vector<Vec3> node_positions_;
  std::unordered_map<int, int> node_index_;
  std::vector<RawElement> elements_;
  std::vector<int> element_nodes_;  // node tags, element after element
  std::set<int> element_tags_;
  std::map<int, int> skipped_types_;  // point / line element type -> count
};

GmshMesh MshParser::Parse() {
  std::string_view line;
  bool have_format = false, have_nodes = false;
  while (s_.NextLine(line)) {
    while (!line.empty() && (line.back() == ' ' || line.back() == '\t')) line.remove_suffix(1);
    if (line.empty()) continue;
    if (line.front() != '$') Fail("expected a section ($Name), got '" + Show(line) + "'");
    const std::string name(line.substr(1, 64));
    section_ = "$" + name;
    if (name == "MeshFormat") {
      ReadFormat();
      have_format = true;
    } else if (!have_format) {
      Fail("the file must begin with $MeshFormat");
    } else if (name == "PhysicalNames") {
      ReadPhysicalNames();
    } else if (name == "Entities") {
      ReadEntities();
    } else if (name == "Nodes") {
      major_ == 2 ? ReadNodes2() : ReadNodes4();
      have_nodes = true;
    } else if (name == "Elements") {
      major_ == 2 ? ReadElements2() : ReadElements4();
    } else {
      SkipSection(name);
      out_.notes.push_back(source_ + ": section $" + name + " skipped");
    }
    section_.clear();
  }
  if (!have_format) Fail("not a gmsh mesh file (no $MeshFormat)");
  if (!have_nodes) Fail("no $Nodes section");
  return Build();
}

void MshParser::ReadFormat() {
  std::string_view version;
  if (!s_.NextToken(version)) Fail("expected the version, got the end of the file");
  const int file_type = Tag("the file type");
  const int data_size = Tag("the data size");
  if (version == "2.2" || version == "2.1" || version == "2" || version == "2.0") {
    major_ = 2;
  } else if (version == "4.1") {
    major_ = 4;
  } else if (version.substr(0, 2) == "4." || version == "4") {
    Fail("MSH version " + Show(version) + " is not supported: save the mesh as version 4.1 or 2.2");
  } else {
    Fail("unknown MSH version '" + Show(version) + "' (2.2 and 4.1 are read)");
  }
  out_.version = major_ == 2 ? "2.2" : "4.1";
  if (file_type != 0 && file_type != 1) Fail("file type must be 0 (ASCII) or 1 (binary), got " + std::to_string(file_type));
  binary_ = file_type == 1;
  out_.binary = binary_;
  if (binary_) {
    if (data_size != 8) Fail("binary data size " + std::to_string(data_size) + " (only 8-byte size_t is read)");
    s_.SkipLine();
    if (Bin<std::int32_t>() != 1) Fail("big-endian binary files are not supported");
  }
  EndSection("MeshFormat");
}

void MshParser::ReadPhysicalNames() {
  const std::int64_t n = Count("the number of physical names");
  for (std::int64_t i = 0; i < n; ++i) {
    const int dim = Tag("a dimension"), tag = Tag("a physical tag");
    s_.Seek(s_.position());
    std::string_view rest;
    if (!s_.NextLine(rest)) Fail("expected a quoted name");
    const std::size_t open = rest.find('"'), close = rest.rfind('"');
    if (open == std::string_view::npos || close == open) Fail("expected a quoted name, got '" + Show(rest) + "'");
    physical_names_[{dim, tag}] = std::string(rest.substr(open + 1, std::min<std::size_t>(close - open - 1, 256)));
  }
  EndSection("PhysicalNames");
}

void MshParser::ReadEntities() {
  if (major_ == 2) return SkipSection("Entities");
  std::uint64_t counts[4];
  for (auto& c : counts) c = binary_ ? Bin<std::uint64_t>() : static_cast<std::uint64_t>(Count("an entity count"));
  out_.volume_entities = static_cast<int>(std::min<std::uint64_t>(counts[3], INT_MAX));
  for (int dim = 0; dim < 4; ++dim) {
    NeedBytes(counts[dim], binary_ ? 4 + 24 + 8 : 8);
    for (std::uint64_t i = 0; i < counts[dim]; ++i) {
      // tag, box (a point: its position), physical tags, bounding entities (not points)
      const int tag = binary_ ? Bin<std::int32_t>() : Tag("an entity tag");
      for (int k = 0; k < (dim == 0 ? 3 : 6); ++k) binary_ ? (void)Bin<double>() : (void)Real("a coordinate");
      const std::uint64_t np = binary_ ? Bin<std::uint64_t>() : static_cast<std::uint64_t>(Count("a tag count"));
      NeedBytes(np, binary_ ? 4 : 2);
      std::vector<int>& phys = entity_physicals_[{dim, tag}];
      for (std::uint64_t k = 0; k < np; ++k) phys.push_back(binary_ ? Bin<std::int32_t>() : Tag("a physical tag"));
      if (dim == 0) continue;
      const std::uint64_t nb = binary_ ? Bin<std::uint64_t>() : static_cast<std::uint64_t>(Count("a tag count"));
      NeedBytes(nb, binary_ ? 4 : 2);
      for (std::uint64_t k = 0; k < nb; ++k) binary_ ? (void)Bin<std::int32_t>() : (void)Tag("a bounding entity");
    }
  }
  EndSection("Entities");
}

void MshParser::AddNode(std::int64_t tag, double x, double y, double z) {
  if (tag < 1 || tag > INT_MAX) Fail("node tag " + std::to_string(tag) + " is not in 1.." + std::to_string(INT_MAX));
  if (!std::isfinite(x) || !std::isfinite(y) || !std::isfinite(z))
    Fail("node " + std::to_string(tag) + " has a non-finite coordinate");
  const Vec3 p(x * options_.scale, y * options_.scale, z * options_.scale);
  if (p.cwiseAbs().maxCoeff() > options_.max_coordinate_m)
    Fail("node " + std::to_string(tag) + " lies beyond " + Num(options_.max_coordinate_m) +
         " m from the origin (wrong unit or a corrupt file?)");
  if (!node_index_.emplace(static_cast<int>(tag), static_cast<int>(node_tags_.size())).second)
    Fail("node tag " + std::to_string(tag) + " appears twice");
  node_tags_.push_back(static_cast<int>(tag));
  node_positions_.push_back(p);
}

void MshParser::ReadNodes2() {
  const std::int64_t n = Count("the number of nodes");
  if (binary_) {
    s_.SkipLine();
    NeedBytes(static_cast<std::uint64_t>(n), 4 + 24);
  }
  for (std::int64_t i = 0; i < n; ++i) {
    if (binary_) {
      const std::int32_t tag = Bin<std::int32_t>();
      const double x = Bin<double>(), y = Bin<double>(), z = Bin<double>();
      AddNode(tag, x, y, z);
    } else {
      const std::int64_t tag = Int("a node tag");
      const double x = Real("x"), y = Real("y"), z = Real("z");
      AddNode(tag, x, y, z);
    }
  }
  EndSection("Nodes");
}

void MshParser::ReadNodes4() {
  std::uint64_t header[4];
  for (auto& h : header) h = binary_ ? Bin<std::uint64_t>() : static_cast<std::uint64_t>(Count("a node count"));
  const std::uint64_t blocks = header[0];
  NeedBytes(blocks, binary_ ? 20 : 8);
  std::vector<std::int64_t> tags;
  for (std::uint64_t b = 0; b < blocks; ++b) {
    int dim = 0, parametric = 0;
    std::uint64_t n = 0;
    if (binary_) {
      dim = Bin<std::int32_t>();
      Bin<std::int32_t>();  // entity tag
      parametric = Bin<std::int32_t>();
      n = Bin<std::uint64_t>();
    } else {
      dim = Tag("an entity dimension");
      Tag("an entity tag");
      parametric = Tag("the parametric flag");
      n = static_cast<std::uint64_t>(Count("a block's node count"));
    }
    if (dim < 0 || dim > 3) Fail("entity dimension " + std::to_string(dim) + " is not 0..3");
    const int values = 3 + (parametric != 0 ? dim : 0);
    NeedBytes(n, binary_ ? 8 + 8 * values : 2 + 2 * values);
    tags.resize(n);
    for (auto& t : tags) t = binary_ ? static_cast<std::int64_t>(Bin<std::uint64_t>()) : Int("a node tag");
    for (std::uint64_t i = 0; i < n; ++i) {
      double x[3] = {0, 0, 0};
      for (int k = 0; k < values; ++k) {
        const double v = binary_ ? Bin<double>() : Real("a coordinate");
        if (k < 3) x[k] = v;
      }
      AddNode(tags[i], x[0], x[1], x[2]);
    }
  }
  EndSection("Nodes");
}

void MshParser::AddElement(int tag, int type, int entity_dim, int entity_tag, int physical) {
  if (!element_tags_.insert(tag).second) Fail("element tag " + std::to_string(tag) + " appears twice");
  elements_.push_back({type, tag, entity_dim, entity_tag, physical, element_nodes_.size()});
}

void MshParser::ReadElements2() {
  const std::int64_t n = Count("the number of elements");
  if (!binary_) {
    for (std::int64_t i = 0; i < n; ++i) {
      const int tag = Tag("an element tag");
      const int type = Tag("an element type");
      const std::optional<TypeInfo> info = GmshType(type);
      if (!info) Fail("element " + std::to_string(tag) + ": unknown element type " + std::to_string(type));
      const int ntags = Tag("the number of tags");
      if (ntags < 0 || ntags > 64) Fail("element " + std::to_string(tag) + ": " + std::to_string(ntags) + " tags");
      int physical = 0, entity = 0;
      for (int k = 0; k < ntags; ++k) {
        const int t = Tag("a tag");
        if (k == 0) physical = t;
        if (k == 1) entity = t;
      }
      AddElement(tag, type, info->dim, entity, physical);
      for (int k = 0; k < info->nodes; ++k) element_nodes_.push_back(Tag("a node tag"));
    }
    return EndSection("Elements");
  }
  // Binary: blocks of (type, count, tags per element), then count x (tag, tags, nodes)
  s_.SkipLine();
  std::int64_t read = 0;
  while (read < n) {
    const std::int32_t type = Bin<std::int32_t>(), count = Bin<std::int32_t>(), ntags = Bin<std::int32_t>();
    const std::optional<TypeInfo> info = GmshType(type);
    if (!info) Fail("unknown element type " + std::to_string(type));
    if (count < 1 || count > n - read || ntags < 0 || ntags > 64)
      Fail("bad element block header (type " + std::to_string(type) + ", " + std::to_string(count) + " elements, " +
           std::to_string(ntags) + " tags)");
    NeedBytes(static_cast<std::uint64_t>(count), 4ull * (1 + ntags + info->nodes));
    for (std::int32_t i = 0; i < count; ++i) {
      const int tag = Bin<std::int32_t>();
      int physical = 0, entity = 0;
      for (int k = 0; k < ntags; ++k) {
        const int t = Bin<std::int32_t>();
        if (k == 0) physical = t;
        if (k == 1) entity = t;
      }
      AddElement(tag, type, info->dim, entity, physical);
      for (int k = 0; k < info->nodes; ++k) element_nodes_.push_back(Bin<std::int32_t>());
    }
    read += count;
  }
  EndSection("Elements");
}

void MshParser::ReadElements4() {
  std::uint64_t header[4];
  for (auto& h : header) h = binary_ ? Bin<std::uint64_t>() : static_cast<std::uint64_t>(Count("an element count"));
  const std::uint64_t blocks = header[0];
  NeedBytes(blocks, binary_ ? 20 : 8);
  for (std::uint64_t b = 0; b < blocks; ++b) {
    int dim = 0, entity = 0, type = 0;
    std::uint64_t n = 0;
    if (binary_) {
      dim = Bin<std::int32_t>();
      entity = Bin<std::int32_t>();
      type = Bin<std::int32_t>();
      n = Bin<std::uint64_t>();
    } else {
      dim = Tag("an entity dimension");
      entity = Tag("an entity tag");
      type = Tag("an element type");
      n = static_cast<std::uint64_t>(Count("a block's element count"));
    }
    const std::optional<TypeInfo> info = GmshType(type);
    if (!info) Fail("unknown element type " + std::to_string(type));
    NeedBytes(n, binary_ ? 8ull * (1 + info->nodes) : 2ull * (1 + info->nodes));
    for (std::uint64_t i = 0; i < n; ++i) {
      const int tag = binary_ ? BinTag("element tag") : Tag("an element tag");
      AddElement(tag, type, dim, entity, 0);
      for (int k = 0; k < info->nodes; ++k) element_nodes_.push_back(binary_ ? BinTag("node tag") : Tag("a node tag"));
    }
  }
  EndSection("Elements");
}

void MshParser::EndSection(const std::string& name) {
  std::string_view token;
  const std::string end = "$End" + name;
  if (!s_.NextToken(token)) Fail("expected " + end + ", got the end of the file");
  if (token != end) Fail("expected " + end + ", got '" + Show(token) + "'");
}

void MshParser::SkipSection(const std::string& name) {
  std::string_view line;
  const std::string end = "$End" + name;
  while (s_.NextLine(line))
    if (line.substr(0, end.size()) == end) return;
  Fail("no " + end);
}

std::string MshParser::GroupName(int dim, int tag) const {
  const auto it = physical_names_.find({dim, tag});
  return it != physical_names_.end() && !it->second.empty()
             ? it->second
             : "PHYSICAL" + std::to_string(dim) + "D_" + std::to_string(tag);
}

std::vector<std::string> MshParser::PhysicalGroupsOf(const RawElement& e) const {
  std::vector<std::string> names;
  if (major_ == 2) {
    if (e.physical != 0) names.push_back(GroupName(e.entity_dim, e.physical));
  } else if (const auto it = entity_physicals_.find({e.entity_dim, e.entity_tag}); it != entity_physicals_.end()) {
    for (int p : it->second) names.push_back(GroupName(e.entity_dim, p));
  }
  return names;
}

GmshMesh MshParser::Build() {
  section_.clear();
  building_ = true;
  // Which nodes the volume elements use (they alone enter the FE mesh)
  std::vector<char> used(node_tags_.size(), 0);
  const auto index_of = [&](const RawElement& e, int k) {
    const int tag = element_nodes_[e.first + k];
    const auto it = node_index_.find(tag);
    if (it == node_index_.end())
      Fail("element " + std::to_string(e.tag) + " refers to node " + std::to_string(tag) + ", which is not in $Nodes");
    return it->second;
  };
  for (const RawElement& e : elements_) {
    const TypeInfo info = *GmshType(e.type);
    for (int k = 0; k < info.nodes; ++k) {
      const int i = index_of(e, k);
      if (info.dim == 3) used[i] = 1;
    }
    if (info.dim == 3 && !FeType(e.type))
      Fail("element " + std::to_string(e.tag) + " is a " + info.name + " (gmsh type " + std::to_string(e.type) +
           "), which Orrery's FE solids do not have (tet4, tet10, hex8, hex20)");
  }
  flex::FeMesh& mesh = out_.mesh;
  for (std::size_t i = 0; i < node_tags_.size(); ++i)
    if (used[i]) mesh.AddNode(node_tags_[i], node_positions_[i]);

  // Volume elements in CalculiX node order; physical groups to node and element sets
  std::map<std::string, std::vector<int>> node_sets, element_sets;
  std::vector<int> ids;
  for (const RawElement& e : elements_) {
    const TypeInfo info = *GmshType(e.type);
    const std::vector<std::string> groups = PhysicalGroupsOf(e);
    if (info.dim == 3) {
      const flex::ElementType t = *FeType(e.type);
      ids.resize(info.nodes);
      for (int k = 0; k < info.nodes; ++k) {
        const int from = t == flex::ElementType::kTet10 ? kTet10FromGmsh[k]
                         : t == flex::ElementType::kHex20 ? kHex20FromGmsh[k]
                                                           : k;
        ids[k] = element_nodes_[e.first + from];
      }
      int index = 0;
      try {
        index = mesh.AddElement(e.tag, t, ids);
      } catch (const std::invalid_argument& x) {
        Fail(std::string("element ") + std::to_string(e.tag) + ": " + x.what());
      }
      for (const std::string& g : groups) element_sets[g].push_back(index);
    } else if (info.dim < 2) {
      ++skipped_types_[e.type];
    }
    for (const std::string& g : groups)
      for (int k = 0; k < info.nodes; ++k)
        if (const std::optional<int> n = mesh.FindNode(element_nodes_[e.first + k])) node_sets[g].push_back(*n);
  }
  for (auto& [name, nodes] : node_sets) {
    std::sort(nodes.begin(), nodes.end());
    nodes.erase(std::unique(nodes.begin(), nodes.end()), nodes.end());
    if (!nodes.empty()) mesh.AddToNodeSet(name, nodes);
  }
  for (const auto& [name, elements] : element_sets) mesh.AddToElementSet(name, elements);

  // Surface: tri / quad elements over their corner nodes, regions by physical group
  RawSurface& surface = out_.surface;
  surface.format = "gmsh MSH " + out_.version + (binary_ ? " (binary)" : " (ASCII)");
  std::unordered_map<int, int> vertex_of;  // node index -> surface vertex
  std::map<std::string, int> regions;
  const auto vertex = [&](int node) {
    const auto [it, added] = vertex_of.emplace(node, static_cast<int>(surface.vertices.size()));
    if (added) surface.vertices.push_back(node_positions_[node]);
    return it->second;
  };
  for (const RawElement& e : elements_) {
    const TypeInfo info = *GmshType(e.type);
    if (info.dim != 2) continue;
    const std::vector<std::string> groups = PhysicalGroupsOf(e);
    const std::string region = groups.empty() ? "" : groups.front();
    const auto [it, added] = regions.emplace(region, static_cast<int>(surface.region_names.size()));
    if (added) surface.region_names.push_back(region);
    const bool quad = e.type == 3 || e.type == 10 || e.type == 16;
    int c[4];
    for (int k = 0; k < (quad ? 4 : 3); ++k) c[k] = vertex(index_of(e, k));
    surface.triangles.push_back({c[0], c[1], c[2]});
    surface.triangle_region.push_back(it->second);
    if (quad) {
      surface.triangles.push_back({c[0], c[2], c[3]});
      surface.triangle_region.push_back(it->second);
    }
  }
  if (surface.region_names.empty()) surface.region_names.push_back("");
  for (const auto& [type, count] : skipped_types_)
    out_.notes.push_back(source_ + ": " + std::to_string(count) + " " + GmshType(type)->name +
                         " elements used for their physical groups only");
  return std::move(out_);
}

}  // namespace

GmshMesh ParseGmshMsh(std::string_view bytes, const std::string& source, const GmshReadOptions& options) {
  return MshParser(bytes, source, options).Parse();
}

GmshMesh ReadGmshMsh(const std::filesystem::path& path, const GmshReadOptions& options) {
  const std::string bytes = ReadFileBounded(path, options.max_bytes);
  return ParseGmshMsh(bytes, path.string(), options);
}

}  // namespace orrery
