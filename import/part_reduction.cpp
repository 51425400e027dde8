#include "import/part_reduction.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <filesystem>
#include <numbers>
#include <set>
#include <stdexcept>

#include "flex/inp_file.h"
#include "import/fe_matrices.h"
#include "import/mass_properties.h"
#include "import/msh_reader.h"
#include "import/surface_mesh.h"
#include "import/volume_mesh.h"

namespace orrery {
namespace {

namespace fs = std::filesystem;

std::string Lower(std::string s) {
  for (char& c : s) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return s;
}

std::string Extension(const std::string& path) { return Lower(fs::path(path).extension().string()); }

// The bore: boundary nodes within 2 % of the smallest distance from the centroid z axis; *centre
// receives the solid's centroid (the master's position: on the axis, mid-face for a gear, where the
// slave nodes' own centroid is off by the mesh's uneven node density).
std::vector<int> BoreNodes(const flex::FeMesh& mesh, const std::string& spec, Eigen::Vector3d* centre) {
  const auto fail = [&](const std::string& what) { throw std::runtime_error("--interface " + spec + ": " + what); };
  // The centroid of the solid (its boundary's corner polyhedron, mass_properties.h), not of the
  // nodes, whose density varies
  TriangleMesh hull;
  hull.vertices = mesh.positions();
  hull.triangles = flex::BoundaryTriangles(mesh, false);
  const Eigen::Vector3d centroid = CalcMassProperties(hull, 1.0).center_of_mass_m;
  *centre = centroid;
  std::set<int> boundary;
  for (const auto& t : flex::BoundaryTriangles(mesh, true)) boundary.insert(t.begin(), t.end());
  const auto radius = [&](int n) { return (mesh.positions()[n] - centroid).head<2>().norm(); };
  // The smallest radius over corner nodes (they lie on the surface; a midside node of a straight
  // edge lies on a chord, inside it)
  double r_min = INFINITY;
  for (const auto& t : hull.triangles)
    for (int n : t) r_min = std::min(r_min, radius(n));
  std::vector<int> nodes;
  std::vector<double> angles;
  for (int n : boundary)
    if (radius(n) <= 1.02 * r_min) {
      nodes.push_back(n);
      const Eigen::Vector3d d = mesh.positions()[n] - centroid;
      angles.push_back(std::atan2(d.y(), d.x()));
    }
  if (nodes.size() < 3) fail("found " + std::to_string(nodes.size()) + " bore nodes (no bore about the z axis?)");
  // The nodes must go round the axis: no angular gap of half a turn or more
  std::sort(angles.begin(), angles.end());
  double gap = angles.front() + 2 * std::numbers::pi - angles.back();
  for (std::size_t i = 1; i < angles.size(); ++i) gap = std::max(gap, angles[i] - angles[i - 1]);
  if (gap >= std::numbers::pi)
    fail("the innermost boundary nodes (r = " + std::to_string(r_min) +
         " m from the centroid z axis) do not go round the axis: no bore found");
  return nodes;
}

// The material of a mesh input: the given one, or the file's (.inp with materials) when none.
void AssignMaterial(flex::FeMesh& mesh, const PartReductionInput& in) {
  if (in.material) {
    mesh.AssignMaterialToAll(*in.material);
  } else if (mesh.materials().empty()) {
    throw std::runtime_error(in.input + " has no material: give --E, --nu and --density");
  }
}

// External matrices: the files, the mesh, the FE model.
void PrepareMatrices(const PartReductionInput& in, PartReduction& job) {
  const std::string ext = Extension(in.input);
  FeMatrices matrices;
  std::string mesh_file = in.mesh_file;
  if (ext == ".sti") {
    if (!in.mass_matrix.empty() || !in.dof_table.empty())
      throw std::runtime_error(in.input + ": CalculiX matrices come as job.sti, job.mas and job.dof side by side");
    matrices = ReadCalculixMatrices(in.input);
    if (mesh_file.empty()) mesh_file = fs::path(in.input).replace_extension(".inp").string();
  } else {
    if (in.mass_matrix.empty() || in.dof_table.empty() || mesh_file.empty())
      throw std::runtime_error(in.input + ": a Matrix Market stiffness needs --mass M.mtx, --dofs TABLE and --mesh "
                                          "MESH (.inp or .msh: node positions and sets)");
    matrices = ReadMatrixMarketPair(in.input, in.mass_matrix, in.dof_table);
  }
  if (in.material) throw std::runtime_error("--E, --nu and --density do not apply to FE matrices (" + in.input + ")");
  const flex::FeMesh mesh = Extension(mesh_file) == ".msh" ? ReadGmshMsh(mesh_file).mesh : flex::ReadInp(mesh_file).mesh;
  ExternalFeModel model = ToFeModel(matrices, mesh, mesh_file);
  job.mesh = std::move(model.mesh);
  job.system = std::move(model.system);
  job.notes = std::move(model.notes);
  job.matrices_digest = matrices.digest;
  job.source = matrices.source + " on the nodes of " + mesh_file;
}

}  // namespace

bool IsPartReductionInput(const std::string& path) {
  const std::string ext = Extension(path);
  return ext == ".sti" || ext == ".mtx" || ext == ".inp" || DetectMeshFileFormat(path) != MeshFileFormat::kUnknown;
}

flex::FeInterface SelectInterface(const flex::FeMesh& mesh, const std::string& spec) {
  const std::size_t colon = spec.rfind(':');
  const std::string what = spec.substr(0, colon);
  const std::string kind = colon == std::string::npos ? "rbe2" : Lower(spec.substr(colon + 1));
  if (what.empty() || (kind != "rbe2" && kind != "rbe3"))
    throw std::runtime_error("--interface " + spec + ": expected NODESET, NODESET:rbe2 or NODESET:rbe3 (NODESET a node set or bore)");
  const flex::InterfaceKind k = kind == "rbe3" ? flex::InterfaceKind::kRbe3 : flex::InterfaceKind::kRbe2;
  if (Lower(what) == "bore") {
    flex::FeInterface i;
    i.name = "BORE";
    i.kind = k;
    Eigen::Vector3d centre;
    i.nodes = BoreNodes(mesh, spec, &centre);
    i.master_position_m = centre;
    return i;
  }
  try {
    flex::FeInterface i = flex::MakeInterface(mesh, what, k);
    i.name = flex::UpperName(what);
    return i;
  } catch (const std::invalid_argument& e) {
    throw std::runtime_error("--interface " + spec + ": " + e.what());
  }
}

PartReduction PreparePartReduction(const PartReductionInput& in) {
  PartReduction job;
  if (in.interfaces.empty())
    throw std::runtime_error("a mesh input needs --interface NODESET|bore[:rbe2|rbe3] (the first is the body frame's): " +
                             in.input);
  const std::string ext = Extension(in.input);
  if (ext == ".sti" || ext == ".mtx") {
    PrepareMatrices(in, job);
  } else {
    if (!in.mass_matrix.empty() || !in.dof_table.empty() || !in.mesh_file.empty())
      throw std::runtime_error("--mass, --dofs and --mesh go with FE matrices (.sti, .mtx), not with " + in.input);
    VolumeMesh v = ReadVolumeMesh(in.input, {.unit = in.unit, .meshing = in.meshing});
    job.mesh = std::move(v.mesh);
    job.notes = std::move(v.notes);
    job.warnings = std::move(v.warnings);
    job.source = v.description;
    AssignMaterial(job.mesh, in);
  }
  for (const std::string& spec : in.interfaces) {
    job.interfaces.push_back(SelectInterface(job.mesh, spec));
    job.interface_sets.push_back(spec.substr(0, spec.rfind(':')));
  }
  // Each interface once
  std::set<std::string> names;
  for (const flex::FeInterface& i : job.interfaces)
    if (!names.insert(i.name).second) throw std::runtime_error("--interface " + i.name + " is given twice");
  job.cb_options = {.num_modes = in.modes, .cutoff_hz = in.cutoff_hz};
  // Stress modes and geometric stiffness need elements with a material
  const bool has_material = job.mesh.num_elements() > 0 &&
                            std::none_of(job.mesh.element_material().begin(), job.mesh.element_material().end(),
                                         [](int m) { return m < 0; });
  job.outputs = {.stress_modes = has_material, .geometric_stiffness = has_material};
  if (!has_material) job.notes.push_back(in.input + ": no elements with a material: no stress modes, no geometric stiffness");
  return job;
}

}  // namespace orrery
