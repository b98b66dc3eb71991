// time.dt's rule (core/time_step_rule.hpp).
#include "core/time_step_rule.hpp"

#include <cmath>
#include <cstdio>
#include <string>

#include "core/error.hpp"

namespace pd {

namespace {

std::string number(double value) {
  char buffer[32];
  std::snprintf(buffer, sizeof buffer, "%.6g", value);
  return buffer;
}

}  // namespace

double explicit_time_step(const Case& c, double dt_stable, const std::function<double()>& dt_exact) {
  if (c.time.dt_rule == "stable") {
    if (!std::isfinite(dt_stable))
      throw Error(c.file.string() + ": time.dt: \"stable\" needs bonds, but no node has a partner within the horizon " +
                  number(c.horizon) + " m");
    return dt_stable * c.time.safety_factor;
  }
  if (c.time.dt_rule == "exact") {
    const double limit = dt_exact();
    if (!std::isfinite(limit))
      throw Error(c.file.string() + ": time.dt: \"exact\" needs bonds, but no node has a partner within the horizon " +
                  number(c.horizon) + " m");
    return limit * c.time.safety_factor;
  }
  return c.time.dt_value;
}

}  // namespace pd
