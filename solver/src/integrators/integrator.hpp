// The integrator contract (MFEM's ODESolver::Step): step(state, t, dt) advances the state from t;
// on return t is the new time and dt the step actually taken, which a step-size controller
// (the adaptive Zohdi scheme, integrators/adaptive.hpp) may have changed. An integrator sees the
// physics only through the operator (operator/force_operator.hpp).
#pragma once
#include <cstring>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "core/case.hpp"
#include "core/registry.hpp"
#include "core/state.hpp"
#include "operator/force_operator.hpp"

namespace pd {

struct StepReport {
  int iterations = 1;         // fixed-point iterations K of the accepted step (1 for Verlet)
  int rejected = 0;           // rejected attempts before acceptance (0 for Verlet)
  std::int64_t broken_now = 0;  // bonds broken during the step, each counted once
  double broken_energy_now = 0.0;  // energy those bonds held when they broke [J] (materials/pmb/pmb.hpp)
  int force_evaluations = 1;  // force evaluations of the step, rejected attempts included
  double next_dt = 0.0;       // the step the integrator proposes next [s]; 0: no proposal (fixed dt)
};

// Thrown by step() when no step can be taken (the adaptive step does not converge at dt_min);
// the state is left as it was at t, so the caller can keep it as the last good state.
struct StepFailed : std::runtime_error {
  using std::runtime_error::runtime_error;
};

class Integrator {
 public:
  virtual ~Integrator() = default;
  virtual std::string name() const = 0;
  // Reads the integrator's own settings from the case (the adaptive section); Verlet has none.
  // dt_exact: the exact stability limit (core/stability) if the caller has already computed it
  // (time.dt "exact"), else 0; it saves a second Lanczos run.
  virtual void configure(const Case&, double /*dt_exact*/ = 0.0) {}
  // Imposes the prescribed motion at t and evaluates f and the powers there; call once first.
  virtual void initialize(State& state, double t) = 0;
  virtual void step(State& state, double& t, double& dt) = 0;
  const StepReport& last_step() const { return report_; }
  // The integrator's own state between steps (a checkpoint, io/checkpoint.hpp), as bytes: the last
  // report (history.csv reads it) plus what a subclass carries from step to step (the adaptive
  // proposal). load_state() after initialize() continues bitwise as if never stopped.
  virtual std::vector<char> save_state() const {
    std::vector<char> bytes;
    auto put = [&bytes](const auto& value) {
      const auto* p = reinterpret_cast<const char*>(&value);
      bytes.insert(bytes.end(), p, p + sizeof value);
    };
    put(report_.iterations), put(report_.rejected), put(report_.broken_now), put(report_.broken_energy_now);
    put(report_.force_evaluations), put(report_.next_dt);
    return bytes;
  }
  // The integrator's per-node arrays that a checkpoint carries (the implicit scheme's a_n), over
  // the operator's nodes: written in pieces, each rank its owned nodes, and restored into every
  // node of the piece before load_state (run/state_checkpoint.hpp), not in save_state's bytes.
  virtual std::vector<Vec3Array*> checkpointed_node_arrays() { return {}; }
  // Throws std::runtime_error if the bytes are not what save_state() of this integrator writes.
  virtual void load_state(const std::vector<char>& bytes) { load_report(bytes, 0); }

  // ---- What the run (run/) asks of an integrator, so that it never tests a name or a type.
  // Lines for run.log about the integrator's own settings, after the dt line; dt_exact: what the
  // caller passed to configure() (0: it had not computed the exact limit). Verlet has none.
  virtual std::vector<std::string> describe(double /*dt_exact*/) const { return {}; }
  // An explicit step of the given dt, stable only below the limit: a step above it explains a
  // blow-up, and an indenter's growing stiffness 2K·h is watched (run/watches.hpp).
  virtual bool explicit_step() const { return false; }
  // A controller chooses the step: time.dt gives only the first one.
  virtual bool controls_step() const { return false; }
  // The first step from the integrator's own settings (adaptive.dt_initial), once configured.
  virtual std::optional<double> initial_dt() const { return std::nullopt; }
  // The kind of the last step for history.csv's `mode` column: 1 a quasi-static load step, 0 a
  // dynamic one (explicit or implicit). Empty: every step is dynamic (0).
  virtual std::optional<int> step_mode() const { return std::nullopt; }
  // Lines for run.log that the last step produced (a mixed scheme's switches), handed over once.
  virtual std::vector<std::string> take_log_lines() { return {}; }
  // What the run's linear algebra cost, appended to run.log's done: line (quasi_static and mixed:
  // factorisations and solves with their wall time, so that a benchmark can weigh them against
  // force evaluations). Empty for a scheme without a linear solver: the done: line is unchanged.
  virtual std::string linear_algebra_summary() const { return {}; }
  // The linear solver of the scheme's Newton iterations ("direct", "cg block_jacobi", "cg amg"; ""
  // for a scheme without one). With linear_solver or preconditioner auto it depends on the rank
  // count, the build and the machine (integrators/newton_krylov.hpp), and each solves the systems
  // to other bits: a checkpoint records it (io/checkpoint.hpp) so that a restart can keep it.
  virtual std::string linear_solver() const { return {}; }
  // On a restart, after configure() and before initialize(): go on with the linear solver the
  // checkpoint recorded, so that the run continues bitwise. "" when the run now uses it; otherwise
  // why it cannot (the run keeps its own choice, and the caller says the results will differ).
  virtual std::string keep_linear_solver(const std::string& /*recorded*/) { return {}; }
  // ---- end of what the run asks

 protected:
  static constexpr std::size_t kReportBytes = 3 * sizeof(int) + sizeof(std::int64_t) + 2 * sizeof(double);
  // Reads what Integrator::save_state wrote; `extra` more bytes follow it (a subclass's own).
  void load_report(const std::vector<char>& bytes, std::size_t extra) {
    if (bytes.size() != kReportBytes + extra) throw std::runtime_error("integrator state of the wrong size");
    std::size_t at = 0;
    auto get = [&](auto& value) {
      std::memcpy(&value, bytes.data() + at, sizeof value);
      at += sizeof value;
    };
    get(report_.iterations), get(report_.rejected), get(report_.broken_now), get(report_.broken_energy_now);
    get(report_.force_evaluations), get(report_.next_dt);
  }
  StepReport report_;
};

using IntegratorFactory = std::unique_ptr<Integrator> (*)(ForceOperator&);
const Registry<IntegratorFactory>& integrator_registry();

}  // namespace pd
