// The interface every material model implements (one folder per model under materials/<name>/),
// and the registry that chooses one by the case's `blocks[].model` (pipeline/formats.md §3).
//
// A material owns everything that depends on its constitutive law: its parameters from the case,
// its constants per block (micromodulus c, critical stretch s0: Model::material, the pair table of
// core/material.hpp, which contact and run.log read too), its force and strain-energy
// kernel, its breaking rule and damage, its term of the stable step (thesis eq. 2.5), its linearised
// force (for the exact step limit and for implicit solves). Nothing outside materials/<name>/ knows
// the law; the operator (operator/force_operator.hpp) calls it through this interface, in the way
// Peridigm's Material and LAMMPS's pair styles are separate from the time integrators.
//
// To add a model: a folder materials/<name>/ whose .cpp files define
//   void register_material_<name>(MaterialRegistry&);
// (CMake finds the folder and calls it: no other file lists the models), a test file
// tests/materials/test_<name>.cpp, and its schema entry in pipeline/schema.py. A model with history
// (a value per node or per bond that its breaking passes carry on) declares it
// (state_declarations, core/state_arrays.hpp): the checkpoint, the halo, mixed's rollback and the
// frames carry it without naming it.
#pragma once
#include <array>
#include <cstdint>
#include <limits>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "core/material.hpp"
#include "core/nodes.hpp"
#include "core/state_arrays.hpp"
#include "core/registry.hpp"
#include "parallel/row_split.hpp"

namespace pd {

class Decomposed;  // parallel/decomposed.hpp

struct Model;

// A small strain tensor, symmetric, row-major 3×3 (ε_xx, ε_xy, ε_xz, ε_yx, …).
using StrainTensor = std::array<double, 9>;

// tr ε and ε:ε of `strain` over the first `dims` axes (3, or 2 for the in-plane part).
inline double strain_trace(const StrainTensor& strain, int dims) {
  double t = 0.0;
  for (int a = 0; a < dims; ++a) t += strain[static_cast<std::size_t>(4 * a)];
  return t;
}
inline double strain_contraction(const StrainTensor& strain, int dims) {
  double s = 0.0;
  for (int a = 0; a < dims; ++a)
    for (int b = 0; b < dims; ++b) s += strain[static_cast<std::size_t>(3 * a + b)] * strain[static_cast<std::size_t>(3 * a + b)];
  return s;
}

// A number a model reads from its block in case.json (blocks[k].<name>), checked by the reader.
struct MaterialParameter {
  std::string name;
  std::string unit;  // SI
  std::string doc;   // one line
  bool required = true;
  // The reader requires lower < value < upper (strict; +inf: no upper bound), or lower ≤ value
  // when lower_inclusive.
  double lower = 0.0;
  double upper = std::numeric_limits<double>::infinity();
  // Not empty: a text parameter, one of these names (the first is the default), not a number.
  std::vector<std::string> choices = {};
  // Why the range is what it is, appended to the reader's error for a value outside it.
  std::string bounds_reason = {};
  bool lower_inclusive = false;  // lower ≤ value instead of lower < value
};

// What a model's own check finds wrong with a block's parameters as a whole (a key and what to do);
// an empty key: nothing.
struct ParameterProblem {
  std::string key, message;
};

// Bonds broken by one call, each counted once, and the energy they held then [J].
struct BreakReport {
  std::int64_t broken = 0;
  double energy = 0.0;
  // The bonds of several breaking passes together (a load step's rounds and attempts).
  BreakReport& operator+=(const BreakReport& other) {
    broken += other.broken;
    energy += other.energy;
    return *this;
  }
};

// How far the intact bonds that can break are from breaking at some u: the largest stretch ratio
// s/s_c over them (s_c the threshold the law's breaking criterion compares s with; 0 when there is
// none) and how many bonds the law's break_bonds would break at this u (each counted once: the
// same count as its BreakReport::broken). `over` is decided by the criterion itself, not by
// largest > 1, so the two agree exactly; largest is for interpolating the load at which the first
// bond breaks (integrators/quasi_static.cpp, the cut of a load step). A maximum and an integer
// count: exact and independent of the order of the bonds, threads and ranks.
struct StretchRatio {
  double largest = 0.0;
  std::int64_t over = 0;
};

class BondModel {
 public:
  virtual ~BondModel() = default;
  virtual std::string name() const = 0;

