// Lanczos on the material's linearised operator for ω_max², and the exact explicit step 2/ω_max.
#include "core/stability.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <string>

#include "core/error.hpp"
#include "parallel/decomposed.hpp"
#include "parallel/local_model.hpp"

namespace pd {

namespace {

// The Lanczos coefficients' sums: a plain sum of the products in the serial order — component by
// component, in global node order — so that dt does not depend on the thread or rank count. Not
// an exact sum (core/exact_sum.hpp): ω_max² is the end of hundreds of iterations, and any other
// rounding of a single α or β moves it by an ulp or more, which would change every dt: exact run
// and the adaptive step's default Δt_max from what they have always been. A decomposed run
// therefore gathers the owned products to rank 0 in global order (Decomposed::gather, 24 bytes a
// node there while it sums), which adds them as the serial loop does and sends the sum to all.
double dot(const Vec3Array& a, const Vec3Array& b, const Decomposed* dec) {
  if (!dec) {
    double s = 0.0;
    for (std::size_t d = 0; d < 3; ++d)
      for (std::size_t i = 0; i < a[d].size(); ++i) s += a[d][i] * b[d][i];
    return s;
  }
  std::vector<double> products(3 * a[0].size());
  for (std::int32_t l : dec->piece().owned_local)
    for (std::size_t d = 0; d < 3; ++d) {
      const auto i = static_cast<std::size_t>(l);
      products[3 * i + d] = a[d][i] * b[d][i];
    }
  const std::vector<double> ordered = dec->gather(products, 3);  // node g's at 3g …, on rank 0
  std::vector<double> s{0.0};
  const std::size_t n = ordered.size() / 3;
  for (std::size_t d = 0; d < 3; ++d)
    for (std::size_t g = 0; g < n; ++g) s[0] += ordered[3 * g + d];
  dec->broadcast(s);
  return s[0];
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

LanczosReport largest_eigenvalue(const Model& m, std::array<double, 3> period, const Decomposed* dec) {
  // On a piece: its local nodes (owned and ghosts); the counts that steer the iteration are the
  // whole model's, so every rank iterates alike.
  const std::size_t n = m.nodes.size();
  const auto whole_nodes = static_cast<std::size_t>(dec ? dec->piece().global_nodes : static_cast<std::int64_t>(n));
  const std::int64_t directed = dec ? dec->total(m.bonds.directed()) : m.bonds.directed();
  LanczosReport report;
  if (whole_nodes == 0 || directed == 0) return report;
  // The law's product reads x at a row's partners, ghosts included: PMB's one sweep does. LPS's
  // second sweep reads its partners' δθ too, which would have to travel between the sweeps.
  if (dec && m.bond_model->name() != "pmb")
    throw Error("time.dt: the exact limit (Lanczos) on a rank's piece is written for pmb bonds only, not " +
                m.bond_model->name() + ": run this case on one rank (core/stability.cpp)");
  // Lanczos without re-orthogonalisation: the extreme Ritz value converges first and loss of
  // orthogonality only duplicates converged values, it does not spoil the largest one.
  Vec3Array v = make_vec3(n), v_prev = make_vec3(n), w = make_vec3(n);
  // A fixed pseudo-random start (a hash of the global node number): reproducible, the same on any
  // number of ranks, and not orthogonal to the top mode, which a smooth or constant start on a
  // lattice could be.
  for (std::size_t d = 0; d < 3; ++d)
    for (std::size_t i = 0; i < n; ++i) {
      const std::uint64_t g = dec ? static_cast<std::uint64_t>(dec->piece().global[i]) : i;
      std::uint64_t h = (g * 3 + d + 1) * 0x9E3779B97F4A7C15ull;
      h ^= h >> 31;
      h *= 0xBF58476D1CE4E5B9ull;
      h ^= h >> 29;
      v[d][i] = static_cast<double>(h >> 11) * 0x1.0p-53 - 0.5;
    }
  const double norm = std::sqrt(dot(v, v, dec));
  for (auto& c : v)
    for (double& x : c) x /= norm;

  std::vector<double> alpha, beta;
  constexpr int kMaxIterations = 600;
  const int max_iterations = static_cast<int>(std::min<std::size_t>(kMaxIterations, 3 * whole_nodes));
  double previous = 0.0, theta = 0.0;
  int stable_for = 0;
  double beta_prev = 0.0;
  for (int it = 0; it < max_iterations; ++it) {
    // A ghost's entries of v are its owner's: an owned row of the product is the serial row.
    if (dec) dec->update_ghosts(v);
    apply_symmetric_operator(m, period, v, w);
    ++report.iterations;
    const double a = dot(w, v, dec);
    for (std::size_t d = 0; d < 3; ++d)
      for (std::size_t i = 0; i < n; ++i) w[d][i] -= a * v[d][i] + beta_prev * v_prev[d][i];
    alpha.push_back(a);
    const double b = std::sqrt(dot(w, w, dec));
    // Every rank holds the same α and β, so the same Ritz value and the same decision below.
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

double exact_time_step(const Model& m, const Decomposed* dec) {
  const LanczosReport r = largest_eigenvalue(m, {0.0, 0.0, 0.0}, dec);
  if (!(r.lambda_max > 0.0)) return std::numeric_limits<double>::infinity();
  return 2.0 / std::sqrt(r.lambda_max);  // velocity Verlet on ü = −ω²u: stable for ωΔt < 2
}

}  // namespace pd
