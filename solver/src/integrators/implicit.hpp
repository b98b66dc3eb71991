// Implicit dynamics (time.integrator: implicit): the generalized-α method of Chung & Hulbert (1993,
// J. Appl. Mech. 60:371–375), solved for u_{n+1} by Newton with the assembled tangent factorised by
// CHOLMOD, the step limited by accuracy and not by stability (issue 13, item 4).
//
// The scheme. With the lumped mass m_i = ρ_i V_i, the force V_i f_i(u, t) of the operator and the
// damping force −α m v of the case (α = `damping`), the balance is taken at intermediate points,
//   m[(1−α_m) a_{n+1} + α_m a_n] + α m[(1−α_f) v_{n+1} + α_f v_n] = V[(1−α_f) f(u_{n+1}, t_{n+1}) + α_f f_n],
// the forces (not the displacements) interpolated — the variant analysed by Erlicher, Bonaventura &
// Bursi (2002, Comput. Mech. 28:83–104), chosen because f_n is already known and the state keeps
// f at u_{n+1}, where bonds break and the work ledger reads it. Newmark's updates relate u, v, a:
//   u_{n+1} = ũ + β Δt² a_{n+1},   ũ = u_n + Δt v_n + Δt²(½ − β) a_n
//   v_{n+1} = ṽ + γ Δt a_{n+1},    ṽ = v_n + Δt(1 − γ) a_n
// with the parameters of one user value, the spectral radius at infinite frequency ρ∞ ∈ [0, 1]:
//   α_m = (2ρ∞ − 1)/(ρ∞ + 1), α_f = ρ∞/(ρ∞ + 1), γ = ½ − α_m + α_f, β = ¼(1 − α_m + α_f)²
// (Chung & Hulbert eqs. 25, 17, 20): second order, unconditionally stable on linear problems, the
// high frequencies damped to ρ∞ per step and the low ones barely (third-order dissipation).
// ρ∞ = 1 gives α_m = α_f = ½, β = ¼, γ = ½: with a_0 = M⁻¹(V f_0 − α m v_0) the balance then holds
// at every step end, and the scheme is Newmark's average acceleration (trapezoidal) rule, which
// conserves ½vᵀMv + ½uᵀKu of a linear system exactly and lengthens the period of a mode ω by
// ωΔt / (2 arctan(ωΔt/2)) ≈ 1 + (ωΔt)²/12.
//
// Newton. The unknown is u_{n+1} at the free components (FreeDofs; prescribed ones follow their
// tables). The residual r(u) = m[(1−α_m)a + α_m a_n] + α m[(1−α_f)v + α_f v_n] − V[(1−α_f)f(u) + α_f f_n],
// with a(u) and v(u) from Newmark's updates, has the derivative
//   ∂r/∂u = (1−α_f)·K_eff,  K_eff = K + m·[(1−α_m)/((1−α_f) β Δt²) + α γ/(β Δt)],
// K = −V ∂f/∂u the assembled tangent (operator/force_operator.hpp). So each iteration solves
// K_eff Δu = −r/(1−α_f), factorised by CHOLMOD (linalg/cholesky.hpp). The mass term makes K_eff
// positive definite where K is only semi-definite: a free body needs no support. A factorisation is
// kept across iterations and steps while Δt is unchanged and Newton keeps the residual falling by
// 4× per iteration (modified Newton, as quasi_static); otherwise it is assembled again. A correction
// that raises the residual is halved (up to 1/32: backtracking line search). Converged when the last
// correction ω_K = ‖Δu‖/‖u_{n+1} − u_n‖ ≤ newton_tol (eq. 2.6 for Newton), the residual
// ≤ residual_tol × (‖inertia‖ + ‖force‖), the residual no longer falling (round-off floor): two of them.
//
// Step control, two ways, the smaller step wins:
// - Φ_K of thesis eq. 2.8 (control/zohdi.hpp) from the Newton corrections, aimed at K_d iterations.
// - A local error estimate, so that `tol` bounds the time-discretisation error of a step: Zienkiewicz
//   & Xie (1991, Earthquake Eng. Struct. Dyn. 20:871–887) estimate Newmark's local displacement error
//   as (β − 1/6) Δt² (a_{n+1} − a_n). For generalized-α the algorithmic acceleration is shifted,
//   a_n ≈ ü(t_n) + (α_m − α_f) Δt u⃛ (from the balance above along the exact solution, which is also
//   why γ = ½ − α_m + α_f), and the same Taylor expansion gives
//     e_{n+1} = (β − 1/6 + (α_m − α_f)/2) Δt² (a_{n+1} − a_n) = (β − γ/2 + 1/12) Δt² (a_{n+1} − a_n),
//   Z&X's estimate at ρ∞ = 1 (coefficient 1/12). Measured like eq. 2.6 against the step's motion,
//   η = ‖e‖/‖u_{n+1} − u_n‖ ≈ C (ωΔt)² for a motion of frequency ω: about the relative phase error the
//   step adds (the motion taken as at least 1e-9 dx per dof, kMotionFloor: a body at rest or a load
//   starting smoothly from zero is not measured against its own round-off). η > tol rejects the step and redoes it from t_n with Δt·max(0.2, 0.9 (tol/η)^{1/2});
//   an accepted step proposes 0.9 (tol/η)^{1/2} Δt (η ∝ Δt²). Lowering tol lowers the error in
//   proportion.
// The proposal is capped at 2× and kept equal to Δt while the step was accepted and would grow by
// less than 25 % (the factorisation made for Δt then stays valid: a Δt changed by a few per cent
// every step would cost a factorisation per step); dt_min ≤ Δt ≤ dt_max. A step that Newton cannot bring to
// convergence is redone with Δt/2; below dt_min the run stops (StepFailed).
//
// Fracture, in the thesis's order (§2.2; as Verlet and the adaptive step): the converged step is
// accepted, then bonds over their critical stretch break at u_{n+1}, then f(u_{n+1}) is evaluated
// with the bonds left and used from the next step on; the step is not re-solved. The algorithmic
// acceleration takes the force's jump, a_{n+1} += (f_new − f_old)/ρ, so that at ρ∞ = 1 the balance
// m a = V f − α m v still holds at the step end.
//
// implicit.linear_solver: cg solves K_eff Δu = −r/(1−α_f) matrix-free instead (linalg/pcg.hpp):
// K_eff x = −V ∂f/∂u·x + c m x from ForceOperator::apply_jacobian, preconditioned by K_eff's 3×3
// node blocks (the law's definite diagonal blocks plus c m), to kCgTolerance relative or half the
// residual tolerance absolute; the tangent is then that of every iterate (full Newton). It needs no
// assembled tangent, so auto takes it for lps and contact, for 3D models with at least
// kCgFromDofs3d free dofs (quasi_static's measured threshold), and on several MPI ranks, where the
// products are force evaluations with ghosts and every norm and dot product is summed in global
// dof order (parallel/dof_sums.hpp): the same bits for any rank count.
#pragma once
#include <memory>

