// Algebraic multigrid (linalg/amg.hpp): CG preconditioned by one BoomerAMG V-cycle solves the
// assembled PMB tangent of a held 3D bar to the solution block-Jacobi CG finds, in fewer iterations.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "jacobian_check.hpp"
#include "lattice.hpp"
#include "linalg/amg.hpp"
#include "linalg/pcg.hpp"
#include "one_thread.hpp"
#include "operator/force_operator.hpp"

namespace {

constexpr double kDx = 1e-3;

// A 32×6×6 bar, δ = 3.015dx, its first two x-layers clamped and its last two held along x: long in
// nodes, where block-Jacobi's iteration count grows and a multigrid cycle's does not.
pd::Model held_bar() {
  pd::Case c = pdtest::lattice_case(3, "3d", kDx, 3.015 * kDx, 1e9, 1000.0, -1.0);
  pdtest::clamp_left_pull_right(c, 0.0, 1.0, false);
  return pd::build_model(c, pdtest::bar_with_grips(32, 6, 6, kDx));
}

}  // namespace

TEST(Amg, CgWithAmgReachesTheBlockJacobiSolutionInFewerIterations) {
  if (!pd::AmgPreconditioner::available()) GTEST_SKIP() << "built without hypre (PD_HYPRE off)";
  pdtest::OneThread one;
  pd::Model m = held_bar();
  const pd::ForceOperator op(m);
  pd::State s(m.nodes.size());
  for (std::size_t i = 0; i < s.size(); ++i) s.u[0][i] = 1e-3 * m.nodes.x[0][i];  // stretched along x
  const pd::FreeDofs dofs = pd::FreeDofs::of(s.size(), 3, m.conditions.fixed);
  const pd::SparseMatrix K = op.assemble_stiffness(s, 0.0, dofs);
  ASSERT_GT(K.rows, 0);
  std::vector<double> b;
  dofs.gather(pdtest::pseudo_random(s.size(), 7), b);
  const pd::LinearOperator A = [&](const std::vector<double>& x, std::vector<double>& y) { K.multiply(x, y); };
  pd::PcgSettings settings;
  settings.relative_tol = 1e-10;
  settings.max_iterations = 5000;

  std::vector<std::int64_t> first;
  std::vector<double> blocks;
  ASSERT_TRUE(op.stiffness_diagonal_blocks(s, 0.0, dofs, first, blocks));
  pd::BlockJacobi jacobi;
  jacobi.build(first, blocks);
  std::vector<double> x_jacobi, x_amg;
  const pd::PcgResult by_jacobi = pd::preconditioned_cg(A, jacobi, b, x_jacobi, settings);
  ASSERT_TRUE(by_jacobi.converged()) << by_jacobi.message();

  pd::AmgPreconditioner amg;
  amg.set_up(K, 3, dofs.component);
  ASSERT_TRUE(amg.ready());
  EXPECT_GE(amg.levels(), 2);
  EXPECT_GT(amg.operator_complexity(), 1.0);
  const pd::PcgResult by_amg = pd::preconditioned_cg(A, amg, b, x_amg, settings);
  ASSERT_TRUE(by_amg.converged()) << by_amg.message();

  double diff = 0.0, size = 0.0;
  for (std::size_t k = 0; k < b.size(); ++k)
    diff = std::max(diff, std::fabs(x_amg[k] - x_jacobi[k])), size = std::max(size, std::fabs(x_jacobi[k]));
  EXPECT_LT(diff, 1e-8 * size);
  EXPECT_LT(2 * by_amg.iterations, by_jacobi.iterations);
  std::printf("%zu dofs, %zu entries: block-Jacobi %d iterations, AMG %d (%d levels, complexity %.2f); %.2g apart\n",
              b.size(), K.nonzeros(), by_jacobi.iterations, by_amg.iterations, amg.levels(), amg.operator_complexity(),
              diff / size);

  // The same hierarchy set up again gives the same bits (the restart of quasi_static relies on it),
  // and the cycle is a fixed linear map: applying it twice to the same r gives the same z.
  pd::AmgPreconditioner again;
  again.set_up(K, 3, dofs.component);
  std::vector<double> z1, z2, z3;
  amg.apply(b, z1);
  amg.apply(b, z2);
  again.apply(b, z3);
  EXPECT_EQ(z1, z2);
  EXPECT_EQ(z1, z3);
  amg.clear();
  EXPECT_FALSE(amg.ready());
}
