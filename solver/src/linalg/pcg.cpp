// Preconditioned conjugate gradients and the block-Jacobi preconditioner (see pcg.hpp).
#include "linalg/pcg.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace pd {

namespace {

// The chunk of the fixed summation order: large enough that OpenMP's overhead is small, fixed so
// that the partial sums (and hence the bits) are those of any thread count.
constexpr std::int64_t kChunk = 4096;
// Below this many unknowns the vector loops run on one thread (OpenMP's fork and barrier cost more
// than the loop); the bits are the same either way.
constexpr std::int64_t kParallelFrom = 32768;

// Block g of size k ≤ 3 (row-major in a 3×3 frame) → its inverse, by A = L D Lᵀ (L unit lower):
// d_j = a_jj − Σ_{m<j} l_jm² d_m, l_ij = (a_ij − Σ_{m<j} l_im l_jm d_m)/d_j; then A⁻¹ column by
// column from L y = e, D z = y, Lᵀ x = z. False at a pivot ≤ tiny × the largest diagonal entry.
bool invert_ldlt(const double* a, int k, double* inverse) {
  double l[3][3] = {}, d[3] = {};
  double largest = 0.0;
  for (int j = 0; j < k; ++j) largest = std::max(largest, std::fabs(a[3 * j + j]));
  for (int j = 0; j < k; ++j) {
    d[j] = a[3 * j + j];
    for (int m = 0; m < j; ++m) d[j] -= l[j][m] * l[j][m] * d[m];
    if (!(d[j] > 1e-12 * largest)) return false;
    l[j][j] = 1.0;
    for (int i = j + 1; i < k; ++i) {
      double v = a[3 * i + j];
      for (int m = 0; m < j; ++m) v -= l[i][m] * l[j][m] * d[m];
      l[i][j] = v / d[j];
    }
  }
  for (int c = 0; c < k; ++c) {
    double y[3] = {};
    for (int i = 0; i < k; ++i) {
      y[i] = (i == c) ? 1.0 : 0.0;
      for (int m = 0; m < i; ++m) y[i] -= l[i][m] * y[m];
    }
    for (int i = 0; i < k; ++i) y[i] /= d[i];
    for (int i = k - 1; i >= 0; --i)
      for (int m = i + 1; m < k; ++m) y[i] -= l[m][i] * y[m];
    for (int i = 0; i < k; ++i) inverse[3 * i + c] = y[i];
  }
  return true;
}

// y = x + beta·y and x += alpha·p: element by element, the same bits for any thread count.
void xpby(const std::vector<double>& x, double beta, std::vector<double>& y) {
  const auto n = static_cast<std::int64_t>(x.size());
#pragma omp parallel for schedule(static) if (n >= kParallelFrom)
  for (std::int64_t k = 0; k < n; ++k) y[static_cast<std::size_t>(k)] = x[static_cast<std::size_t>(k)] + beta * y[static_cast<std::size_t>(k)];
}

void axpy(double alpha, const std::vector<double>& x, std::vector<double>& y) {
  const auto n = static_cast<std::int64_t>(x.size());
#pragma omp parallel for schedule(static) if (n >= kParallelFrom)
  for (std::int64_t k = 0; k < n; ++k) y[static_cast<std::size_t>(k)] += alpha * x[static_cast<std::size_t>(k)];
}

}  // namespace

namespace {

// Σ term(k) for k < n in the fixed order of pcg.hpp: each kChunk-long chunk summed serially, the
// chunk sums added serially in chunk order.
template <class Term>
double chunked_sum(std::int64_t n, const Term& term) {
  const std::int64_t chunks = (n + kChunk - 1) / kChunk;
  std::vector<double> partial(static_cast<std::size_t>(chunks), 0.0);
#pragma omp parallel for schedule(static) if (n >= kParallelFrom)
  for (std::int64_t c = 0; c < chunks; ++c) {
    double sum = 0.0;
    const std::int64_t end = std::min(n, (c + 1) * kChunk);
    for (std::int64_t k = c * kChunk; k < end; ++k) sum += term(static_cast<std::size_t>(k));
    partial[static_cast<std::size_t>(c)] = sum;
  }
  double sum = 0.0;
  for (double p : partial) sum += p;
  return sum;
}

}  // namespace

double fixed_order_dot(const std::vector<double>& a, const std::vector<double>& b) {
  return chunked_sum(static_cast<std::int64_t>(a.size()), [&](std::size_t k) { return a[k] * b[k]; });
}

