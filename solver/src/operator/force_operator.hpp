// The operator between the integrators and the physics (MFEM's TimeDependentOperator idea): built
// once from the model, it owns the material law and every force term the scene needs, and the
// prescribed motion. An integrator sees only this: the force at (u, t), the breaking step, the
// prescribed motion at t, energies and powers, and the linearised force for implicit solves.
// No integrator names a force term or a material; no force term or material names an integrator.
#pragma once
#include <memory>
#include <string>
#include <vector>

#include "core/case.hpp"
#include "core/model.hpp"
#include "core/state.hpp"
#include "forces/force_term.hpp"
#include "linalg/sparse_matrix.hpp"
#include "parallel/decomposed.hpp"

namespace pd {

class ForceOperator {
 public:
  explicit ForceOperator(Model& model);

  const Model& model() const { return model_; }
  Model& model() { return model_; }
  std::size_t size() const { return model_.nodes.size(); }
  const std::vector<double>& density() const { return model_.density; }  // ρ_i [kg/m³]
  double damping() const { return model_.damping; }                     // α [1/s]
  // 1 where a component is prescribed (its motion comes from the tables, not from the force).
  const std::array<std::vector<std::uint8_t>, 3>& fixed() const { return model_.conditions.fixed; }
  // "Can anything break?", asked of the material's constants: the one place.
  bool can_break() const { return model_.material.can_break(); }

  // A decomposed run (issue 15): the model is this rank's piece (parallel/local_model), and the
  // ghosts' displacements come from their owners while the law sweeps the rows that read no ghost
  // (parallel/row_split.hpp: evaluate, break_bonds_and_evaluate, break_bonds, apply_jacobian);
  // energies and break reports are reduced over the ranks in an order that does not depend on
  // them. Null (the default): serial.
  void set_decomposed(const Decomposed* d);
  const Decomposed* decomposed() const { return decomposed_; }

  // s.f = force density at (s.u, t) (cleared, then the bonds and every active term add into it);
  // also s.w (strain-energy density), s.term_energies and s.indenter_force.
  void evaluate(State& s, double t) const;
  // Bonds over their critical stretch at s.u break (thesis §2.2: after the state update, before the
  // force there), then evaluate(s, t) in the same sweep over the bonds. Returns what broke now.
  BreakReport break_bonds_and_evaluate(State& s, double t);
  // Only the breaking: bonds over their critical stretch at s.u break (the implicit integrators
  // break after a converged solve, then solve again). Serial: the law's break_bonds, as before.
  // Decomposed: the pass of break_bonds_and_evaluate into scratch force arrays (the ghosts' u, and
  // LAMMPS's s0, overlapped with the interior rows), the count summed over the ranks and the energy
  // in node order. Collective on a decomposed run.
  BreakReport break_bonds(State& s);
  // The largest stretch ratio over the intact bonds that can break at s.u and how many bonds
  // break_bonds(s) would break there (materials/bond_model.hpp StretchRatio); changes no flag.
  // Decomposed: the ghosts' u (and LAMMPS's per-node s0) first, as break_bonds, then a maximum and a
  // total over the ranks — both exact, so the same value on any number of ranks. Collective then.
  StretchRatio stretch_ratio(State& s) const;
  // Whether any bond of the whole model is broken (collective on a decomposed run).
  bool any_broken() const;
  // The free dofs of the implicit solves (linalg/sparse_matrix.hpp FreeDofs) over the nodes this
  // operator owns: all nodes serially; on a decomposed run the owned ones only (a ghost's row is
  // its owner's), in local order, which is ascending global order.
  FreeDofs free_dofs(int dimension) const;

  // y = ∂f/∂u·x at (s.u, t): the linearised force density (matrix-free). Prescribed components are
  // not treated specially: a solver constrains them itself. Decomposed: x's ghost entries are taken
  // from their owners first (a halo exchange of a copy; s.u's ghosts must be current, as after
  // evaluate(s, t)), so an owned row is the serial row bit for bit. Collective then.
  void apply_jacobian(const State& s, double t, const Vec3Array& x, Vec3Array& y) const;

