// Reaction forces at supports: the force that the prescribed motion applies to a node set, for a
// force–displacement curve (the pulled grip of a tensile test) in history.csv (formats.md §4).
#pragma once
#include <array>
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "core/model.hpp"
#include "core/state.hpp"

namespace pd {

// R = Σ V_i (ρ_i a_i − f_i) over the nodes of the set and the components that a displacement or
// velocity condition prescribes there [N]: the support's force on the body, the same term whose
// power external_power() integrates (a is the slope of a velocity table, 0 for a displacement
// table). Free components of a node contribute nothing. f is state.f, the force density at u
// from the last force evaluation. Throws pd::Error if the set is not in the node file.
std::array<double, 3> reaction_force(const Model& model, const State& state, const std::string& set, double t);

// The same sum in pieces (a decomposed run: parallel/decomposed.hpp gather_keyed). Each term of R
// with a key that orders it where the serial sum adds it: condition k's node of global number g has
// key k·global_nodes + g (the conditions are in the same order on every piece, and a condition's
// nodes ascend). A piece's conditions hold its owned nodes only, so each key comes from one rank.
// global: the global number of each node of `model` (a piece's LocalPiece::global).
struct ReactionTerms {
  std::vector<std::int64_t> key;
  std::vector<double> value;
};
ReactionTerms reaction_terms(const Model& model, const State& state, const std::string& set, double t,
                             const std::vector<std::int32_t>& global, std::int64_t global_nodes);
// R from every piece's terms sorted by key: added one by one in that order, the serial bits.
std::array<double, 3> sum_reaction_terms(const Model& model, const std::vector<std::pair<std::int64_t, double>>& sorted,
                                         std::int64_t global_nodes);

}  // namespace pd