  // f += the bond force density at u over intact bonds; w (if not null) = strain-energy density
  // W_i per node (overwritten). Each node writes only its own row: bitwise the same for any
  // thread count. Accumulates; never clears f.
  virtual void add_force(const Model& model, const Vec3Array& u, Vec3Array& f, double* w) const = 0;
  // Breaks every intact bond over its critical stretch at u, then adds the force of the intact
  // bonds as add_force does (the thesis §2.2 order: bonds break after the state update, before the
  // force there). want_energy: also the energy the broken bonds held. lost_per_node (a decomposed
  // run, size = nodes, zeros on entry): each node's share of that energy is left there instead and
  // BreakReport::energy is 0 — the operator sums the shares over the ranks in node order.
  virtual BreakReport break_bonds_and_add_force(Model& model, const Vec3Array& u, Vec3Array& f, double* w,
                                                bool want_energy, double* lost_per_node = nullptr) const = 0;
  // add_force and break_bonds_and_add_force on a decomposed run with u's ghost values still on
  // their way (parallel/row_split.hpp says why): the law sweeps u_ghosts.rows.interior, calls
  // u_ghosts.wait(), then sweeps u_ghosts.rows.boundary; the same f, w, flags and report as the
  // plain call after the exchange, bit for bit. By default: wait, then the plain call (no overlap).
  // The breaking call's u_ghosts carries the ghosts' entries of the declared per-node arrays with
  // `halo` too (state_declarations), in the same exchange: its wait() fills them all.
  virtual void add_force_overlapped(const Model& model, const Vec3Array& u, Vec3Array& f, double* w,
                                    const GhostsInFlight& u_ghosts) const {
    u_ghosts.wait();
    add_force(model, u, f, w);
  }
  virtual BreakReport break_bonds_and_add_force_overlapped(Model& model, const Vec3Array& u, Vec3Array& f, double* w,
                                                           bool want_energy, double* lost_per_node,
                                                           const GhostsInFlight& u_ghosts) const {
    u_ghosts.wait();
    return break_bonds_and_add_force(model, u, f, w, want_energy, lost_per_node);
  }
  // The law's history (core/state_arrays.hpp): the arrays it keeps in Model::state_arrays, per node
  // or per bond, and what the run does with each. Asked once the bonds exist (core/model.cpp
  // declare_state); by default none.
  virtual std::vector<StateDeclaration> state_declarations(const Model& model) const {
    (void)model;
    return {};
  }
  // Fills the declared arrays at rest (no displacement yet) from the model's bonds: their values
  // before the first step. On a decomposed run it is called on each piece, whose ghosts have empty
  // rows: the ghosts' entries of `halo` arrays are then their owners' (parallel/mpi_decomposed).
  virtual void initialise_state(Model& model) const { (void)model; }
  // Only the breaking of break_bonds_and_add_force.
  virtual BreakReport break_bonds(Model& model, const Vec3Array& u, bool want_energy) const = 0;
  // The largest stretch ratio over the intact bonds with no no-fail end and how many of them are
  // over their critical stretch at u (StretchRatio), by the same criterion break_bonds applies; reads
  // only (no flag, no per-node threshold changes). Rows in any order: a maximum and a count.
  virtual StretchRatio stretch_ratio(const Model& model, const Vec3Array& u) const = 0;
  // W_i per node at u [J/m³].
  virtual std::vector<double> strain_energy_density(const Model& model, const Vec3Array& u) const = 0;
  // Damage φ_i ∈ [0, 1] per node (0 intact, 1 every bond broken).
  virtual std::vector<double> damage(const Model& model) const = 0;

