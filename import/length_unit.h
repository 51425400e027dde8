#pragma once
// Length units of imported files. The engine is SI inside; a mesh file that carries no unit (STL,
// OBJ, PLY, ...) is read in the unit its user states, metres by default.
#include <optional>
#include <string>
#include <string_view>

namespace orrery {

enum class LengthUnit { kMetre, kCentimetre, kMillimetre, kInch };

// "m", "cm", "mm", "in" (exactly these); nullopt for anything else.
std::optional<LengthUnit> ParseLengthUnit(std::string_view name);
// The name ParseLengthUnit takes.
const char* LengthUnitName(LengthUnit unit);
// Metres per unit: 1, 0.01, 0.001, 0.0254 (the international inch, exact).
double MetresPerUnit(LengthUnit unit);
// "m, cm, mm or in", for messages.
inline constexpr const char* kLengthUnitChoices = "m, cm, mm or in";

}  // namespace orrery
