#pragma once
// What a contact element (contact_element.h, flexible_contact_element.h) reports after its own
// outputs: a gear pair's mesh outputs (gear_mesh_outputs.h) when it has gears, then its recorded
// contact points (contact_point_record.h) when asked for n > 0 of them. Both elements list,
// size and write them through these, in this order.
#include <string>
#include <vector>

#include "contact/contact_point_record.h"
#include "contact/gear_mesh_outputs.h"

namespace orrery::contact {

struct ContactOutputOptions {
  bool gear = false;      // mesh outputs
  int record_points = 0;  // n
};

// Appends the names and the units of the optional outputs.
void AppendContactOutputs(const ContactOutputOptions& o, std::vector<std::string>* names,
                          std::vector<std::string>* units);
// Columns of every output: one each for the element's own and the mesh outputs, 3 n and n for
// the points.
std::vector<int> ContactOutputColumns(const ContactOutputOptions& o, int own_outputs);
// Writes the optional outputs' values from `values` on.
void WriteContactOutputs(const ContactOutputOptions& o, const GearMeshObserver& gear,
                         const ContactPointRecord& points, double* values);

}  // namespace orrery::contact
