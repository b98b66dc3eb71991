// Trouble spots of a state (run/measures.hpp).
#include "run/measures.hpp"

#include <algorithm>
#include <cmath>

namespace pd {

std::int64_t first_non_finite(const State& s) {
  const auto n = static_cast<std::int64_t>(s.size());
  std::int64_t first = n;
#pragma omp parallel for schedule(static) reduction(min : first)
  for (std::int64_t i = 0; i < n; ++i) {
    bool ok = true;
    for (std::size_t d = 0; d < 3; ++d)
      ok = ok && std::isfinite(s.u[d][static_cast<std::size_t>(i)]) && std::isfinite(s.v[d][static_cast<std::size_t>(i)]);
    if (!ok) first = std::min(first, i);
  }
  return first == n ? -1 : first;
}

std::int64_t fastest_node(const State& s) {
  std::int64_t best = 0;
  double best_speed = -1.0;
  for (std::size_t i = 0; i < s.size(); ++i) {
    const double speed = s.v[0][i] * s.v[0][i] + s.v[1][i] * s.v[1][i] + s.v[2][i] * s.v[2][i];
    if (std::isfinite(speed) && speed > best_speed) best_speed = speed, best = static_cast<std::int64_t>(i);
  }
  return best;
}

}  // namespace pd
