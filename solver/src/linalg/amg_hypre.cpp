// AMG by hypre's BoomerAMG (see linalg/amg.hpp): K copied into an IJ/ParCSR matrix on
// MPI_COMM_SELF (every rank that asks builds its own, serial hierarchy), one V-cycle per apply.
#include <mpi.h>

#include <HYPRE.h>
#include <HYPRE_IJ_mv.h>
#include <HYPRE_parcsr_ls.h>
// For the hierarchy's levels and sizes (run.log): hypre has no public getter for them.
#include <_hypre_parcsr_ls.h>

#include <cstdlib>
#include <limits>

#include "core/error.hpp"
#include "linalg/amg.hpp"

namespace pd {

namespace {

// hypre is an MPI library: MPI must be up before its first call. pdsolve built with PD_MPI has
// initialised it (parallel/mpi_session.cpp); a serial build, a test or a benchmark has not: then
// initialise it here, once, and finalise it at exit (after every hierarchy is destroyed).
void ensure_mpi() {
  int initialized = 0;
  MPI_Initialized(&initialized);
  if (initialized) return;
  int provided = 0;
  MPI_Init_thread(nullptr, nullptr, MPI_THREAD_FUNNELED, &provided);
  std::atexit([] {
    int finalized = 0;
    MPI_Finalized(&finalized);
    if (!finalized) MPI_Finalize();
  });
}

}  // namespace

struct AmgPreconditioner::Impl {
  HYPRE_IJMatrix ij_matrix = nullptr;
  HYPRE_ParCSRMatrix matrix = nullptr;
  HYPRE_IJVector ij_b = nullptr, ij_x = nullptr;
  HYPRE_ParVector b = nullptr, x = nullptr;
  HYPRE_Solver solver = nullptr;
  std::vector<HYPRE_Int> index;  // 0 … rows−1, for IJVector Set/GetValues
  int levels = 0;
  double complexity = 0.0;

