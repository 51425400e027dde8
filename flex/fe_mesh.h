#pragma once
// Finite-element mesh of a linear elastic solid: nodes, solid elements, element and node sets,
// isotropic materials assigned to element sets. The data an .inp file (inp_reader.h) holds and
// the assembly (fe_assembly.h) needs.
//
// Element types and node order (CalculiX / Abaqus, checked against CalculiX's shape function
// routines shape4tet.f, shape10tet.f, shape8h.f, shape20h.f):
//   kTet4  (C3D4):  corners 1-4; natural coordinates (xi, eta, zeta) in the unit tetrahedron,
//                   node 1 at the origin, 2 on xi, 3 on eta, 4 on zeta.
//   kTet10 (C3D10): corners 1-4 as C3D4, midside nodes 5 (1-2), 6 (2-3), 7 (3-1), 8 (1-4),
//                   9 (2-4), 10 (3-4).
//   kHex8  (C3D8):  corners 1-4 on the face zeta = -1 counter-clockwise seen from +zeta
//                   (1 at (-1,-1), 2 at (1,-1), 3 at (1,1), 4 at (-1,1)), 5-8 above them.
//   kHex20 (C3D20): corners as C3D8; midside nodes 9 (1-2), 10 (2-3), 11 (3-4), 12 (4-1),
//                   13 (5-6), 14 (6-7), 15 (7-8), 16 (8-5), 17 (1-5), 18 (2-6), 19 (3-7),
//                   20 (4-8).
// A right-handed element (positive Jacobian determinant) has node 4 (tets) or the face 5-8
// (hexes) on the side of +zeta.
//
// Conventions: SI units (m, Pa, kg/m^3). Nodes, elements and sets keep the ids and names of
// their source; set names are stored upper case (Abaqus names are case-insensitive). Indices
// (0-based, dense) are what the assembly uses; ids are what users and files see.
//
// Usage:
//   FeMesh mesh;
//   mesh.AddNode(1, {0, 0, 0}); ...                       // ids, positions in m
//   mesh.AddElement(1, ElementType::kTet4, {1, 2, 3, 4}); // node ids
//   mesh.AssignMaterial("EALL", {.name = "STEEL", .youngs_modulus_pa = 210e9, ...});
#include <array>
#include <initializer_list>
#include <map>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <unordered_map>
#include <vector>

#include <Eigen/Core>

namespace orrery::flex {

enum class ElementType { kTet4, kTet10, kHex8, kHex20 };

inline constexpr int kMaxElementNodes = 20;

// Nodes of an element of type `t` (4, 10, 8, 20).
int NodeCount(ElementType t);
// Corner nodes (4 or 8): the first NodeCount entries of the corner list.
int CornerCount(ElementType t);
bool IsTet(ElementType t);
// "C3D4", "C3D10", "C3D8", "C3D20".
const char* CalculixName(ElementType t);
// The type of a CalculiX/Abaqus element name (case-insensitive); nullopt for other names.
std::optional<ElementType> ElementTypeFromCalculixName(std::string_view name);

struct FeElement {
  int id = 0;
  ElementType type = ElementType::kTet4;
  std::array<int, kMaxElementNodes> nodes{};  // node indices (0-based), NodeCount(type) used
};

// Isotropic linear elastic material.
struct IsotropicMaterial {
  std::string name;
  double youngs_modulus_pa = 0;
  double poissons_ratio = 0;
  double density_kg_m3 = 0;
};

// Throws std::invalid_argument unless E > 0, -1 < nu < 0.5 and rho > 0 (all finite).
void ValidateMaterial(const IsotropicMaterial& m);

class FeMesh {
 public:
  // Adds a node; throws std::invalid_argument if `id` exists. Returns its index.
  int AddNode(int id, const Eigen::Vector3d& p_m);
  // Adds an element with the given node ids (NodeCount(type) of them, CalculiX order); throws
  // std::invalid_argument if the id exists, a node id is unknown or the count is wrong.
  int AddElement(int id, ElementType type, std::span<const int> node_ids);
  int AddElement(int id, ElementType type, std::initializer_list<int> node_ids) {
    return AddElement(id, type, std::span<const int>(node_ids.begin(), node_ids.size()));
  }

  // Adds node / element indices to a set (created if missing; duplicates dropped, order kept).
  void AddToNodeSet(std::string_view name, std::span<const int> node_indices);
  void AddToElementSet(std::string_view name, std::span<const int> element_indices);

  // Assigns `material` to every element of `element_set` (replacing an earlier assignment of
  // these elements). Throws std::invalid_argument for an unknown set or an invalid material.
  void AssignMaterial(std::string_view element_set, const IsotropicMaterial& material);
  // Assigns `material` to every element (element set "EALL" is created / extended).
  void AssignMaterialToAll(const IsotropicMaterial& material);

  int num_nodes() const { return static_cast<int>(node_ids_.size()); }
  int num_elements() const { return static_cast<int>(elements_.size()); }

  const std::vector<int>& node_ids() const { return node_ids_; }                 // (num_nodes)
  const std::vector<Eigen::Vector3d>& positions() const { return positions_; }   // (num_nodes) m
  const std::vector<FeElement>& elements() const { return elements_; }           // (num_elements)
  const std::map<std::string, std::vector<int>>& node_sets() const { return node_sets_; }
  const std::map<std::string, std::vector<int>>& element_sets() const { return element_sets_; }
  const std::vector<IsotropicMaterial>& materials() const { return materials_; }
  // Per element: index into materials(), -1 where none is assigned.       (num_elements)
  const std::vector<int>& element_material() const { return element_material_; }
  // Element sets named in material assignments, in order, with their material index.
  const std::vector<std::pair<std::string, int>>& sections() const { return sections_; }

  // Index of a node / element id; nullopt if unknown.
  std::optional<int> FindNode(int id) const;
  std::optional<int> FindElement(int id) const;
  // The indices of a node / element set (name case-insensitive); throws std::invalid_argument
  // naming the set (and the sets that exist) if unknown.
  const std::vector<int>& NodeSet(std::string_view name) const;
  const std::vector<int>& ElementSet(std::string_view name) const;

  // The positions of element e's nodes, one row per node (NodeCount x 3).
  Eigen::MatrixX3d ElementPositions(int element_index) const;

 private:
  std::vector<int> node_ids_;
  std::vector<Eigen::Vector3d> positions_;
  std::unordered_map<int, int> node_index_;
  std::vector<FeElement> elements_;
  std::unordered_map<int, int> element_index_;
  std::map<std::string, std::vector<int>> node_sets_;
  std::map<std::string, std::vector<int>> element_sets_;
  std::vector<IsotropicMaterial> materials_;
  std::vector<int> element_material_;
  std::vector<std::pair<std::string, int>> sections_;
};

// Upper-case copy of an Abaqus name (ASCII).
std::string UpperName(std::string_view name);

}  // namespace orrery::flex