#include "integrators/integrator.hpp"
#include "integrators/linear_solve.hpp"
#include "integrators/newton_krylov.hpp"
#include "linalg/sparse_matrix.hpp"
#include "parallel/dof_sums.hpp"

namespace pd {

// The generalized-α parameters of one ρ∞ (Chung & Hulbert 1993).
struct GeneralizedAlpha {
  double alpha_m, alpha_f, beta, gamma;
  static GeneralizedAlpha of(double rho_infinity);
  // The coefficient C of the local error e = C Δt² (a_{n+1} − a_n) (implicit.hpp).
  double error_coefficient() const { return beta - 0.5 * gamma + 1.0 / 12.0; }
};

class Implicit : public Integrator {
 public:
  explicit Implicit(ForceOperator& op) : op_(op) {}
  std::string name() const override { return "implicit"; }
  void configure(const Case& c, double dt_exact = 0.0) override;
  void initialize(State& state, double t) override;
  void step(State& state, double& t, double& dt) override;

  // The base state, the algorithmic acceleration a_n, the last proposal, and where the factorisation
  // in use was assembled (u, t, Δt); load_state() assembles and factorises it there again, so a
  // restarted run reuses exactly the factor the uninterrupted one does (bitwise).
  std::vector<char> save_state() const override;
  std::vector<Vec3Array*> checkpointed_node_arrays() override { return {&a_}; }
  void load_state(const std::vector<char>& bytes) override;

