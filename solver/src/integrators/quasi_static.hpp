// Quasi-static loading (time.integrator: quasi_static): time is a load parameter, the boundary-
// condition tables are the load path, and every load step t → t + Δt is brought to equilibrium,
// V_i f_i(u) = 0 at every free component, by Newton's method:
//   K(u_K) Δu = V f(u_K),  u_{K+1} = u_K + α Δu,   K = −V ∂f/∂u the assembled tangent
// (operator/force_operator.hpp), factorised by CHOLMOD (linalg/cholesky.hpp); α < 1 only when the
// full step does not lower the residual (backtracking line search). A factorisation is reused for
// later iterations and load steps while it keeps the residual falling by 4× per iteration (below
// the first bond failure PMB is nearly linear, so one factorisation serves many steps); otherwise
// the tangent is assembled and factorised again, on the symbolic analysis (CHOLMOD's ordering) of
// the first: the pattern keeps every bond, broken or not. After bonds have broken, the first tangent
// of a step that starts from an explicit step's state (mixed's return) is the definite variant.
//
// Newton starts from u_n + Δt·v_n at the free components, v_n the mean velocity of the last load
// step: the linear extrapolation of the load path, which is the
// equilibrium itself while the response is linear (PMB below its first failure), so the first
// residual is that of the nonlinearity only and Newton needs fewer corrections.
//
// Converged when ω_K = ‖Δu‖/‖u_K − u_n‖ ≤ tol (eq. 2.6 for Newton's corrections) and either
// ‖V f‖ ≤ residual_tol × the load (‖reactions‖ + ‖body forces‖) or the residual has stopped falling
// (the round-off floor of the stretches, ~1e-16/strain of the load, above residual_tol at small strain). Then bonds over their critical
// stretch break (thesis §2.2 rule) and the same load is solved again, until none breaks
// (max_breaking_rounds: more is unstable crack growth, and the step fails; mixed also fails it when
// a re-solve breaks no fewer bonds than the one before, see limit()). The re-solve keeps the
// factorisation in use with the round's bonds taken out of it by the Woodbury identity
// (integrators/bonds_out_of_factor.hpp, linalg/woodbury.hpp) while they fit in kMaxRemovedColumns,
// instead of factorising again; for that load step only (a step that ends so drops its factor). The next step is
// Φ_K·Δt with Φ_K of eq. 2.8 (control/zohdi.hpp) from the last correction, not larger after a step
// in which bonds broke; a step that does not converge is redone from t with Δt/2. Velocities are
// the mean over the load step, (u_{n+1} − u_n)/Δt, so the work ledger integrates the reactions.
//
// The cut to the first bond failure. A long load step can carry the body far past the load at which
// its first bond reaches its critical stretch: many bonds are then over s0 at once, break together
// and the step fails by breaking (unstable crack growth, where mixed switches to Verlet from the
// start of the step, all of whose elastic range it then runs explicitly). So after the first
// equilibrium of a load step t → t + h that started from the last load step's equilibrium (not from
// an explicit step's state in mixed, which is none) with no bond over its critical stretch and none
// broken yet (the first failure only: see step()), if
// bonds are over it at the end (the law's own criterion: materials/bond_model.hpp StretchRatio) by
// more than kCutMargin in the largest ratio r = s/s0, the step is redone to the load where r reaches
// the target: below the first failure PMB's equilibrium is linear in the load (the displacements of
// K u = load, thesis eq. 2.3 linearised), so r(t + τ) ≈ r0 + (r1 − r0) τ/h from r0 at the start and
// r1 at the end, τ = h (target − r0)/(r1 − r0). The target is 1 − kCutMargin/2 when the step
// started further than kCutMargin below failure (the step ends on the elastic equilibrium just
// before the first failure, nothing broken, so that a crack that then runs unstably starts from
// there), else 1 + kCutMargin/2 (the first bonds cross by at most about the margin). If the
// redone step still overshoots by more than the margin, one more such secant cut, through the start
// and the redone step. Nothing of the trial survives: no bond was broken, and a factorisation (or
// an AMG hierarchy) made in it is made again where the one in use at the start of the step was
// made (as load_state does), so the redone step is bitwise the step asked for directly.
// quasi_static.cut_to_first_failure: false turns the cut off (the steps as before it).
//
// quasi_static.linear_solver: cg replaces the factorisation by matrix-free preconditioned CG
// (linalg/pcg.hpp) on K Δu = V f, K x = −V ∂f/∂u·x from ForceOperator::apply_jacobian, with the
// block-Jacobi preconditioner of K's 3×3 node blocks: an inexact Newton–Krylov iteration. Each
// linear solve stops at ‖V f − K Δu‖ ≤ η_k ‖V f‖ with the forcing term of Eisenstat & Walker (1996,
// choice 2), η_k = 0.9 (‖F_k‖/‖F_{k−1}‖)², safeguarded and capped at kEtaMax, and never asked below
// half the residual tolerance (Kelley 1995, §6.3): Newton's line search and convergence tests are
// unchanged. It needs no assembled tangent, so contact and the state-based LPS law work (LPS gives
// its own diagonal blocks: materials/lps/lps_tangent.cpp); a direction of negative curvature
// (an indefinite tangent after damage) ends CG with its iterate so far (Steihaug 1983).
//
// quasi_static.preconditioner: amg (or auto on large 3D models) preconditions that CG by one
// V-cycle of algebraic multigrid (linalg/amg.hpp) set up on the assembled tangent (its definite
// variant, diagonal shifted by kDiagonalShift: a preconditioner must be positive definite, and need
// not be K). The hierarchy is reused across Newton iterations and load steps; it is set up again
// (1) after bonds break (the tangent lost them: cracks are where an old hierarchy is worst), and
// (2) when a CG solve needs more than kAmgRebuildGrowth × the iterations per tenfold residual
// reduction of the first solve after the set-up (the tangent has drifted from the one it was built
// on, by large rotations or compressed bonds). The point of the set-up (u, t) and that first rate
// are checkpointed, and load_state sets the hierarchy up again there: hypre's serial set-up is
// deterministic, so a restarted run continues bitwise.
//
// Once bonds have broken, nodes that hang by bonds on one line and one side (or by none) are left
// out of each static solve and placed on their bonds' line after it (integrators/hanging_nodes.hpp:
// Newton converges on their sideways offset only linearly, and they carry no load in statics); so
// are free fragments (no intact chain to a prescribed motion), which stay where they are.
#pragma once
#include <algorithm>
#include <memory>
#include <optional>

