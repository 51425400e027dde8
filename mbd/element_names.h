#pragma once
// Names of what a row or coordinate of the equations belongs to, for messages that must say
// where a run failed: "joint 'crank' coordinate 0 (body 'crank')", "flexible body 'planet' mode
// 3", and, for the unknowns of the DAE integrated by IDA (dae.h), "velocity of joint ...",
// "multiplier of loop closure 'c' row 1".
#include <string>

#include "mbd/model.h"

namespace orrery {

// Velocity index k (0 .. nv - 1).
std::string CoordinateName(const Model& model, int k);
// Position index i (0 .. nq - 1).
std::string PositionName(const Model& model, int i);
// Component i of IDA's unknowns y = (q, v, lambda, mu) (dae.h).
std::string DaeUnknownName(const Model& model, int i);

}  // namespace orrery