  std::vector<std::string> describe(double dt_exact) const override;
  bool controls_step() const override { return true; }
  std::optional<double> initial_dt() const override { return settings_.dt_initial; }

  const ImplicitSettings& settings() const { return settings_; }
  const GeneralizedAlpha& parameters() const { return ga_; }
  int factorisations() const { return linear_.factorisations(); }
  bool uses_cg() const { return linear_.uses_cg(); }
  std::string linear_solver() const override { return linear_solver_name(linear_.uses_cg()); }
  std::string keep_linear_solver(const std::string& recorded) override;
  std::int64_t cg_iterations() const { return linear_.cg_iterations(); }  // since configure (not checkpointed)
  std::string linear_algebra_summary() const override;
  double dt_min() const { return dt_min_; }
  double dt_max() const { return dt_max_; }
  // The local error estimate η of the last accepted step (implicit.hpp).
  double last_error() const { return last_error_; }
  const Vec3Array& acceleration() const { return a_; }

  // ---- For the mixed integrator (integrators/mixed.hpp), which hands fracture to Verlet.
  // Take over from another scheme at a state it reached (u, v, f at t; bonds broken meanwhile):
  // a_n from the equation of motion, as initialize() takes it, and no factorisation or proposal
  // carried over.
  void resume(const State& state);

 private:
  // Newton for u_{n+1} at t1 from the predictor in s; true when converged (iterations, the last ω).
  bool solve_step(const State& start, State& s, double t1, double h, int& iterations, double& omega);
  // a(u) and v(u) at the free dofs from Newmark's updates, and the residual r(u) at the free dofs;
  // returns ‖r‖ and sets scale = ‖inertia‖ + ‖force‖.
  double residual(const State& start, const State& s, double h, double& scale);
  bool factorize_at(const State& s, double t1, double h, bool definite);
  double mass_coefficient(double h) const;  // the bracket multiplying m in K_eff
  // The motion the local error is measured against is at least this × dx per dof (implicit.cpp).
  static constexpr double kMotionFloor = 1e-9;

  ForceOperator& op_;
  ImplicitSettings settings_;
  GeneralizedAlpha ga_{};
  double dt_min_ = 0.0, dt_max_ = 0.0;
  FreeDofs dofs_;
  std::vector<double> mass_;  // m = ρV per dof
  Vec3Array a_;               // the algorithmic acceleration a_n (zero at non-dofs)
  double proposal_ = 0.0;     // the last proposal handed out, to recognise a shortened step
  double last_error_ = 0.0;

  // The linear solver (direct or CG, and why), the factorisation in use with where it was assembled
  // (u, t, Δt, definite or not: for save_state), and CG's block Jacobi (linear_solve.hpp).
  LinearSolve linear_;

  State trial_;
  std::vector<double> r_, correction_, a_new_, v_new_;

  // Sums over the dofs (every rank's on a decomposed run) and their per-dof terms.
  DofSums sums_;
  std::vector<double> terms_[3];
  // The matrix-free path: K_eff Δu = rhs by PCG at (s, t1) into correction_; false when CG made no
  // progress.
  static constexpr double kCgTolerance = 1e-6;
  bool solve_krylov(const State& s, double t1, double h, double floor);
};

}  // namespace pd