#include "integrators/hanging_nodes.hpp"
#include "integrators/integrator.hpp"
#include "integrators/linear_solve.hpp"
#include "integrators/newton_krylov.hpp"
#include "linalg/amg.hpp"
#include "linalg/sparse_matrix.hpp"
#include "parallel/dof_sums.hpp"

namespace pd {

class QuasiStatic : public Integrator {
 public:
  explicit QuasiStatic(ForceOperator& op) : op_(op) {}
  std::string name() const override { return "quasi_static"; }
  std::optional<int> step_mode() const override { return 1; }  // every step a load step (history.csv `mode`)
  void configure(const Case& c, double dt_exact = 0.0) override;
  void initialize(State& state, double t) override;
  void step(State& state, double& t, double& dt) override;

  std::vector<std::string> describe(double dt_exact) const override;
  bool controls_step() const override { return true; }
  std::optional<double> initial_dt() const override { return dt_initial_; }

  // The factorisation in use, if any, is saved as where it was assembled (u, t and how), and
  // load_state() assembles and factorises it again there: CHOLMOD gives the same factor for the
  // same matrix, so a restarted run reuses it exactly as the uninterrupted run does (bitwise).
  std::vector<char> save_state() const override;
  void load_state(const std::vector<char>& bytes) override;

  // Work of the whole run, for run.log and the tests.
  int factorisations() const { return linear_.factorisations(); }
  // Factorisations CHOLMOD refused (the tangent not positive definite), since configure.
  int refused_factorisations() const { return linear_.refused(); }
  // CHOLMOD's symbolic analyses (orderings) behind the factorisations, and their wall time: one per
  // CHOLMOD object in use while the tangent's pattern stays (it keeps every bond, broken or not).
  int analyses() const { return linear_.analyses(); }
  double analysis_seconds() const { return linear_.analysis_seconds(); }
  // "N factorisations in X s, M solves in Y s" (wall time of assembling and factorising the tangent,
  // and of the solves with its factor; this process's only: a restarted run counts from the restart).
  std::string linear_algebra_summary() const override;
  bool uses_cg() const { return linear_.uses_cg(); }
  bool uses_amg() const { return linear_.uses_cg() && use_amg_; }
  std::string linear_solver() const override { return uses_amg() ? "cg amg" : linear_solver_name(linear_.uses_cg()); }
  std::string keep_linear_solver(const std::string& recorded) override;
  int amg_setups() const { return amg_setups_; }  // since configure (not checkpointed)
  // Load steps cut to the first bond failure (see the head of this file), since configure (not checkpointed).
  int cuts() const { return cuts_; }
  // The length the last step() was cut to, 0 if it was not cut: after a failure, the load step the
  // body was found to fail in (mixed takes it as the first load step after a return from Verlet).
  double cut_to() const { return cut_to_; }
  // The largest overshoot of the ratio s/s0 a load step keeps without a cut, and the cut's targets
  // 1 ∓ kCutMargin/2 (the head of this file).
  static constexpr double kCutMargin = 1e-3;
  std::int64_t cg_iterations() const { return linear_.cg_iterations(); }  // since configure (not checkpointed)
  int cg_solves() const { return linear_.cg_solves(); }
  // Auto picks cg at or above this many free dofs in 3D (measured: see the .cpp).
  static constexpr std::size_t kCgFromDofs3d = pd::kCgFromDofs3d;
  // Auto picks amg (when CG is used, the tangent can be assembled and hypre is built in) from this
  // many free dofs in 3D, if its estimated memory is below kAmgMemoryShare of the memory available.
  static constexpr std::size_t kAmgFromDofs3d = 20000;
  static constexpr double kAmgMemoryShare = 0.5;
  static constexpr double kAmgRebuildGrowth = 2.0;
  const QuasiStaticSettings& settings() const { return settings_; }

