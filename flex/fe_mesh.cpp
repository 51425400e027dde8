#include "flex/fe_mesh.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <stdexcept>
#include <unordered_set>

namespace orrery::flex {

int NodeCount(ElementType t) {
  switch (t) {
    case ElementType::kTet4: return 4;
    case ElementType::kTet10: return 10;
    case ElementType::kHex8: return 8;
    case ElementType::kHex20: return 20;
  }
  return 0;
}

int CornerCount(ElementType t) { return IsTet(t) ? 4 : 8; }

bool IsTet(ElementType t) { return t == ElementType::kTet4 || t == ElementType::kTet10; }

const char* CalculixName(ElementType t) {
  switch (t) {
    case ElementType::kTet4: return "C3D4";
    case ElementType::kTet10: return "C3D10";
    case ElementType::kHex8: return "C3D8";
    case ElementType::kHex20: return "C3D20";
  }
  return "?";
}

std::optional<ElementType> ElementTypeFromCalculixName(std::string_view name) {
  const std::string n = UpperName(name);
  if (n == "C3D4") return ElementType::kTet4;
  if (n == "C3D10") return ElementType::kTet10;
  if (n == "C3D8") return ElementType::kHex8;
  if (n == "C3D20") return ElementType::kHex20;
  return std::nullopt;
}

std::string UpperName(std::string_view name) {
  std::string s(name);
  for (char& c : s) c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
  return s;
}

void ValidateMaterial(const IsotropicMaterial& m) {
  const std::string who = m.name.empty() ? std::string("material") : "material " + m.name;
  if (!(m.youngs_modulus_pa > 0) || !std::isfinite(m.youngs_modulus_pa))
    throw std::invalid_argument(who + ": Young's modulus must be > 0 Pa, got " +
                                std::to_string(m.youngs_modulus_pa));
  if (!(m.poissons_ratio > -1 && m.poissons_ratio < 0.5))
    throw std::invalid_argument(who + ": Poisson's ratio must be in (-1, 0.5), got " +
                                std::to_string(m.poissons_ratio));
  if (!(m.density_kg_m3 > 0) || !std::isfinite(m.density_kg_m3))
    throw std::invalid_argument(who + ": density must be > 0 kg/m^3, got " +
                                std::to_string(m.density_kg_m3));
}

int FeMesh::AddNode(int id, const Eigen::Vector3d& p_m) {
  if (node_index_.contains(id)) throw std::invalid_argument("node " + std::to_string(id) + " defined twice");
  if (!p_m.allFinite()) throw std::invalid_argument("node " + std::to_string(id) + ": non-finite coordinate");
  const int index = num_nodes();
  node_index_.emplace(id, index);
  node_ids_.push_back(id);
  positions_.push_back(p_m);
  return index;
}

int FeMesh::AddElement(int id, ElementType type, std::span<const int> node_ids) {
  const std::string who = std::string("element ") + std::to_string(id);
  if (element_index_.contains(id)) throw std::invalid_argument(who + " defined twice");
  if (static_cast<int>(node_ids.size()) != NodeCount(type))
    throw std::invalid_argument(who + " (" + CalculixName(type) + "): " + std::to_string(node_ids.size()) +
                                " nodes, expected " + std::to_string(NodeCount(type)));
  FeElement e{.id = id, .type = type};
  for (int k = 0; k < NodeCount(type); ++k) {
    const std::optional<int> n = FindNode(node_ids[k]);
    if (!n) throw std::invalid_argument(who + ": unknown node " + std::to_string(node_ids[k]));
    for (int j = 0; j < k; ++j)
      if (e.nodes[j] == *n) throw std::invalid_argument(who + ": node " + std::to_string(node_ids[k]) + " repeated");
    e.nodes[k] = *n;
  }
  const int index = num_elements();
  element_index_.emplace(id, index);
  elements_.push_back(e);
  element_material_.push_back(-1);
  return index;
}

namespace {
void AppendUnique(std::vector<int>& set, std::span<const int> items) {
  std::unordered_set<int> present(set.begin(), set.end());
  for (int i : items)
    if (present.insert(i).second) set.push_back(i);
}

std::string SetNames(const std::map<std::string, std::vector<int>>& sets) {
  if (sets.empty()) return "none";
  std::string s;
  for (const auto& [name, items] : sets) s += (s.empty() ? "" : ", ") + name;
  return s;
}
}  // namespace

void FeMesh::AddToNodeSet(std::string_view name, std::span<const int> node_indices) {
  for (int i : node_indices)
    if (i < 0 || i >= num_nodes()) throw std::out_of_range("node set " + std::string(name) + ": bad node index");
  AppendUnique(node_sets_[UpperName(name)], node_indices);
}

void FeMesh::AddToElementSet(std::string_view name, std::span<const int> element_indices) {
  for (int i : element_indices)
    if (i < 0 || i >= num_elements())
      throw std::out_of_range("element set " + std::string(name) + ": bad element index");
  AppendUnique(element_sets_[UpperName(name)], element_indices);
}

void FeMesh::AssignMaterial(std::string_view element_set, const IsotropicMaterial& material) {
  ValidateMaterial(material);
  const std::vector<int>& elements = ElementSet(element_set);
  int m = -1;
  for (int i = 0; i < static_cast<int>(materials_.size()); ++i)
    if (!material.name.empty() && materials_[i].name == material.name) m = i;
  if (m < 0) {
    m = static_cast<int>(materials_.size());
    materials_.push_back(material);
  } else {
    materials_[m] = material;
  }
  for (int e : elements) element_material_[e] = m;
  sections_.emplace_back(UpperName(element_set), m);
}

void FeMesh::AssignMaterialToAll(const IsotropicMaterial& material) {
  std::vector<int> all(num_elements());
  for (int i = 0; i < num_elements(); ++i) all[i] = i;
  AddToElementSet("EALL", all);
  AssignMaterial("EALL", material);
}

std::optional<int> FeMesh::FindNode(int id) const {
  const auto it = node_index_.find(id);
  if (it == node_index_.end()) return std::nullopt;
  return it->second;
}

std::optional<int> FeMesh::FindElement(int id) const {
  const auto it = element_index_.find(id);
  if (it == element_index_.end()) return std::nullopt;
  return it->second;
}

const std::vector<int>& FeMesh::NodeSet(std::string_view name) const {
  const auto it = node_sets_.find(UpperName(name));
  if (it == node_sets_.end())
    throw std::invalid_argument("no node set '" + std::string(name) + "' (node sets: " + SetNames(node_sets_) + ")");
  return it->second;
}

const std::vector<int>& FeMesh::ElementSet(std::string_view name) const {
  const auto it = element_sets_.find(UpperName(name));
  if (it == element_sets_.end())
    throw std::invalid_argument("no element set '" + std::string(name) + "' (element sets: " +
                                SetNames(element_sets_) + ")");
  return it->second;
}

Eigen::MatrixX3d FeMesh::ElementPositions(int element_index) const {
  const FeElement& e = elements_.at(element_index);
  const int n = NodeCount(e.type);
  Eigen::MatrixX3d X(n, 3);
  for (int k = 0; k < n; ++k) X.row(k) = positions_[e.nodes[k]].transpose();
  return X;
}

}  // namespace orrery::flex
