// The law's declared state in and out of a checkpoint (run/state_checkpoint.hpp).
#include "run/state_checkpoint.hpp"

namespace pd {

std::vector<StateArray> checkpointed_state(const Model& model) {
  std::vector<StateArray> out;
  for (const StateArray& a : model.state_arrays.all())
    if (a.declaration.checkpoint) out.push_back(a);
  return out;
}

bool fits_checkpointed_state(const std::vector<StateArray>& saved, const Model& model, std::size_t nodes,
                             std::size_t directed) {
  std::size_t k = 0;
  for (const StateArray& a : model.state_arrays.all()) {
    const StateDeclaration& d = a.declaration;
    if (!d.checkpoint) continue;
    if (k == saved.size()) return false;
    const StateDeclaration& s = saved[k].declaration;
    if (s.name != d.name || s.extent != d.extent || s.components != d.components ||
        saved[k].values.size() != StateArrays::size_of(d, nodes, directed))
      return false;
    ++k;
  }
  return k == saved.size();
}

void restore_checkpointed_state(std::vector<StateArray> saved, Model& whole, LocalPiece* piece) {
  StateArrays by_name;
  by_name.all() = std::move(saved);
  if (piece) state_to_local(*piece, whole.bonds, by_name, piece->model.state_arrays);
  for (StateArray& a : whole.state_arrays.all()) {
    StateArray* from = by_name.find(a.declaration.name);
    if (!from || !a.declaration.checkpoint) continue;
    if (a.declaration.extent == StateExtent::per_node || !whole.bonds.neighbour.empty()) a.values = std::move(from->values);
  }
}

}  // namespace pd
