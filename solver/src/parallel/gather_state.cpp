// A decomposed run's declared state gathered on rank 0 (parallel/gather_state.hpp).
#include "parallel/gather_state.hpp"

#include "parallel/local_model.hpp"

namespace pd {

void gather_state(const Decomposed& d, Model& whole, bool (*which)(const StateDeclaration&)) {
  const Model& piece = d.piece().model;
  for (const StateArray& a : piece.state_arrays.all()) {
    const StateDeclaration& declared = a.declaration;
    if (!which(declared)) continue;
    std::vector<double> values =
        declared.extent == StateExtent::per_node
            ? d.gather(a.values, declared.components)
            : d.gather_bond_values(piece.bonds, a.values, declared.components, whole.bonds);
    if (d.rank() != 0) continue;
    StateArray* into = whole.state_arrays.find(declared.name);
    if (into) into->values = std::move(values);
  }
}

}  // namespace pd
