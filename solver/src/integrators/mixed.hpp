// The mixed scheme (time.integrator: mixed): quasi-static load steps (integrators/quasi_static.hpp)
// while the body is in equilibrium, velocity Verlet (integrators/verlet.hpp) while it is not, and
// the switch made by the run itself, in both directions (issue 13; Peridigm switches one way only,
// PeriLab by hand):
//
// - quasi-static → explicit, when a load step fails: bonds keep breaking through more than
//   mixed.unstable_rounds re-solves at one load, or a re-solve breaks no fewer bonds than the one
//   before it (the crack grows unstably: the released energy becomes motion, which equilibrium
//   cannot describe; QuasiStatic::limit), or Newton does not converge down to the smallest load
//   step. The bonds that broke in the failed attempt are restored and Verlet goes on
//   from the last equilibrium, with its velocities (the loading rate) and the same time: time is
//   physical here, so the boundary-condition tables must be loading rates.
// - explicit → quasi-static, when the crack has arrested: bonds have broken in the explicit phase
//   (a phase in which none breaks has not yet reached the crack: it stays explicit until it
//   does, so that a failed load step is not tried again at once), then no bond has broken and the kinetic energy
//   has stayed below mixed.kinetic_fraction × the strain energy for mixed.arrest_steps steps in a
//   row. The next load step solves equilibrium from the current state; the kinetic energy left is
//   given up (added to the damping work, so that the energy balance still closes, and said in
//   run.log). Also when the cracks have cut every load path between two prescribed motions that the
//   uncut body linked (the specimen has separated, integrators/load_path.hpp), cut_steps() steps
//   after the cut (δ/c, as the pause rule below; mixed.arrest_steps if shorter or without a Young's
//   modulus), whatever the kinetic energy and the bonds that still break in the ringing: the halves
//   then hang each from its grip and ring undamped for ever (measured on cases/traction: the kinetic
//   energy stays above the strain energy), which the quasi-static answer does without; the load
//   steps finish the loading. Why δ/c and no longer arrest_steps (4 Dec 2026): what breaks after
//   the cut is the ringing's overshoot at the crack faces, which the load steps do without; on
//   plate_with_hole at its own dx the 200 steps after the cut were 1.8 s of a 22 s run, and
//   returning 4 steps after it moved each half's crack centroid by 1 µm (bench/quasi_static_cases.py's
//   case, 1 thread; docs/notes/2026-12-04-mixed-full-resolution.md,
//   "After the cut: δ/c, not 200 steps").
//   From that return on, every load step starts with each piece carried by the one grip that
//   holds it alone (LoadPath::held_by_one_group, QuasiStatic::carry_rigidly): unstrained, which is
//   its equilibrium when nothing else loads it, so Newton accepts it without a tangent (measured on
//   plate_with_hole at its own dx, bench/quasi_static_cases.py's case, 1 thread: the return 8.5 s →
//   0.06 s, the run 35.0 → 25.6 s; its strain energy after the return 5.5·10⁻³ J → 5.0·10⁻⁴ J, what
//   the free fragments keep: Newton from the ringing state had stopped in a self-stressed state).
//   And, first of all, when the crack has stopped running: bonds have broken in the explicit phase
//   and then none for pause_steps() explicit steps in a row, the time a stress wave needs to cross a
//   horizon (δ/c, c = √(E/ρ) of the slowest block): a running crack tip breaks bonds at least that
//   often, since what loads the bonds ahead of it travels at most at the wave speed. Whether the
//   crack has stopped for good is then asked of the equilibrium itself: one tentative load step
//   (kTentativeIterations Newton iterations on at most kPauseFactorisations new tangents, no
//   iteration of which may stall, QuasiStatic::kStallRatio; no halving, and no more than
//   unstable_rounds breaking rounds) from the current state at the current load. If it converges
//   the crack is stable under the load and the load steps go on (the first kProbationSteps tentative); if not, the bonds it
//   broke heal and Verlet goes on until the next pause. After kPauseTries failed tries (counted
//   since the last load step past a probation) the rule rests until such a step. Why: the explicit
//   phase is undamped, and after the crack has run its released energy rings in the pieces for
//   ever; a slowly loaded test (the benchmark's reference: Verlet with ζ = 0.1 of light damping)
//   loses that ringing to damping, and the pieces do not crack again. Measured on cases/traction at
//   dx × 2 (docs/notes/2026-12-03-mixed-hanging-nodes-pause-rule.md,
//   "The pause rule"): without it the middle piece between the two
//   cracks, still linked to the halves by ligaments at the specimen's edges, cracks a third time 52
//   steps after the cracks ran and 48 steps before the ligaments break, so that no rule that waits
//   for the cut can return before it; undamped Verlet at 0.0625 m/s does the same, damped Verlet
//   does not.
//
// mixed.start: implicit puts generalized-α implicit dynamics (integrators/implicit.hpp) in the
// place of the quasi-static load steps, for loads where inertia matters but is slow next to the
// explicit limit (a structure shaken or hit gently until it cracks):
// - implicit → explicit, when an implicit step fails down to implicit.dt_min (Newton or the local
//   error estimate: a motion the implicit step cannot follow), or when bonds have broken
//   in more than mixed.unstable_rounds implicit steps in a row (a crack that keeps running: its tip
//   moves at a wave speed that an implicit step set by the smooth motion does not resolve). The
//   implicit step that broke bonds was accepted (a dynamic state, as Verlet's), so Verlet goes on
//   from it; a failed step left the state of t_n, from which Verlet goes on.
// - explicit → implicit, on the same arrest watch as above; the motion is dynamic in both schemes, so
//   the kinetic energy is kept (nothing given up), and the implicit scheme takes its acceleration
//   from the equation of motion at the current state (Implicit::resume).
// history.csv's mode column is 2 for an implicit step.
//
// The explicit step is time.dt's (stable × safety_factor, exact × safety_factor, or a number), the
// quasi-static steps those of the quasi_static section; quasi_static.dt_min defaults to 10 explicit
// steps (a load step that must be cut below that is cheaper done explicitly). history.csv's `mode`
// column is the kind of each step: 1 quasi-static, 0 explicit.
#pragma once
#include <string>
#include <vector>

