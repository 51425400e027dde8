#include "import/fe_matrices.h"

#include <algorithm>
#include <array>
#include <cctype>
#include <climits>
#include <cmath>
#include <stdexcept>
#include <unordered_map>

#include "flex/reduced_body_file.h"
#include "import/text_scanner.h"

namespace orrery {
namespace {

using Triplet = Eigen::Triplet<double>;

std::string Lower(std::string_view s) {
  std::string out(s);
  for (char& c : out) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return out;
}

std::string Show(std::string_view t) { return std::string(t.substr(0, 40)); }

// Reads "i j value" entries (1-based) until the end, `expected` of them when >= 0.
class EntryReader {
 public:
  EntryReader(TextScanner& s, const std::string& source) : s_(s), source_(source) {}

  [[noreturn]] void Fail(const std::string& what) const {
    throw std::runtime_error(source_ + ":" + std::to_string(s_.line()) + ": " + what);
  }
  std::int64_t Int(const char* what) {
    std::string_view t;
    std::int64_t v = 0;
    if (!s_.NextToken(t)) Fail(std::string("expected ") + what + ", got the end of the file");
    if (!ParseInt64(t, v)) Fail(std::string("expected ") + what + " (an integer), got '" + Show(t) + "'");
    return v;
  }
  double Real(const char* what) {
    std::string_view t;
    double v = 0;
    if (!s_.NextToken(t)) Fail(std::string("expected ") + what + ", got the end of the file");
    if (!ParseDouble(t, v)) Fail(std::string("expected ") + what + " (a number), got '" + Show(t) + "'");
    if (!std::isfinite(v)) Fail(std::string(what) + " is not finite: '" + Show(t) + "'");
    return v;
  }
  int Index(const char* what, std::int64_t size) {
    const std::int64_t i = Int(what);
    if (i < 1 || i > size) Fail(std::string(what) + " " + std::to_string(i) + " outside 1.." + std::to_string(size));
    return static_cast<int>(i - 1);
  }

