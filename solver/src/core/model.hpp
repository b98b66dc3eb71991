// Everything the time loop needs that does not change with time: nodes, bonds, material, conditions.
#pragma once
#include <cstdint>
#include <memory>
#include <vector>

#include "core/bonds.hpp"
#include "core/case.hpp"
#include "core/conditions.hpp"
#include "core/material.hpp"
#include "core/nodes.hpp"
#include "core/state_arrays.hpp"
#include "core/neighbour_list.hpp"
#include "materials/bond_model.hpp"

namespace pd {

struct Model {
  Nodes nodes;
  BondList bonds;  // the only part that changes: bonds break
  MaterialTable material;  // c and s0 per block pair, from the material model's formulas
  // The blocks' materials as the case gives them and the analysis (3d, plane_stress,
  // plane_strain): a law whose constants are more than c and s0 (a state-based one's moduli per
  // block) reads them when it is made.
  std::vector<BlockMaterial> block_materials;
  std::string analysis = "3d";
  std::shared_ptr<const BondModel> bond_model;  // the material law (materials/<model>/)
  double horizon = 0.0;  // δ [m]
  double grid_spacing = 0.0;  // dx [m]
  double thickness = 0.0;     // h [m] of a 2D analysis (unused in 3D)
  double damping = 0.0;  // α [1/s]
  std::vector<double> density;             // ρ per node [kg/m³]
  std::vector<std::int32_t> block_index;   // block id − 1 per node (row of the pair tables)
  std::vector<std::uint8_t> no_fail;       // 1: bonds with this end never break
  // Where a breaking pass puts the bonds it breaks (Case::breaking_order): false, the thesis §2.2
  // order (they break before the force at the new state); true, LAMMPS peri/pmb's (they carry their
  // force in the step they break and are gone from the next one).
  bool break_after_force = false;
  // The law's history (core/state_arrays.hpp): the arrays it declared, per node or per bond, which
  // its breaking passes update (LAMMPS's per-node critical stretch: materials/pmb/). State, like
  // bonds.broken; empty for a law without history.
  StateArrays state_arrays;
  Conditions conditions;
  // Short-range contact (docs/theory.md T8) and rigid indenters: what the scene needs is decided
  // once from the case (core/work_plan); contact.pairs is false when nothing can touch.
  ContactParameters contact;
  std::vector<IndenterSettings> indenters;
  // A cache of the proximity search, not state: the forces are the same whether or not it was
  // rebuilt (tested), so it may change behind a const Model.
  mutable NeighbourList contact_list;
};

// Checks the node file against the case (blocks in range, sets present) and builds the bonds.
Model build_model(const Case& c, Nodes nodes);
// build_model without the bonds (issue 15: a decomposed run's ranks build their own rows): the
// nodes, per-node data, material, conditions, contact plan and the bonds' volume weight; bonds'
// rows, pre-cracks, LAMMPS's s0, the law and the surface correction are left to the caller.
Model build_model_without_bonds(const Case& c, Nodes nodes);
// The bond search's cut-off: the horizon, widened by the partial-volume rule's family (HHB).
double bond_search_cutoff(const Case& c);
// The law's declared state (bond_model->state_declarations, core/state_arrays.hpp) sized for the
// model's nodes and the bonds of the rows it holds (none for a whole model whose rows are on the
// ranks: rank 0 gathers per-bond arrays only for a checkpoint), each array at its declared initial
// value; then, with `at_rest`, filled by the law from the bonds (BondModel::initialise_state).
void declare_state(Model& model, bool at_rest = true);

// Broken bonds, each counted once (both stored copies of a bond break together).
std::int64_t broken_bond_count(const Model& model);

// Stable step of the explicit scheme, thesis eq. 2.5 (docs/theory.md T10):
// Δt = min_i √(2ρ_i / Σ_p V_p C_ip), C_ip = c_ip/|ξ_p| for PMB, without safety factor; +inf if no node has a bond.
// ν_p (partial volume) multiplies V_p; with contact, every bond shorter than 2r_s adds a contact
// spring V_p·c_s/δ to the sum.
double stable_time_step(const Model& model);
// The sum of eq. 2.5 for node i, Σ_p V_p ν_p C_ip (the material's bond_stiffness, c_ip/|ξ_p| for
// PMB; + the contact springs) [N/m⁴]: the stiffness per unit volume that bounds node i's stable
// step, √(2ρ_i / sum).
double node_stiffness(const Model& model, std::size_t i);

}  // namespace pd
