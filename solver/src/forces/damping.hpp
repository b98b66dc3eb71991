// Velocity damping, force density −ρ·α·v (the thesis's damping correction for velocities),
// integrated with the trapezoidal rule inside velocity Verlet so it is stable for any α·Δt:
//   v^{n+½} = (1 − αΔt/2)·v^n + Δt/2·f^n/ρ
//   v^{n+1} = (v^{n+½} + Δt/2·f^{n+1}/ρ) / (1 + αΔt/2)
// Eliminating v^{n+½}: (1 + αΔt/2)v^{n+1} = (1 − αΔt/2)v^n + Δt(f^n + f^{n+1})/(2ρ), i.e. the
// damping term is Crank–Nicolson, whose amplification (1 − αΔt/2)/(1 + αΔt/2) has modulus < 1.
#pragma once
#include <cstdint>
#include <vector>

#include "core/nodes.hpp"
#include "parallel/node_sum.hpp"

namespace pd {

struct DampingFactors {
  double explicit_half;  // 1 − αΔt/2, multiplies v^n in the first half step
  double implicit_half;  // 1/(1 + αΔt/2), divides in the second half step
};

inline DampingFactors damping_factors(double alpha, double dt) {
  return {1.0 - 0.5 * alpha * dt, 1.0 / (1.0 + 0.5 * alpha * dt)};
}

// Σ ρ α V |v_c|² over components that are not prescribed (damping acts on free motion only;
// at a prescribed component the reaction takes whatever force is needed) [W]. One exact sum per
// component, continuing the last (parallel/node_sum.hpp): the same bits serially (d == null) and
// on a decomposed run (collective there).
inline double damping_power(double alpha, const std::vector<double>& density, const std::vector<double>& volume,
                            const Vec3Array& v, const std::array<std::vector<std::uint8_t>, 3>& fixed,
                            const Decomposed* d = nullptr) {
  if (alpha == 0.0) return 0.0;
  double p = 0.0;
  for (std::size_t c = 0; c < 3; ++c)
    p = sum_over_nodes(d, volume.size(), [&](std::size_t i) {
      return fixed[c][i] ? 0.0 : density[i] * volume[i] * v[c][i] * v[c][i];
    }, p);
  return alpha * p;
}

}  // namespace pd