#include "integrators/implicit.hpp"
#include "integrators/integrator.hpp"
#include "integrators/load_path.hpp"
#include "integrators/quasi_static.hpp"
#include "integrators/verlet.hpp"

namespace pd {

class Mixed : public Integrator {
 public:
  enum Mode : int { kExplicit = 0, kQuasiStatic = 1, kImplicit = 2 };

  explicit Mixed(ForceOperator& op) : op_(op), static_(op), implicit_(op), explicit_(op) {}
  std::string name() const override { return "mixed"; }
  void configure(const Case& c, double dt_exact = 0.0) override;
  void initialize(State& state, double t) override;
  void step(State& state, double& t, double& dt) override;

  // The base state, the mode and its watch, then the quasi-static integrator's own state.
  std::vector<char> save_state() const override;
  std::vector<Vec3Array*> checkpointed_node_arrays() override {
    return home_ == kImplicit ? implicit_.checkpointed_node_arrays() : static_.checkpointed_node_arrays();
  }
  void load_state(const std::vector<char>& bytes) override;

  std::vector<std::string> describe(double dt_exact) const override;
  bool controls_step() const override { return true; }
  std::optional<double> initial_dt() const override {
    return home_ == kImplicit ? implicit_.initial_dt() : static_.initial_dt();
  }
  std::optional<int> step_mode() const override { return step_mode_; }
  std::vector<std::string> take_log_lines() override { return std::move(log_lines_); }
  std::string linear_algebra_summary() const override {
    return home_ == kImplicit ? implicit_.linear_algebra_summary() : static_.linear_algebra_summary();
  }
  // The start scheme's (the explicit steps solve nothing).
  std::string linear_solver() const override {
    return home_ == kImplicit ? implicit_.linear_solver() : static_.linear_solver();
  }
  std::string keep_linear_solver(const std::string& recorded) override {
    return home_ == kImplicit ? implicit_.keep_linear_solver(recorded) : static_.keep_linear_solver(recorded);
  }