  // Bond i→j's term of thesis eq. 2.5, V_j ν C [N/m⁴], C the linearised bond stiffness at the
  // reference configuration (c/|ξ| for PMB): node i's stable step is √(2ρ_i / Σ_j (this + other
  // terms)), core/model.hpp node_stiffness.
  virtual double bond_stiffness(const Model& model, std::size_t i, std::size_t j, double length) const = 0;
  // The continuum strain-energy density [J/m³] of node i's material (its block's, without surface
  // factors) under the uniform small strain `strain` (symmetric, row-major 3×3; in 2D only the
  // in-plane components are read): the bulk value W(ε) the law tends to for a whole family. The
  // reference of the energy surface correction (core/surface_correction), which probes each node
  // with a uniaxial stress built from it.
  virtual double continuum_energy_density(const Model& model, std::size_t i, const StrainTensor& strain) const = 0;
  // The dilatation θ_i per node at u, for a law whose energy is (κ/2)θ² plus a deviatoric part (LPS);
  // empty for a law without one (PMB). The surface correction corrects such a law's two parts
  // separately (core/surface_correction.hpp, the split method).
  virtual std::vector<double> dilatation(const Model& model, const Vec3Array& u) const {
    (void)model, (void)u;
    return {};
  }
  // y = M^{-1/2} K M^{-1/2} x with K the stiffness linearised about the reference configuration
  // and M the lumped masses ρ_i V_i (core/stability: its largest eigenvalue is ω_max²). period[d] > 0
  // makes axis d periodic for the bond direction (the tests' infinite lattice).
  virtual void apply_reference_stiffness(const Model& model, const std::array<double, 3>& period, const Vec3Array& x,
                                         Vec3Array& y) const = 0;
  // y += J(u)·x, J = ∂f/∂u the linearised force density at u (a Jacobian–vector product, matrix-free):
  // the Newton and Krylov solves of the implicit integrators use it.
  virtual void add_jacobian_product(const Model& model, const Vec3Array& u, const Vec3Array& x, Vec3Array& y) const = 0;
  // The same on a decomposed run with x's ghost values still on their way (u's are current), as
  // add_force_overlapped: interior rows, x_ghosts.wait(), boundary rows. By default no overlap.
  virtual void add_jacobian_product_overlapped(const Model& model, const Vec3Array& u, const Vec3Array& x, Vec3Array& y,
                                               const GhostsInFlight& x_ghosts) const {
    x_ghosts.wait();
    add_jacobian_product(model, u, x, y);
  }
  // The same Jacobian assembled, for a bond-based law whose force on i depends on u_j − u_i only:
  // blocks[9k..9k+8] = ∂f_i/∂u_j (row-major 3×3) for bond k of row i at u (zeros for a broken
  // bond); ∂f_i/∂u_i is minus their sum. Returns false for a law that has no such form (a
  // state-based one couples i with its neighbours' neighbours): solvers then stay matrix-free.
  // definite: leave out the (negative) stiffness of compressed bonds across their line, so that
  // the assembled matrix is positive semi-definite — a Newton iteration with it still converges
  // to the same equilibrium, only no longer quadratically (the residual decides, not the matrix).
  virtual bool bond_tangent_row(const Model& model, const Vec3Array& u, std::size_t i, double* blocks,
                                bool definite = false) const = 0;
  // For a law without bond_tangent_row (a state-based one): every node's own block of the Jacobian,
  // blocks[9i..9i+8] = ∂f_i/∂u_i (row-major 3×3) at u, overwritten — what the block-Jacobi
  // preconditioner of the matrix-free solves needs (linalg/pcg.hpp). definite: leave out the terms
  // that can make a block indefinite (as bond_tangent_row does). Returns false when the law has no
  // such form (then its solves run unpreconditioned); a bond-based law's blocks come from its rows.
  virtual bool jacobian_diagonal_blocks(const Model&, const Vec3Array&, std::vector<double>&, bool = false) const {
    return false;
  }

  // A decomposed run (issue 15, parallel/local_model): the law for a rank's piece `local`, whose
  // node l is node global[l] of the model this law was built for. By default built again from the
  // registry on the piece; a law with per-node constants that need a whole row (LPS's m_i) copies
  // them from this one when it has them, else (a skeleton's law, no rows) has the owned nodes' from
  // the piece's rows and takes the ghosts' in set_decomposed. `registry_make` is the registry's
  // factory of this law; a law outside the registry (the tests') makes itself.
  virtual std::shared_ptr<const BondModel> for_piece(
      const Model& local, const std::vector<std::int32_t>& global,
      std::shared_ptr<const BondModel> (*registry_make)(const Model&)) const {
    (void)global;
    return registry_make(local);
  }
  // A decomposed run: a law whose force sweep reads per-node values of the bond's far end that only
  // the end's own row gives (LPS's P_j) fills its ghosts' copies through `d` between its sweeps, and
  // its per-node constants of the ghosts once (LPS's m_j: a ghost's row is empty on the piece).
  // Collective: called by the piece's maker once the halo exists (parallel/mpi_decomposed), then
  // by the operator with the same d; the default law needs nothing.
  virtual void set_decomposed(const Decomposed* d) const { (void)d; }
};

// What the registry holds per model: its parameters (the reader checks them and --describe prints
// them), its constants per block, and its law (every block of a case uses one model).
struct MaterialDefinition {
  std::string doc;
  std::vector<MaterialParameter> parameters;
  // c and s0 of one block from its parameters; thickness h is ignored in 3D.
  PairConstants (*constants)(const BlockMaterial& block, const std::string& analysis, double horizon,
                             double thickness) = nullptr;
  // Rules that tie one parameter to another (e.g. PMB: E and G0, or c and s0, not a mix), checked by
  // the case reader after each parameter's own range; null: none.
  ParameterProblem (*check)(const BlockMaterial& block) = nullptr;
  // The law, built once the bonds exist (so a model may precompute per-node quantities).
  std::shared_ptr<const BondModel> (*make)(const Model& model) = nullptr;
};

// Damage per node, 1 − Σ_intact V_j / Σ_all V_j (0 for a node without bonds): what every
// bond-breaking model's damage() returns (materials/damage.cpp).
std::vector<double> bond_damage(const Model& model);

using MaterialRegistry = Registry<MaterialDefinition>;
const MaterialRegistry& material_registry();

// c and s0 per block and block pair (core/material.hpp) from the formulas of the blocks' model
// (every block uses blocks[0]'s; the case reader checks that they agree).
MaterialTable make_material_table(const std::vector<BlockMaterial>& blocks, const std::string& analysis, double horizon,
                                  double thickness);

}  // namespace pd
