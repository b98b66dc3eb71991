// Preconditioned CG (linalg/pcg.hpp): on the assembled tangent of a held 3D lattice it gives
// CHOLMOD's solution to 1e-10; the block-Jacobi blocks the operator builds matrix-free are the
// assembled matrix's diagonal blocks; an indefinite matrix and an iteration cap are reported as
// such; the fixed-order dot product is bitwise the same for 1 and 2 threads.
#include <gtest/gtest.h>
#include <omp.h>

#include <cmath>
#include <cstring>

#include "jacobian_check.hpp"
#include "lattice.hpp"
#include "linalg/cholesky.hpp"
#include "linalg/pcg.hpp"
#include "one_thread.hpp"
#include "operator/force_operator.hpp"

namespace {

constexpr double kDx = 1e-3;

// A 10×5×5 lattice, δ = 3.015dx, its first two x-layers held in every direction.
pd::Model held_block() {
  return pdtest::held_at_left(pdtest::lattice_case(3, "3d", kDx, 3.015 * kDx, 1e9, 1000.0, -1.0),
                              pdtest::cubic_lattice(10, 5, 5, kDx, 3), kDx);
}

// The 3×3 diagonal blocks of a CSR matrix over node-numbered dofs (groups as BlockJacobi wants).
void diagonal_blocks(const pd::SparseMatrix& K, const std::vector<std::int64_t>& first, std::vector<double>& blocks) {
  blocks.assign(9 * (first.size() - 1), 0.0);
  for (std::size_t g = 0; g + 1 < first.size(); ++g)
    for (std::int64_t r = first[g]; r < first[g + 1]; ++r)
      for (std::int64_t q = K.row_start[static_cast<std::size_t>(r)]; q < K.row_start[static_cast<std::size_t>(r) + 1]; ++q) {
        const std::int64_t c = K.column[static_cast<std::size_t>(q)];
        if (c >= first[g] && c < first[g + 1])
          blocks[9 * g + static_cast<std::size_t>(3 * (r - first[g]) + (c - first[g]))] = K.value[static_cast<std::size_t>(q)];
      }
}

}  // namespace

TEST(Pcg, SolvesTheHeldLatticeTangentAsCholmodDoes) {
  pdtest::OneThread one;
  pd::Model m = held_block();
  const pd::ForceOperator op(m);
  pd::State s(m.nodes.size());
  const pd::Vec3Array wiggle = pdtest::pseudo_random(s.size(), 5);
  for (std::size_t d = 0; d < 3; ++d)
    for (std::size_t i = 0; i < s.size(); ++i) s.u[d][i] = 1e-3 * m.nodes.x[d][i] + 1e-7 * wiggle[d][i];
  const pd::FreeDofs dofs = pd::FreeDofs::of(s.size(), 3, m.conditions.fixed);
  const pd::SparseMatrix K = op.assemble_stiffness(s, 0.0, dofs);
  ASSERT_GT(K.rows, 0);

  // The matrix-free blocks are the assembled diagonal blocks (stretched everywhere: the definite
  // variant the preconditioner uses is the exact tangent).
  std::vector<std::int64_t> first;
  std::vector<double> blocks, assembled;
  ASSERT_TRUE(op.stiffness_diagonal_blocks(s, 0.0, dofs, first, blocks));
  ASSERT_EQ(first.size(), dofs.size() / 3 + 1);
  diagonal_blocks(K, first, assembled);
  double scale = 0.0, error = 0.0;
  for (std::size_t q = 0; q < blocks.size(); ++q) {
    scale = std::max(scale, std::fabs(assembled[q]));
    error = std::max(error, std::fabs(blocks[q] - assembled[q]));
  }
  EXPECT_LT(error, 1e-13 * scale);

  const pd::Vec3Array load = pdtest::pseudo_random(s.size(), 6);
  std::vector<double> b, direct;
  dofs.gather(load, b);
  pd::SparseCholesky chol;
  ASSERT_TRUE(chol.factorize(K)) << chol.failure();
  chol.solve(b, direct);

  pd::BlockJacobi M;
  M.build(first, blocks);
  EXPECT_EQ(M.fallbacks(), 0);
  pd::PcgSettings settings;
  settings.relative_tol = 1e-13;
  settings.max_iterations = 2000;
  std::vector<double> x;
  int products = 0;
  const pd::PcgResult result = pd::preconditioned_cg(
      [&](const std::vector<double>& v, std::vector<double>& y) { ++products, K.multiply(v, y); }, M, b, x, settings);
  ASSERT_TRUE(result.converged()) << result.message();
  EXPECT_EQ(products, result.iterations);  // x₀ = 0: no product for the first residual
  double diff = 0.0, size = 0.0;
  for (std::size_t k = 0; k < x.size(); ++k) diff = std::max(diff, std::fabs(x[k] - direct[k])), size = std::max(size, std::fabs(direct[k]));
  EXPECT_LT(diff, 1e-10 * size);

  // Block-Jacobi pays: plain CG (identity blocks) needs more iterations for the same tolerance.
  pd::BlockJacobi identity;
  std::vector<std::int64_t> each(dofs.size() + 1);
  std::vector<double> ones(9 * dofs.size(), 0.0);
  for (std::size_t k = 0; k <= dofs.size(); ++k) each[k] = static_cast<std::int64_t>(k);
  for (std::size_t k = 0; k < dofs.size(); ++k) ones[9 * k] = 1.0;
  identity.build(each, ones);
  std::vector<double> y;
  const pd::PcgResult plain =
      pd::preconditioned_cg([&](const std::vector<double>& v, std::vector<double>& w) { K.multiply(v, w); }, identity, b, y, settings);
  ASSERT_TRUE(plain.converged()) << plain.message();
  EXPECT_GT(plain.iterations, result.iterations);
  std::printf("PCG on %zu dofs: %d iterations with block-Jacobi, %d without; %.3g from CHOLMOD\n", dofs.size(),
              result.iterations, plain.iterations, diff / size);

  // A cap is reported, with the last iterate and its residual.
  settings.max_iterations = 3;
  std::vector<double> z;
  const pd::PcgResult capped =
      pd::preconditioned_cg([&](const std::vector<double>& v, std::vector<double>& w) { K.multiply(v, w); }, M, b, z, settings);
  EXPECT_EQ(capped.status, pd::PcgResult::kNotConverged);
  EXPECT_EQ(capped.iterations, 3);
  EXPECT_LT(capped.residual, capped.initial_residual);
  EXPECT_NE(capped.message().find("did not converge in 3 iterations"), std::string::npos) << capped.message();
}

