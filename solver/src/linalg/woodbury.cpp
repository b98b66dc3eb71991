// The Woodbury correction (see woodbury.hpp): S's LU factorisation and solves by LAPACK.
#include "linalg/woodbury.hpp"

#include <cmath>
#include <algorithm>
#include <cstddef>
#include <string>

#include "core/error.hpp"

// LAPACK (Debian's liblapack, through its Fortran interface; Debian 12 ships no lapack.h). The
// trailing size_t is the hidden length of each character argument (gfortran's convention).
extern "C" {
void dgetrf_(const int* m, const int* n, double* a, const int* lda, int* ipiv, int* info);
void dgetrs_(const char* trans, const int* n, const int* nrhs, const double* a, const int* lda, const int* ipiv,
             double* b, const int* ldb, int* info, std::size_t trans_length);
void dgecon_(const char* norm, const int* n, const double* a, const int* lda, const double* anorm, double* rcond,
             double* work, int* iwork, int* info, std::size_t norm_length);
}

namespace pd {

void Woodbury::clear() {
  plus_.clear(), minus_.clear(), block_of_.clear(), block_size_.clear(), c_.clear();
  w_.clear(), lu_.clear(), pivots_.clear();
  solved_ = 0;
}

void Woodbury::add_block(const std::int64_t* plus, const std::int64_t* minus, const double* c, int m) {
  if (m < 1 || m > 3) throw Error("Woodbury::add_block: a block of " + std::to_string(m) + " columns (1 to 3)");
  const int first = columns();
  for (int a = 0; a < m; ++a) {
    plus_.push_back(plus[a]);
    minus_.push_back(minus[a]);
    block_of_.push_back(first);
    block_size_.push_back(m);
    for (int b = 0; b < 3; ++b) c_.push_back(b < m ? c[a * m + b] : 0.0);
  }
}

double Woodbury::difference(const double* x, int a) const {
  const auto i = static_cast<std::size_t>(a);
  return (plus_[i] >= 0 ? x[plus_[i]] : 0.0) - (minus_[i] >= 0 ? x[minus_[i]] : 0.0);
}

bool Woodbury::update(const SparseCholesky& factor, std::size_t rows) {
  const int r = columns();
  if (solved_ > 0 && rows != rows_) throw Error("Woodbury::update: the rows changed since the last update");
  rows_ = rows;
  // W's new columns: K⁻¹ applied to U's columns added since the last update, in one solve.
  const int fresh = r - solved_;
  if (fresh > 0) {
    std::vector<double> u(rows * static_cast<std::size_t>(fresh), 0.0);
    for (int a = 0; a < fresh; ++a) {
      const auto column = static_cast<std::size_t>(solved_ + a);
      double* col = u.data() + static_cast<std::size_t>(a) * rows;
      if (plus_[column] >= 0) col[plus_[column]] = 1.0;
      if (minus_[column] >= 0) col[minus_[column]] = -1.0;
    }
    // W's new columns straight after the old ones (column-major): no copy of them.
    const std::size_t old_size = w_.size();
    w_.resize(old_size + u.size());
    factor.solve_columns(u, fresh, w_.data() + old_size);
    solved_ = r;
  }
  if (r == 0) return true;
  // S = I − C Uᵀ W, column-major; C's rows are those of each column's block.
  const auto n = static_cast<std::size_t>(r);
  std::vector<double> g(n * n);  // Uᵀ W: g[a + b n] = U_aᵀ W_b
  for (std::size_t b = 0; b < n; ++b)
    for (std::size_t a = 0; a < n; ++a) g[a + b * n] = difference(w_.data() + b * rows, static_cast<int>(a));
  lu_.assign(n * n, 0.0);
  for (std::size_t b = 0; b < n; ++b)
    for (std::size_t a = 0; a < n; ++a) {
      const auto first = static_cast<std::size_t>(block_of_[a]);
      double cg = 0.0;
      for (int q = 0; q < block_size_[a]; ++q) cg += c_[3 * a + static_cast<std::size_t>(q)] * g[first + static_cast<std::size_t>(q) + b * n];
      lu_[a + b * n] = (a == b ? 1.0 : 0.0) - cg;
    }
  double norm1 = 0.0;  // ‖S‖₁, for the condition estimate
  for (std::size_t b = 0; b < n; ++b) {
    double sum = 0.0;
    for (std::size_t a = 0; a < n; ++a) sum += std::fabs(lu_[a + b * n]);
    norm1 = std::max(norm1, sum);
  }
  pivots_.assign(n, 0);
  int info = 0;
  dgetrf_(&r, &r, lu_.data(), &r, pivots_.data(), &info);
  if (info != 0) return false;  // an exactly zero pivot
  double rcond = 0.0;
  std::vector<double> work(4 * n);
  std::vector<int> iwork(n);
  dgecon_("1", &r, lu_.data(), &r, &norm1, &rcond, work.data(), iwork.data(), &info, 1);
  return info == 0 && rcond >= kSingularRcond;
}

void Woodbury::apply(std::vector<double>& y) const {
  const int r = columns();
  if (r == 0) return;
  if (solved_ != r || y.size() != rows_) throw Error("Woodbury::apply before update() or with the wrong size");
  const auto n = static_cast<std::size_t>(r);
  std::vector<double> t(n), z(n);
  for (std::size_t a = 0; a < n; ++a) t[a] = difference(y.data(), static_cast<int>(a));
  for (std::size_t a = 0; a < n; ++a) {  // C Uᵀ y
    const auto first = static_cast<std::size_t>(block_of_[a]);
    double sum = 0.0;
    for (int q = 0; q < block_size_[a]; ++q) sum += c_[3 * a + static_cast<std::size_t>(q)] * t[first + static_cast<std::size_t>(q)];
    z[a] = sum;
  }
  const int one = 1;
  int info = 0;
  dgetrs_("N", &r, &one, lu_.data(), &r, pivots_.data(), z.data(), &r, &info, 1);
  if (info != 0) throw Error("LAPACK dgetrs failed (info " + std::to_string(info) + ")");
  for (std::size_t b = 0; b < n; ++b) {
    const double* w = w_.data() + b * rows_;
    const double zb = z[b];
    for (std::size_t q = 0; q < rows_; ++q) y[q] += w[q] * zb;
  }
}

}  // namespace pd
