// What the run's watches measure on a state: the first non-finite node, the fastest node (the
// energies come from the operator, operator/force_operator.hpp).
#pragma once
#include <cstdint>

#include "core/model.hpp"
#include "core/state.hpp"

namespace pd {

// The first node (lowest index) with a non-finite displacement or velocity, or −1.
std::int64_t first_non_finite(const State& state);

// The node with the largest finite speed (lowest index on ties): where an instability that grows
// geometrically has grown longest, i.e. most likely where it started.
std::int64_t fastest_node(const State& state);

}  // namespace pd
