// Body-force density from the piecewise-linear tables of the case.
#include "forces/body_force.hpp"

namespace pd {

void BodyForceTerm::AddMult(double t, Vec3Array& f) const {
  for (const auto& b : model_.conditions.body_forces) {
    const double value = b.table.value(t);
    auto& fc = f[static_cast<std::size_t>(b.component)];
    for (std::int32_t i : b.nodes) fc[static_cast<std::size_t>(i)] += value;
  }
}

double BodyForceTerm::power(double t, const Vec3Array& v) const {
  double p = 0.0;
  for (const auto& b : model_.conditions.body_forces) {
    const double value = b.table.value(t);
    const auto& vc = v[static_cast<std::size_t>(b.component)];
    for (std::int32_t i : b.nodes) p += model_.nodes.volume[static_cast<std::size_t>(i)] * value * vc[static_cast<std::size_t>(i)];
  }
  return p;
}

}  // namespace pd
