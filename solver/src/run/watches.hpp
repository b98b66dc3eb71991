// The time loop's watches: the blow-up watch (a non-finite state, or the energy growing ×1.5 a step
// for 20 steps) and the energy-balance watch (an explicit run holding far more energy than it was
// given) stop a run; the indenter-depth watch warns once that an explicit step may no longer be
// stable. Each decides and words its message; the loop measures and acts.
#pragma once
#include <cstdint>
#include <optional>
#include <string>

#include "forces/indenter.hpp"
#include "run/loop_state.hpp"

namespace pd {

class BlowUpWatch {
 public:
  // An explicit step above its limit makes the energy grow geometrically (×47 per step at 1.5× the
  // limit); physical loading does not keep up ×1.5 per step for 20 steps.
  static constexpr double kGrowthPerStep = 1.5;
  static constexpr int kGrowthSteps = 20;

  // memory: the loop state's (a checkpoint carries the streak across a restart).
  explicit BlowUpWatch(EnergyGrowth& memory) : memory_(memory) {}
  // After a step with total energy `energy` [J]: true at the kGrowthSteps-th step in a row that
  // grew ×kGrowthPerStep or more.
  bool grew_too_long(double energy);

  // The error messages; `where` and `fastest` are node_text()s, `cause` the likely cause.
  std::string growth_message(double energy, std::int64_t step, double t, const std::string& fastest,
                             const std::string& cause) const;
  static std::string non_finite_message(const std::string& where, std::int64_t step, double t,
                                        const std::string& fastest, const std::string& cause);
  // Why a run blew up at step h, from the exact stability limit and eq. 2.5 [s]; `explicit_step`:
  // the integrator is bounded by the limit (Integrator::explicit_step); `contact`: the scene has
  // contact pairs, whose stiffness the linear limit does not hold, so it is named only then.
  static std::string likely_cause(double h, double dt_exact, double dt_stable, bool explicit_step,
                                  bool contact = false);

 private:
  EnergyGrowth& memory_;
};

// The energy balance of an explicit run: E(t) + D(t) + B(t) = E(0) + W(t), with E the kinetic,
// strain, contact and indenter energy, D the damping work, B the energy of the bonds broken so far and W the
// external work (reactions, body forces, indenters; thesis §2.3's energy check). Verlet keeps it to
// a few per cent (the shipped cases and bench-accuracy's runs: E + D ≤ 1.05 × (E(0) + W)); a step
// above the stability limit breaks it long before the ×1.5-a-step growth shows or a value overflows
// (issue 17, item 12: membrane at safety_factor 1.5 held 10 × its energy by step ~4100, but was
// stopped only at step 5097 with 6.9·10¹² J). Fracture turns strain into kinetic energy and impact
// turns kinetic into strain and contact energy: the balance holds for both, so the watch compares
// E + D with what the run was given, never the kinetic energy alone.
class EnergyBalanceWatch {
 public:
  static constexpr double kStop = 10.0;    // E + D above kStop × (E(0) + W⁺): stop
  static constexpr double kSuspect = 2.0;  // the frames from the step it first exceeded ×kSuspect go

  // active: an explicit (Verlet) run; the integrators that choose their step bound it themselves.
  explicit EnergyBalanceWatch(bool active) : active_(active) {}
  // The balance's constant E(0), from any state: at step 0 (damping, broken and external all 0) or
  // at a restart (E + D + B − W of the state read back).
  void start(double energy, double damping_work, double broken_energy, double external_work) {
    initial_ = energy + damping_work + broken_energy - external_work;
  }
  // After step `step`: true when E + D exceeds kStop × the energy given, E(0) + max(W, 0).
  bool broken(std::int64_t step, double energy, double damping_work, double external_work);
  // The first step of the current excess above ×kSuspect (frames from it on are dropped), or −1.
  std::int64_t suspect_from() const { return suspect_from_; }
  std::string message(std::int64_t step, double t, double energy, double damping_work, double external_work,
                      const std::string& fastest, const std::string& cause) const;

 private:
  bool active_;
  double initial_ = 0.0;
  std::int64_t suspect_from_ = -1;
};

// A fixed explicit step has no room for the indenter's stiffness 2K·h, which grows with depth
// (forces/indenter.hpp): warns once when a node is deeper than the step allows.
class IndenterDepthWatch {
 public:
  explicit IndenterDepthWatch(bool active) : active_(active) {}
  // Whether the loop should still compute the step limit (not after the warning).
  bool watching() const { return active_ && !warned_; }
  // After step `step` to t with dt_taken: the warning, the first time the limit is below dt_taken.
  // indenter / where: the limiting indenter's name and node_text(limit.node), asked only then.
  template <class Name, class Where>
  std::optional<std::string> check(const IndenterStepLimit& limit, std::int64_t step, double t, double dt_taken,
                                   Name indenter, Where where) {
    if (!watching() || limit.node < 0 || !(dt_taken > limit.dt)) return std::nullopt;
    warned_ = true;
    return message(limit, step, t, dt_taken, indenter(), where());
  }

 private:
  static std::string message(const IndenterStepLimit& limit, std::int64_t step, double t, double dt_taken,
                             const std::string& indenter, const std::string& where);
  bool active_;
  bool warned_ = false;
};

}  // namespace pd
