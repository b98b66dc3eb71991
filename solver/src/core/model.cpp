// Builds the Model from a checked case and node file; the stable time step of thesis eq. 2.5.
#include "core/model.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "core/cracks.hpp"
#include "core/error.hpp"
#include "core/partial_volume.hpp"
#include "core/surface_correction.hpp"
#include "core/work_plan.hpp"

namespace pd {

void declare_state(Model& m, bool at_rest) {
  // Per bond: the rows the model holds (none for a whole model whose rows are on the ranks).
  m.state_arrays = StateArrays(m.bond_model->state_declarations(m), m.nodes.size(), m.bonds.neighbour.size());
  if (at_rest) m.bond_model->initialise_state(m);
}

double bond_search_cutoff(const Case& c) {
  return bond_cutoff(partial_volume_registry().get(c.partial_volume), c.horizon, c.grid_spacing);
}

Model build_model_without_bonds(const Case& c, Nodes nodes) {
  const std::size_t n = nodes.size();
  const std::string where = c.nodes_file.string() + ": ";
  if (nodes.dimension != c.dimension)
    throw Error(where + "dimension " + std::to_string(nodes.dimension) + " differs from " + c.file.string() +
                ": dimension " + std::to_string(c.dimension));
  if (std::abs(nodes.grid_spacing - c.grid_spacing) > 1e-9 * c.grid_spacing)
    throw Error(where + "grid_spacing differs from " + c.file.string() + ": grid_spacing");
  if (n == 0) throw Error(where + "the node file has no nodes");
  const auto sets_named = [&](const std::vector<std::string>& names, const std::string& key) {
    for (const auto& name : names)
      if (!nodes.find_set(name))
        throw Error(c.file.string() + ": " + key + ": node set '" + name + "' has no array 'set_" + name +
                    "' in " + c.nodes_file.string());
  };
  sets_named(c.no_fail_sets, "no_fail_sets");
  for (const auto& bc : c.boundary_conditions) sets_named({bc.set}, "boundary_conditions[].set");
  for (const auto& ic : c.initial_conditions) sets_named({ic.set}, "initial_conditions[].set");

  Model m;
  m.horizon = c.horizon;
  m.grid_spacing = c.grid_spacing;
  m.thickness = c.thickness;
  m.damping = c.damping;
  // Every block uses one material model (the reader checks it); its formulas give c and s0.
  m.material = make_material_table(c.blocks, c.analysis, c.horizon, c.thickness);
  m.block_materials = c.blocks;
  m.analysis = c.analysis;
  m.density.resize(n);
  m.block_index.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    const std::int32_t b = nodes.block[i];
    if (b < 1 || b > static_cast<std::int32_t>(c.blocks.size()))
      throw Error(where + "node " + std::to_string(i) + " has block " + std::to_string(b) + ", but " +
                  c.file.string() + " defines blocks 1.." + std::to_string(c.blocks.size()));
    m.block_index[i] = b - 1;
    m.density[i] = c.blocks[static_cast<std::size_t>(b - 1)].density;
  }
  m.no_fail.assign(n, 0);
  for (const auto& name : c.no_fail_sets) {
    const NodeSet* set = nodes.find_set(name);
    for (std::size_t i = 0; i < n; ++i) m.no_fail[i] |= set->member[i];
  }
  m.conditions = make_conditions(c, nodes);
  // A partial-volume rule may widen the family (HHB) and weights each bond by ν (docs/theory.md T5).
  const PartialVolumeRule& rule = partial_volume_registry().get(c.partial_volume);
  const double cutoff = bond_search_cutoff(c);
  apply_partial_volume(rule, c.horizon, c.grid_spacing, m.bonds);
  m.contact = plan_contact(c, m.block_index, cutoff * (1.0 + kHorizonTolerance));
  m.indenters = c.indenters;
  m.break_after_force = c.breaking_order == "lammps";
  m.nodes = std::move(nodes);
  return m;
}

Model build_model(const Case& c, Nodes nodes) {
  Model m = build_model_without_bonds(c, std::move(nodes));
  BondList bonds = build_bonds(m.nodes.x, bond_search_cutoff(c));
  bonds.volume_weight = m.bonds.volume_weight;
  m.bonds = std::move(bonds);
  cut_crossing_bonds(c.cracks, m.nodes.x, m.bonds);  // pre-cracks (notches) start broken
  m.bond_model = material_registry().get(c.blocks.empty() ? std::string("pmb") : c.blocks[0].model).make(m);
  // Factors from the law's own energy on each node's family (pre-cracks are free surfaces); every
  // kernel reads them from the bonds.
  apply_surface_correction(c.surface_correction, m);
  // A law that precomputes from the weights (LPS's bound of the stable step) is made again with them.
  if (m.bonds.corrected()) m.bond_model = material_registry().get(c.blocks[0].model).make(m);
  // The law's history at rest, from the bonds (pre-cracks included).
  declare_state(m);
  return m;
}

std::int64_t broken_bond_count(const Model& m) {
  std::int64_t count = 0;
  for (std::uint8_t b : m.bonds.broken) count += b;
  return count / 2;
}

double node_stiffness(const Model& m, std::size_t i) {
  const auto nb = static_cast<std::size_t>(m.material.blocks);
  const auto bi = static_cast<std::size_t>(m.block_index[i]);
  double sum = 0.0;
  // thesis eq. 2.5 with the material's linearised bond stiffness (c/|ξ| for PMB).
  for (std::int64_t k = m.bonds.offsets[i]; k < m.bonds.offsets[i + 1]; ++k) {
    const auto j = static_cast<std::size_t>(m.bonds.neighbour[static_cast<std::size_t>(k)]);
    const double length = bond_length(m.nodes.x, i, j);
    sum += m.bond_model->bond_stiffness(m, i, j, length) * m.bonds.factor(static_cast<std::size_t>(k));
    // With contact, a node pressed into a surface meets about as many contact partners as it has
    // bonds shorter than 2r_s, each a spring c_s·V_j/δ (docs/theory.md T10: the contact stiffness
    // 15c needs extra margin in impacts).
    if (m.contact.pairs && length <= m.contact.distance) {
      const double micromodulus = m.material.micromodulus_pair[bi * nb + static_cast<std::size_t>(m.block_index[j])];
      sum += m.nodes.volume[j] * m.contact.stiffness_factor * micromodulus / m.horizon;
    }
  }
  return sum;
}

double stable_time_step(const Model& m) {
  const std::size_t n = m.nodes.size();
  double dt = std::numeric_limits<double>::infinity();
#pragma omp parallel for schedule(static) reduction(min : dt)
  for (std::int64_t i = 0; i < static_cast<std::int64_t>(n); ++i) {
    const double sum = node_stiffness(m, static_cast<std::size_t>(i));
    if (sum > 0.0) dt = std::min(dt, std::sqrt(2.0 * m.density[static_cast<std::size_t>(i)] / sum));
  }
  return dt;  // min is exact, so the reduction is deterministic for any thread count
}

}  // namespace pd
