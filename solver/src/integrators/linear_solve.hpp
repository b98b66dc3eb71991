// The linear solve of a Newton iteration, K Δu = rhs, as quasi_static and implicit make it: one
// object of this class in each (issue 37, item 5). It holds
// - the choice: a CHOLMOD factorisation (direct) or matrix-free CG, and why (choose_linear_solver
//   of newton_krylov.hpp; a restart keeps the checkpoint's, keep_recorded);
// - the factorisation cache: the factor in use, where it was assembled (u, t and how: the
//   integrator's checkpoint names the point and a restart factorises again there, bitwise), the
//   broken bonds taken out of it since (linalg/woodbury.hpp, quasi_static's breaking rounds), and a
//   spare CHOLMOD object for quasi_static's cut trial (remember_factor / restore_factor: the factor
//   of the step's start survives the trial);
// - CG's block-Jacobi preconditioner of K's 3×3 node blocks and its scratch.
// What K is stays the integrator's: quasi_static's tangent (shifted after damage), implicit's
// K + c M. It changes the assembled tangent (the callable handed to factorize) and the blocks' diagonals.
#pragma once
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "core/case.hpp"
#include "linalg/cholesky.hpp"
#include "linalg/pcg.hpp"
#include "linalg/sparse_matrix.hpp"
#include "linalg/woodbury.hpp"
#include "operator/force_operator.hpp"
#include "parallel/dof_sums.hpp"

namespace pd {

// How the factor in use was assembled, besides the displacements: at load or time t, the tangent's
// definite variant or not, its diagonal shifted (quasi_static after damage), for step dt (implicit's
// K_eff depends on it). Each integrator records and checkpoints the parts it uses.
struct FactorPoint {
  double t = 0.0;
  bool definite = false;
  bool shifted = false;
  double dt = 0.0;
};

class LinearSolve {
 public:
  // ---- The choice (newton_krylov.hpp choose_linear_solver; collective on a decomposed run).
  void choose(const ForceOperator& op, const Case& c, const std::string& section, const std::string& choice,
              int dof_dimension);
  bool uses_cg() const { return use_cg_; }
  const std::string& reason() const { return reason_; }
  // Solve as the checkpoint's solver did (`cg`: by CG), which this run alone would not (`here`, its
  // own name for the solver, and `also`, appended to the reason, say what it would take).
  void keep_recorded(bool cg, const std::string& here, const std::string& also = {});

  // ---- The factorisation (direct).
  // K: the tangent −V ∂f/∂u at (s, at.t) over dofs (ForceOperator::assemble_stiffness; its definite
  // variant if at.definite), changed by adjust; its factorisation becomes the one in use, made at
  // s.u and `at`. False (counted in refused()) when CHOLMOD refuses K: not positive definite.
  // StepFailed naming `scheme` when the scene has no assembled tangent. The bonds taken out of the
  // old factor are dropped; the wall time of assembling and factorising is added to factorise_seconds().
  bool factorize(const ForceOperator& op, const State& s, const FreeDofs& dofs, const FactorPoint& at,
                 const std::string& scheme, const std::function<void(SparseMatrix&)>& adjust);
  // x = K⁻¹ rhs with the factor in use, corrected by the bonds taken out of it.
  void solve(const std::vector<double>& rhs, std::vector<double>& x);
  bool have_factor() const { return have_factor_; }
  // The factor no longer fits (bonds broke, Δt changed, a failed step): the next solve factorises.
  void forget_factor() { have_factor_ = false, bonds_out_.clear(); }
  const SparseCholesky& factor() const { return *factor_; }
  const Vec3Array& factor_u() const { return factor_u_; }
  const FactorPoint& factor_point() const { return factor_at_; }
  // The broken bonds taken out of the factor in use (integrators/bonds_out_of_factor.hpp).
  Woodbury& bonds_out() { return bonds_out_; }
  const Woodbury& bonds_out() const { return bonds_out_; }

