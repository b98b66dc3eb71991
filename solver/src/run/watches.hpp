// The time loop's two watches: the blow-up watch (a non-finite state, or the energy growing ×1.5
// a step for 20 steps) stops a run; the indenter-depth watch warns once that an explicit step may
// no longer be stable. Each decides and words its message; the loop measures and acts.
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
  // the integrator is bounded by the limit (Integrator::explicit_step).
  static std::string likely_cause(double h, double dt_exact, double dt_stable, bool explicit_step);

 private:
  EnergyGrowth& memory_;
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
