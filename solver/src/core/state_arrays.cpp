// The declared state of a model's law (core/state_arrays.hpp).
#include "core/state_arrays.hpp"

#include "core/error.hpp"

namespace pd {

StateArrays::StateArrays(const std::vector<StateDeclaration>& declarations, std::size_t nodes, std::size_t bonds) {
  for (const StateDeclaration& d : declarations) {
    // A law's mistake, not the user's: said once, when the model is built, with the array's name.
    const std::string what = "declared state '" + d.name + "': ";
    if (d.name.empty()) throw Error("declared state: an array without a name");
    if (find(d.name)) throw Error(what + "declared twice");
    if (d.components < 1) throw Error(what + "components must be at least 1");
    if (d.extent == StateExtent::per_bond && d.halo)
      throw Error(what + "a per-bond array cannot be exchanged with ghosts (a ghost has no bonds of its own)");
    if (d.extent == StateExtent::per_bond && d.frames)
      throw Error(what + "a per-bond array cannot be written to frames (frames hold per-node fields)");
    arrays_.push_back(StateArray{d, std::vector<double>(size_of(d, nodes, bonds), d.initial)});
  }
}

StateArray* StateArrays::find(const std::string& name) {
  for (StateArray& a : arrays_)
    if (a.declaration.name == name) return &a;
  return nullptr;
}

const StateArray* StateArrays::find(const std::string& name) const {
  return const_cast<StateArrays*>(this)->find(name);
}

std::size_t StateArrays::size_of(const StateDeclaration& d, std::size_t nodes, std::size_t bonds) {
  return (d.extent == StateExtent::per_node ? nodes : bonds) * static_cast<std::size_t>(d.components);
}

std::vector<std::vector<double>> StateArrays::save_rollback() const {
  std::vector<std::vector<double>> saved;
  for (const StateArray& a : arrays_)
    if (a.declaration.rollback) saved.push_back(a.values);
  return saved;
}

void StateArrays::restore_rollback(const std::vector<std::vector<double>>& saved) {
  std::size_t k = 0;
  for (StateArray& a : arrays_)
    if (a.declaration.rollback && k < saved.size()) a.values = saved[k++];
}

std::int64_t StateArrays::bytes() const {
  std::int64_t bytes = 0;
  for (const StateArray& a : arrays_) bytes += static_cast<std::int64_t>(a.values.capacity() * sizeof(double));
  return bytes;
}

}  // namespace pd
