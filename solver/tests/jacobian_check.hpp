// Test helpers for linearised forces: a central finite difference of the operator's force, and
// norms and volume-weighted dot products of 3-component arrays.
#pragma once
#include <cmath>

#include "operator/force_operator.hpp"

namespace pdtest {

// (f(u + εx) − f(u − εx)) / 2ε at t: the derivative the Jacobian–vector product must equal.
inline pd::Vec3Array force_difference(const pd::ForceOperator& op, const pd::State& at, double t,
                                      const pd::Vec3Array& x, double eps) {
  pd::State plus = at, minus = at;
  for (std::size_t d = 0; d < 3; ++d)
    for (std::size_t i = 0; i < at.size(); ++i) {
      plus.u[d][i] += eps * x[d][i];
      minus.u[d][i] -= eps * x[d][i];
    }
  op.evaluate(plus, t);
  op.evaluate(minus, t);
  pd::Vec3Array out = pd::make_vec3(at.size());
  for (std::size_t d = 0; d < 3; ++d)
    for (std::size_t i = 0; i < at.size(); ++i) out[d][i] = (plus.f[d][i] - minus.f[d][i]) / (2.0 * eps);
  return out;
}

inline double norm(const pd::Vec3Array& a) {
  double s = 0.0;
  for (const auto& c : a)
    for (double v : c) s += v * v;
  return std::sqrt(s);
}

inline double distance(const pd::Vec3Array& a, const pd::Vec3Array& b) {
  double s = 0.0;
  for (std::size_t d = 0; d < 3; ++d)
    for (std::size_t i = 0; i < a[d].size(); ++i) s += (a[d][i] - b[d][i]) * (a[d][i] - b[d][i]);
  return std::sqrt(s);
}

// Σ_i V_i a_i·b_i: the force-vector pairing under which the stiffness is symmetric.
inline double volume_dot(const std::vector<double>& volume, const pd::Vec3Array& a, const pd::Vec3Array& b) {
  double s = 0.0;
  for (std::size_t d = 0; d < 3; ++d)
    for (std::size_t i = 0; i < volume.size(); ++i) s += volume[i] * a[d][i] * b[d][i];
  return s;
}

// A reproducible field of values in [−1, 1] per component (a hash of the index).
inline pd::Vec3Array pseudo_random(std::size_t n, unsigned salt) {
  pd::Vec3Array out = pd::make_vec3(n);
  for (std::size_t d = 0; d < 3; ++d)
    for (std::size_t i = 0; i < n; ++i) {
      std::uint64_t h = (i * 3 + d + 1 + 1000003ull * salt) * 0x9E3779B97F4A7C15ull;
      h ^= h >> 31;
      h *= 0xBF58476D1CE4E5B9ull;
      h ^= h >> 29;
      out[d][i] = 2.0 * (static_cast<double>(h >> 11) * 0x1.0p-53) - 1.0;
    }
  return out;
}

}  // namespace pdtest