 private:
  TextScanner& s_;
  const std::string& source_;
};

// Sum of duplicates, mirrored off-diagonal entries of a symmetric matrix from one triangle.
Eigen::SparseMatrix<double> Symmetric(int n, const std::vector<Triplet>& entries, bool mirror) {
  std::vector<Triplet> all;
  all.reserve(entries.size() * (mirror ? 2 : 1));
  for (const Triplet& t : entries) {
    all.push_back(t);
    if (mirror && t.row() != t.col()) all.emplace_back(t.col(), t.row(), t.value());
  }
  Eigen::SparseMatrix<double> A(n, n);
  A.setFromTriplets(all.begin(), all.end());
  return A;
}

void CheckSymmetric(const Eigen::SparseMatrix<double>& A, const std::string& source) {
  const Eigen::SparseMatrix<double> At = A.transpose();
  const Eigen::SparseMatrix<double> D = A - At;
  const double scale = A.nonZeros() ? A.coeffs().cwiseAbs().maxCoeff() : 0.0;
  const double asym = D.nonZeros() ? D.coeffs().cwiseAbs().maxCoeff() : 0.0;
  if (asym > 1e-9 * scale)
    throw std::runtime_error(source + ": the matrix is not symmetric (largest |A - A^T| " + std::to_string(asym) +
                             " against entries up to " + std::to_string(scale) + ")");
}

std::string StemPath(const std::filesystem::path& job, const char* extension) {
  std::filesystem::path p = job;
  const std::string e = Lower(p.extension().string());
  if (e == ".sti" || e == ".mas" || e == ".dof" || e == ".inp") p.replace_extension();
  return p.string() + extension;
}

}  // namespace

Eigen::SparseMatrix<double> ParseMatrixMarket(std::string_view bytes, const std::string& source) {
  TextScanner s(bytes);
  EntryReader r(s, source);
  // Banner: %%MatrixMarket matrix <format> <field> <symmetry>
  std::string_view line;
  if (!s.NextLine(line)) throw std::runtime_error(source + ": empty file (not a Matrix Market file)");
  TextScanner banner(line);
  std::string_view word[5];
  for (auto& w : word)
    if (!banner.NextToken(w)) r.Fail("expected '%%MatrixMarket matrix coordinate|array real|integer general|symmetric'");
  if (Lower(word[0]) != "%%matrixmarket" || Lower(word[1]) != "matrix")
    r.Fail("not a Matrix Market file (the first line must begin with '%%MatrixMarket matrix')");
  const std::string format = Lower(word[2]), field = Lower(word[3]), symmetry = Lower(word[4]);
  if (format != "coordinate" && format != "array") r.Fail("format '" + format + "' (coordinate or array are read)");
  if (field != "real" && field != "integer" && field != "double")
    r.Fail("field '" + field + "' (real or integer are read: stiffness and mass are real)");
  if (symmetry != "general" && symmetry != "symmetric")
    r.Fail("symmetry '" + symmetry + "' (general or symmetric are read)");
  // Comments, then the size line
  for (;;) {
    const std::size_t before = s.position();
    if (!s.NextLine(line)) break;
    std::size_t i = 0;
    while (i < line.size() && std::isspace(static_cast<unsigned char>(line[i]))) ++i;
    if (i < line.size() && line[i] != '%') {
      s.Seek(before);
      break;
    }
  }
  const std::int64_t rows = r.Int("the number of rows"), cols = r.Int("the number of columns");
  if (rows != cols || rows < 1 || rows > INT_MAX / 3)
    r.Fail("a stiffness or mass matrix is square: got " + std::to_string(rows) + " x " + std::to_string(cols));
  const int n = static_cast<int>(rows);
  const bool symmetric = symmetry == "symmetric";
  std::vector<Triplet> entries;
  if (format == "coordinate") {
    const std::int64_t nnz = r.Int("the number of entries");
    if (nnz < 0 || static_cast<std::uint64_t>(nnz) > s.remaining() / 6 + 1)
      r.Fail("header says " + std::to_string(nnz) + " entries, more than the " + std::to_string(s.remaining()) +
             " bytes left can hold");
    entries.reserve(static_cast<std::size_t>(nnz));
    for (std::int64_t k = 0; k < nnz; ++k) {
      const int i = r.Index("row", n), j = r.Index("column", n);
      entries.emplace_back(i, j, r.Real("a value"));
    }
  } else {
    // Column-major; symmetric: the lower triangle of each column
    const std::uint64_t count = symmetric ? std::uint64_t(n) * (n + 1) / 2 : std::uint64_t(n) * n;
    if (count > s.remaining() / 2 + 1)
      r.Fail("an array of " + std::to_string(n) + " x " + std::to_string(n) + " needs more values than the file holds");
    for (int j = 0; j < n; ++j)
      for (int i = symmetric ? j : 0; i < n; ++i) {
        const double v = r.Real("a value");
        if (v != 0) entries.emplace_back(i, j, v);
      }
  }
  std::string_view extra;
  if (s.NextToken(extra)) r.Fail("unexpected data after the last entry: '" + Show(extra) + "'");
  Eigen::SparseMatrix<double> A = Symmetric(n, entries, symmetric);
  if (!symmetric) CheckSymmetric(A, source);
  return A;
}

Eigen::SparseMatrix<double> ReadMatrixMarket(const std::filesystem::path& path, std::uintmax_t max_bytes) {
  return ParseMatrixMarket(ReadFileBounded(path, max_bytes), path.string());
}

Eigen::SparseMatrix<double> ParseCalculixMatrix(std::string_view bytes, int size, const std::string& source) {
  TextScanner s(bytes);
  EntryReader r(s, source);
  std::vector<Triplet> entries;
  std::string_view token;
  for (;;) {
    const std::size_t before = s.position();
    if (!s.NextToken(token)) break;
    s.Seek(before);
    const int i = r.Index("row", size), j = r.Index("column", size);
    if (i > j) r.Fail("entry (" + std::to_string(i + 1) + ", " + std::to_string(j + 1) + ") below the diagonal (ccx writes the upper triangle)");
    entries.emplace_back(i, j, r.Real("a value"));
  }
  if (entries.empty()) throw std::runtime_error(source + ": no matrix entries");
  return Symmetric(size, entries, true);
}

std::vector<DofEntry> ParseDofTable(std::string_view bytes, const std::string& source) {
  TextScanner s(bytes);
  std::vector<DofEntry> dofs;
  std::string_view line;
  while (s.NextLine(line)) {
    const std::size_t comment = line.find_first_of("#%");
    if (comment != std::string_view::npos) line = line.substr(0, comment);
    TextScanner words(line);
    std::string_view a, b;
    if (!words.NextToken(a)) continue;
    const auto fail = [&](const std::string& what) {
      throw std::runtime_error(source + ":" + std::to_string(s.line()) + ": " + what);
    };
    if (!words.NextToken(b)) {
      // "node.dir"
      const std::size_t dot = a.find('.');
      if (dot == std::string_view::npos) fail("expected 'NODE DIR' or 'NODE.DIR', got '" + Show(a) + "'");
      b = a.substr(dot + 1);
      a = a.substr(0, dot);
    }
    std::string_view rest;
    if (words.NextToken(rest)) fail("unexpected '" + Show(rest) + "' after the node and direction");
    std::int64_t node = 0, dir = 0;
    if (!ParseInt64(a, node) || node < 1 || node > INT_MAX) fail("expected a node id, got '" + Show(a) + "'");
    const std::string d = Lower(b);
    dir = d == "x" ? 1 : d == "y" ? 2 : d == "z" ? 3 : 0;
    if (dir == 0 && !ParseInt64(d, dir)) fail("expected a direction 1-3 or x, y, z, got '" + Show(b) + "'");
    if (dir < 1 || dir > 3)
      fail("direction " + std::to_string(dir) + " of node " + std::to_string(node) +
           ": only the translations 1-3 of solid elements are supported (no shell or beam rotations)");
    dofs.push_back({static_cast<int>(node), static_cast<int>(dir)});
  }
  if (dofs.empty()) throw std::runtime_error(source + ": no DOFs listed");
  return dofs;
}

FeMatrices ReadCalculixMatrices(const std::filesystem::path& job, std::uintmax_t max_bytes) {
  const std::string sti = StemPath(job, ".sti"), mas = StemPath(job, ".mas"), dof = StemPath(job, ".dof");
  FeMatrices m;
  const std::string dof_bytes = ReadFileBounded(dof, max_bytes);
  m.dofs = ParseDofTable(dof_bytes, dof);
  const int n = static_cast<int>(m.dofs.size());
  const std::string k_bytes = ReadFileBounded(sti, max_bytes);
  m.K = ParseCalculixMatrix(k_bytes, n, sti);
  const std::string m_bytes = ReadFileBounded(mas, max_bytes);
  m.M = ParseCalculixMatrix(m_bytes, n, mas);
  m.source = "CalculiX matrices " + sti + ", " + mas + ", " + dof;
  m.digest = flex::Fnv1a64Hex(dof_bytes + '\0' + k_bytes + '\0' + m_bytes);
  return m;
}

FeMatrices ReadMatrixMarketPair(const std::filesystem::path& stiffness, const std::filesystem::path& mass,
                                const std::filesystem::path& dof_table, std::uintmax_t max_bytes) {
  FeMatrices m;
  const std::string k_bytes = ReadFileBounded(stiffness, max_bytes);
  const std::string m_bytes = ReadFileBounded(mass, max_bytes);
  const std::string dof_bytes = ReadFileBounded(dof_table, max_bytes);
  m.K = ParseMatrixMarket(k_bytes, stiffness.string());
  m.M = ParseMatrixMarket(m_bytes, mass.string());
  m.dofs = ParseDofTable(dof_bytes, dof_table.string());
  if (m.K.rows() != m.M.rows())
    throw std::runtime_error(stiffness.string() + " is " + std::to_string(m.K.rows()) + " x " +
                             std::to_string(m.K.rows()) + " but " + mass.string() + " is " +
                             std::to_string(m.M.rows()) + " x " + std::to_string(m.M.rows()));
  if (static_cast<Eigen::Index>(m.dofs.size()) != m.K.rows())
    throw std::runtime_error(dof_table.string() + ": lists " + std::to_string(m.dofs.size()) +
                             " DOFs but the matrices have " + std::to_string(m.K.rows()) + " rows");
  m.source = "Matrix Market " + stiffness.string() + ", " + mass.string() + ", DOFs " + dof_table.string();
  m.digest = flex::Fnv1a64Hex(dof_bytes + '\0' + k_bytes + '\0' + m_bytes);
  return m;
}

ExternalFeModel ToFeModel(const FeMatrices& matrices, const flex::FeMesh& mesh, const std::string& mesh_source) {
  ExternalFeModel out;
  const std::string& msrc = matrices.source;
  // Each DOF of the table: a node of the mesh, each (node, direction) once
  std::unordered_map<int, std::array<int, 3>> row_of;  // node id -> row of each direction
  for (std::size_t r = 0; r < matrices.dofs.size(); ++r) {
    const DofEntry& d = matrices.dofs[r];
    if (!mesh.FindNode(d.node_id))
      throw std::runtime_error(msrc + ": DOF " + std::to_string(r + 1) + " is on node " + std::to_string(d.node_id) +
                               ", which " + mesh_source + " does not have");
    auto [it, added] = row_of.emplace(d.node_id, std::array<int, 3>{-1, -1, -1});
    int& slot = it->second[d.direction - 1];
    if (slot >= 0)
      throw std::runtime_error(msrc + ": node " + std::to_string(d.node_id) + " direction " +
                               std::to_string(d.direction) + " is listed twice");
    slot = static_cast<int>(r);
  }
  for (const auto& [node, rows] : row_of)
    for (int k = 0; k < 3; ++k)
      if (rows[k] < 0)
        throw std::runtime_error(msrc + ": node " + std::to_string(node) + " has no DOF " + std::to_string(k + 1) +
                                 " (held by a boundary condition in the exporting model? export the free model)");

  // The mesh restricted to those nodes, in mesh order; elements, sets and materials carried over
  flex::FeMesh& fe = out.mesh;
  std::vector<int> new_index(mesh.num_nodes(), -1);
  for (int i = 0; i < mesh.num_nodes(); ++i)
    if (row_of.count(mesh.node_ids()[i])) new_index[i] = fe.AddNode(mesh.node_ids()[i], mesh.positions()[i]);
  if (fe.num_nodes() < mesh.num_nodes())
    out.notes.push_back(mesh_source + ": " + std::to_string(mesh.num_nodes() - fe.num_nodes()) +
                        " nodes without DOFs in the matrices left out");
  std::vector<int> ids;
  for (const flex::FeElement& e : mesh.elements()) {
    ids.resize(flex::NodeCount(e.type));
    for (std::size_t a = 0; a < ids.size(); ++a) {
      if (new_index[e.nodes[a]] < 0)
        throw std::runtime_error(mesh_source + ": element " + std::to_string(e.id) + " uses node " +
                                 std::to_string(mesh.node_ids()[e.nodes[a]]) + ", which has no DOFs in " + msrc);
      ids[a] = mesh.node_ids()[e.nodes[a]];
    }
    fe.AddElement(e.id, e.type, ids);
  }
  for (const auto& [name, nodes] : mesh.node_sets()) {
    std::vector<int> kept;
    for (int n : nodes)
      if (new_index[n] >= 0) kept.push_back(new_index[n]);
    if (!kept.empty()) fe.AddToNodeSet(name, kept);
  }
  for (const auto& [name, elements] : mesh.element_sets()) fe.AddToElementSet(name, elements);
  for (const auto& [set, material] : mesh.sections()) fe.AssignMaterial(set, mesh.materials()[material]);

  // K and M in the FE numbering: row r -> DOF 3 new_index(node) + direction - 1
  std::vector<int> perm(matrices.dofs.size());
  for (std::size_t r = 0; r < matrices.dofs.size(); ++r) {
    const DofEntry& d = matrices.dofs[r];
    perm[r] = 3 * new_index[*mesh.FindNode(d.node_id)] + d.direction - 1;
  }
  const auto permute = [&](const Eigen::SparseMatrix<double>& A) {
    std::vector<Triplet> t;
    t.reserve(A.nonZeros());
    for (int c = 0; c < A.outerSize(); ++c)
      for (Eigen::SparseMatrix<double>::InnerIterator it(A, c); it; ++it)
        t.emplace_back(perm[it.row()], perm[it.col()], it.value());
    Eigen::SparseMatrix<double> B(A.rows(), A.cols());
    B.setFromTriplets(t.begin(), t.end());
    return B;
  };
  out.system.K = permute(matrices.K);
  out.system.M = permute(matrices.M);
  // Mass: the x-translation block summed (a rigid x translation's kinetic energy, 2 T / v^2)
  double mass = 0;
  for (int c = 0; c < out.system.M.outerSize(); ++c)
    for (Eigen::SparseMatrix<double>::InnerIterator it(out.system.M, c); it; ++it)
      if (it.row() % 3 == 0 && it.col() % 3 == 0) mass += it.value();
  out.system.mass_kg = mass;
  return out;
}

}  // namespace orrery
