// What the run measures on a state for history.csv and its watches: the energies, the first
// non-finite node, the fastest node.
#pragma once
#include <cstdint>

#include "core/model.hpp"
#include "core/state.hpp"

namespace pd {

// Σ ½ρV|v|² and Σ wV [J], summed serially in node order: the same for any thread count.
double kinetic_energy(const Model& model, const State& state);
double stored_strain_energy(const Model& model, const State& state);

// The first node (lowest index) with a non-finite displacement or velocity, or −1.
std::int64_t first_non_finite(const State& state);

// The node with the largest finite speed (lowest index on ties): where an instability that grows
// geometrically has grown longest, i.e. most likely where it started.
std::int64_t fastest_node(const State& state);

}  // namespace pd
