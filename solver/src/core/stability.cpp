// Lanczos on the material's linearised operator for ω_max², and the exact explicit step 2/ω_max.
#include "core/stability.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>

namespace pd {

namespace {

// Serial sums in node order: the Lanczos coefficients, and so dt, do not depend on the thread count.
double dot(const Vec3Array& a, const Vec3Array& b) {
  double s = 0.0;
  for (std::size_t d = 0; d < 3; ++d)
    for (std::size_t i = 0; i < a[d].size(); ++i) s += a[d][i] * b[d][i];
  return s;
}

// Number of eigenvalues of the symmetric tridiagonal (alpha, beta) below x (Sturm sequence).
int count_below(const std::vector<double>& alpha, const std::vector<double>& beta, double x) {
  int count = 0;
  double q = 1.0;
  for (std::size_t k = 0; k < alpha.size(); ++k) {
    const double b2 = k == 0 ? 0.0 : beta[k - 1] * beta[k - 1];
    q = alpha[k] - x - (k == 0 ? 0.0 : b2 / q);
    if (q == 0.0) q = -1e-300;  // the standard nudge off an exact zero pivot
    if (q < 0.0) ++count;
  }
  return count;
}

// Largest eigenvalue of the tridiagonal by bisection inside its Gershgorin interval.
double tridiagonal_max(const std::vector<double>& alpha, const std::vector<double>& beta) {
  double lo = std::numeric_limits<double>::max(), hi = -lo;
  for (std::size_t k = 0; k < alpha.size(); ++k) {
    const double r = (k > 0 ? std::fabs(beta[k - 1]) : 0.0) + (k + 1 < alpha.size() ? std::fabs(beta[k]) : 0.0);
    lo = std::min(lo, alpha[k] - r);
    hi = std::max(hi, alpha[k] + r);
  }
  const int n = static_cast<int>(alpha.size());
  for (int it = 0; it < 200 && hi - lo > 1e-15 * std::max(std::fabs(hi), std::fabs(lo)); ++it) {
    const double mid = 0.5 * (lo + hi);
    if (count_below(alpha, beta, mid) == n) hi = mid;  // every eigenvalue is below mid
    else lo = mid;
  }
  return 0.5 * (lo + hi);
}

}  // namespace

void apply_symmetric_operator(const Model& m, const std::array<double, 3>& period, const Vec3Array& x,
                              Vec3Array& y) {
  m.bond_model->apply_reference_stiffness(m, period, x, y);
}

LanczosReport largest_eigenvalue(const Model& m, std::array<double, 3> period) {
  const std::size_t n = m.nodes.size();
  LanczosReport report;
  if (n == 0 || m.bonds.directed() == 0) return report;
  // Lanczos without re-orthogonalisation: the extreme Ritz value converges first and loss of
  // orthogonality only duplicates converged values, it does not spoil the largest one.
  Vec3Array v = make_vec3(n), v_prev = make_vec3(n), w = make_vec3(n);
  // A fixed pseudo-random start (a hash of the index): reproducible, and not orthogonal to the
  // top mode, which a smooth or constant start on a lattice could be.
  double norm = 0.0;
  for (std::size_t d = 0; d < 3; ++d)
    for (std::size_t i = 0; i < n; ++i) {
      std::uint64_t h = (i * 3 + d + 1) * 0x9E3779B97F4A7C15ull;
      h ^= h >> 31;
      h *= 0xBF58476D1CE4E5B9ull;
      h ^= h >> 29;
      v[d][i] = static_cast<double>(h >> 11) * 0x1.0p-53 - 0.5;
    }
  norm = std::sqrt(dot(v, v));
  for (auto& c : v)
    for (double& x : c) x /= norm;

  std::vector<double> alpha, beta;
  constexpr int kMaxIterations = 600;
  const int max_iterations = static_cast<int>(std::min<std::size_t>(kMaxIterations, 3 * n));
  double previous = 0.0, theta = 0.0;
  int stable_for = 0;
  double beta_prev = 0.0;
  for (int it = 0; it < max_iterations; ++it) {
    apply_symmetric_operator(m, period, v, w);
    ++report.iterations;
    const double a = dot(w, v);
    for (std::size_t d = 0; d < 3; ++d)
      for (std::size_t i = 0; i < n; ++i) w[d][i] -= a * v[d][i] + beta_prev * v_prev[d][i];
    alpha.push_back(a);
    const double b = std::sqrt(dot(w, w));
    theta = tridiagonal_max(alpha, beta);
    // Converged when the largest Ritz value has not moved by 1e-10 relative for 10 iterations,
    // or when the Krylov space is invariant (b = 0: the Ritz values are exact).
    stable_for = std::fabs(theta - previous) <= 1e-10 * theta ? stable_for + 1 : 0;
    previous = theta;
    if (stable_for >= 10 || b <= 1e-14 * std::max(theta, 1e-300)) {
      report.converged = true;
      break;
    }
    beta.push_back(b);
    beta_prev = b;
    std::swap(v_prev, v);
    for (std::size_t d = 0; d < 3; ++d)
      for (std::size_t i = 0; i < n; ++i) v[d][i] = w[d][i] / b;
  }
  report.lambda_max = theta;
  return report;
}

double exact_time_step(const Model& m) {
  const LanczosReport r = largest_eigenvalue(m);
  if (!(r.lambda_max > 0.0)) return std::numeric_limits<double>::infinity();
  return 2.0 / std::sqrt(r.lambda_max);  // velocity Verlet on ü = −ω²u: stable for ωΔt < 2
}

}  // namespace pd
