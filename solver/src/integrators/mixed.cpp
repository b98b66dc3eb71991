// One step of the mixed scheme: a quasi-static load step (or an implicit step, mixed.start:
// implicit) or a Verlet step, and the switches between them (integrators/mixed.hpp).
#include "integrators/mixed.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>

#include "core/error.hpp"
#include "core/time_step_rule.hpp"
#include "integrators/messages.hpp"
#include "parallel/decomposed.hpp"

namespace pd {

void Mixed::configure(const Case& c, double dt_exact) {
  settings_ = c.mixed;
  // The explicit phase's step: time.dt's rule, as the run's set-up applies it (run/prepare.cpp).
  dt_explicit_ = explicit_time_step(c, op_.stable_time_step(),
                                    [this, dt_exact] { return dt_exact > 0.0 ? dt_exact : op_.exact_time_step(); });
  if (!(dt_explicit_ > 0.0) || !std::isfinite(dt_explicit_))
    throw Error(c.file.string() + ": time.dt: the mixed scheme's explicit step is not a positive number (" +
                message_number(dt_explicit_) + " s): the body needs bonds");
  home_ = settings_.start == "implicit" ? kImplicit : kQuasiStatic;
  if (home_ == kImplicit) {
    // implicit.dt_min keeps its own default (1e-6 × eq. 2.5): a load that starts with a jump in
    // velocity (a displacement ramp) has an O(1) local error at any step until the step is tiny,
    // and the steps grow again 2× per step once past it. Capped at the explicit step it would
    // fail at t = 0.
    implicit_.configure(c, dt_exact);
    static_dt_ = implicit_.initial_dt().value_or(implicit_.dt_max());
    return;
  }
  static_.configure(c, dt_exact);
  static_.limit(settings_.unstable_rounds, c.quasi_static.dt_min.value_or(10.0 * dt_explicit_), steady_breaking_rule_);
  static_dt_ = static_.initial_dt().value_or(static_.dt_max());
  set_pause_steps(c);
}

// δ / c in explicit steps, rounded up, c = √(E/ρ) the bar wave speed of the slowest block (below the
// P-wave speed of a 2D or 3D body: the longer wait). Measured on cases/traction (PMMA, c = 1640
// m/s): δ/c = 0.92 µs, 4 steps of 0.274 µs at dx × 2 and 4 of 0.137 µs at dx = 0.25 mm. 0 without a
// Young's modulus in every block. From the case, not the model: a decomposed run's piece carries no
// block materials. The pause rule waits that long (off with an implicit home or no tries), and so
// does the return on the separation (cut_steps()).
void Mixed::set_pause_steps(const Case& c) {
  pause_steps_ = crossing_steps_ = 0;
  double slowest = HUGE_VAL;
  for (const BlockMaterial& block : c.blocks) {
    const std::optional<double> youngs = block.parameter("youngs_modulus");
    if (!youngs || !(*youngs > 0.0) || !(block.density > 0.0)) return;
    slowest = std::min(slowest, std::sqrt(*youngs / block.density));
  }
  if (!std::isfinite(slowest) || !(c.horizon > 0.0)) return;
  // (less a round-off's worth, so that an exact ratio is not rounded up a step by its last bit)
  crossing_steps_ = std::max<std::int64_t>(1, static_cast<std::int64_t>(std::ceil(c.horizon / (slowest * dt_explicit_) - 1e-9)));
  if (home_ == kQuasiStatic && pause_tries_ > 0) pause_steps_ = crossing_steps_;
}

bool Mixed::cut_is_crossing() const { return crossing_steps_ > 0 && crossing_steps_ <= settings_.arrest_steps; }

std::int64_t Mixed::cut_steps() const { return cut_is_crossing() ? crossing_steps_ : settings_.arrest_steps; }

bool Mixed::crack_paused() const {
  return pause_steps_ > 0 && cracked_ && quiet_steps_ >= pause_steps_ && pause_failures_ < pause_tries_;
}

void Mixed::initialize(State& state, double t) {
  // The prescribed motion, the force and powers at t (and quasi_static's free-body check).
  if (home_ == kImplicit) implicit_.initialize(state, t);
  else static_.initialize(state, t);
  report_ = StepReport{};
  mode_ = home_;
  step_mode_ = home_;
  calm_steps_ = 0;
  breaking_steps_ = 0;
  quiet_steps_ = 0;
  pause_return_ = pause_probation_ = false;
  pause_failures_ = 0;
  log_lines_.clear();
  // From the bond list with every bond, broken or not: the same before and after a restart. On a
  // decomposed run from the piece's rows, the ranks' components joined (load_path.hpp). Collective.
  if (home_ == kQuasiStatic) load_path_.emplace(op_.model(), op_.decomposed());
  separated_ = false;
}

void Mixed::to_explicit(State&, double t, const std::string& reason) {
  mode_ = kExplicit;
  calm_steps_ = 0;
  cracked_ = false;
  quiet_steps_ = 0;
  ++switches_;
  log_lines_.push_back("mixed: t = " + message_number(t) + " s: " + (home_ == kImplicit ? "implicit" : "quasi-static") +
                       " → explicit (" + reason + "); Verlet at dt " + message_number(dt_explicit_) + " s");
}

void Mixed::to_quasi_static(State&, double t, double kinetic, double strain) {
  mode_ = kQuasiStatic;
  ++switches_;
  if (pause_return_ || (separated_ && !separation_given_up_)) probation_steps_ = kProbationSteps;
  pause_probation_ = pause_return_;
  static_.forget_factorisation();  // bonds broke in the explicit steps
  // The next load step finds equilibrium and leaves only the mean velocity of the load step: the
  // kinetic energy now, and the strain energy of the ringing beyond the equilibrium's, are given
  // up, booked as damping work (run/loop.cpp: every quasi-static step's ledger) when that step is
  // accepted (Mixed::step: a tentative step that fails leaves the motion to Verlet).
  const std::string why =
      pause_return_ ? "the crack stopped running: no bond broke for " + std::to_string(quiet_steps_) +
                          " steps, a horizon's crossing time of a stress wave; a tentative load step asks whether it is stable"
      : separated_ && !separation_given_up_ ? "the cracks cut the load path between the prescribed motions; back after " +
                       std::to_string(calm_steps_) + " explicit steps" + (cut_is_crossing() ? ", δ/c" : "")
                 : "the crack arrested: no bond broke and the kinetic energy stayed below " +
                       message_number(settings_.kinetic_fraction) + " × the strain energy for " +
                       std::to_string(settings_.arrest_steps) + " steps";
  log_lines_.push_back("mixed: t = " + message_number(t) + " s: explicit → quasi-static (" + why + "); kinetic energy " +
                       message_number(kinetic) + " J (" + message_number(strain > 0.0 ? kinetic / strain : 0.0) +
                       " of the strain energy) and the strain energy above the equilibrium's given up, booked as damping work if the "
                       "load step finds equilibrium");
}

void Mixed::to_implicit(const State& state, double t, double kinetic, double strain) {
  mode_ = kImplicit;
  ++switches_;
  breaking_steps_ = 0;
  implicit_.resume(state);  // a_n from the equation of motion here; bonds broke in the explicit steps
  log_lines_.push_back("mixed: t = " + message_number(t) + " s: explicit → implicit (the crack arrested: no bond broke and " +
                       "the kinetic energy stayed below " + message_number(settings_.kinetic_fraction) +
                       " × the strain energy for " + std::to_string(settings_.arrest_steps) + " steps); kinetic energy " +
                       message_number(kinetic) + " J (" + message_number(strain > 0.0 ? kinetic / strain : 0.0) +
                       " of the strain energy) kept");
}

bool Mixed::implicit_step(State& state, double& t, double& dt, int& evaluations, int& rejected) {
  static_dt_ = dt;
  try {
    implicit_.step(state, t, dt);
  } catch (const StepFailed&) {
    // The state is still that of t (Implicit::step works on a copy and breaks bonds only in an
    // accepted step), with its force: Verlet goes on from it.
    evaluations = implicit_.last_step().force_evaluations;
    rejected = implicit_.last_step().rejected + 1;
    to_explicit(state, t, "no implicit step met Newton's and the error's tolerances down to implicit.dt_min = " +
                              message_number(implicit_.dt_min()) + " s");
    return false;
  }
  report_ = implicit_.last_step();
  step_mode_ = kImplicit;
  static_dt_ = report_.next_dt;
  breaking_steps_ = report_.broken_now > 0 ? breaking_steps_ + 1 : 0;
  if (breaking_steps_ > settings_.unstable_rounds) {
    // The accepted step stands (a dynamic state); the next steps are Verlet's.
    to_explicit(state, t, "bonds broke in " + std::to_string(breaking_steps_) + " implicit steps in a row: a running crack");
    report_.next_dt = dt_explicit_;
  }
  return true;
}

void Mixed::step(State& state, double& t, double& dt) {
  int evaluations = 0, rejected = 0;
  if (mode_ == kImplicit && implicit_step(state, t, dt, evaluations, rejected)) return;
  if (mode_ == kQuasiStatic) {
    broken_before_ = op_.model().bonds.broken;
    history_before_ = op_.model().state_arrays.save_rollback();  // the law's declared history (core/state_arrays.hpp)
    static_dt_ = dt;
    static_.guess_from_velocity(step_mode_ == kQuasiStatic);  // not from an explicit step's velocity
    // The first load step after a return on the separation rule is tentative: the pieces left
    // ringing may hold mechanisms that keep Newton from converging (measured on plate_with_hole at
    // dx = 0.5 mm before hanging nodes were left out of the solve, integrators/hanging_nodes.hpp:
    // 6 attempts of 30 iterations, then explicit again); it then fails after kTentativeIterations,
    // and the rule is given up.
    // So are the kProbationSteps - 1 after it (probation_steps_). A return on the pause rule is
    // tentative too, and so are the load steps of its probation.
    const bool from_explicit = step_mode_ == kExplicit;
    const bool on_pause = from_explicit && pause_return_;
    pause_return_ = false;
    const bool returning = from_explicit && (on_pause || (separated_ && !separation_given_up_));
    const bool tentative = returning || probation_steps_ > 0;
    static_.load_path_cut(separated_ && !separation_given_up_);  // strands carry no load then (hanging_nodes.hpp)
    const bool pause_rule = on_pause || (!from_explicit && probation_steps_ > 0 && pause_probation_);
    if (tentative) static_.try_once(kTentativeIterations, pause_rule ? pause_factorisations_ : 0);
    // Once separated, every load step starts from the pieces each carried by the one grip that holds
    // it (QuasiStatic::carry_rigidly): unstrained, their equilibrium, which Newton then accepts
    // without a factorisation (measured in the header).
    if (separated_ && !separation_given_up_) static_.carry_pieces(load_path_->held_by_one_group(op_.model().bonds), load_path_->groups());
    try {
      static_.step(state, t, dt);
      report_ = static_.last_step();
      if (tentative) probation_steps_ = std::max(probation_steps_ - 1, 0);
      else pause_failures_ = 0;  // a load step past any probation: the pause rule's tries count anew
      if (returning)
        log_lines_.push_back("mixed: t = " + message_number(t) + " s: back in load steps: " +
                             (static_.accepted_as_carried()
                                  ? std::string("each piece carried by the one grip that holds it is in equilibrium (no correction, no tangent)")
                                  : "equilibrium in " + std::to_string(report_.iterations) + " Newton iterations") +
                             (report_.broken_now > 0 ? ", " + std::to_string(report_.broken_now) + " bonds broken on the way" : "") +
                             " (" + std::to_string(static_.hanging_nodes() - static_.linkage_nodes()) +
                             " nodes hanging by collinear bonds left out of the solve and placed on their bonds' line, " +
                             std::to_string(static_.linkage_nodes()) + " links of linkages and strands left out and placed among their anchors, " +
                             std::to_string(static_.free_fragment_nodes()) + " nodes of free fragments left as they were)");
      step_mode_ = kQuasiStatic;
      static_dt_ = report_.next_dt;
      return;
    } catch (const StepFailed&) {
      // A failure the explicit scheme cannot help with (no tangent, a body not held) has no reason.
      if (static_.failure_reason().empty()) throw;
      // Back to the last equilibrium: the state is that of t (step() works on a copy and leaves it
      // so), the bonds broken in the attempt heal, and the tangent they were in is forgotten. The
      // state's force is already that of this state with these bonds (evaluated when the step that
      // reached it ended), so Verlet's first half kick needs no new evaluation.
      op_.model().bonds.broken = broken_before_;
      op_.model().state_arrays.restore_rollback(history_before_);
      static_.forget_factorisation();
      // A step cut to the first bond failure (quasi_static.hpp) failed there: the load step to try
      // on the return is that cut one, not the long step asked for, which would carry the crack on
      // through a load range Newton must then cross in one go (measured on plate_with_hole, dx×2,
      // dt_max 1 ms: the tentative step of 1 ms found no equilibrium in its 10 iterations).
      if (static_.cut_to() > 0.0) static_dt_ = static_.cut_to();
      evaluations = static_.last_step().force_evaluations;
      rejected = static_.last_step().rejected + 1;
      std::string then;
      if (pause_rule) {
        // The crack had not stopped, or the pieces hold what Newton cannot meet in a few iterations:
        // Verlet until bonds break and pause again (to_explicit), pause_tries_ failures in all.
        ++pause_failures_;
        then = pause_failures_ < pause_tries_ ? "; the next try when the crack pauses again"
                                              : "; no more tries on a pause of the crack";
      } else if (tentative) {
        separation_given_up_ = true;
        then = "; no more returns on the separation, only when the motion has died down";
      }
      probation_steps_ = 0;
      pause_probation_ = false;
      to_explicit(state, t, static_.failure_reason() + then);
    }
  }
  double h = std::min(dt, dt_explicit_);
  explicit_.step(state, t, h);
  dt = h;
  report_ = explicit_.last_step();
  report_.force_evaluations += evaluations;
  report_.rejected = rejected;
  report_.next_dt = dt_explicit_;
  step_mode_ = kExplicit;
  // The arrest watch: the crack has stopped and the motion it released has died down.
  const ForceOperator::KineticAndStrain energies = op_.kinetic_and_strain_energy(state);  // one pass, the same bits
  const double kinetic = energies.kinetic, strain = energies.strain;
  if (report_.broken_now > 0) {
    cracked_ = true;
    // The graph changes only when bonds break: one O(bonds) pass then.
    if (load_path_ && !separated_ && (separated_ = load_path_->separated(op_.model().bonds))) {
      log_lines_.push_back("mixed: t = " + message_number(t) +
                           " s: the cracks have cut the load path between the prescribed motions");
      calm_steps_ = 0;  // the wait after the cut counts from this step (the calm steps before it are another watch's)
    }
  }
  // Once the load path is cut, the pieces hang each from one grip: what still breaks is the
  // overshoot of their undamped ringing at the crack faces, which the equilibrium ahead does
  // without (unloaded pieces); the watch counts the steps since the cut.
  const bool cut = separated_ && !separation_given_up_;
  if (cut || (cracked_ && report_.broken_now == 0 && kinetic < settings_.kinetic_fraction * strain)) ++calm_steps_;
  else calm_steps_ = 0;
  quiet_steps_ = report_.broken_now > 0 ? 0 : quiet_steps_ + 1;
  if (home_ == kQuasiStatic && crack_paused()) {
    pause_return_ = true;
    to_quasi_static(state, t, kinetic, strain);
    report_.next_dt = std::min(std::max(static_dt_, static_.dt_min()), static_.dt_max());
  } else if (calm_steps_ >= (cut ? cut_steps() : settings_.arrest_steps)) {
    if (home_ == kImplicit) {
      to_implicit(state, t, kinetic, strain);
      report_.next_dt = std::min(std::max(static_dt_, implicit_.dt_min()), implicit_.dt_max());
    } else {
      to_quasi_static(state, t, kinetic, strain);
      report_.next_dt = std::min(std::max(static_dt_, static_.dt_min()), static_.dt_max());
    }
  }
}

std::vector<char> Mixed::save_state() const {
  std::vector<char> bytes = Integrator::save_state();
  auto put = [&bytes](const auto& value) {
    const auto* p = reinterpret_cast<const char*>(&value);
    bytes.insert(bytes.end(), p, p + sizeof value);
  };
  const int mode = mode_;
  const std::uint8_t cracked = cracked_ ? 1 : 0;
  put(mode), put(step_mode_), put(calm_steps_), put(static_dt_), put(switches_), put(cracked);
  // The separation rule in one byte (older checkpoints hold 0 or 1): 0 active, 1 given up, 1 + k
  // active with k load steps of probation left.
  const std::uint8_t given_up = separation_given_up_ ? 1 : probation_steps_ > 0 ? static_cast<std::uint8_t>(1 + probation_steps_) : 0;
  if (home_ == kImplicit) put(breaking_steps_);
  else put(given_up);
  const std::vector<char> inner = home_ == kImplicit ? implicit_.save_state() : static_.save_state();
  bytes.insert(bytes.end(), inner.begin(), inner.end());
  // The pause rule's state after the inner state, closed by a tag (a checkpoint written before the
  // rule has none, and reads as a run that has not paused).
  const std::uint8_t pause_return = pause_return_ ? 1 : 0, pause_probation = pause_probation_ ? 1 : 0;
  put(quiet_steps_), put(pause_failures_), put(pause_return), put(pause_probation), put(kPauseTag);
  return bytes;
}

void Mixed::load_state(const std::vector<char>& bytes) {
  const std::size_t own = 2 * sizeof(int) + sizeof(std::int64_t) + sizeof(double) + sizeof(int) + 1 +
                          (home_ == kImplicit ? sizeof(std::int64_t) : 1);
  if (bytes.size() < kReportBytes + own) throw std::runtime_error("integrator state of the wrong size");
  load_report(std::vector<char>(bytes.begin(), bytes.begin() + static_cast<std::ptrdiff_t>(kReportBytes)), 0);
  const char* at = bytes.data() + kReportBytes;
  auto get = [&at](auto& value) {
    std::memcpy(&value, at, sizeof value);
    at += sizeof value;
  };
  int mode = 0;
  std::uint8_t cracked = 0;
  get(mode), get(step_mode_), get(calm_steps_), get(static_dt_), get(switches_), get(cracked);
  cracked_ = cracked != 0;
  if (mode != kExplicit && mode != home_) throw std::runtime_error("integrator state: unknown mixed mode");
  mode_ = static_cast<Mode>(mode);
  // The pause rule's bytes at the end, if the tag is there.
  constexpr std::size_t pause_bytes = sizeof(std::int64_t) + sizeof(int) + 2 + sizeof(kPauseTag);
  std::size_t end = bytes.size();
  quiet_steps_ = 0, pause_failures_ = 0, pause_return_ = pause_probation_ = false;
  std::uint64_t tag = 0;
  if (bytes.size() >= kReportBytes + own + pause_bytes)
    std::memcpy(&tag, bytes.data() + bytes.size() - sizeof tag, sizeof tag);
  if (tag == kPauseTag) {
    end -= pause_bytes;
    const char* p = bytes.data() + end;
    std::uint8_t pause_return = 0, pause_probation = 0;
    std::memcpy(&quiet_steps_, p, sizeof quiet_steps_), p += sizeof quiet_steps_;
    std::memcpy(&pause_failures_, p, sizeof pause_failures_), p += sizeof pause_failures_;
    std::memcpy(&pause_return, p, 1), p += 1;
    std::memcpy(&pause_probation, p, 1);
    pause_return_ = pause_return != 0, pause_probation_ = pause_probation != 0;
  }
  const std::vector<char> inner(bytes.begin() + static_cast<std::ptrdiff_t>(kReportBytes + own),
                                bytes.begin() + static_cast<std::ptrdiff_t>(end));
  if (home_ == kImplicit) {
    get(breaking_steps_);
    implicit_.load_state(inner);
  } else {
    // The bonds of the checkpoint are restored before load_state (run/start.cpp).
    std::uint8_t given_up = 0;
    get(given_up);
    separation_given_up_ = given_up == 1;
    probation_steps_ = given_up > 1 ? given_up - 1 : 0;
    // A restart restored the piece's broken flags (run/start.cpp) before this. Collective.
    separated_ = load_path_ && load_path_->separated(op_.model().bonds);
    static_.load_path_cut(separated_ && !separation_given_up_);  // the nodes load_state masks, as step() found them
    static_.load_state(inner);
  }
}

std::vector<std::string> Mixed::describe(double dt_exact) const {
  if (home_ == kImplicit) {
    std::vector<std::string> lines = implicit_.describe(dt_exact);
    lines.push_back("mixed: starts implicit (mixed.start); explicit steps of dt " + message_number(dt_explicit_) +
                    " s when an implicit step fails down to " + message_number(implicit_.dt_min()) +
                    " s or bonds break in more than " + std::to_string(settings_.unstable_rounds) +
                    " implicit steps in a row; back to implicit after " + std::to_string(settings_.arrest_steps) +
                    " steps without breaking and with kinetic energy below " +
                    message_number(settings_.kinetic_fraction) + " × the strain energy");
    return lines;
  }
  std::vector<std::string> lines = static_.describe(dt_exact);
  lines.push_back("mixed: explicit steps of dt " + message_number(dt_explicit_) + " s when a load step fails (more than " +
                  std::to_string(settings_.unstable_rounds) + " re-solves while bonds break, or no equilibrium down to " +
                  message_number(static_.dt_min()) + " s); back to quasi-static after " +
                  std::to_string(settings_.arrest_steps) + " steps without breaking and with kinetic energy below " +
                  message_number(settings_.kinetic_fraction) + " × the strain energy" +
                  (load_path_ && load_path_->linked_uncut()
                       ? ", or " + std::to_string(cut_steps()) + " steps" + (cut_is_crossing() ? " (δ/c)" : "") +
                             " after the cracks have cut the load path between the prescribed motions"
                       : "") +
                  (pause_steps_ > 0 ? "; and a tentative load step when the crack has stopped running (no bond broken for " +
                                          std::to_string(pause_steps_) + " steps, δ/c; at most " +
                                          std::to_string(pause_tries_) + " failed tries)"
                                    : ""));
  return lines;
}

}  // namespace pd