  // ---- For the mixed integrator (integrators/mixed.hpp), which hands unstable steps to Verlet.
  // A step needing more than max_breaking_rounds re-solves, or not converging at dt_min, fails;
  // with fail_on_steady_breaking also one whose re-solve broke at least as many bonds as the
  // re-solve before it (the crack's growth at this load is not slowing down: unstable).
  void limit(int max_breaking_rounds, double dt_min, bool fail_on_steady_breaking = false);
  // Whether the next step's Newton starts from u_n + Δt·v_n (see step()); false after an explicit
  // step, whose velocity is the motion of the vibrating body, not the rate of the load path.
  void guess_from_velocity(bool use) { guess_from_velocity_ = use; }
  // For the next step only: a single attempt at the step asked for (no halving), at most
  // max_iterations Newton iterations and, when max_factorisations > 0, at most that many new
  // factorisations of the tangent: a tentative step, which fails fast (and cheaply: on a large 2D
  // lattice one factorisation costs some 200 explicit steps, see mixed.hpp kPauseFactorisations).
  // With a cap on factorisations it also fails at a Newton iteration that stalls (kStallRatio).
  void try_once(int max_iterations, int max_factorisations = 0) {
    try_once_iterations_ = max_iterations;
    try_once_factorisations_ = max_factorisations;
  }
  // The most columns of broken bonds taken out of a factorisation (kMaxRemovedColumns; 0: none, a
  // breaking round then always factorises anew at its re-solve). Before the steps.
  void set_max_removed_columns(int columns) { max_removed_columns_ = columns; }
  // A capped try (try_once with a cap on factorisations) also fails at the first Newton iteration that takes the
  // residual down by less than this: a stall. Measured (bench/quasi_static_cases.py's mixed case, 1
  // thread, 4 Dec 2026): the pause tries that succeed on plate_with_hole and traction at dx × 2 and
  // × 4 reduce it by ×0.06–×0.80 at every iteration (the worst, ×0.80 and ×0.72, on the definite
  // tangent of the ringing state, before a new one); the try that fails on plate_with_hole at its own
  // dx by ×0.99 at its second iteration, after which three more tangents (two refused by CHOLMOD:
  // indefinite) bought linear convergence (×0.45) and the cap: 7.3 s of a 24.4 s run, against
  // 2.1 s when it stops at the stall, with every other history.csv bit the same (a failed try
  // leaves the state as it found it). Deuflhard's residual monotonicity test (Newton Methods for
  // Nonlinear Problems, 2004, §3.3: ×(1 − λ/4), ×0.75 for a full step) would fail the dx × 2 plate's
  // successful try at its ×0.80.
  static constexpr double kStallRatio = 0.9;
  // The stall ratio of a capped try (kStallRatio; see there). Before the step that tries.
  void set_stall_ratio(double ratio) { stall_ratio_limit_ = ratio; }
  std::int64_t bonds_taken_out() const { return bonds_taken_out_; }
  // For the next step only: the pieces the cracks have separated, carried by their grips. Per local
  // node the group of prescribed motions that alone holds its piece, −1 for none or several
  // (LoadPath::held_by_one_group), and the number of groups (the same on every rank). See
  // carry_rigidly().
  void carry_pieces(std::vector<std::int32_t> group_of_node, std::int32_t groups) {
    carried_ = std::move(group_of_node);
    carried_groups_ = groups;
  }
  // Whether the last step's equilibrium was the carried state itself (no correction, no tangent).
  bool accepted_as_carried() const { return accepted_carried_; }
  // Bonds broke outside this integrator (an explicit step): the factorisation no longer fits.
  void forget_factorisation() { linear_.forget_factor(), amg_.clear(); }
  // Why the last step() threw StepFailed, in a few words for run.log.
  const std::string& failure_reason() const { return failure_reason_; }
  double dt_min() const { return dt_min_; }
  double dt_max() const { return dt_max_; }
  // The nodes the last static solve left out as hanging (hanging_nodes.hpp), over the whole model.
  std::int64_t hanging_nodes() const { return hanging_.count(); }
  std::int64_t free_fragment_nodes() const { return hanging_.free_count(); }
  std::int64_t linkage_nodes() const { return hanging_.linkage_count(); }  // links of linkages and strands among them
  // The cracks have cut the load path (mixed's separation rule): no piece carries load, so the links
  // of strands (collinear bonds on both sides) are mechanisms too (hanging_nodes.hpp). Not
  // checkpointed: mixed sets it from its own state before every step.
  void load_path_cut(bool cut) { strands_ = cut; }

