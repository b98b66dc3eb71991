// The blow-up and indenter-depth watches and their messages (run/watches.hpp).
#include "run/watches.hpp"

#include <algorithm>
#include <cmath>

#include "run/text.hpp"

namespace pd {

bool BlowUpWatch::grew_too_long(double energy) {
  if (memory_.energy_before > 0.0 && energy > kGrowthPerStep * memory_.energy_before) {
    if (memory_.streak++ == 0) memory_.streak_start = memory_.energy_before;
  } else {
    memory_.streak = 0;
  }
  memory_.energy_before = energy;
  return memory_.streak >= kGrowthSteps;
}

std::string BlowUpWatch::growth_message(double energy, std::int64_t step, double t, const std::string& fastest,
                                        const std::string& cause) const {
  return "pdsolve: error: the energy grew from " + format("%.3g", memory_.streak_start) + " J to " + format("%.3g", energy) +
         " J in the " + std::to_string(kGrowthSteps) + " steps up to and after step " + std::to_string(step) + " (t = " +
         format("%.6g", t) + " s), at least ×" + format("%g", kGrowthPerStep) +
         " every step: the run is unstable, most likely starting at " + fastest + " (the largest speed); " + cause +
         "; stopped without writing this state, the last frame written is the last valid one";
}

std::string BlowUpWatch::non_finite_message(const std::string& where, std::int64_t step, double t,
                                            const std::string& fastest, const std::string& cause) {
  return "pdsolve: error: non-finite displacement or velocity at " + where + " after step " + std::to_string(step) +
         " (t = " + format("%.6g", t) + " s; the largest finite speed is at " + fastest + "); " + cause +
         "; stopped without writing this state, the last frame written is the last valid one";
}

std::string BlowUpWatch::likely_cause(double h, double dt_exact, double dt_stable, bool explicit_step, bool contact) {
  // A decomposed run whose ranks hold only their rows has not computed the exact limit when its
  // step needed none (NaN: rank 0 cannot compute it alone): its step is eq. 2.5's × a safety factor
  // ≤ 1, below the exact limit.
  if (std::isnan(dt_exact) && explicit_step)
    return "dt = " + format("%.6g", h) + " s is within eq. 2.5's limit " + format("%.6g", dt_stable) +
           " s, so within the linear limit, which large deformation lowers" +
           (contact ? std::string(" and contact stiffness (contact.stiffness_factor) is not part of") : std::string()) +
           "; use a smaller time.safety_factor (e.g. 0.8)" +
           (contact ? std::string(" or a smaller contact.stiffness_factor") : std::string());
  if (std::isnan(dt_exact))
    return "dt = " + format("%.6g", h) + " s: look for contact stiffness, large deformation or a load that makes the state jump";
  const double ratio = h / dt_exact;
  std::string text = "dt = " + format("%.6g", h) + " s is " + format("%.3g", ratio) + " × the exact stability limit " +
                     format("%.6g", dt_exact) + " s (eq. 2.5: " + format("%.6g", dt_stable) + " s): ";
  if (ratio > 1.0 && explicit_step)
    return text + "the time step is above the stability limit; use time.dt: stable or exact with safety_factor < 1";
  if (explicit_step)  // below the linear limit, yet unstable: the limit dropped while the run went on
    return text + "the step is within the linear limit, which large deformation lowers" +
           (contact ? std::string(" and contact stiffness (contact.stiffness_factor) is not part of") : std::string()) +
           "; use a smaller time.safety_factor (e.g. 0.8)" +
           (contact ? std::string(" or a smaller contact.stiffness_factor") : std::string());
  return text + "the step is within the linear limit, so look for contact stiffness, large deformation or a load "
                "that makes the state jump";
}

bool EnergyBalanceWatch::broken(std::int64_t step, double energy, double damping_work, double external_work) {
  if (!active_) return false;
  const double given = initial_ + std::max(external_work, 0.0);
  if (!(given > 0.0)) return false;  // nothing given yet: nothing to compare with
  const double held = energy + damping_work;
  if (!(held <= kSuspect * given)) {  // a NaN counts as an excess
    if (suspect_from_ < 0) suspect_from_ = step;
  } else {
    suspect_from_ = -1;
  }
  return !(held <= kStop * given);
}

std::string EnergyBalanceWatch::message(std::int64_t step, double t, double energy, double damping_work,
                                        double external_work, const std::string& fastest, const std::string& cause) const {
  const double given = initial_ + std::max(external_work, 0.0);
  return "pdsolve: error: after step " + std::to_string(step) + " (t = " + format("%.6g", t) +
         " s) the kinetic, strain and contact energy plus the damping work are " + format("%.3g", energy + damping_work) +
         " J, " + format("%.3g", (energy + damping_work) / given) + " × the energy the run was given (" +
         format("%.3g", initial_) + " J at the start + " + format("%.3g", std::max(external_work, 0.0)) +
         " J of external work; a sound run stays near 1 ×" +
         (suspect_from_ >= 0 ? ", this one passed " + format("%g", kSuspect) + " × at step " + std::to_string(suspect_from_)
                             : std::string()) +
         "): the energy balance is broken and the run is unstable, most likely starting at " + fastest +
         " (the largest speed); " + cause + "; stopped without writing this state";
}

std::string IndenterDepthWatch::message(const IndenterStepLimit& limit, std::int64_t step, double t, double dt_taken,
                                        const std::string& indenter, const std::string& where) {
  return "warning: step " + std::to_string(step) + " (t = " + format("%.6g", t) + " s): indenter '" + indenter + "' is " +
         format("%.4g", limit.depth) + " m deep at " + where + "; with its stiffness 2K·h the step is guaranteed stable only below " +
         format("%.4g", limit.dt) + " s < dt " + format("%.4g", dt_taken) +
         " s: the run may blow up (lower indenters[].stiffness or time.safety_factor); warned once";
}

}  // namespace pd
