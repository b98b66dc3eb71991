// Sparse Cholesky factorisation K = L Lᵀ of a symmetric positive definite matrix by CHOLMOD
// (SuiteSparse, Debian's libsuitesparse-dev): supernodal, fill-reducing ordering (AMD, or METIS
// nested dissection where CHOLMOD finds it better), the symbolic analysis kept and reused while
// the sparsity pattern stays the same. The only code that calls CHOLMOD.
#pragma once
#include <memory>
#include <string>
#include <vector>

#include "linalg/sparse_matrix.hpp"

namespace pd {

class SparseCholesky {
 public:
  // Below this reciprocal condition estimate the matrix counts as singular (a rigid motion left
  // free gives ~1e-16; a well-held body of 10⁶ nodes stays far above).
  static constexpr double kSingularRcond = 1e-14;

  SparseCholesky();
  ~SparseCholesky();
  SparseCholesky(const SparseCholesky&) = delete;
  SparseCholesky& operator=(const SparseCholesky&) = delete;

  // Factorises K (its upper triangle is read). False when K is not positive definite (then
  // failure() says at which column): a singular or indefinite tangent, e.g. a body free to move.
  bool factorize(const SparseMatrix& K);
  // x = K⁻¹ b with the last successful factorisation.
  void solve(const std::vector<double>& b, std::vector<double>& x) const;
  // X = K⁻¹ B for `columns` right-hand sides at once (B and X column-major, rows × columns; X is the
  // caller's memory): one pass of CHOLMOD's supernodal solve over L for all of them (BLAS-3 on each
  // supernode).
  void solve_columns(const std::vector<double>& B, int columns, double* X) const;

  const std::string& failure() const { return failure_; }
  int analyses() const { return analyses_; }            // symbolic analyses so far (orderings)
  double analysis_seconds() const { return analysis_seconds_; }  // wall time of those analyses
  double factor_nonzeros() const { return factor_nonzeros_; }  // entries of L

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
  std::string failure_;
  int analyses_ = 0;
  double analysis_seconds_ = 0.0;
  double factor_nonzeros_ = 0.0;
};

}  // namespace pd
