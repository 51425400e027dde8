#include "contact/contact_outputs.h"

namespace orrery::contact {

void AppendContactOutputs(const ContactOutputOptions& o, std::vector<std::string>* names,
                          std::vector<std::string>* units) {
  if (o.gear) {
    if (names) names->insert(names->end(), kGearMeshOutputNames.begin(), kGearMeshOutputNames.end());
    if (units) units->insert(units->end(), kGearMeshOutputUnits.begin(), kGearMeshOutputUnits.end());
  }
  if (o.record_points > 0) {
    if (names) names->insert(names->end(), {"point_positions", "point_normal_forces"});
    if (units) units->insert(units->end(), {"m", "N"});
  }
}

std::vector<int> ContactOutputColumns(const ContactOutputOptions& o, int own_outputs) {
  std::vector<int> columns(own_outputs + (o.gear ? kGearMeshOutputNames.size() : 0), 1);
  if (o.record_points > 0) columns.insert(columns.end(), {3 * o.record_points, o.record_points});
  return columns;
}

void WriteContactOutputs(const ContactOutputOptions& o, const GearMeshObserver& gear,
                         const ContactPointRecord& points, double* values) {
  if (o.gear) {
    WriteGearMeshOutputs(gear.outputs(), values);
    values += kGearMeshOutputNames.size();
  }
  if (o.record_points > 0) points.Write(o.record_points, values, values + 3 * o.record_points);
}

}  // namespace orrery::contact
