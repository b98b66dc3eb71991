// The step-size controller of thesis eq. 2.8 (after T.I. Zohdi), one function for every integrator
// that iterates (the fixed-point adaptive step, Newton in quasi_static):
//   Φ_K = (TOL/ω_0)^{1/(p K_d)} / (ω_K/ω_0)^{1/(p K)}, with ω_0 = 1,
// where ω_K is the relative size of the K-th correction (eq. 2.6), K_d the desired number of
// iterations and p the order of convergence per step size. Δt ← Φ_K·Δt.
#pragma once
#include <cmath>

namespace pd {

// Φ_K; +inf when ω_K = 0 (the iteration is exact: the caller caps the step).
inline double zohdi_step_factor(double tol, double omega, int k, int kd, double p) {
  return omega > 0.0 ? std::pow(tol, 1.0 / (p * kd)) / std::pow(omega, 1.0 / (p * k)) : HUGE_VAL;
}

}  // namespace pd
