// Reaction forces of node sets under prescribed motion (core/reactions.hpp).
#include "core/reactions.hpp"

#include "core/error.hpp"

namespace pd {

std::array<double, 3> reaction_force(const Model& model, const State& state, const std::string& name, double t) {
  const NodeSet* set = model.nodes.find_set(name);
  if (!set) throw Error("output.reactions: node set '" + name + "' is not in the node file");
  std::array<double, 3> r{0.0, 0.0, 0.0};
  // Serial in condition and node order: the sum is the same for any thread count.
  for (const auto& p : model.conditions.prescribed) {
    const auto c = static_cast<std::size_t>(p.component);
    const double a = p.kind == Kinematic::velocity ? p.table.slope(t) : 0.0;
    for (std::int32_t i32 : p.nodes) {
      const auto i = static_cast<std::size_t>(i32);
      if (!set->member[i]) continue;
      r[c] += model.nodes.volume[i] * (model.density[i] * a - state.f[c][i]);
    }
  }
  return r;
}

}  // namespace pd
