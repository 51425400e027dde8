#include "flex/reduced_body_file.h"

#include <array>
#include <bit>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <set>
#include <utility>

#include "mbd/hdf5_reader.h"
#include "mbd/result_file.h"

namespace orrery::flex {
namespace {

constexpr const char* kFormatName = "orrery reduced body";

// ---------------------------------------------------------------------------------------------
// Hashing

// FNV-1a 64 over bytes fed piece by piece.
class Fnv1a64 {
 public:
  void Bytes(const void* data, std::size_t n) {
    const auto* p = static_cast<const unsigned char*>(data);
    for (std::size_t i = 0; i < n; ++i) {
      h_ ^= p[i];
      h_ *= 0x100000001b3ull;
    }
  }
  void Int(std::int64_t v) { Bytes(&v, sizeof v); }
  void Double(double v) { Int(static_cast<std::int64_t>(std::bit_cast<std::uint64_t>(v))); }
  // Length-prefixed, so that ("ab", "c") and ("a", "bc") differ.
  void Text(std::string_view s) {
    Int(static_cast<std::int64_t>(s.size()));
    Bytes(s.data(), s.size());
  }
  std::string Hex() const {
    char buf[32];
    std::snprintf(buf, sizeof buf, "fnv1a64:%016llx", static_cast<unsigned long long>(h_));
    return buf;
  }

 private:
  std::uint64_t h_ = 0xcbf29ce484222325ull;
};

void HashMaterial(Fnv1a64& h, const IsotropicMaterial& m) {
  h.Text(m.name);
  h.Double(m.youngs_modulus_pa);
  h.Double(m.poissons_ratio);
  h.Double(m.density_kg_m3);
}

const char* KindName(InterfaceKind k) { return k == InterfaceKind::kRbe2 ? "rbe2" : "rbe3"; }

// Shortest text that reads back to the same double.
std::string Num(double x) {
  char buf[32];
  const auto result = std::to_chars(buf, buf + sizeof buf, x);
  return std::string(buf, result.ptr);
}

// ---------------------------------------------------------------------------------------------
// Reading helpers: every size mismatch names the file and the dataset

class BodyReader {
 public:
  explicit BodyReader(const std::string& path) : r_(path), path_(path) {}
  const Hdf5Reader& r() const { return r_; }

  [[noreturn]] void Fail(const std::string& object, const std::string& reason) const {
    throw std::runtime_error(path_ + ": " + object + ": " + reason);
  }
  // A matrix of the given shape (-1: any), every entry finite.
  Eigen::MatrixXd Matrix(const std::string& object, Eigen::Index rows, Eigen::Index cols) const {
    Eigen::MatrixXd m = r_.ReadMatrix(object);
    CheckShape(object, m.rows(), m.cols(), rows, cols);
    CheckFinite(object, m);
    return m;
  }
  // A matrix of any shape, every entry finite (a NaN or inf would flow into every result).
  Eigen::MatrixXd FiniteMatrix(const std::string& object) const {
    Eigen::MatrixXd m = r_.ReadMatrix(object);
    CheckFinite(object, m);
    return m;
  }
  void CheckFinite(const std::string& object, const Eigen::MatrixXd& m) const {
    for (Eigen::Index j = 0; j < m.cols(); ++j)
      for (Eigen::Index i = 0; i < m.rows(); ++i)
        if (!std::isfinite(m(i, j)))
          Fail(object, "value " + Num(m(i, j)) + " at row " + std::to_string(i) + ", column " + std::to_string(j) +
                           " is not finite");
  }
  std::vector<double> Vector(const std::string& object, Eigen::Index n) const {
    std::vector<double> v = r_.ReadVector(object);
    if (n >= 0 && static_cast<Eigen::Index>(v.size()) != n)
      Fail(object, "expected " + std::to_string(n) + " values, found " + std::to_string(v.size()));
    for (std::size_t i = 0; i < v.size(); ++i)
      if (!std::isfinite(v[i])) Fail(object, "value " + Num(v[i]) + " at " + std::to_string(i) + " is not finite");
    return v;
  }
  // Integers in [lo, hi) (hi < 0: no upper bound), `n` of them (-1: any).
  std::vector<int> Ints(const std::string& object, Eigen::Index n, std::int64_t lo, std::int64_t hi) const {
    const std::vector<std::int64_t> v = r_.ReadInts(object);
    if (n >= 0 && static_cast<Eigen::Index>(v.size()) != n)
      Fail(object, "expected " + std::to_string(n) + " values, found " + std::to_string(v.size()));
    std::vector<int> out;
    out.reserve(v.size());
    for (std::size_t i = 0; i < v.size(); ++i) {
      if (v[i] < lo || (hi >= 0 && v[i] >= hi))
        Fail(object, "value " + std::to_string(v[i]) + " at " + std::to_string(i) + " is outside [" +
                         std::to_string(lo) + ", " + (hi >= 0 ? std::to_string(hi) : "inf") + ")");
      out.push_back(static_cast<int>(v[i]));
    }
    return out;
  }
  std::vector<std::string> Strings(const std::string& object, Eigen::Index n) const {
    std::vector<std::string> v = r_.ReadStrings(object);
    if (n >= 0 && static_cast<Eigen::Index>(v.size()) != n)
      Fail(object, "expected " + std::to_string(n) + " strings, found " + std::to_string(v.size()));
    return v;
  }
  // CSR offsets: n + 1 ascending values from 0 to `total` (-1: any end).
  std::vector<int> Offsets(const std::string& object, Eigen::Index n) const {
    std::vector<int> o = Ints(object, n + 1, 0, -1);
    if (o.front() != 0) Fail(object, "offsets must start at 0");
    for (std::size_t i = 1; i < o.size(); ++i)
      if (o[i] < o[i - 1]) Fail(object, "offsets must not decrease (at " + std::to_string(i) + ")");
    return o;
  }
  void CheckShape(const std::string& object, Eigen::Index r, Eigen::Index c, Eigen::Index rows,
                  Eigen::Index cols) const {
    if ((rows >= 0 && r != rows) || (cols >= 0 && c != cols))
      Fail(object, "expected " + (rows >= 0 ? std::to_string(rows) : std::string("any")) + " x " +
                       (cols >= 0 ? std::to_string(cols) : std::string("any")) + ", found " + std::to_string(r) +
                       " x " + std::to_string(c));
  }

