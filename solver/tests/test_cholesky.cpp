// SparseCholesky (linalg/cholesky.hpp) runs CHOLMOD on at most our --threads threads: CHOLMOD 3
// asks for teams of 4 with a num_threads clause, which on a 2-core machine cost 60 % of a
// factorisation in thread wake-ups (docs/notes/2026-12-03-mixed-cut-cholmod.md,
// "CHOLMOD's threads").
#include <gtest/gtest.h>
#include <omp.h>

#include <cmath>
#include <filesystem>

#include "lattice.hpp"
#include "linalg/cholesky.hpp"
#include "one_thread.hpp"
#include "operator/force_operator.hpp"

namespace {

constexpr double kDx = 1e-3;

// Threads of this process now (/proc/self/task has one entry per thread).
int process_threads() {
  int n = 0;
  for ([[maybe_unused]] const auto& entry : std::filesystem::directory_iterator("/proc/self/task")) ++n;
  return n;
}

// A 2D lattice of 70 × 70 nodes, δ = 3.015 dx (the plate's horizon), its first two columns held:
// 9 520 free dofs, whose factor has supernodes large enough for CHOLMOD's parallel loops.
pd::Model held_plate() {
  return pdtest::held_at_left(pdtest::lattice_case(2, "plane_stress", kDx, 3.015 * kDx, 1e9, 1000.0, -1.0),
                              pdtest::cubic_lattice(70, 70, 1, kDx, 2), kDx);
}

}  // namespace

TEST(Cholesky, RunsOnNoMoreThreadsThanAskedAndSolves) {
  pdtest::OneThread one;
  pd::Model m = held_plate();
  const pd::ForceOperator op(m);
  pd::State s(m.nodes.size());
  for (std::size_t i = 0; i < s.size(); ++i) s.u[0][i] = 1e-4 * m.nodes.x[0][i];
  const pd::FreeDofs dofs = pd::FreeDofs::of(s.size(), 2, m.conditions.fixed);
  const pd::SparseMatrix K = op.assemble_stiffness(s, 0.0, dofs);
  ASSERT_EQ(K.rows, 2 * 70 * 68);

  const int before = process_threads();
  pd::SparseCholesky cholesky;
  ASSERT_TRUE(cholesky.factorize(K)) << cholesky.failure();
  std::vector<double> b(static_cast<std::size_t>(K.rows)), x;
  for (std::size_t r = 0; r < b.size(); ++r) b[r] = std::sin(0.37 * static_cast<double>(r));
  cholesky.solve(b, x);
  // One thread asked: CHOLMOD started no thread of its own (its default teams are 4).
  EXPECT_EQ(process_threads(), before);
  // Our own setting is left as it was.
  EXPECT_EQ(omp_get_dynamic(), 0);
  EXPECT_EQ(omp_get_max_threads(), 1);

  // And the factor is a factor: K x = b to round-off.
  std::vector<double> kx(b.size(), 0.0);
  double residual = 0.0, norm_b = 0.0;
  for (std::int64_t r = 0; r < K.rows; ++r) {
    for (std::int64_t q = K.row_start[static_cast<std::size_t>(r)]; q < K.row_start[static_cast<std::size_t>(r) + 1]; ++q)
      kx[static_cast<std::size_t>(r)] += K.value[static_cast<std::size_t>(q)] * x[static_cast<std::size_t>(K.column[static_cast<std::size_t>(q)])];
    residual = std::max(residual, std::fabs(kx[static_cast<std::size_t>(r)] - b[static_cast<std::size_t>(r)]));
    norm_b = std::max(norm_b, std::fabs(b[static_cast<std::size_t>(r)]));
  }
  EXPECT_LT(residual, 1e-8 * norm_b);
}
