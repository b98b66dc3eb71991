// The mixed explicit–implicit adaptive step of thesis §2.2 (Zohdi's staggered fixed-point
// iteration with step-size control, eqs. 2.6–2.8; docs/theory.md T12).
//
// The step n → n+1 is the θ-method with θ = φ on (u, v), solved by fixed-point iteration K = 1, 2, …:
//   v^{n+1,K} = v^n + Δt/ρ·[φ f(u^{n+1,K−1}) + (1−φ) f(u^n)]        (damping: see below)
//   u^{n+1,K} = u^n + Δt·[(1−φ) v^n + φ v^{n+1,K}]
// φ = 1 gives u^{n+1} = u^n + Δt v^n + Δt²/ρ·f(u^{n+1}), the thesis's update (§2.2): backward Euler
// on (u, v), first order and numerically dissipative. φ = ½ is the trapezoidal rule (Newmark
// β = ¼, γ = ½): second order, and it conserves the energy of a linear system. (Weighting only the
// force by φ while keeping the thesis's Δt² in u would be first order in u for every φ: its Taylor
// coefficient of the acceleration must be ½, and it is 1.) In Newmark terms β = φ², γ = φ, so every
// φ in [½, 1] is unconditionally stable once the iteration has converged. The iteration contracts
// only while φ²·Δt²·ω_max² < 1 (docs/theory.md T12): Δt < Δt_exact/(2φ), where Δt_exact = 2/ω_max is
// the Verlet limit; the controller finds this by itself.
//
// Error and control (eqs. 2.6–2.8): ω_K = Σ_i‖u_i^{K} − u_i^{K−1}‖ / Σ_i‖u_i^{K} − u_i^n‖, Z_K = ω_K/TOL,
// Φ_K = (TOL/ω_0)^{1/(p K_d)} / (ω_K/ω_0)^{1/(p K)}. Z_K ≤ 1 at any K ≤ K_d accepts the step and
// proposes Δt ← min(Φ_K Δt, Δt_max); Z_K > 1 at K = K_d redoes the step from t with Δt ← Φ_K Δt.
//
// ω_0 and the first iterate. Started from u^{n+1,0} = u^n (the thesis's guess), ω_1 is exactly 1
// for every Δt and carries no information. Here the iteration starts from the explicit predictor
// u^{n+1,0} = u^n + Δt v^n + Δt² f(u^n)/ρ, which costs no force evaluation (f(u^n) is known), and
// ω_0 = 1 is the normalised size of that zeroth increment measured against itself. Then
// ω_K ≈ (S Δt^p)^K·ω_0 holds from K = 1 on (each iteration multiplies the correction by about
// φ²Δt²ω²), which is the model eq. 2.8 is derived from, and a smooth motion can be accepted after
// a single iteration.
//
// Additions to the thesis rules, each for a case it does not cover:
// - divergence: when the correction Σ‖u^K − u^{K−1}‖ grows twice in a row (K ≥ 3), the iteration
//   cannot meet TOL at K_d; the attempt is rejected at once and Δt shrinks by the observed growth
//   ratio r: Φ = min(½, (TOL^{1/K_d}/r)^{1/p}). A non-finite iterate is rejected with Φ = 0.01.
//   Without this a start far above the limit costs K_d evaluations per rejection and Φ_{K_d} → 0.89.
// - a rejection shrinks Δt by at least 0.9, so repeated rejections always make progress.
// - a step that the caller shortened (to land on an output time) and that was accepted at once
//   does not lower the proposal below the one it was shortened from unless Φ_K < 1.
// - at Δt_min a failed attempt throws StepFailed; the state stays at t (the last accepted one).
// Bonds break on the accepted state only, then f(u^{n+1}) is evaluated once more for the next step:
// a step costs K + 1 force evaluations, plus K per rejected attempt.
//
// Damping −ρ α v enters the velocity with the same weight φ, solved per node in closed form:
//   (1 + φαΔt) v^{n+1} = (1 − (1−φ)αΔt) v^n + Δt/ρ·[φ f^{n+1} + (1−φ) f^n] (Crank–Nicolson at φ = ½).
#pragma once
#include "integrators/integrator.hpp"

namespace pd {

class AdaptiveStep : public Integrator {
 public:
  explicit AdaptiveStep(ForceOperator& op) : op_(op) {}
  std::string name() const override { return "adaptive"; }
  void configure(const Case& c, double dt_exact = 0.0) override;
  void initialize(State& state, double t) override;
  // dt in: the step to try (the caller's proposal, possibly shortened to land on an output time);
  // dt out: the step taken. last_step().next_dt is the controller's proposal for the next step.
  void step(State& state, double& t, double& dt) override;

  // The base state plus proposal_ (what a shortened step is measured against).
  std::vector<char> save_state() const override;
  void load_state(const std::vector<char>& bytes) override;

  const AdaptiveSettings& settings() const { return settings_; }
  double dt_min() const { return dt_min_; }
  double dt_max() const { return dt_max_; }
  // Wall time of the eigenvalue estimate behind the default dt_max [s]; 0 when dt_max was given.
  double limit_seconds() const { return limit_seconds_; }

  // ---- What the run asks (integrator.hpp); the run.log line in adaptive.cpp's last block
  std::vector<std::string> describe(double dt_exact) const override;
  bool controls_step() const override { return true; }
  std::optional<double> initial_dt() const override { return settings_.dt_initial; }

 private:
  // One iterate: v_new, u_new from (u^n, v^n, f^n) in state and the implicit force f_imp at t1.
  void update(const State& state, const Vec3Array& f_imp, double t, double t1, double dt);

  ForceOperator& op_;
  AdaptiveSettings settings_;
  double dt_min_ = 0.0, dt_max_ = 0.0;
  double limit_seconds_ = 0.0;
  double proposal_ = 0.0;  // the last proposal handed out, to recognise a shortened step
  State trial_;            // u^{n+1,K−1} and f(u^{n+1,K−1}) (scratch: f, w, contact of trial states)
  Vec3Array u_new_, v_new_;
  std::vector<double> correction_, motion_;  // per-node ‖u^K − u^{K−1}‖ and ‖u^K − u^n‖
};

}  // namespace pd
