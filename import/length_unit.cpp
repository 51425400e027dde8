#include "import/length_unit.h"

namespace orrery {

std::optional<LengthUnit> ParseLengthUnit(std::string_view name) {
  if (name == "m") return LengthUnit::kMetre;
  if (name == "cm") return LengthUnit::kCentimetre;
  if (name == "mm") return LengthUnit::kMillimetre;
  if (name == "in") return LengthUnit::kInch;
  return std::nullopt;
}

const char* LengthUnitName(LengthUnit unit) {
  switch (unit) {
    case LengthUnit::kCentimetre: return "cm";
    case LengthUnit::kMillimetre: return "mm";
    case LengthUnit::kInch: return "in";
    default: return "m";
  }
}

double MetresPerUnit(LengthUnit unit) {
  switch (unit) {
    case LengthUnit::kCentimetre: return 0.01;
    case LengthUnit::kMillimetre: return 0.001;
    case LengthUnit::kInch: return 0.0254;
    default: return 1.0;
  }
}

}  // namespace orrery