TEST(Pcg, AnIndefiniteMatrixIsReportedNotSolved) {
  // diag(2, 1, −1, 3): CG meets pᵀAp ≤ 0 as soon as a direction leans on the negative eigenvalue.
  const std::vector<double> d = {2.0, 1.0, -1.0, 3.0};
  const pd::LinearOperator A = [&](const std::vector<double>& x, std::vector<double>& y) {
    y.resize(x.size());
    for (std::size_t k = 0; k < x.size(); ++k) y[k] = d[k] * x[k];
  };
  pd::BlockJacobi identity;
  identity.build({0, 1, 2, 3, 4}, std::vector<double>{1, 0, 0, 0, 0, 0, 0, 0, 0, 1, 0, 0, 0, 0, 0, 0, 0, 0,
                                                      1, 0, 0, 0, 0, 0, 0, 0, 0, 1, 0, 0, 0, 0, 0, 0, 0, 0});
  const std::vector<double> b = {0.0, 0.0, 1.0, 0.0};
  std::vector<double> x;
  const pd::PcgResult r = pd::preconditioned_cg(A, identity, b, x, pd::PcgSettings{});
  EXPECT_EQ(r.status, pd::PcgResult::kIndefinite);
  EXPECT_EQ(r.iterations, 0);
  EXPECT_DOUBLE_EQ(r.curvature, -1.0);
  EXPECT_NE(r.message().find("not positive definite"), std::string::npos) << r.message();
  for (double v : x) EXPECT_EQ(v, 0.0);  // no step taken along the bad direction
}

TEST(Pcg, BlockJacobiInvertsItsBlocksAndFallsBackOnASingularOne) {
  // One 3×3 SPD block, one 2×2, one singular 1×1 (a loose node): M⁻¹ M e = e for the first two.
  const double a[9] = {4, 1, 0.5, 1, 3, 0.25, 0.5, 0.25, 2};
  std::vector<double> blocks(27, 0.0);
  std::copy(a, a + 9, blocks.begin());
  blocks[9] = 5, blocks[10] = 2, blocks[12] = 2, blocks[13] = 3;
  pd::BlockJacobi M;
  M.build({0, 3, 5, 6}, blocks);
  EXPECT_EQ(M.fallbacks(), 1);
  for (int e = 0; e < 5; ++e) {
    std::vector<double> Me(6, 0.0), z;
    if (e < 3)
      for (int r = 0; r < 3; ++r) Me[static_cast<std::size_t>(r)] = a[3 * r + e];
    else
      for (int r = 0; r < 2; ++r) Me[static_cast<std::size_t>(3 + r)] = blocks[static_cast<std::size_t>(9 + 3 * r + (e - 3))];
    M.apply(Me, z);
    for (int k = 0; k < 5; ++k) EXPECT_NEAR(z[static_cast<std::size_t>(k)], k == e ? 1.0 : 0.0, 1e-15);
  }
  std::vector<double> r = {0, 0, 0, 0, 0, 7.0}, z;
  M.apply(r, z);
  EXPECT_EQ(z[5], 7.0);  // a zero block: the identity
}

TEST(Pcg, DotProductIsBitwiseTheSameForOneAndTwoThreads) {
  const std::size_t n = 100003;  // many chunks and a ragged last one
  std::vector<double> a(n), b(n);
  for (std::size_t k = 0; k < n; ++k) a[k] = std::sin(0.37 * static_cast<double>(k)) * 1e3, b[k] = std::cos(1.3 * static_cast<double>(k)) / 7.0;
  const int saved = omp_get_max_threads();
  omp_set_num_threads(1);
  const double one = pd::fixed_order_dot(a, b);
  omp_set_num_threads(2);
  const double two = pd::fixed_order_dot(a, b);
  omp_set_num_threads(saved);
  EXPECT_EQ(std::memcmp(&one, &two, sizeof one), 0);
  double plain = 0.0;
  for (std::size_t k = 0; k < n; ++k) plain += a[k] * b[k];
  EXPECT_NEAR(one, plain, 1e-10 * std::fabs(plain) + 1e-9);
}
