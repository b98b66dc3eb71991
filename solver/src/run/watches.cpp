// The blow-up and indenter-depth watches and their messages (run/watches.hpp).
#include "run/watches.hpp"

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

std::string BlowUpWatch::likely_cause(double h, double dt_exact, double dt_stable, bool explicit_step) {
  const double ratio = h / dt_exact;
  std::string text = "dt = " + format("%.6g", h) + " s is " + format("%.3g", ratio) + " × the exact stability limit " +
                     format("%.6g", dt_exact) + " s (eq. 2.5: " + format("%.6g", dt_stable) + " s): ";
  if (ratio > 1.0 && explicit_step)
    return text + "the time step is above the stability limit; use time.dt: stable or exact with safety_factor < 1";
  return text + "the step is within the linear limit, so look for contact stiffness, large deformation or a load "
                "that makes the state jump";
}

std::string IndenterDepthWatch::message(const IndenterStepLimit& limit, std::int64_t step, double t, double dt_taken,
                                        const std::string& indenter, const std::string& where) {
  return "warning: step " + std::to_string(step) + " (t = " + format("%.6g", t) + " s): indenter '" + indenter + "' is " +
         format("%.4g", limit.depth) + " m deep at " + where + "; with its stiffness 2K·h the step is guaranteed stable only below " +
         format("%.4g", limit.dt) + " s < dt " + format("%.4g", dt_taken) +
         " s: the run may blow up (lower indenters[].stiffness or time.safety_factor); warned once";
}

}  // namespace pd