  Mode mode() const { return mode_; }  // the mode of the next step
  double explicit_dt() const { return dt_explicit_; }
  int switches() const { return switches_; }
  // Load steps after a return on the separation rule still taken tentatively (kProbationSteps).
  int probation_steps() const { return probation_steps_; }
  // The pause rule: explicit steps without breaking that end a crack's run (0: the rule is off),
  // and the tentative returns on it that have failed so far.
  std::int64_t pause_steps() const { return pause_steps_; }
  int pause_failures() const { return pause_failures_; }
  // Failed tries before the pause rule is given up (kPauseTries; 0 switches the rule off: the tests
  // of the other rules). Before configure().
  void set_pause_tries(int tries) { pause_tries_ = tries; }
  // A try on the pause rule is a guess that the crack has stopped. Its Newton iterations
  // refactorise whenever the residual falls less than 4× (quasi_static.cpp), and each breaking
  // round on a new tangent: a try that needs a fourth is still far from equilibrium and fails there,
  // not after kTentativeIterations (the tries on test_mixed.cpp's bar need at most 3).
  // Measured (bench/quasi_static_cases.py's mixed case, 1 thread): the tries that succeeded on
  // plate_with_hole and traction at dx × 2 used 3 factorisations (with a cap of 1 or 2 both
  // failed, and the plate's run took 2 760 steps instead of 217); the one that failed at the
  // plate's own dx used 13 in 15 iterations, 23.8 s of the run's 50.3 s (a factorisation 1.86 s
  // there, an explicit step 10 ms), its residual still 6.8·10⁻⁴ against 4.9·10⁻⁷ wanted. A cap of 3
  // instead of 4 (4 Dec 2026): the same history.csv bits on all four, the plate's own dx 25.3 →
  // 22.5 s wall. Starting the try from the last equilibrium instead of the ringing state (probed
  // the same day) changed nothing: the same 3 tangents at dx × 2, a failure at the plate's own dx.
  static constexpr int kPauseFactorisations = 3;
  // New factorisations a try may make before it fails (kPauseFactorisations; 0: no cap, only
  // kTentativeIterations). Before the step that tries.
  void set_pause_factorisations(int factorisations) { pause_factorisations_ = factorisations; }
  // The load steps' knobs of quasi_static.hpp, for tests: broken bonds taken out of the factorisation
  // (0 columns: none) and a try's stall ratio.
  void set_max_removed_columns(int columns) { static_.set_max_removed_columns(columns); }
  void set_stall_ratio(double ratio) { static_.set_stall_ratio(ratio); }
  // Load steps cut to the first bond failure (quasi_static.hpp), since configure.
  int cuts_in_use() const { return home_ == kImplicit ? 0 : static_.cuts(); }
  int factorisations_in_use() const { return home_ == kImplicit ? implicit_.factorisations() : static_.factorisations(); }
  int refused_factorisations() const { return home_ == kImplicit ? 0 : static_.refused_factorisations(); }
  int analyses_in_use() const { return home_ == kImplicit ? 0 : static_.analyses(); }  // CHOLMOD's symbolic analyses
  // The early verdict of unstable crack growth (a re-solve breaking no fewer bonds than the one
  // before it, QuasiStatic::limit); on by default, off only to compare (the tests). Before configure().
  void set_steady_breaking_rule(bool on) { steady_breaking_rule_ = on; }
  Mode home() const { return home_; }  // mixed.start: the scheme away from a running crack

 private:
  void to_explicit(State& state, double t, const std::string& reason);
  void to_quasi_static(State& state, double t, double kinetic, double strain);
  void to_implicit(const State& state, double t, double kinetic, double strain);
  // One implicit step, and the switch to explicit when it fails or bonds keep breaking; false when
  // the step fell to Verlet (then evaluations and rejected say what the failed attempt cost).
  bool implicit_step(State& state, double& t, double& dt, int& evaluations, int& rejected);

