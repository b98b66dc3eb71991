// The explicit step that time.dt asks for, the one rule the run's set-up (run/prepare.cpp) and the
// mixed integrator's explicit phase (integrators/mixed.cpp) both use:
//   "stable": thesis eq. 2.5 × safety_factor;
//   "exact":  the linear limit 2/ω_max of the operator (core/stability.hpp) × safety_factor;
//   a number: used as given.
#pragma once
#include <functional>

#include "core/case.hpp"

namespace pd {

// dt_stable is eq. 2.5 for the model (core/model.hpp); dt_exact is called only for "exact" (it runs
// Lanczos unless the value is known). Throws pd::Error naming the case file when the rule needs
// bonds and the model has none (the limit is not finite).
double explicit_time_step(const Case& c, double dt_stable, const std::function<double()>& dt_exact);

}  // namespace pd
