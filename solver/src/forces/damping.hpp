// Velocity damping, force density −ρ·α·v (the thesis's damping correction for velocities),
// integrated with the trapezoidal rule inside velocity Verlet so it is stable for any α·Δt:
//   v^{n+½} = (1 − αΔt/2)·v^n + Δt/2·f^n/ρ
//   v^{n+1} = (v^{n+½} + Δt/2·f^{n+1}/ρ) / (1 + αΔt/2)
// Eliminating v^{n+½}: (1 + αΔt/2)v^{n+1} = (1 − αΔt/2)v^n + Δt(f^n + f^{n+1})/(2ρ), i.e. the
// damping term is Crank–Nicolson, whose amplification (1 − αΔt/2)/(1 + αΔt/2) has modulus < 1.
#pragma once
#include "core/exact_sum.hpp"
#include <cstdint>
#include <vector>

#include "core/nodes.hpp"

namespace pd {

struct DampingFactors {
  double explicit_half;  // 1 − αΔt/2, multiplies v^n in the first half step
  double implicit_half;  // 1/(1 + αΔt/2), divides in the second half step
};

inline DampingFactors damping_factors(double alpha, double dt) {
  return {1.0 - 0.5 * alpha * dt, 1.0 / (1.0 + 0.5 * alpha * dt)};
}

// Σ ρ α V |v_c|² over components that are not prescribed (damping acts on free motion only;
// at a prescribed component the reaction takes whatever force is needed) [W].
inline double damping_power(double alpha, const std::vector<double>& density, const std::vector<double>& volume,
                            const Vec3Array& v, const std::array<std::vector<std::uint8_t>, 3>& fixed) {
  if (alpha == 0.0) return 0.0;
  double p = 0.0;
  for (std::size_t d = 0; d < 3; ++d) {  // one exact sum per component, continuing the last (core/exact_sum.hpp)
    ExactSum sum(p);
    for (std::size_t i = 0; i < volume.size(); ++i)
      if (!fixed[d][i]) sum.add(density[i] * volume[i] * v[d][i] * v[d][i]);
    p = sum.value();
  }
  return alpha * p;
}

}  // namespace pd