  // quasi_static's cut (quasi_static.hpp): remember the factor in use at the start of a step; the
  // step's first new factorisation then goes into a spare CHOLMOD object, and restore_factor puts
  // the start's back in use (each object keeps its symbolic analysis). end_remembering: the step
  // ends, or can no longer be cut; the factor in use stays.
  void remember_factor();
  void restore_factor();
  void end_remembering() { at_start_.active = false; }
  bool remembering() const { return at_start_.active; }

  // Work since configure: factorisations made (a checkpoint's count is set back by
  // set_factorisations), refused, solves, and CHOLMOD's symbolic analyses over both objects.
  int factorisations() const { return factorisations_; }
  void set_factorisations(int count) { factorisations_ = count; }
  int refused() const { return refused_; }
  std::int64_t solves() const { return solves_; }
  double factorise_seconds() const { return factorise_seconds_; }
  double solve_seconds() const { return solve_seconds_; }
  int analyses() const { return factor_->analyses() + (spare_factor_ ? spare_factor_->analyses() : 0); }
  double analysis_seconds() const {
    return factor_->analysis_seconds() + (spare_factor_ ? spare_factor_->analysis_seconds() : 0.0);
  }

  // ---- Matrix-free CG (newton_krylov.hpp solve_newton_system).
  // Scratch for a state of this many nodes; before the first CG solve.
  void size_cg(std::size_t nodes);
  // The preconditioner's blocks: K's 3×3 node blocks at (s, t) (ForceOperator::stiffness_diagonal_blocks),
  // or, for a law with neither form of them, 1×1 blocks of `fallback`. Then each_block_diagonal lets
  // the integrator change their diagonals, and build_block_jacobi factorises them.
  void stiffness_blocks(const ForceOperator& op, const State& s, double t, const FreeDofs& dofs, double fallback);
  // f(entry, dof) for every diagonal entry of every block: its value and its dof.
  template <class F>
  void each_block_diagonal(F f) {
    for (std::size_t g = 0; g + 1 < block_first_.size(); ++g)
      for (std::int64_t a = 0; a < block_first_[g + 1] - block_first_[g]; ++a)
        f(blocks_[9 * g + static_cast<std::size_t>(4 * a)], static_cast<std::size_t>(block_first_[g] + a));
  }
  void build_block_jacobi() { block_jacobi_.build(block_first_, blocks_); }
  // K + D per dof for CG's products: the integrator fills D (the shift, or c m) before solve_cg.
  std::vector<double>& cg_diagonal() { return diagonal_; }
  // correction = K⁻¹ rhs by PCG from zero, preconditioned by M (block Jacobi when null); counted.
  PcgResult solve_cg(const ForceOperator& op, const State& s, double t, const FreeDofs& dofs, const DofSums& sums,
                     const std::vector<double>& rhs, std::vector<double>& correction, const PcgSettings& settings,
                     const Preconditioner* M = nullptr);
  std::int64_t cg_iterations() const { return cg_iterations_; }  // since configure (not checkpointed)
  int cg_solves() const { return cg_solves_; }

 private:
  bool use_cg_ = false;
  std::string reason_;

  std::unique_ptr<SparseCholesky> factor_ = std::make_unique<SparseCholesky>(), spare_factor_;
  bool have_factor_ = false;
  Vec3Array factor_u_;
  FactorPoint factor_at_;
  Woodbury bonds_out_;
  int factorisations_ = 0, refused_ = 0;
  std::int64_t solves_ = 0;
  double factorise_seconds_ = 0.0, solve_seconds_ = 0.0;  // wall time, for the integrators' summaries
  // The factor in use when remember_factor was called, and whether factor_ is the spare now (then
  // factor_u holds the start's factor's u).
  struct AtStart {
    bool active = false, have_factor = false, swapped = false;
    FactorPoint at;
    Vec3Array factor_u;
  };
  AtStart at_start_;

  BlockJacobi block_jacobi_;
  std::vector<std::int64_t> block_first_;
  std::vector<double> blocks_, diagonal_;
  Vec3Array cg_x_, cg_y_;
  std::int64_t cg_iterations_ = 0;
  int cg_solves_ = 0;
};

}  // namespace pd