  // K = −V_i ∂f_i/∂u_j over the free dofs at (s.u, t): the assembled tangent stiffness (symmetric;
  // positive semi-definite for bonds in tension), rows of nodes with all their bonds, broken ones
  // included as zeros so that the pattern stays that of the first assembly (a factorisation's
  // ordering is reused). Empty (rows = −1) when the material or an active term has no assembled
  // form (a state-based law, contact): a solver then stays matrix-free.
  // definite: the material's positive semi-definite variant (materials/bond_model.hpp).
  SparseMatrix assemble_stiffness(const State& s, double t, const FreeDofs& dofs, bool definite = false) const;
  // Whether assemble_stiffness has a form for this scene: the law has bond_tangent_row and every
  // active term an add_tangent_diagonal (not contact).
  bool has_assembled_stiffness(const State& s, double t) const;
  // What has no assembled form, in words for an error or run.log ("the state-based material lps",
  // "contact"), or "" when has_assembled_stiffness.
  std::string missing_assembled_stiffness(const State& s, double t) const;
  // The diagonal blocks of K = −V ∂f/∂u over the free dofs at (s.u, t), the block-Jacobi
  // preconditioner of the matrix-free solves (linalg/pcg.hpp): group g is a node with free
  // components, its dofs first[g] … first[g+1]−1 (FreeDofs numbers a node's dofs together), its block
  // blocks[9g…9g+8] row-major in a 3×3 frame over those dofs. From the law's definite
  // bond_tangent_row (or, for a state-based law, its jacobian_diagonal_blocks) and every term's
  // add_jacobian_diagonal (contact included). False, and nothing filled, when the law has neither.
  bool stiffness_diagonal_blocks(const State& s, double t, const FreeDofs& dofs, std::vector<std::int64_t>& first,
                                 std::vector<double>& blocks) const;

  // What every integrator does first: the prescribed motion at t, then the force and the powers
  // there (the work ledger starts from them).
  void start(State& s, double t) const;

  // Prescribed motion. impose: u and v of every prescribed component at t.
  void impose_prescribed_motion(State& s, double t) const;
  // Prescribed components over a step t → t1 = t + dt: u_to = their u at t1 (a displacement table)
  // or u_from + ∫v dt (a velocity table); v_to = the mean velocity over the step, or for a velocity
  // table with `end_velocity` its value at t1. u_from may be u_to.
  void advance_prescribed_motion(const Vec3Array& u_from, Vec3Array& u_to, Vec3Array& v_to, double t, double t1,
                                 double dt, bool end_velocity) const;
  // v of every velocity-table component = its value at t1 (the end of a Verlet step).
  void impose_prescribed_velocity(Vec3Array& v, double t1) const;

  // Energies [J], summed in node order by parallel/node_sum.hpp (the same for any thread and rank count).
  double kinetic_energy(const State& s) const;
  double strain_energy(const State& s) const;  // Σ W_i V_i from the last force evaluation
  // Both, the same bits as the two calls, in one reduction on a decomposed run (the run loop's
  // blow-up watch asks every step: one wait for the slowest rank instead of two).
  struct KineticAndStrain {
    double kinetic = 0.0, strain = 0.0;
  };
  KineticAndStrain kinetic_and_strain_energy(const State& s) const;
  // Body-force and moving-indenter power plus the power of the reactions at prescribed components,
  // Σ V (ρa − f)·v with a the prescribed acceleration (the slope of a velocity table; 0 for a
  // piecewise-linear displacement — the impulses at its kinks are not counted) [W].
  double external_power(const State& s, double t) const;
  // Recomputes s.external_power and s.damping_power at t and adds the trapezoidal work increments
  // dt/2·(P_old + P_new) to the ledger; dt = 0 only initialises the powers.
  void update_work(State& s, double t, double dt) const;

  // The stable step of thesis eq. 2.5 and the exact explicit limit 2/ω_max (core/stability) [s],
  // the whole model's on a decomposed run (both collective then).
  double stable_time_step() const;
  double exact_time_step() const;

  // The work plan for run.log, from the material and the registered terms: what runs, what not.
  std::vector<std::string> work_plan(const Case& c) const;

 private:
  Model& model_;
  std::vector<std::unique_ptr<ForceTerm>> terms_;        // in force order (forces/force_term.hpp)
  std::vector<const ForceTerm*> power_terms_;            // the same, in power order
  std::vector<const ForceTerm*> built_;                  // per registry entry: its term, or null
  const Decomposed* decomposed_ = nullptr;
  mutable Vec3Array ghosted_x_;  // apply_jacobian's x with its ghosts filled (decomposed only)
  std::vector<double> lost_;     // the breaking pass's energy lost per node (decomposed only; kept, not allocated per step)
  // report.broken and report.energy summed over the ranks from this rank's count and lost_, in one
  // reduction (decomposed only).
  void reduce_break_report(BreakReport& report);
  // A decomposed run's breaking pass with the force into f and w (break_bonds_and_evaluate's s.f and
  // s.w, break_bonds' scratch arrays): u's ghosts (and the declared history) travel while the law sweeps the
  // interior rows; the report summed over the ranks.
  BreakReport break_on_piece(Vec3Array& u, Vec3Array& f, double* w);
  // u and the law's declared per-node history with `halo` (LAMMPS's s0 under its α rule): what a
  // breaking test reads of a ghost, in one halo exchange (one message per neighbour).
  NodeColumns breaking_ghost_values(Vec3Array& u) const;
};

}  // namespace pd