  ForceOperator& op_;
  QuasiStatic static_;
  Implicit implicit_;
  VelocityVerlet explicit_;
  MixedSettings settings_;
  double dt_explicit_ = 0.0;
  Mode home_ = kQuasiStatic;  // mixed.start
  Mode mode_ = kQuasiStatic;
  int step_mode_ = kQuasiStatic;
  // Explicit steps in a row with no breaking and low kinetic energy; once the load path is cut,
  // explicit steps since the cut (or since a later explicit phase began).
  std::int64_t calm_steps_ = 0;
  bool cracked_ = false;         // a bond has broken in this explicit phase
  double static_dt_ = 0.0;       // the load step proposed when the quasi-static mode was left [s]
  int switches_ = 0;
  std::int64_t breaking_steps_ = 0;  // implicit steps in a row in which bonds broke
  // The grips' load path (load_path.hpp) and whether the cracks have cut it: cut_steps() steps
  // after they have, the quasi-static home returns whatever the kinetic energy (the separated
  // halves ring undamped; that motion is not the quasi-static answer). The first load step then is
  // tentative (kTentativeIterations); if it fails, the rule is given up for the run.
  std::optional<LoadPath> load_path_;
  bool separated_ = false;
  bool separation_given_up_ = false;  // a tentative load step after the separation failed
  // Load steps after a return on the separation rule still to be taken tentatively: the first ones
  // meet what the ringing left (the second step of traction's mixed.yaml at dx = 0.25 mm found no
  // equilibrium down to dt_min, halving 6 times, then the run came back and did it again: 122
  // factorisations where one failed return costs 1); a failure among them gives the rule up.
  int probation_steps_ = 0;
  // The pause rule (see above): ceil(δ / (c·Δt_explicit)), 0 when some block gives no Young's
  // modulus or the home is implicit; the steps in a row without breaking so far; a tentative return
  // on it decided by the last explicit step (taken by the next step); whether the probation under
  // way is this rule's; its failed tries.
  std::int64_t pause_steps_ = 0;
  std::int64_t quiet_steps_ = 0;
  bool pause_return_ = false;
  bool pause_probation_ = false;
  int pause_failures_ = 0;
  // One: a failed try costs up to kTentativeIterations refactorisations (measured on
  // plate_with_hole at dx = 0.25 mm: three failed tries, 32 factorisations and 412 s wall against
  // 214 s without the rule); every try that succeeded in the measurements was the first.
  static constexpr int kPauseTries = 1;
  int pause_tries_ = kPauseTries;
  bool steady_breaking_rule_ = true;
  // Sets the above from the case (configure).
  void set_pause_steps(const Case& c);
  // After an explicit step: whether the crack has paused long enough to try a load step.
  bool crack_paused() const;
  // Explicit steps from the cut of the load path (or from the start of a later explicit phase) to
  // the return (see the header), and whether that is δ/c (else mixed.arrest_steps).
  std::int64_t cut_steps() const;
  bool cut_is_crossing() const;
  // δ/c in explicit steps (0: some block gives no Young's modulus, or the home is implicit).
  std::int64_t crossing_steps_ = 0;
  static constexpr std::uint64_t kPauseTag = 0x7061757365727531ULL;  // "pauseru1": the bytes of the pause rule follow
  // 15, not 10: on the full-resolution plate_with_hole, once load steps are cut to the first bond
  // failure, the return on the separation converged in 12 iterations (ω 4.4·10⁻⁷ at the 10th, the
  // residual not yet below its tolerance); with 10 the rule was given up and the run stayed explicit
  // to its end: 2 693 steps against 774 (bench/result_hashes.py's input, 1 thread, 3 Dec 2026).
  static constexpr int kTentativeIterations = 15;
  int pause_factorisations_ = kPauseFactorisations;
  static constexpr int kProbationSteps = 3;
  std::vector<std::uint8_t> broken_before_;  // the bonds' state before a quasi-static attempt
  std::vector<std::vector<double>> history_before_;  // and the law's declared history with `rollback`
  std::vector<std::string> log_lines_;
};

}  // namespace pd
