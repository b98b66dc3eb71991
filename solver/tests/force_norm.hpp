// Test helper: the norm of the nodal forces V_i f_i [N] over the free components (the residual of
// an equilibrium solve) or over the held ones (the applied load, carried by the supports).
#pragma once
#include <cmath>
#include <cstddef>

#include "core/model.hpp"
#include "core/state.hpp"

namespace pdtest {

inline double force_norm(const pd::Model& m, const pd::State& s, bool free) {
  double sum = 0.0;
  for (std::size_t d = 0; d < 3; ++d)
    for (std::size_t i = 0; i < s.size(); ++i)
      if (static_cast<bool>(m.conditions.fixed[d][i]) != free) sum += std::pow(m.nodes.volume[i] * s.f[d][i], 2);
  return std::sqrt(sum);
}

}  // namespace pdtest
