// PMB's history: LAMMPS's per-node critical stretch s0_i (materials/pmb/pmb.hpp), declared once
// (core/state_arrays.hpp) so that the checkpoint, the halo and mixed's rollback carry it.
#include <algorithm>
#include <limits>

#include "core/model.hpp"
#include "materials/pmb/pmb.hpp"

namespace pd {

std::vector<double>* node_critical_stretch(Model& model) {
  StateArray* a = model.state_arrays.find(kNodeCriticalStretch);
  return a ? &a->values : nullptr;
}

const std::vector<double>* node_critical_stretch(const Model& model) {
  const StateArray* a = model.state_arrays.find(kNodeCriticalStretch);
  return a ? &a->values : nullptr;
}

StateDeclaration node_critical_stretch_declaration() {
  StateDeclaration s0;
  s0.name = kNodeCriticalStretch;
  s0.extent = StateExtent::per_node;
  s0.initial = std::numeric_limits<double>::infinity();  // a node without intact bonds: LAMMPS's DBL_MAX
  s0.checkpoint = true;
  s0.halo = true;  // a bond's threshold min(s0_i, s0_j) reads its far end's
  s0.rollback = true;
  s0.frames = false;  // not in the frames before it was declared: they stay byte for byte the same
  return s0;
}

std::vector<StateDeclaration> pmb_state_declarations(const Model& model) {
  if (!model.material.node_rule()) return {};  // α = 0 everywhere: s0 is the pair table's, no history
  return {node_critical_stretch_declaration()};
}

std::vector<double> initial_node_critical_stretch(const MaterialTable& table, const std::vector<std::int32_t>& block,
                                                  const BondList& bonds) {
  const std::size_t n = bonds.nodes(), nb = static_cast<std::size_t>(table.blocks);
  std::vector<double> s0(n, std::numeric_limits<double>::infinity());
  for (std::size_t i = 0; i < n; ++i) {
    bool first = true;
    for (std::int64_t k = bonds.offsets[i]; k < bonds.offsets[i + 1]; ++k) {
      if (bonds.broken[static_cast<std::size_t>(k)]) continue;
      const std::size_t j = static_cast<std::size_t>(bonds.neighbour[static_cast<std::size_t>(k)]);
      const double pair = table.critical_pair[static_cast<std::size_t>(block[i]) * nb + static_cast<std::size_t>(block[j])];
      s0[i] = first ? pair : std::max(s0[i], pair);
      first = false;
    }
  }
  return s0;
}

void PmbModel::initialise_state(Model& model) const {
  if (std::vector<double>* s0 = node_critical_stretch(model))
    *s0 = initial_node_critical_stretch(model.material, model.block_index, model.bonds);
}

}  // namespace pd
