// Reaction forces of node sets under prescribed motion (core/reactions.hpp).
#include "core/reactions.hpp"

#include "core/error.hpp"

namespace pd {

namespace {

const NodeSet& find_set(const Model& model, const std::string& name) {
  const NodeSet* set = model.nodes.find_set(name);
  if (!set) throw Error("output.reactions: node set '" + name + "' is not in the node file");
  return *set;
}

// Node i's term of condition p: V_i (ρ_i a − f_c,i), the support's force on it along p's component.
double reaction_term(const Model& model, const State& state, const PrescribedMotion& p, double a, std::size_t i) {
  return model.nodes.volume[i] * (model.density[i] * a - state.f[static_cast<std::size_t>(p.component)][i]);
}

double table_acceleration(const PrescribedMotion& p, double t) {
  return p.kind == Kinematic::velocity ? p.table.slope(t) : 0.0;
}

}  // namespace

std::array<double, 3> reaction_force(const Model& model, const State& state, const std::string& name, double t) {
  const NodeSet& set = find_set(model, name);
  std::array<double, 3> r{0.0, 0.0, 0.0};
  // Serial in condition and node order: the sum is the same for any thread count.
  for (const auto& p : model.conditions.prescribed) {
    const double a = table_acceleration(p, t);
    for (std::int32_t i32 : p.nodes) {
      const auto i = static_cast<std::size_t>(i32);
      if (set.member[i]) r[static_cast<std::size_t>(p.component)] += reaction_term(model, state, p, a, i);
    }
  }
  return r;
}

ReactionTerms reaction_terms(const Model& model, const State& state, const std::string& name, double t,
                             const std::vector<std::int32_t>& global, std::int64_t global_nodes) {
  const NodeSet& set = find_set(model, name);
  ReactionTerms terms;
  for (std::size_t k = 0; k < model.conditions.prescribed.size(); ++k) {
    const PrescribedMotion& p = model.conditions.prescribed[k];
    const double a = table_acceleration(p, t);
    for (std::int32_t i32 : p.nodes) {
      const auto i = static_cast<std::size_t>(i32);
      if (!set.member[i]) continue;
      terms.key.push_back(static_cast<std::int64_t>(k) * global_nodes + global[i]);
      terms.value.push_back(reaction_term(model, state, p, a, i));
    }
  }
  return terms;
}

std::array<double, 3> sum_reaction_terms(const Model& model, const std::vector<std::pair<std::int64_t, double>>& sorted,
                                         std::int64_t global_nodes) {
  std::array<double, 3> r{0.0, 0.0, 0.0};
  for (const auto& [key, value] : sorted) {
    const auto k = static_cast<std::size_t>(key / global_nodes);  // the condition: its component
    r[static_cast<std::size_t>(model.conditions.prescribed.at(k).component)] += value;
  }
  return r;
}

}  // namespace pd