 private:
  // Newton at load t1 from state.u (prescribed components already at t1). True when converged;
  // iterations, the last ω_K and the evaluations are added to the report.
  bool solve_equilibrium(State& trial, double t1, const Vec3Array& u_start, int& iterations, double& omega);
  // Newton itself, over the free dofs but those of hanging nodes (solve_equilibrium masks their bonds).
  bool newton(State& trial, double t1, const Vec3Array& u_start, int& iterations, double& omega);
  // Finds the hanging nodes now (after bonds have broken, for a bond-based law): skip_dof_ is then
  // 1 at their dofs, else empty. Collective.
  void find_hanging();
  HangingNodes hanging_;
  bool strands_ = false;  // see load_path_cut()
  bool bond_based_ = false;               // the law has bond_tangent_row (PMB): see hanging_nodes.hpp
  std::vector<std::uint8_t> skip_dof_;    // per free dof: a hanging or free node's (empty: none)
  double load_scale(const State& s, double t) const;
  // The force the residual test measures against: the load now, or the largest load an accepted
  // load step has carried when that is larger (see solve_equilibrium).
  double force_scale(const State& s, double t) const { return std::max(load_scale(s, t), carried_load_); }
  double carried_load_ = 0.0;  // the largest load_scale of an accepted equilibrium (checkpointed)
  double residual_norm(const State& s) const;  // ‖V f‖ over free dofs
  double shift_diagonal(SparseMatrix& K) const;  // returns the shift added
  static constexpr double kDiagonalShift = 1e-8;
  bool broken_since_start_ = false;  // a bond has broken in this run (then K is shifted, see .cpp)
  bool guess_from_velocity_ = true;
  bool started_cold_ = false;  // the last accepted step started without the predictor (checkpointed)
  // The next step's pieces carried by their grips (carry_pieces; empty: none); kept through the step
  // in progress, which starts from them (and every halving of it), and cleared when it ends.
  std::vector<std::int32_t> carried_;
  std::int32_t carried_groups_ = 0;
  bool accepted_carried_ = false;  // the last step's equilibrium was the carried state itself
  void carry_rigidly(State& s) const;
  int try_once_iterations_ = 0;  // the caps of try_once (0: none)
  int try_once_factorisations_ = 0;
  bool fail_on_steady_breaking_ = false;  // see limit()
  bool definite_first_ = false;  // the step's first factorisation is the definite variant (see newton())
  int iteration_cap_ = 0;        // the step in progress's (0: none)
  int factorisation_cap_ = 0;    // the step in progress's new factorisations at most (0: no cap)
  int factorisations_at_step_ = 0;  // factorisations_ when the step in progress began
  bool factorisation_cap_hit_ = false;  // the step in progress failed on factorisation_cap_
  double stall_ratio_limit_ = kStallRatio;
  double stall_ratio_ = 0.0;  // the ratio of the stall that failed the try in progress, at
  int stalled_at_ = 0;        // this Newton iteration (0: none)