 private:
  Hdf5Reader r_;
  std::string path_;
};

// Rows [3 i, 3 i + 3) of every node's 3 x nf block stacked.
Eigen::MatrixXd StackShapes(const std::vector<FlexibleBodyModes::Node>& nodes, int nf, bool rotation) {
  Eigen::MatrixXd s(3 * static_cast<Eigen::Index>(nodes.size()), nf);
  for (std::size_t i = 0; i < nodes.size(); ++i)
    s.middleRows(3 * static_cast<Eigen::Index>(i), 3) = rotation ? nodes[i].rotation_shapes : nodes[i].translation_shapes;
  return s;
}

// Throws std::invalid_argument "reduced body <path>: <field>: <reason>" for a body that cannot be
// stored consistently.
void CheckWritable(const std::string& path, const ReducedBody& b) {
  const auto fail = [&](const std::string& field, const std::string& reason) {
    throw std::invalid_argument("reduced body " + path + ": " + field + ": " + reason);
  };
  const FlexibleBodyModes& m = b.modes;
  const int nf = m.nf;
  const auto n = static_cast<Eigen::Index>(m.nodes.size());
  if (nf < 0) fail("modes.nf", "negative");
  if (m.I2.cols() != nf) fail("modes.I2", "expected 3 x " + std::to_string(nf));
  if (static_cast<int>(m.I4.size()) != nf) fail("modes.I4", "expected " + std::to_string(nf) + " matrices");
  if (static_cast<Eigen::Index>(m.I5.size()) != static_cast<Eigen::Index>(nf) * nf)
    fail("modes.I5", "expected nf^2 = " + std::to_string(nf * nf) + " matrices");
  if (m.stiffness.rows() != nf || m.stiffness.cols() != nf) fail("modes.stiffness", "expected nf x nf");
  if (m.damping.size() != 0 && (m.damping.rows() != nf || m.damping.cols() != nf))
    fail("modes.damping", "expected nf x nf or empty");
  if (!m.geometric_stiffness.empty() && m.geometric_stiffness.size() != 6)
    fail("modes.geometric_stiffness", "expected 0 or 6 matrices");
  for (const Eigen::MatrixXd& g : m.geometric_stiffness)
    if (g.rows() != nf || g.cols() != nf) fail("modes.geometric_stiffness", "expected nf x nf matrices");
  for (const FlexibleBodyModes::Node& node : m.nodes)
    if (node.translation_shapes.cols() != nf || node.rotation_shapes.cols() != nf)
      fail("modes.nodes[id " + std::to_string(node.id) + "]", "translation and rotation shapes must be 3 x nf");
  for (const auto& [name, members] : m.node_sets)
    for (int i : members)
      if (i < 0 || i >= n) fail("modes.node_sets[" + name + "]", "index " + std::to_string(i) + " out of range");
  for (const auto& t : m.surface_triangles)
    for (int i : t)
      if (i < 0 || i >= n) fail("modes.surface_triangles", "index " + std::to_string(i) + " out of range");
  for (int i : m.stress_nodes)
    if (i < 0 || i >= n) fail("modes.stress_nodes", "index " + std::to_string(i) + " out of range");
  if (m.stress_modes.rows() != 6 * static_cast<Eigen::Index>(m.stress_nodes.size()) ||
      (m.stress_modes.size() != 0 && m.stress_modes.cols() != nf))
    fail("modes.stress_modes", "expected 6 (stress nodes) x nf");
  if (static_cast<int>(m.frequencies_hz.size()) != nf) fail("modes.frequencies_hz", "expected nf values");
  if (b.K.rows() != b.K.cols() || b.M.rows() != b.K.rows() || b.M.cols() != b.K.cols())
    fail("K, M", "expected square matrices of one size");
  if (static_cast<Eigen::Index>(b.reduced_frequencies_hz.size()) != b.K.rows())
    fail("reduced_frequencies_hz", "expected one per reduced coordinate (" + std::to_string(b.K.rows()) + ")");
  if (b.interfaces.empty()) fail("interfaces", "none");
  if (b.reference_interface < 0 || b.reference_interface >= static_cast<int>(b.interfaces.size()))
    fail("reference_interface", "not an index into interfaces");
  for (const ReducedInterface& i : b.interfaces)
    if (i.weights.size() != i.slave_node_ids.size())
      fail("interfaces[" + i.name + "]", "expected one weight per slave node");
}

}  // namespace

// ---------------------------------------------------------------------------------------------
// Provenance

std::string Fnv1a64Hex(std::string_view bytes) {
  Fnv1a64 h;
  h.Bytes(bytes.data(), bytes.size());
  return h.Hex();
}

std::string HashFeMesh(const FeMesh& mesh) {
  Fnv1a64 h;
  // Nodes
  h.Int(mesh.num_nodes());
  for (int i = 0; i < mesh.num_nodes(); ++i) {
    h.Int(mesh.node_ids()[i]);
    for (int k = 0; k < 3; ++k) h.Double(mesh.positions()[i][k]);
  }
  // Elements and their materials
  h.Int(mesh.num_elements());
  for (int e = 0; e < mesh.num_elements(); ++e) {
    const FeElement& el = mesh.elements()[e];
    h.Int(el.id);
    h.Int(static_cast<int>(el.type));
    for (int k = 0; k < NodeCount(el.type); ++k) h.Int(el.nodes[k]);
    const int mat = mesh.element_material()[e];
    if (mat < 0) {
      h.Int(-1);
    } else {
      HashMaterial(h, mesh.materials()[mat]);
    }
  }
  // Node and element sets
  for (const auto* sets : {&mesh.node_sets(), &mesh.element_sets()}) {
    h.Int(static_cast<std::int64_t>(sets->size()));
    for (const auto& [name, members] : *sets) {
      h.Text(name);
      h.Int(static_cast<std::int64_t>(members.size()));
      for (int i : members) h.Int(i);
    }
  }
  return h.Hex();
}

std::string HashReductionOptions(const CraigBamptonOptions& options, std::span<const FeInterface> interfaces,
                                 const FlexibleBodyModesOptions& outputs) {
  Fnv1a64 h;
  h.Text("craig-bampton");
  h.Int(options.num_modes);
  h.Double(options.cutoff_hz);
  h.Int(options.reference_interface);
  h.Double(options.tolerance);
  if (options.inertial_load_modes) h.Text("inertial-load-modes");  // files reduced without them keep their hash
  h.Int(static_cast<std::int64_t>(interfaces.size()));
  for (const FeInterface& i : interfaces) {
    h.Text(i.name);
    h.Text(KindName(i.kind));
    h.Int(static_cast<std::int64_t>(i.nodes.size()));
    for (int n : i.nodes) h.Int(n);
    h.Int(static_cast<std::int64_t>(i.weights.size()));
    for (double w : i.weights) h.Double(w);
    h.Int(i.master_position_m.has_value());
    if (i.master_position_m)
      for (int k = 0; k < 3; ++k) h.Double((*i.master_position_m)[k]);
  }
  h.Int(outputs.export_surface_nodes);
  h.Int(static_cast<std::int64_t>(outputs.export_node_sets.size()));
  for (const std::string& set : outputs.export_node_sets) h.Text(set);
  h.Int(outputs.surface_triangles);
  h.Int(outputs.split_quadratic_faces);
  h.Int(static_cast<std::int64_t>(outputs.master_ids.size()));
  for (int id : outputs.master_ids) h.Int(id);
  h.Int(outputs.stress_modes);
  h.Int(outputs.geometric_stiffness);
  return h.Hex();
}

ReducedBodyProvenance MakeReducedBodyProvenance(const FeMesh& mesh, const CraigBamptonOptions& options,
                                                std::span<const FeInterface> interfaces,
                                                const FlexibleBodyModesOptions& outputs, std::string source,
                                                std::string faults) {
  ReducedBodyProvenance p;
  p.source = std::move(source);
  p.faults = std::move(faults);
  p.mesh_hash = HashFeMesh(mesh);
  p.options_hash = HashReductionOptions(options, interfaces, outputs);
  // Element types in enum order, joined by '+'
  std::set<int> types;
  for (const FeElement& e : mesh.elements()) types.insert(static_cast<int>(e.type));
  for (int t : types) {
    if (!p.element_type.empty()) p.element_type += '+';
    p.element_type += CalculixName(static_cast<ElementType>(t));
  }
  // One material, or "MIXED"
  std::set<int> used(mesh.element_material().begin(), mesh.element_material().end());
  if (used.size() == 1 && *used.begin() >= 0) {
    p.material = mesh.materials()[*used.begin()];
  } else {
    p.material = {.name = "MIXED"};
  }
  p.modes_kept = options.num_modes;
  p.engine_version = ORRERY_VERSION;
  return p;
}

ReducedInterface DescribeInterface(const FeMesh& mesh, const FeInterface& interface) {
  ReducedInterface r;
  r.name = interface.name;
  r.kind = interface.kind;
  r.master_position_m = InterfaceMasterPosition(mesh, interface);
  for (int n : interface.nodes) r.slave_node_ids.push_back(mesh.node_ids()[n]);
  r.weights = interface.weights.empty() ? std::vector<double>(interface.nodes.size(), 1.0) : interface.weights;
  return r;
}

void CheckReducedBodyMatches(const ReducedBodyProvenance& file, const ReducedBodyProvenance& expected,
                             const std::string& file_path) {
  std::vector<std::string> reasons;
  if (!expected.mesh_hash.empty() && expected.mesh_hash != file.mesh_hash)
    reasons.push_back("mesh hash differs: file was reduced from " + file.source + " (" + file.mesh_hash +
                      "), the scene's mesh is " + expected.source + " (" + expected.mesh_hash + ")");
  // Faults: a known expectation must match a known record; a file without the record was written
  // before faults were recorded and counts as healthy only for a healthy expectation.
  if (!expected.faults.empty() && expected.faults != (file.faults.empty() ? "none" : file.faults))
    reasons.push_back("tooth faults differ: file " + (file.faults.empty() ? std::string("none recorded") : file.faults) +
                      ", the scene asks " + expected.faults);
  if (!expected.options_hash.empty() && expected.options_hash != file.options_hash)
    reasons.push_back("reduction options differ (interfaces, modes, cutoff or outputs): file " + file.options_hash +
                      ", scene " + expected.options_hash);
  if (!expected.element_type.empty() && expected.element_type != file.element_type)
    reasons.push_back("element type " + file.element_type + ", the scene's mesh has " + expected.element_type);
  const IsotropicMaterial& fm = file.material;
  const IsotropicMaterial& em = expected.material;
  if (em.youngs_modulus_pa > 0 &&
      (fm.youngs_modulus_pa != em.youngs_modulus_pa || fm.poissons_ratio != em.poissons_ratio ||
       fm.density_kg_m3 != em.density_kg_m3))
    reasons.push_back("material E " + Num(fm.youngs_modulus_pa) + " Pa, nu " + Num(fm.poissons_ratio) + ", rho " +
                      Num(fm.density_kg_m3) + " kg/m^3; the scene asks E " + Num(em.youngs_modulus_pa) + " Pa, nu " +
                      Num(em.poissons_ratio) + ", rho " + Num(em.density_kg_m3) + " kg/m^3");
  if (expected.modes_kept >= 0 && expected.modes_kept != file.modes_kept)
    reasons.push_back("modes kept " + std::to_string(file.modes_kept) + ", the scene asks " +
                      std::to_string(expected.modes_kept));
  if (reasons.empty()) return;
  std::string message = file_path.empty() ? "reduced body is stale: " : file_path + ": reduced body is stale: ";
  for (std::size_t i = 0; i < reasons.size(); ++i) message += (i ? "; " : "") + reasons[i];
  throw StaleReducedBodyError(message);
}

// ---------------------------------------------------------------------------------------------
// Writing

void WriteReducedBody(const std::string& path, const ReducedBody& b) {
  CheckWritable(path, b);
  const FlexibleBodyModes& m = b.modes;
  const int nf = m.nf;
  ResultFile f = ResultFile::Create(path);
  // Format and provenance
  f.SetAttribute("/", "format", std::string(kFormatName));
  f.SetAttribute("/", "format_version", std::int64_t{kReducedBodyFormatVersion});
  f.SetAttribute("/", "engine_version", std::string(ORRERY_VERSION));
  const ReducedBodyProvenance& p = b.provenance;
  f.SetAttribute("/provenance", "source", p.source);
  f.SetAttribute("/provenance", "mesh_hash", p.mesh_hash);
  f.SetAttribute("/provenance", "options_hash", p.options_hash);
  f.SetAttribute("/provenance", "element_type", p.element_type);
  f.SetAttribute("/provenance", "material_name", p.material.name);
  f.SetAttribute("/provenance", "youngs_modulus_pa", p.material.youngs_modulus_pa);
  f.SetAttribute("/provenance", "poissons_ratio", p.material.poissons_ratio);
  f.SetAttribute("/provenance", "density_kg_m3", p.material.density_kg_m3);
  f.SetAttribute("/provenance", "modes_kept", std::int64_t{p.modes_kept});
  f.SetAttribute("/provenance", "engine_version", p.engine_version);
  if (!p.faults.empty()) f.SetAttribute("/provenance", "faults", p.faults);
  // Craig-Bampton matrices and frequencies, the full model's frequencies
  f.WriteMatrix("/craig_bampton/K", b.K, "N/m");
  f.WriteMatrix("/craig_bampton/M", b.M, "kg");
  f.WriteVector("/craig_bampton/frequencies_hz", b.reduced_frequencies_hz, "Hz");
  f.SetAttribute("/craig_bampton", "reference_interface", std::int64_t{b.reference_interface});
  f.WriteVector("/full_model/frequencies_hz", b.full_frequencies_hz, "Hz");
  f.SetAttribute("/full_model", "boundary", b.full_model_boundary);
  // Interfaces: parallel lists, slaves in CSR form
  std::vector<std::string> names, kinds;
  Eigen::MatrixXd masters(static_cast<Eigen::Index>(b.interfaces.size()), 3);
  std::vector<std::int64_t> offsets{0}, slaves;
  std::vector<double> weights;
  for (std::size_t i = 0; i < b.interfaces.size(); ++i) {
    const ReducedInterface& in = b.interfaces[i];
    names.push_back(in.name);
    kinds.push_back(KindName(in.kind));
    masters.row(static_cast<Eigen::Index>(i)) = in.master_position_m.transpose();
    slaves.insert(slaves.end(), in.slave_node_ids.begin(), in.slave_node_ids.end());
    weights.insert(weights.end(), in.weights.begin(), in.weights.end());
    offsets.push_back(static_cast<std::int64_t>(slaves.size()));
  }
  f.WriteStrings("/interfaces/names", names);
  f.WriteStrings("/interfaces/kinds", kinds);
  f.WriteMatrix("/interfaces/master_positions", masters, "m");
  f.WriteIntVector("/interfaces/slave_offsets", offsets);
  f.WriteIntVector("/interfaces/slave_node_ids", slaves);
  f.WriteVector("/interfaces/slave_weights", weights, "1");
  // Inertia invariants
  f.SetAttribute("/modes", "nf", std::int64_t{nf});
  f.WriteVector("/modes/inertia/mass", {m.mass}, "kg");
  f.WriteMatrix("/modes/inertia/I1", m.I1, "kg m");
  f.WriteMatrix("/modes/inertia/I2", m.I2, "kg m");
  f.WriteMatrix("/modes/inertia/I3", m.I3, "kg m^2");
  Eigen::MatrixXd I4(3 * nf, 3), I5(3 * static_cast<Eigen::Index>(nf) * nf, 3);
  for (int k = 0; k < nf; ++k) I4.middleRows(3 * k, 3) = m.I4[k];
  for (std::size_t kl = 0; kl < m.I5.size(); ++kl) I5.middleRows(3 * static_cast<Eigen::Index>(kl), 3) = m.I5[kl];
  f.WriteMatrix("/modes/inertia/I4", I4, "kg m");
  f.WriteMatrix("/modes/inertia/I5", I5, "kg");
  // Modal stiffness, damping, geometric stiffness (the 6 G_c stacked)
  f.WriteMatrix("/modes/stiffness", m.stiffness, "N/m");
  f.WriteMatrix("/modes/damping", m.damping, "N s/m");
  Eigen::MatrixXd G(static_cast<Eigen::Index>(m.geometric_stiffness.size()) * nf, nf);
  for (std::size_t c = 0; c < m.geometric_stiffness.size(); ++c)
    G.middleRows(static_cast<Eigen::Index>(c) * nf, nf) = m.geometric_stiffness[c];
  f.WriteMatrix("/modes/geometric_stiffness", G, "kg");
  f.SetAttribute("/modes/geometric_stiffness", "count", static_cast<std::int64_t>(m.geometric_stiffness.size()));
  // Nodes and their shapes
  std::vector<std::int64_t> ids;
  Eigen::MatrixXd positions(static_cast<Eigen::Index>(m.nodes.size()), 3);
  for (std::size_t i = 0; i < m.nodes.size(); ++i) {
    ids.push_back(m.nodes[i].id);
    positions.row(static_cast<Eigen::Index>(i)) = m.nodes[i].position.transpose();
  }
  f.WriteIntVector("/modes/nodes/ids", ids);
  f.WriteMatrix("/modes/nodes/positions", positions, "m");
  f.WriteMatrix("/modes/nodes/translation_shapes", StackShapes(m.nodes, nf, false), "m");
  f.WriteMatrix("/modes/nodes/rotation_shapes", StackShapes(m.nodes, nf, true), "rad");
  // Node sets in CSR form
  std::vector<std::string> set_names;
  std::vector<std::int64_t> set_offsets{0}, set_members;
  for (const auto& [name, members] : m.node_sets) {
    set_names.push_back(name);
    set_members.insert(set_members.end(), members.begin(), members.end());
    set_offsets.push_back(static_cast<std::int64_t>(set_members.size()));
  }
  f.WriteStrings("/modes/node_sets/names", set_names);
  f.WriteIntVector("/modes/node_sets/offsets", set_offsets);
  f.WriteIntVector("/modes/node_sets/members", set_members);
  // Surface triangles, stress modes, frequencies
  Hdf5Reader::IntMatrix tri(static_cast<Eigen::Index>(m.surface_triangles.size()), 3);
  for (std::size_t t = 0; t < m.surface_triangles.size(); ++t)
    for (int k = 0; k < 3; ++k) tri(static_cast<Eigen::Index>(t), k) = m.surface_triangles[t][k];
  f.WriteIntMatrix("/modes/surface_triangles", tri);
  f.WriteIntVector("/modes/stress_nodes", std::vector<std::int64_t>(m.stress_nodes.begin(), m.stress_nodes.end()));
  f.WriteMatrix("/modes/stress_modes", m.stress_modes, "Pa");
  f.WriteVector("/modes/frequencies_hz", m.frequencies_hz, "Hz");
  f.Close();
}

// ---------------------------------------------------------------------------------------------
// Reading

ReducedBody ReadReducedBody(const std::string& path, const ReducedBodyProvenance* expected) {
  const BodyReader in(path);
  const Hdf5Reader& r = in.r();
  // Format
  if (!r.HasAttribute("/", "format") || r.ReadStringAttribute("/", "format") != kFormatName)
    throw std::runtime_error(path + ": not an orrery reduced body file (attribute format on / is not '" +
                             std::string(kFormatName) + "')");
  const std::int64_t version = r.ReadIntAttribute("/", "format_version");
  if (version != kReducedBodyFormatVersion)
    throw std::runtime_error(path + ": reduced body format version " + std::to_string(version) +
                             ", this engine reads version " + std::to_string(kReducedBodyFormatVersion));
  ReducedBody b;
  // Provenance
  ReducedBodyProvenance& p = b.provenance;
  p.source = r.ReadStringAttribute("/provenance", "source");
  p.mesh_hash = r.ReadStringAttribute("/provenance", "mesh_hash");
  p.options_hash = r.ReadStringAttribute("/provenance", "options_hash");
  p.element_type = r.ReadStringAttribute("/provenance", "element_type");
  p.material.name = r.ReadStringAttribute("/provenance", "material_name");
  p.material.youngs_modulus_pa = r.ReadNumberAttribute("/provenance", "youngs_modulus_pa");
  p.material.poissons_ratio = r.ReadNumberAttribute("/provenance", "poissons_ratio");
  p.material.density_kg_m3 = r.ReadNumberAttribute("/provenance", "density_kg_m3");
  p.modes_kept = static_cast<int>(r.ReadIntAttribute("/provenance", "modes_kept"));
  p.engine_version = r.ReadStringAttribute("/provenance", "engine_version");
  if (r.HasAttribute("/provenance", "faults")) p.faults = r.ReadStringAttribute("/provenance", "faults");
  if (expected != nullptr) CheckReducedBodyMatches(p, *expected, path);
  // Craig-Bampton
  b.K = in.Matrix("/craig_bampton/K", -1, -1);
  const Eigen::Index nr = b.K.rows();
  in.CheckShape("/craig_bampton/K", b.K.rows(), b.K.cols(), nr, nr);
  b.M = in.Matrix("/craig_bampton/M", nr, nr);
  b.reduced_frequencies_hz = in.Vector("/craig_bampton/frequencies_hz", nr);
  b.full_frequencies_hz = in.Vector("/full_model/frequencies_hz", -1);
  b.full_model_boundary = r.ReadStringAttribute("/full_model", "boundary");
  // Interfaces
  const std::vector<std::string> names = in.Strings("/interfaces/names", -1);
  const auto ni = static_cast<Eigen::Index>(names.size());
  if (ni == 0) in.Fail("/interfaces/names", "no interfaces");
  const std::vector<std::string> kinds = in.Strings("/interfaces/kinds", ni);
  const Eigen::MatrixXd masters = in.Matrix("/interfaces/master_positions", ni, 3);
  const std::vector<int> offsets = in.Offsets("/interfaces/slave_offsets", ni);
  const std::vector<int> slaves = in.Ints("/interfaces/slave_node_ids", offsets.back(), INT32_MIN, -1);
  const std::vector<double> weights = in.Vector("/interfaces/slave_weights", offsets.back());
  for (Eigen::Index i = 0; i < ni; ++i) {
    ReducedInterface& itf = b.interfaces.emplace_back();
    itf.name = names[i];
    if (kinds[i] != "rbe2" && kinds[i] != "rbe3")
      in.Fail("/interfaces/kinds", "unknown kind '" + kinds[i] + "' (expected rbe2 or rbe3)");
    itf.kind = kinds[i] == "rbe2" ? InterfaceKind::kRbe2 : InterfaceKind::kRbe3;
    itf.master_position_m = masters.row(i).transpose();
    itf.slave_node_ids.assign(slaves.begin() + offsets[i], slaves.begin() + offsets[i + 1]);
    itf.weights.assign(weights.begin() + offsets[i], weights.begin() + offsets[i + 1]);
  }
  const std::int64_t ref = r.ReadIntAttribute("/craig_bampton", "reference_interface");
  if (ref < 0 || ref >= ni)
    in.Fail("/craig_bampton", "attribute reference_interface " + std::to_string(ref) + " is not an interface index");
  b.reference_interface = static_cast<int>(ref);
  // Inertia invariants
  FlexibleBodyModes& m = b.modes;
  const std::int64_t nf64 = r.ReadIntAttribute("/modes", "nf");
  if (nf64 < 0 || nf64 > nr) in.Fail("/modes", "attribute nf " + std::to_string(nf64) + " is out of range");
  const int nf = static_cast<int>(nf64);
  m.nf = nf;
  m.mass = in.Vector("/modes/inertia/mass", 1).front();
  m.I1 = in.Matrix("/modes/inertia/I1", 3, 1);
  m.I2 = in.Matrix("/modes/inertia/I2", 3, nf);
  m.I3 = in.Matrix("/modes/inertia/I3", 3, 3);
  const Eigen::MatrixXd I4 = in.Matrix("/modes/inertia/I4", 3 * nf, 3);
  const Eigen::MatrixXd I5 = in.Matrix("/modes/inertia/I5", 3 * static_cast<Eigen::Index>(nf) * nf, 3);
  for (int k = 0; k < nf; ++k) m.I4.push_back(I4.middleRows(3 * k, 3));
  for (Eigen::Index kl = 0; kl < static_cast<Eigen::Index>(nf) * nf; ++kl) m.I5.push_back(I5.middleRows(3 * kl, 3));
  // Stiffness, damping, geometric stiffness
  m.stiffness = in.Matrix("/modes/stiffness", nf, nf);
  m.damping = in.FiniteMatrix("/modes/damping");
  if (m.damping.size() != 0) in.CheckShape("/modes/damping", m.damping.rows(), m.damping.cols(), nf, nf);
  else m.damping.resize(0, 0);
  const std::int64_t ng = r.ReadIntAttribute("/modes/geometric_stiffness", "count");
  if (ng != 0 && ng != 6) in.Fail("/modes/geometric_stiffness", "attribute count must be 0 or 6, is " + std::to_string(ng));
  const Eigen::MatrixXd G = in.FiniteMatrix("/modes/geometric_stiffness");
  if (ng > 0) in.CheckShape("/modes/geometric_stiffness", G.rows(), G.cols(), ng * nf, nf);
  for (std::int64_t c = 0; c < ng; ++c) m.geometric_stiffness.push_back(G.middleRows(c * nf, nf));
  // Nodes
  const std::vector<int> ids = in.Ints("/modes/nodes/ids", -1, INT32_MIN, -1);
  const auto n = static_cast<Eigen::Index>(ids.size());
  const Eigen::MatrixXd positions = in.Matrix("/modes/nodes/positions", n, 3);
  const Eigen::MatrixXd tshapes = in.Matrix("/modes/nodes/translation_shapes", 3 * n, nf);
  const Eigen::MatrixXd rshapes = in.Matrix("/modes/nodes/rotation_shapes", 3 * n, nf);
  m.nodes.resize(static_cast<std::size_t>(n));
  for (Eigen::Index i = 0; i < n; ++i) {
    FlexibleBodyModes::Node& node = m.nodes[static_cast<std::size_t>(i)];
    node.id = ids[static_cast<std::size_t>(i)];
    node.position = positions.row(i).transpose();
    node.translation_shapes = tshapes.middleRows(3 * i, 3);
    node.rotation_shapes = rshapes.middleRows(3 * i, 3);
  }
  // Node sets
  const std::vector<std::string> set_names = in.Strings("/modes/node_sets/names", -1);
  const std::vector<int> set_offsets = in.Offsets("/modes/node_sets/offsets", static_cast<Eigen::Index>(set_names.size()));
  const std::vector<int> members = in.Ints("/modes/node_sets/members", set_offsets.back(), 0, n);
  for (std::size_t s = 0; s < set_names.size(); ++s)
    m.node_sets[set_names[s]].assign(members.begin() + set_offsets[s], members.begin() + set_offsets[s + 1]);
  // Surface, stress modes, frequencies
  const Hdf5Reader::IntMatrix tri = r.ReadIntMatrix("/modes/surface_triangles");
  if (tri.size() != 0) in.CheckShape("/modes/surface_triangles", tri.rows(), tri.cols(), -1, 3);
  for (Eigen::Index t = 0; t < tri.rows(); ++t) {
    std::array<int, 3> v{};
    for (int k = 0; k < 3; ++k) {
      if (tri(t, k) < 0 || tri(t, k) >= n)
        in.Fail("/modes/surface_triangles", "node index " + std::to_string(tri(t, k)) + " in row " +
                                               std::to_string(t) + " is outside [0, " + std::to_string(n) + ")");
      v[k] = static_cast<int>(tri(t, k));
    }
    m.surface_triangles.push_back(v);
  }
  m.stress_nodes = in.Ints("/modes/stress_nodes", -1, 0, n);
  m.stress_modes = in.FiniteMatrix("/modes/stress_modes");
  if (m.stress_nodes.empty() && m.stress_modes.size() == 0) {
    m.stress_modes.resize(0, m.stress_modes.cols());
  } else {
    in.CheckShape("/modes/stress_modes", m.stress_modes.rows(), m.stress_modes.cols(),
                  6 * static_cast<Eigen::Index>(m.stress_nodes.size()), nf);
  }
  m.frequencies_hz = in.Vector("/modes/frequencies_hz", nf);
  return b;
}

}  // namespace orrery::flex