void BlockJacobi::build(const std::vector<std::int64_t>& first, const std::vector<double>& blocks) {
  first_ = first;
  const auto groups = static_cast<std::int64_t>(first.empty() ? 0 : first.size() - 1);
  inverse_.assign(static_cast<std::size_t>(9 * groups), 0.0);
  std::int64_t fallbacks = 0;
#pragma omp parallel for schedule(static) reduction(+ : fallbacks) if (groups >= kParallelFrom / 3)
  for (std::int64_t g = 0; g < groups; ++g) {
    const auto gu = static_cast<std::size_t>(g);
    const int k = static_cast<int>(first[gu + 1] - first[gu]);
    const double* a = &blocks[9 * gu];
    double* inverse = &inverse_[9 * gu];
    if (invert_ldlt(a, k, inverse)) continue;
    ++fallbacks;
    for (int q = 0; q < 9; ++q) inverse[q] = 0.0;
    for (int j = 0; j < k; ++j) inverse[3 * j + j] = a[3 * j + j] > 0.0 ? 1.0 / a[3 * j + j] : 1.0;
  }
  fallbacks_ = fallbacks;
}

void BlockJacobi::apply(const std::vector<double>& r, std::vector<double>& z) const {
  z.resize(r.size());
  const auto groups = static_cast<std::int64_t>(first_.empty() ? 0 : first_.size() - 1);
#pragma omp parallel for schedule(static) if (groups >= kParallelFrom / 3)
  for (std::int64_t g = 0; g < groups; ++g) {
    const auto gu = static_cast<std::size_t>(g);
    const auto at = static_cast<std::size_t>(first_[gu]);
    const int k = static_cast<int>(first_[gu + 1] - first_[gu]);
    const double* inverse = &inverse_[9 * gu];
    for (int i = 0; i < k; ++i) {
      double sum = 0.0;
      for (int j = 0; j < k; ++j) sum += inverse[3 * i + j] * r[at + static_cast<std::size_t>(j)];
      z[at + static_cast<std::size_t>(i)] = sum;
    }
  }
}

std::string PcgResult::message() const {
  char buffer[256];
  switch (status) {
    case kConverged:
      std::snprintf(buffer, sizeof buffer, "CG converged in %d iterations (residual %.3g from %.3g)", iterations, residual,
                    initial_residual);
      break;
    case kNotConverged:
      std::snprintf(buffer, sizeof buffer, "CG did not converge in %d iterations (residual %.3g from %.3g)", iterations,
                    residual, initial_residual);
      break;
    case kIndefinite:
      std::snprintf(buffer, sizeof buffer,
                    "CG met a direction of non-positive curvature (pᵀAp = %.3g) at iteration %d: the tangent is "
                    "not positive definite (residual %.3g from %.3g)",
                    curvature, iterations, residual, initial_residual);
      break;
  }
  return buffer;
}

PcgResult preconditioned_cg(const LinearOperator& A, const Preconditioner& M, const std::vector<double>& b,
                            std::vector<double>& x, const PcgSettings& settings) {
  PcgResult result;
  const DotProduct dot = settings.dot ? settings.dot : DotProduct(fixed_order_dot);
  const std::size_t n = b.size();
  std::vector<double> r(n), z, p, q(n);
  if (x.size() != n) {
    x.assign(n, 0.0);
    r = b;
  } else {
    A(x, q);
    for (std::size_t k = 0; k < n; ++k) r[k] = b[k] - q[k];
  }
  double rr = dot(r, r);
  result.initial_residual = result.residual = std::sqrt(rr);
  const double target = std::max(settings.relative_tol * std::sqrt(dot(b, b)), settings.absolute_tol);
  if (result.residual <= target) return result.status = PcgResult::kConverged, result;
  M.apply(r, z);
  p = z;
  double rz = dot(r, z);
  for (int it = 1; it <= settings.max_iterations; ++it) {
    A(p, q);
    const double curvature = dot(p, q);
    if (!(curvature > 0.0)) {  // A is not positive definite along p (or a NaN came in)
      result.status = PcgResult::kIndefinite;
      result.curvature = curvature;
      return result;
    }
    const double alpha = rz / curvature;
    axpy(alpha, p, x);
    axpy(-alpha, q, r);
    result.iterations = it;
    rr = dot(r, r);
    result.residual = std::sqrt(rr);
    if (result.residual <= target) return result.status = PcgResult::kConverged, result;
    M.apply(r, z);
    const double rz_next = dot(r, z);
    const double beta = rz_next / rz;
    rz = rz_next;
    xpby(z, beta, p);  // p = z + β p
  }
  result.status = PcgResult::kNotConverged;
  return result;
}

}  // namespace pd
