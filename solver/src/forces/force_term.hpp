// The interface of every force term besides the material's bonds (contact, indenters, body force),
// and their registry. The operator (operator/force_operator.hpp) builds the terms a scene needs
// once, from this registry, and calls each through this interface; integrators never name one.
#pragma once
#include <memory>
#include <string>
#include <vector>

#include "core/case.hpp"
#include "core/model.hpp"
#include "core/state.hpp"
#include "parallel/decomposed.hpp"

namespace pd {

class ForceTerm {
 public:
  virtual ~ForceTerm() = default;
  // A decomposed run (issue 15): the term's model is this rank's piece, and whatever it reports as
  // a sum over nodes (its power, the indenters' force on the body, its energy) must be the serial
  // sum's bits on every rank: the term reduces it through `d` (parallel/decomposed.hpp). Null: serial.
  void set_decomposed(const Decomposed* d) { decomposed_ = d; }
  // s.f += the term's force density at (s.u, t); adds its potential energy, if it has one, to its
  // entry of s.term_energies (add_energy), and sets what it reports (the indenters' forces on the
  // body). Accumulates; never clears.
  virtual void add_force(State& s, double t) const = 0;
  // p += the power the term puts into the body at (s.u, s.v, t) [W] (0 for a conservative term
  // that does not move: contact).
  virtual void add_power(const State& s, double t, double& p) const = 0;
  // y += ∂f/∂u·x at (s.u, t): the term's part of the linearised force (implicit solves).
  virtual void add_jacobian_product(const State& s, double t, const Vec3Array& x, Vec3Array& y) const = 0;
  // block += ∂f_i/∂u_i (row-major 3×3) at node i for a term that acts on each node alone
  // (indenters, body force); false for a term that couples nodes (contact): the assembled tangent
  // does not hold it, and solvers then stay matrix-free.
  virtual bool add_tangent_diagonal(const State& s, double t, std::size_t i, double block[9]) const = 0;
  // block += ∂f_i/∂u_i at node i for every term, coupling ones included (the diagonal blocks of the
  // matrix-free tangent: the block-Jacobi preconditioner of linalg/pcg.hpp). definite: leave out
  // negative stiffness across a line (as BondModel::bond_tangent_row does), so that the block of a
  // preconditioner stays positive. By default the term's add_tangent_diagonal.
  virtual void add_jacobian_diagonal(const State& s, double t, std::size_t i, double block[9], bool definite) const {
    (void)definite;
    add_tangent_diagonal(s, t, i, block);
  }
  // Before add_jacobian_diagonal is called for the nodes at (s.u, t) (from threads, so it cannot
  // communicate): a term whose diagonal reads nodes other ranks own fetches them here. Collective
  // on a decomposed run; nothing to do serially or for a term that acts on each node alone.
  virtual void prepare_jacobian_diagonal(const State& s, double t) const {
    (void)s;
    (void)t;
  }
  // Lines of the work plan (run.log) for this term.
  virtual std::vector<std::string> work_plan() const = 0;

 protected:
  // s.term_energies[entry of the registry's term `term`] += energy (the list sized first if need be).
  static void add_energy(State& s, const std::string& term, double energy);
  const Decomposed* decomposed_ = nullptr;
};

// One registered term: how to build it for a scene (null when the scene does not need it) and
// what the work plan says then. `order` fixes the order in which terms add into f (and so the bits
// of f), `power_order` the order of their powers in the external power: both are those of every
// run before the operator existed, so results stay bitwise the same.
struct ForceTermEntry {
  std::string name;
  int order = 0;
  int power_order = 0;
  std::unique_ptr<ForceTerm> (*make)(const Model& model) = nullptr;
  std::string (*absent)(const Model& model, const Case& c) = nullptr;  // work-plan line when not built; may be ""
  // The history.csv column of the term's potential energy ("contact_energy"); "" for a term without one.
  std::string energy = {};
};

// Every force term, sorted by `order`.
const std::vector<ForceTermEntry>& force_term_registry();
// The energy columns of the registry's terms that have one, in its order: what State::term_energies
// holds, entry by entry, whether or not the scene built the term (then 0), and history.csv's
// columns for them.
const std::vector<std::string>& term_energy_names();
// The entry of State::term_energies that holds the energy of the registry's term `term` (its name);
// throws std::logic_error for a term without an energy.
std::size_t term_energy_index(const std::string& term);
// That entry of s (0 before the first force evaluation).
double term_energy(const State& s, const std::string& term);

// The factories, one per file of forces/ (force_terms.cpp lists them).
std::unique_ptr<ForceTerm> make_contact_term(const Model& model);
std::unique_ptr<ForceTerm> make_indenter_term(const Model& model);
std::unique_ptr<ForceTerm> make_body_force_term(const Model& model);

}  // namespace pd
