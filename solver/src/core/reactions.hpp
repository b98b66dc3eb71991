// Reaction forces at supports: the force that the prescribed motion applies to a node set, for a
// force–displacement curve (the pulled grip of a tensile test) in history.csv (formats.md §4).
#pragma once
#include <array>
#include <string>

#include "core/model.hpp"
#include "core/state.hpp"

namespace pd {

// R = Σ V_i (ρ_i a_i − f_i) over the nodes of the set and the components that a displacement or
// velocity condition prescribes there [N]: the support's force on the body, the same term whose
// power external_power() integrates (a is the slope of a velocity table, 0 for a displacement
// table). Free components of a node contribute nothing. f is state.f, the force density at u
// from the last force evaluation. Throws pd::Error if the set is not in the node file.
std::array<double, 3> reaction_force(const Model& model, const State& state, const std::string& set, double t);

}  // namespace pd