  ForceOperator& op_;
  QuasiStaticSettings settings_;
  double end_ = 0.0, dt_min_ = 0.0, dt_max_ = 0.0;
  std::optional<double> dt_initial_;
  FreeDofs dofs_;
  DofSums sums_;  // the norms and CG's dot products over dofs_ (every rank's on a decomposed run)
  mutable std::vector<double> terms_, motion_terms_;  // per-dof terms of those sums
  // The linear solver (direct or CG, and why), the factorisation in use with where it was assembled
  // (for save_state: u, t, and whether the definite variant and the diagonal shift were used), and
  // CG's block Jacobi (linear_solve.hpp). Its factor's spare object serves the cut (remember_solver).
  LinearSolve linear_;
  bool factorize_at(const State& s, double t1, bool definite, bool shifted);
  // The bonds broken since the factorisation in use are taken out of it (bonds_out_of_factor.hpp,
  // LinearSolve::bonds_out): every solve with the factor is corrected by them. For one load step only:
  // a step that ends with bonds taken out drops its factor, so that what a checkpoint holds (the
  // factor's u with the bonds of the checkpoint) is what a restart factorises again, bit for bit.
  std::int64_t bonds_taken_out_ = 0;  // bonds so, since configure (run.log's summary)
  double bonds_out_seconds_ = 0.0;
  // At most this many columns (2 per bond in 2D, 3 in 3D) are taken out; a round that would pass it
  // factorises anew, as before. A column costs one right-hand side of a solve with many, and then
  // O(n) per solve. Measured on plate_with_hole at its own dx (155 120 dofs, bench/quasi_static_cases.py's
  // mixed case, 1 thread): 10 bonds, 20 columns, in 0.40 s against 1.9 s for the assembly and numeric
  // factorisation they replaced; so 64 columns stay below a factorisation there, and the cap is
  // a count, not a timing, so that the results do not depend on the machine.
  static constexpr int kMaxRemovedColumns = 64;
  // And W's memory at most this (256 MB: 64 columns up to 5·10⁵ dofs, fewer above).
  static constexpr std::size_t kMaxRemovedBytes = std::size_t{256} << 20;
  int max_removed_columns_ = kMaxRemovedColumns;
  // After a breaking round (flags before it): the bonds it broke taken out of the factor, or the
  // factor dropped (have_factor_ false) when that cannot be done.
  void take_out_broken_bonds(const std::vector<std::uint8_t>& broken_before);
  std::vector<std::uint8_t> broken_before_round_;  // scratch: the flags before a breaking round
  std::string failure_reason_;
  // The matrix-free path: the correction by PCG at (s, t1) for the forcing term eta; false when CG
  // made no progress.
  std::string checkpoint_solver_;  // the solver of the checkpoint a restart reads (keep_linear_solver), or ""
  static constexpr double kEtaMax = 0.1;
  bool solve_krylov(const State& s, double t1, double eta, double floor);
  double build_block_jacobi(const State& s, double t1);
  void choose_linear_solver(const Case& c);
  std::string cg_failure_;
  // Algebraic multigrid (see the head of this file): the choice and why, the hierarchy, where it
  // was set up, and the first solve's iterations per tenfold reduction after it (0: none yet).
  void choose_preconditioner(const Case& c, std::size_t free, bool assembled);
  void set_up_amg(const State& s, double t1);
  bool use_amg_ = false;
  std::string preconditioner_reason_;
  AmgPreconditioner amg_;
  Vec3Array amg_u_;
  double amg_t_ = 0.0, amg_rate_ = 0.0;
  double amg_shift_ = 0.0;  // the diagonal shift of the K the hierarchy was set up on
  int amg_setups_ = 0;
  double amg_seconds_ = 0.0;
  State trial_;
  std::vector<double> rhs_, correction_;
  // The cut (see the head of this file): what the linear solver held at the start of the step, to
  // be put back after a trial that is cut. The factor is kept by linear_ (remember_factor: the
  // step's first factorisation goes into its spare object); an AMG hierarchy is set up again where
  // it was (u copied by set_up_amg). Active while linear_.remembering().
  struct SolverAtStart {
    bool amg_ready = false;
    double amg_t = 0.0, amg_rate = 0.0;
    int amg_setups = 0;
    bool amg_u_saved = false;
    Vec3Array amg_u;
  };
  SolverAtStart at_start_;
  void remember_solver();
  // After the first equilibrium `end` of a load step of length h from `start`: the h of the cut
  // (quasi_static.hpp), or 0 for none. start_ratio: the start's StretchRatio, computed once. Collective.
  double cut_step(State& start, State& end, double h, std::optional<StretchRatio>& start_ratio);
  void restore_solver();
  int cuts_ = 0;
  double cut_to_ = 0.0;
};

}  // namespace pd
