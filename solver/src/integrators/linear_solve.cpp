// The linear solve of quasi_static's and implicit's Newton iterations (linear_solve.hpp).
#include "integrators/linear_solve.hpp"

#include <chrono>
#include <utility>

#include "integrators/integrator.hpp"
#include "integrators/newton_krylov.hpp"

namespace pd {

void LinearSolve::choose(const ForceOperator& op, const Case& c, const std::string& section, const std::string& choice,
                         int dof_dimension) {
  const LinearSolverChoice chosen = choose_linear_solver(op, c, section, choice, dof_dimension);
  use_cg_ = chosen.use_cg;
  reason_ = chosen.reason;
}

void LinearSolve::keep_recorded(bool cg, const std::string& here, const std::string& also) {
  use_cg_ = cg;
  reason_ = "as the checkpoint was written; this run alone would take " + here + ", " + reason_ + also;
}

bool LinearSolve::factorize(const ForceOperator& op, const State& s, const FreeDofs& dofs, const FactorPoint& at,
                            const std::string& scheme, const std::function<void(SparseMatrix&)>& adjust) {
  struct Timer {  // the wall time of assembling and factorising, however this returns
    std::chrono::steady_clock::time_point start;
    double& seconds;
    ~Timer() { seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(); }
  } timer{std::chrono::steady_clock::now(), factorise_seconds_};
  bonds_out_.clear();  // a new factor has the bonds as they are
  SparseMatrix K = op.assemble_stiffness(s, at.t, dofs, at.definite);
  if (K.rows < 0)
    throw StepFailed(scheme + " needs an assembled tangent, which this scene's material or contact does not have; "
                     "use time.integrator: verlet");
  adjust(K);
  if (at_start_.active && !at_start_.swapped && at_start_.have_factor) {
    // The step's first new factorisation: into the spare, the start's factor kept for restore_factor.
    if (!spare_factor_) spare_factor_ = std::make_unique<SparseCholesky>();
    std::swap(factor_, spare_factor_);
    std::swap(factor_u_, at_start_.factor_u);
    at_start_.swapped = true;
  }
  have_factor_ = factor_->factorize(K);
  if (!have_factor_) return ++refused_, false;
  ++factorisations_;
  factor_u_ = s.u;
  factor_at_ = at;
  return true;
}

void LinearSolve::solve(const std::vector<double>& rhs, std::vector<double>& x) {
  const auto start = std::chrono::steady_clock::now();
  factor_->solve(rhs, x);
  bonds_out_.apply(x);  // the bonds broken since the factorisation, taken out
  solve_seconds_ += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  ++solves_;
}

void LinearSolve::remember_factor() {
  at_start_.active = true;
  at_start_.have_factor = have_factor_;
  at_start_.at = factor_at_;
  at_start_.swapped = false;
}

void LinearSolve::restore_factor() {
  bonds_out_.clear();  // a cut trial breaks nothing; this is for safety: they belong to the other factor
  if (at_start_.swapped) {
    std::swap(factor_, spare_factor_);
    std::swap(factor_u_, at_start_.factor_u);
    at_start_.swapped = false;
  }
  have_factor_ = at_start_.have_factor;
  factor_at_ = at_start_.at;
}

void LinearSolve::size_cg(std::size_t nodes) {
  cg_x_ = make_vec3(nodes);
  cg_y_ = make_vec3(nodes);
}

void LinearSolve::stiffness_blocks(const ForceOperator& op, const State& s, double t, const FreeDofs& dofs,
                                   double fallback) {
  if (op.stiffness_diagonal_blocks(s, t, dofs, block_first_, blocks_)) return;
  block_first_.clear();
  for (std::size_t k = 0; k <= dofs.size(); ++k) block_first_.push_back(static_cast<std::int64_t>(k));
  blocks_.assign(9 * dofs.size(), 0.0);
  for (std::size_t k = 0; k < dofs.size(); ++k) blocks_[9 * k] = fallback;
}

PcgResult LinearSolve::solve_cg(const ForceOperator& op, const State& s, double t, const FreeDofs& dofs,
                                const DofSums& sums, const std::vector<double>& rhs, std::vector<double>& correction,
                                const PcgSettings& settings, const Preconditioner* M) {
  const PcgResult result = solve_newton_system(op, s, t, dofs, sums, diagonal_, M ? *M : block_jacobi_, rhs, correction,
                                               settings, cg_x_, cg_y_);
  cg_iterations_ += result.iterations;
  ++cg_solves_;
  return result;
}

}  // namespace pd