  ~Impl() { release(); }
  void release() {
    if (solver) HYPRE_BoomerAMGDestroy(solver), solver = nullptr;
    if (ij_matrix) HYPRE_IJMatrixDestroy(ij_matrix), ij_matrix = nullptr;
    if (ij_b) HYPRE_IJVectorDestroy(ij_b), ij_b = nullptr;
    if (ij_x) HYPRE_IJVectorDestroy(ij_x), ij_x = nullptr;
    matrix = nullptr, b = x = nullptr;
    levels = 0, complexity = 0.0;
  }
};

AmgPreconditioner::AmgPreconditioner() : impl_(std::make_unique<Impl>()) {}
AmgPreconditioner::~AmgPreconditioner() = default;
bool AmgPreconditioner::available() { return true; }

// Calibration (docs/performance.md §8: pd_linear_solvers 64 40 40 --amg, a 102,400-node bar, 9.84·10⁷
// entries): the set-up added 2.59 GiB resident (hypre's copy of K, 12 bytes an entry, and the
// hierarchy of operator complexity 1.56 with its interpolation: 28 bytes per entry of K), on top
// of the assembled K it is built from (16 bytes an entry, freed after the set-up): a peak of some
// 44 bytes per entry of K. The guard counts the peak.
std::uint64_t AmgPreconditioner::estimated_bytes(std::uint64_t rows, std::uint64_t nonzeros) {
  return 45 * nonzeros + 200 * rows;
}

void AmgPreconditioner::clear() { impl_->release(); }
bool AmgPreconditioner::ready() const { return impl_->solver != nullptr; }
int AmgPreconditioner::levels() const { return impl_->levels; }
double AmgPreconditioner::operator_complexity() const { return impl_->complexity; }

void AmgPreconditioner::set_up(const SparseMatrix& K, int functions, const std::vector<std::uint8_t>& component) {
  if (K.rows > std::numeric_limits<HYPRE_Int>::max() || K.nonzeros() > static_cast<std::size_t>(std::numeric_limits<HYPRE_Int>::max()))
    throw Error("quasi_static.preconditioner: amg: the tangent has " + std::to_string(K.nonzeros()) +
                " entries, more than this hypre (32-bit indices) takes; use preconditioner: block_jacobi");
  ensure_mpi();
  impl_->release();
  Impl& m = *impl_;
  const auto n = static_cast<HYPRE_Int>(K.rows);
  HYPRE_IJMatrixCreate(MPI_COMM_SELF, 0, n - 1, 0, n - 1, &m.ij_matrix);
  HYPRE_IJMatrixSetObjectType(m.ij_matrix, HYPRE_PARCSR);
  std::vector<HYPRE_Int> sizes(static_cast<std::size_t>(n)), rows(static_cast<std::size_t>(n)),
      columns(K.column.size());
  for (HYPRE_Int r = 0; r < n; ++r) {
    const auto ru = static_cast<std::size_t>(r);
    sizes[ru] = static_cast<HYPRE_Int>(K.row_start[ru + 1] - K.row_start[ru]);
    rows[ru] = r;
  }
  for (std::size_t q = 0; q < K.column.size(); ++q) columns[q] = static_cast<HYPRE_Int>(K.column[q]);
  HYPRE_IJMatrixSetRowSizes(m.ij_matrix, sizes.data());
  HYPRE_IJMatrixInitialize(m.ij_matrix);
  HYPRE_IJMatrixSetValues(m.ij_matrix, n, sizes.data(), rows.data(), columns.data(), K.value.data());
  HYPRE_IJMatrixAssemble(m.ij_matrix);
  void* object = nullptr;
  HYPRE_IJMatrixGetObject(m.ij_matrix, &object);
  m.matrix = static_cast<HYPRE_ParCSRMatrix>(object);
  columns = {};
  for (HYPRE_IJVector* v : {&m.ij_b, &m.ij_x}) {
    HYPRE_IJVectorCreate(MPI_COMM_SELF, 0, n - 1, v);
    HYPRE_IJVectorSetObjectType(*v, HYPRE_PARCSR);
    HYPRE_IJVectorInitialize(*v);
    HYPRE_IJVectorAssemble(*v);
  }
  HYPRE_IJVectorGetObject(m.ij_b, &object), m.b = static_cast<HYPRE_ParVector>(object);
  HYPRE_IJVectorGetObject(m.ij_x, &object), m.x = static_cast<HYPRE_ParVector>(object);
  m.index = std::move(rows);

  HYPRE_BoomerAMGCreate(&m.solver);
  HYPRE_BoomerAMGSetPrintLevel(m.solver, 0);
  HYPRE_BoomerAMGSetMaxIter(m.solver, 1);  // one V-cycle: a fixed linear map, as CG needs
  HYPRE_BoomerAMGSetTol(m.solver, 0.0);    // no convergence test (no residual norms computed)
  HYPRE_BoomerAMGSetNumFunctions(m.solver, functions);  // x, y, z coarsened apart (the unknown approach)
  if (functions > 1) {
    // Each dof's component; hypre takes the array over (its destroy frees it), so hypre allocates it.
    HYPRE_Int* dof_function = hypre_CTAlloc(HYPRE_Int, n, HYPRE_MEMORY_HOST);
    for (HYPRE_Int r = 0; r < n; ++r) dof_function[r] = static_cast<HYPRE_Int>(component[static_cast<std::size_t>(r)]);
    HYPRE_BoomerAMGSetDofFunc(m.solver, dof_function);
  }
  // hypre's advice for 3D problems: a strength threshold of 0.5 (0.25 is for 2D), which keeps the
  // coarse operators sparse. The rest are hypre's defaults (HMIS coarsening, extended+i
  // interpolation, l1 Gauss–Seidel forward down / backward up: a symmetric cycle).
  HYPRE_BoomerAMGSetStrongThreshold(m.solver, functions == 3 ? 0.5 : 0.25);
  HYPRE_ClearAllErrors();
  HYPRE_BoomerAMGSetup(m.solver, m.matrix, m.b, m.x);
  if (HYPRE_GetError() != 0) {
    char message[256] = {};
    HYPRE_DescribeError(HYPRE_GetError(), message);
    HYPRE_ClearAllErrors();
    impl_->release();
    throw Error(std::string("hypre's BoomerAMG set-up failed (") + message + ")");
  }
  auto* data = static_cast<hypre_ParAMGData*>(static_cast<void*>(m.solver));
  m.levels = hypre_ParAMGDataNumLevels(data);
  double total = 0.0;
  for (int l = 0; l < m.levels; ++l) {
    hypre_ParCSRMatrix* A = hypre_ParAMGDataAArray(data)[l];
    total += static_cast<double>(hypre_CSRMatrixNumNonzeros(hypre_ParCSRMatrixDiag(A)) +
                                 hypre_CSRMatrixNumNonzeros(hypre_ParCSRMatrixOffd(A)));
  }
  m.complexity = K.nonzeros() > 0 ? total / static_cast<double>(K.nonzeros()) : 0.0;
}

void AmgPreconditioner::apply(const std::vector<double>& r, std::vector<double>& z) const {
  Impl& m = *impl_;
  z.resize(r.size());
  const auto n = static_cast<HYPRE_Int>(r.size());
  HYPRE_IJVectorSetValues(m.ij_b, n, m.index.data(), r.data());
  HYPRE_ParVectorSetConstantValues(m.x, 0.0);  // the cycle from zero: M⁻¹ r, not a correction
  HYPRE_BoomerAMGSolve(m.solver, m.matrix, m.b, m.x);
  HYPRE_IJVectorGetValues(m.ij_x, n, m.index.data(), z.data());
}

}  // namespace pd
