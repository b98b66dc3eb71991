// The prototype microelastic brittle material, PMB (thesis eqs. 1.9–1.12, 2.1; Silling & Askari
// 2005): its bond-force kernel, bond breaking, strain energy and damage as free functions over the
// model's arrays, and PmbModel, the BondModel (materials/bond_model.hpp) the operator calls.
#pragma once
#include <cfloat>
#include <cstdint>
#include <vector>

#include "core/model.hpp"
#include "core/state.hpp"
#include "materials/bond_model.hpp"

namespace pd {

// A stretch with |s| ≤ kStretchZero is set to zero: round-off in y_j − y_i would otherwise create
// "numerical, not physical forces" (thesis §2.2, machine-precision remark; LAMMPS peri/pmb zeroes
// |dr| < 2.22e−16 for the same reason).
constexpr double kStretchZero = 4.0 * DBL_EPSILON;

// Plain pointers into the model and state, so the kernel is one free function over arrays.
struct PmbArrays {
  const std::int64_t* offsets;
  const std::int32_t* neighbour;
  const std::uint8_t* broken;
  VolumeWeight volume_weight;  // ν(|ξ|) (docs/theory.md T5; 1 for full volumes)
  const double* x[3];          // reference positions; |ξ| is recomputed from them (core/bonds.hpp)
  const double* u[3];          // displacements
  const double* volume;
  const std::int32_t* block;   // block index (0-based) per node
  const double* c_pair;        // micromodulus per block pair
  const double* factor;        // surface-correction factor g_k per directed bond; null: none (g = 1)
  std::int64_t blocks;
  std::int64_t nodes;
  // One block, no surface correction, full volumes (ν = 1) and the same V_i for every node: the
  // kernel then reads no V_j and computes no ν (bitwise the same terms).
  bool uniform = false;
  // Rows by the AVX2 code (pmb_row_avx2.hpp), bitwise the portable rows: set by pmb_arrays from
  // avx2_rows() (core/avx2.hpp: the CPU has AVX2 and the switch is on).
  bool avx2 = false;
};

PmbArrays pmb_arrays(const Model& model, const Vec3Array& u);

// Bond breaking fused into the force pass (see add_pmb_force_density).
struct PmbBreaking {
  std::uint8_t* broken;         // the model's flags: the same array as PmbArrays::broken
  const double* s0_pair;        // critical stretch per block pair (+inf: unbreakable)
  const std::uint8_t* no_fail;  // per node: 1 if its bonds never break
  double* lost;                 // per node, or null: i's share of the energy of bonds broken now [J]
};

// f_i += Σ_j c·s·(y_j − y_i)/|y_j − y_i|·ν_j·V_j over intact bonds, s = (|ξ+η| − |ξ|)/|ξ|
// (thesis eqs. 1.9, 1.10, 2.1). Each node writes only its own f_i: parallel over nodes,
// schedule static, bitwise the same for any thread count. Accumulates; never clears f.
// If w is not null, also stores the strain-energy density W_i = Σ_j ¼ c s² |ξ| ν_j V_j of every node
// (docs/theory.md C4; overwritten, not accumulated): a few flops per bond, so the energy needs no
// second pass over the bonds.
// If breaking is not null, every intact bond whose stretch exceeds s0 of its block pair (and with
// no end in a no-fail set) first breaks for good, as update_broken_bonds would break it on the same
// u, and then adds no force: breaking costs no second sweep over the bonds. lost[i] is set to the
// energy ½ c s² |ξ| ν V_i V_j of the bonds i < j broken now (0 if none). Returns the number of
// bonds broken now, each counted once (0 without breaking).
// Bonds are summed in row order in fixed-size chunks, so the sums are the same for any thread
// count and any vector width the compiler picks (docs/performance.md).
// rows: the rows swept (every row by default); the others' f, w and lost are not touched. A row's
// values do not depend on which others are swept, so sweeping a piece's interior rows and then its
// boundary rows gives every row the bits of one sweep (parallel/row_split.hpp).
std::int64_t add_pmb_force_density(const PmbArrays& a, double* f0, double* f1, double* f2, double* w = nullptr,
                                   const PmbBreaking* breaking = nullptr, RowSubset rows = {});

// f += the PMB force density at u (add_pmb_force_density over the model's arrays), over `rows`.
void add_pmb_force(const Model& model, const Vec3Array& u, Vec3Array& f, double* energy_density = nullptr,
                   RowSubset rows = {});

// After the state update: every intact bond whose stretch exceeds s0 of its block pair breaks for
// good, unless an end is in a no-fail set. The stretch is computed from y_j − y_i, which is the
// exact negative of y_i − y_j in IEEE arithmetic, so both stored copies of a bond see bitwise the
// same stretch and break in the same call: symmetric and deterministic without a reverse index.
// Returns the number of bonds broken now, each counted once. If energy is not null, adds to it the
// energy the broken bonds held at the moment they broke, Σ ½ c s² |ξ| ν V_i V_j over the bonds
// broken now (each once; the strain energy loses exactly this, docs/theory.md C4 with breaking),
// summed per node and then serially, so the value does not depend on the thread count.
std::int64_t update_broken_bonds(Model& model, const Vec3Array& u, double* energy = nullptr);

// update_broken_bonds followed by PmbBondForce::AddMult, in one sweep over the bonds (the path the
// integrators take after each state update; bitwise the same flags, forces, W and energy).
// lost_per_node (size = nodes): the per-node energies of the bonds broken now are left there, and
// broken_energy is not touched (a decomposed run sums them over the ranks, operator/force_operator).
// rows: the rows swept (every row by default), as add_pmb_force_density.
std::int64_t break_bonds_and_add_pmb_force(Model& model, const Vec3Array& u, Vec3Array& f,
                                           double* energy_density = nullptr, double* broken_energy = nullptr,
                                           double* lost_per_node = nullptr, RowSubset rows = {});

// LAMMPS's critical-stretch rule (docs/theory.md T4), when some α > 0 (MaterialTable::node_rule):
// s0_i = max_j (s0_ij − α_ij·s_ij) over i's intact bonds at the previous breaking pass (= s0 −
// α·min_j s_ij for one block), +inf for a node without intact bonds; a bond breaks when
// s > min(s0_i, s0_j). PMB's history: a per-node array it declares (core/state_arrays.hpp) under this
// name, checkpointed, exchanged with ghosts (a bond reads its far end's s0), rolled back with the
// broken flags, not written to frames (materials/pmb/pmb_state.cpp).
constexpr const char* kNodeCriticalStretch = "node_critical_stretch";
// s0_i per node, or null when the rule is off (no α > 0: nothing declared).
std::vector<double>* node_critical_stretch(Model& model);
const std::vector<double>* node_critical_stretch(const Model& model);
// s0_i's declaration: per node, +inf before the set-up pass, checkpointed, with the ghosts, rolled back.
StateDeclaration node_critical_stretch_declaration();
// What PMB declares: s0_i when some α > 0, else nothing.
std::vector<StateDeclaration> pmb_state_declarations(const Model& model);
// s0_i of LAMMPS's rule at rest (every s_ij = 0): max_j s0_ij over i's intact bonds, +inf without
// one — what LAMMPS's set-up force pass leaves before the first step (docs/theory.md T4). A row of
// `bonds` per node of `block` (an empty row, a ghost's: +inf).
std::vector<double> initial_node_critical_stretch(const MaterialTable& table, const std::vector<std::int32_t>& block,
                                                  const BondList& bonds);

// True when the model breaks bonds by LAMMPS peri/pmb's rules (Model::break_after_force, or a
// per-node critical stretch: some α > 0); then break_bonds_lammps_rules is the breaking pass.
bool uses_lammps_rules(const Model& model);

// One breaking pass by LAMMPS peri/pmb's rules (docs/theory.md T4), and, if f is not null, the force:
// - a bond breaks when s > min(s0_i, s0_j), s0_i the per-node value left by the previous pass
//   (node_critical_stretch above), or s > s0_ij when every α is 0; never with a no-fail end;
// - then s0_i ← max_j (s0_ij − α_ij·s_ij) over the bonds intact at the start of the pass
//   (s0 − α·min_j s_ij for one block: Parks et al., LAMMPS pair peri/pmb);
// - Model::break_after_force: f gets the force of every bond intact at the start of the pass (a
//   bond over s0 still pulls in the step it breaks); otherwise the force after breaking, bitwise
//   what break_bonds_and_add_pmb_force gives when the α rule decides the same bonds.
// energy_density (if not null, with f) is overwritten with W_i of the bonds that carried force;
// broken_energy (if not null) gets the energy the broken bonds held; lost_per_node (if not null, a
// decomposed run) gets each node's share instead, as break_bonds_and_add_pmb_force. Each row writes
// only its own flags and s0: the same for any thread count. Returns the bonds broken now, each
// counted once.
// ghosts (a decomposed run): u's ghosts and, with per-node s0, the ghosts' s0 are still on
// their way (one exchange, operator/force_operator): the pass sweeps the interior rows, waits, then
// the boundary rows (parallel/row_split.hpp); the new s0 replace the old once both halves have
// read them. The same bits as the pass over every row after the exchange.
std::int64_t break_bonds_lammps_rules(Model& model, const Vec3Array& u, Vec3Array* f, double* energy_density,
                                      double* broken_energy, double* lost_per_node = nullptr,
                                      const GhostsInFlight* ghosts = nullptr);

// The largest s/s0 over the intact bonds without a no-fail end at u, and how many of them break_bonds
// would break there (each once), by the same criterion and thresholds (materials/bond_model.hpp
// StretchRatio; the thesis rule's pair s0, or LAMMPS's per-node s0 when its α rule is on). Reads only.
StretchRatio pmb_stretch_ratio(const Model& model, const Vec3Array& u);

// U = Σ_i Σ_j ¼ c s² |ξ| V_i V_j over intact bonds (docs/theory.md C4) [J]. Per-node terms are
// summed serially in node order, so the value does not depend on the thread count.
double strain_energy(const Model& model, const Vec3Array& u);
// The same per node, divided by V_i: the strain-energy density W_i [J/m³].
std::vector<double> strain_energy_density(const Model& model, const Vec3Array& u);


// The constants of thesis eqs. 1.11–1.12 for one block (docs/theory.md T2), by analysis; or c and
// s0 as the block gives them (micromodulus, critical_stretch: a LAMMPS pair_coeff); and its α.
PairConstants pmb_constants(const BlockMaterial& block, const std::string& analysis, double horizon, double thickness);
// One pair or the other (E with G0, or c with s0), never a mix; α only with a breakable material.
ParameterProblem pmb_check(const BlockMaterial& block);

// The linearised PMB force. About the reference configuration (thesis eq. 2.3; Silling & Askari
// 2005: C(ξ) = c/|ξ|·e⊗e), and at a deformed state u: per intact bond
//   ∂f_i/∂u_j = c ν V_j·[(1/|ξ|)·n nᵀ + (s/y)·(I − n nᵀ)],  n = (y_j − y_i)/y, y = |y_j − y_i|,
// and ∂f_i/∂u_i = −Σ_j of the same (f depends on u_j − u_i only).
class PmbModel : public BondModel {
 public:
  std::string name() const override { return "pmb"; }
  void add_force(const Model& model, const Vec3Array& u, Vec3Array& f, double* w) const override;
  BreakReport break_bonds_and_add_force(Model& model, const Vec3Array& u, Vec3Array& f, double* w,
                                        bool want_energy, double* lost_per_node = nullptr) const override;
  // The interior rows while u's ghosts travel, then the boundary rows (parallel/row_split.hpp).
  // LAMMPS's rules (uses_lammps_rules) too: their pass replaces every node's s0 at once after both
  // halves have read the old one, whose ghost values travel with u's (u_ghosts).
  void add_force_overlapped(const Model& model, const Vec3Array& u, Vec3Array& f, double* w,
                            const GhostsInFlight& u_ghosts) const override;
  BreakReport break_bonds_and_add_force_overlapped(Model& model, const Vec3Array& u, Vec3Array& f, double* w,
                                                   bool want_energy, double* lost_per_node,
                                                   const GhostsInFlight& u_ghosts) const override;
  BreakReport break_bonds(Model& model, const Vec3Array& u, bool want_energy) const override;
  std::vector<StateDeclaration> state_declarations(const Model& model) const override {
    return pmb_state_declarations(model);
  }
  void initialise_state(Model& model) const override;
  StretchRatio stretch_ratio(const Model& model, const Vec3Array& u) const override { return pmb_stretch_ratio(model, u); }
  std::vector<double> strain_energy_density(const Model& model, const Vec3Array& u) const override;
  std::vector<double> damage(const Model& model) const override { return bond_damage(model); }
  double bond_stiffness(const Model& model, std::size_t i, std::size_t j, double length) const override;
  // ¼ c ∫ (n·ε·n)² |ξ| dV over the full horizon (the linearised stretch s = n·ε·n), with
  // ∫ n_a n_b n_c n_d dΩ = (4π/15)(δ_ab δ_cd + δ_ac δ_bd + δ_ad δ_bc) over the sphere and (π/4)(…)
  // over the circle: (cπδ⁴/60)((tr ε)² + 2 ε:ε) in 3D, (chπδ³/48)(…) in 2D — linear elasticity with
  // λ = μ (ν = 1/4; plane stress ν = 1/3) and, with F1's c, Young's modulus E.
  double continuum_energy_density(const Model& model, std::size_t i, const StrainTensor& strain) const override;
  void apply_reference_stiffness(const Model& model, const std::array<double, 3>& period, const Vec3Array& x,
                                 Vec3Array& y) const override;
  void add_jacobian_product(const Model& model, const Vec3Array& u, const Vec3Array& x, Vec3Array& y) const override;
  void add_jacobian_product_overlapped(const Model& model, const Vec3Array& u, const Vec3Array& x, Vec3Array& y,
                                       const GhostsInFlight& x_ghosts) const override;
  bool bond_tangent_row(const Model& model, const Vec3Array& u, std::size_t i, double* blocks,
                        bool definite = false) const override;
};


}  // namespace pd
