// CHOLMOD behind SparseCholesky (see cholesky.hpp).
#include "linalg/cholesky.hpp"

#include <cholmod.h>
#include <omp.h>

#include <algorithm>
#include <chrono>
#include <cstring>

#include "core/error.hpp"

namespace pd {

namespace {

// CHOLMOD 3 (SuiteSparse 5.12, Debian 12) opens its parallel loops with
// num_threads(CHOLMOD_OMP_NUM_THREADS), a compile-time 4 (cholmod_core.h) that ignores --threads: 4
// threads on this 2-core machine, whose wake-ups and futex waits took 60 % of the factorisation
// time of plate_with_hole-mixed at dx × 2 with --threads 1
// (docs/notes/2026-12-03-mixed-cut-cholmod.md, "CHOLMOD's threads"). With the dynamic adjustment
// on, libgomp gives a team at most nthreads-var (our --threads) threads, fewer when the machine's
// load average says the cores are busy. Only the calls into CHOLMOD run with it: our own loops keep
// exactly --threads. CHOLMOD's loops write disjoint entries, so the factor is the same bits for any
// team size (the hash runs check it).
class AtMostOurThreads {
 public:
  AtMostOurThreads() : was_dynamic_(omp_get_dynamic()) { omp_set_dynamic(1); }
  ~AtMostOurThreads() { omp_set_dynamic(was_dynamic_); }
  AtMostOurThreads(const AtMostOurThreads&) = delete;
  AtMostOurThreads& operator=(const AtMostOurThreads&) = delete;

 private:
  int was_dynamic_;
};

}  // namespace

struct SparseCholesky::Impl {
  cholmod_common common;
  cholmod_factor* factor = nullptr;
  std::vector<std::int64_t> row_start, column;  // the pattern the factor was analysed for
  Impl() {
    cholmod_l_start(&common);
    common.supernodal = CHOLMOD_SUPERNODAL;
    common.print = 0;
  }
  ~Impl() {
    if (factor) cholmod_l_free_factor(&factor, &common);
    cholmod_l_finish(&common);
  }
};

SparseCholesky::SparseCholesky() : impl_(std::make_unique<Impl>()) {}
SparseCholesky::~SparseCholesky() = default;

bool SparseCholesky::factorize(const SparseMatrix& K) {
  cholmod_common* cm = &impl_->common;
  const AtMostOurThreads cap;
  failure_.clear();
  // A CSR matrix stored whole is its own CSC transpose: hand CHOLMOD the arrays as they are and
  // let it read the upper triangle (stype = 1).
  cholmod_sparse A;
  std::memset(&A, 0, sizeof A);
  A.nrow = A.ncol = static_cast<std::size_t>(K.rows);
  A.nzmax = K.nonzeros();
  A.p = const_cast<std::int64_t*>(K.row_start.data());
  A.i = const_cast<std::int64_t*>(K.column.data());
  A.x = const_cast<double*>(K.value.data());
  A.stype = 1;
  A.itype = CHOLMOD_LONG;
  A.xtype = CHOLMOD_REAL;
  A.dtype = CHOLMOD_DOUBLE;
  A.sorted = 1;
  A.packed = 1;
  const bool same_pattern = impl_->factor && impl_->row_start == K.row_start && impl_->column == K.column;
  if (!same_pattern) {
    const auto start = std::chrono::steady_clock::now();
    if (impl_->factor) cholmod_l_free_factor(&impl_->factor, cm);
    impl_->factor = cholmod_l_analyze(&A, cm);
    analysis_seconds_ += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    if (!impl_->factor) throw Error("CHOLMOD could not analyse the tangent matrix (status " + std::to_string(cm->status) + ")");
    impl_->row_start = K.row_start;
    impl_->column = K.column;
    ++analyses_;
  }
  cholmod_l_factorize(&A, impl_->factor, cm);
  if (cm->status == CHOLMOD_NOT_POSDEF || impl_->factor->minor < impl_->factor->n) {
    failure_ = "the tangent is not positive definite at unknown " + std::to_string(impl_->factor->minor) + " of " +
               std::to_string(impl_->factor->n);
    return false;
  }
  if (cm->status < CHOLMOD_OK) throw Error("CHOLMOD failed to factorise the tangent (status " + std::to_string(cm->status) + ")");
  // A singular matrix (a free rigid motion) factorises in floating point with pivots at round-off
  // level instead of failing: CHOLMOD's estimate of the reciprocal condition number tells.
  const double rcond = cholmod_l_rcond(impl_->factor, cm);
  if (!(rcond > kSingularRcond)) {
    failure_ = "the tangent is singular to working precision (reciprocal condition estimate " + std::to_string(rcond) + ")";
    return false;
  }
  factor_nonzeros_ = cm->lnz;
  return true;
}

void SparseCholesky::solve(const std::vector<double>& b, std::vector<double>& x) const {
  x.resize(b.size());
  solve_columns(b, 1, x.data());
}

void SparseCholesky::solve_columns(const std::vector<double>& b, int columns, double* x) const {
  cholmod_common* cm = &impl_->common;
  const AtMostOurThreads cap;
  const std::size_t rows = impl_->factor->n;
  if (columns < 1 || b.size() != rows * static_cast<std::size_t>(columns))
    throw Error("SparseCholesky::solve_columns: " + std::to_string(b.size()) + " values for " + std::to_string(rows) +
                " rows × " + std::to_string(columns) + " columns");
  cholmod_dense B;
  std::memset(&B, 0, sizeof B);
  B.nrow = rows;
  B.ncol = static_cast<std::size_t>(columns);
  B.nzmax = b.size();
  B.d = rows;
  B.x = const_cast<double*>(b.data());
  B.xtype = CHOLMOD_REAL;
  B.dtype = CHOLMOD_DOUBLE;
  cholmod_dense* X = cholmod_l_solve(CHOLMOD_A, impl_->factor, &B, cm);
  if (!X) throw Error("CHOLMOD could not solve with the factorised tangent (status " + std::to_string(cm->status) + ")");
  const auto* values = static_cast<const double*>(X->x);
  std::copy(values, values + b.size(), x);
  cholmod_l_free_dense(&X, cm);
}

}  // namespace pd
