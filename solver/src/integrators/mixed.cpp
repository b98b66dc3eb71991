// One step of the mixed scheme: a quasi-static load step or a Verlet step, and the switches
// between them (integrators/mixed.hpp).
#include "integrators/mixed.hpp"

#include <algorithm>
#include <cstring>

#include "core/error.hpp"
#include "core/time_step_rule.hpp"
#include "integrators/messages.hpp"

namespace pd {

void Mixed::configure(const Case& c, double dt_exact) {
  settings_ = c.mixed;
  // The explicit phase's step: time.dt's rule, as the run's set-up applies it (run/prepare.cpp).
  dt_explicit_ = explicit_time_step(c, op_.stable_time_step(),
                                    [this, dt_exact] { return dt_exact > 0.0 ? dt_exact : op_.exact_time_step(); });
  if (!(dt_explicit_ > 0.0) || !std::isfinite(dt_explicit_))
    throw Error(c.file.string() + ": time.dt: the mixed scheme's explicit step is not a positive number (" +
                message_number(dt_explicit_) + " s): the body needs bonds");
  static_.configure(c, dt_exact);
  static_.limit(settings_.unstable_rounds, c.quasi_static.dt_min.value_or(10.0 * dt_explicit_));
  static_dt_ = static_.initial_dt().value_or(static_.dt_max());
}

void Mixed::initialize(State& state, double t) {
  static_.initialize(state, t);  // the prescribed motion, the force and powers at t, the free-body check
  report_ = StepReport{};
  mode_ = kQuasiStatic;
  step_mode_ = kQuasiStatic;
  calm_steps_ = 0;
  log_lines_.clear();
}

void Mixed::to_explicit(State&, double t, const std::string& reason) {
  mode_ = kExplicit;
  calm_steps_ = 0;
  cracked_ = false;
  ++switches_;
  log_lines_.push_back("mixed: t = " + message_number(t) + " s: quasi-static → explicit (" + reason + "); Verlet at dt " +
                       message_number(dt_explicit_) + " s");
}

void Mixed::to_quasi_static(State& state, double t, double kinetic, double strain) {
  mode_ = kQuasiStatic;
  ++switches_;
  static_.forget_factorisation();  // bonds broke in the explicit steps
  // The next load step finds equilibrium and leaves only the mean velocity of the load step: the
  // kinetic energy now is given up, booked as damping work so that the balance closes.
  state.damping_work += kinetic;
  log_lines_.push_back("mixed: t = " + message_number(t) + " s: explicit → quasi-static (the crack arrested: no bond broke and " +
                       "the kinetic energy stayed below " + message_number(settings_.kinetic_fraction) +
                       " × the strain energy for " + std::to_string(settings_.arrest_steps) + " steps); kinetic energy " +
                       message_number(kinetic) + " J (" + message_number(strain > 0.0 ? kinetic / strain : 0.0) +
                       " of the strain energy) given up, booked as damping work");
}

void Mixed::step(State& state, double& t, double& dt) {
  int evaluations = 0, rejected = 0;
  if (mode_ == kQuasiStatic) {
    broken_before_ = op_.model().bonds.broken;
    critical_before_ = op_.model().node_critical_stretch;  // LAMMPS's per-node s0 (empty unless α > 0)
    static_dt_ = dt;
    try {
      static_.step(state, t, dt);
      report_ = static_.last_step();
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
      op_.model().node_critical_stretch = critical_before_;
      static_.forget_factorisation();
      evaluations = static_.last_step().force_evaluations;
      rejected = static_.last_step().rejected + 1;
      to_explicit(state, t, static_.failure_reason());
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
  const double kinetic = op_.kinetic_energy(state), strain = op_.strain_energy(state);
  if (report_.broken_now > 0) cracked_ = true;
  if (cracked_ && report_.broken_now == 0 && kinetic < settings_.kinetic_fraction * strain) ++calm_steps_;
  else calm_steps_ = 0;
  if (calm_steps_ >= settings_.arrest_steps) {
    to_quasi_static(state, t, kinetic, strain);
    report_.next_dt = std::min(std::max(static_dt_, static_.dt_min()), static_.dt_max());
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
  const std::vector<char> inner = static_.save_state();
  bytes.insert(bytes.end(), inner.begin(), inner.end());
  return bytes;
}

void Mixed::load_state(const std::vector<char>& bytes) {
  constexpr std::size_t own = 2 * sizeof(int) + sizeof(std::int64_t) + sizeof(double) + sizeof(int) + 1;
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
  if (mode != kExplicit && mode != kQuasiStatic) throw std::runtime_error("integrator state: unknown mixed mode");
  mode_ = static_cast<Mode>(mode);
  static_.load_state(std::vector<char>(bytes.begin() + static_cast<std::ptrdiff_t>(kReportBytes + own), bytes.end()));
}

std::vector<std::string> Mixed::describe(double dt_exact) const {
  std::vector<std::string> lines = static_.describe(dt_exact);
  lines.push_back("mixed: explicit steps of dt " + message_number(dt_explicit_) + " s when a load step fails (more than " +
                  std::to_string(settings_.unstable_rounds) + " re-solves while bonds break, or no equilibrium down to " +
                  message_number(static_.dt_min()) + " s); back to quasi-static after " +
                  std::to_string(settings_.arrest_steps) + " steps without breaking and with kinetic energy below " +
                  message_number(settings_.kinetic_fraction) + " × the strain energy");
  return lines;
}

}  // namespace pd
