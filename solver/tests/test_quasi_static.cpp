// The quasi-static integrator: a bar pulled at one end reaches equilibrium (residual far below the
// applied force) equal to one direct solve of the assembled tangent; the assembled tangent is the
// Jacobian–vector product; a body that nothing holds is refused with a message that says why.
#include <gtest/gtest.h>

#include <cmath>

#include "integrators/quasi_static.hpp"
#include "jacobian_check.hpp"
#include "lattice.hpp"
#include "linalg/cholesky.hpp"

namespace {

constexpr double kDx = 1e-3;
constexpr int kNx = 12, kNy = 4, kNz = 4;

// A 12×4×4 bar, δ = 3.015dx, unbreakable: the left two layers clamped, the right two pulled along x
// to strain·L at t = 1 (a displacement table), unless `held` is false (then nothing holds it).
pd::Model bar(double strain, bool held = true) {
  pd::Case c = pdtest::lattice_case(3, "3d", kDx, 3.015 * kDx, 1e9, 1000.0, -1.0);
  pd::Nodes nodes = pdtest::bar_with_grips(kNx, kNy, kNz, kDx);
  if (held) pdtest::clamp_left_pull_right(c, strain * (kNx - 1) * kDx, 1.0, false);
  else c.boundary_conditions.push_back({"right", "body_force", 0, {0.0}, {1e6}});
  c.time.integrator = "quasi_static";
  return pd::build_model(c, std::move(nodes));
}

pd::Case bar_case() {
  pd::Case c;
  c.time.end = 1.0;
  c.quasi_static.residual_tol = 1e-10;
  c.quasi_static.tol = 1e-8;
  return c;
}

double force_norm(const pd::Model& m, const pd::State& s, bool free) {
  double sum = 0.0;
  for (std::size_t d = 0; d < 3; ++d)
    for (std::size_t i = 0; i < s.size(); ++i)
      if (static_cast<bool>(m.conditions.fixed[d][i]) != free) sum += std::pow(m.nodes.volume[i] * s.f[d][i], 2);
  return std::sqrt(sum);
}

}  // namespace

TEST(QuasiStatic, AssembledTangentIsTheJacobianProduct) {
  pd::Model m = bar(1e-3);
  const pd::ForceOperator op(m);
  pd::State s(m.nodes.size());
  const pd::Vec3Array wiggle = pdtest::pseudo_random(s.size(), 11);
  for (std::size_t d = 0; d < 3; ++d)
    for (std::size_t i = 0; i < s.size(); ++i) s.u[d][i] = 1e-3 * m.nodes.x[0][i] * (d == 0) + 1e-6 * wiggle[d][i];
  const pd::FreeDofs dofs = pd::FreeDofs::of(s.size(), 3, m.conditions.fixed);
  const pd::SparseMatrix K = op.assemble_stiffness(s, 0.0, dofs);
  ASSERT_EQ(K.rows, static_cast<std::int64_t>(dofs.size()));
  // K x = −V J x at the free dofs, for x zero at the prescribed ones.
  pd::Vec3Array x = pdtest::pseudo_random(s.size(), 12);
  for (std::size_t d = 0; d < 3; ++d)
    for (std::size_t i = 0; i < s.size(); ++i)
      if (m.conditions.fixed[d][i]) x[d][i] = 0.0;
  pd::Vec3Array jx = pd::make_vec3(s.size());
  op.apply_jacobian(s, 0.0, x, jx);
  std::vector<double> xv, kx;
  dofs.gather(x, xv);
  K.multiply(xv, kx);
  double error = 0.0, scale = 0.0;
  for (std::size_t k = 0; k < dofs.size(); ++k) {
    const auto i = static_cast<std::size_t>(dofs.node[k]);
    const double expected = -m.nodes.volume[i] * jx[dofs.component[k]][i];
    error = std::max(error, std::fabs(kx[k] - expected));
    scale = std::max(scale, std::fabs(expected));
  }
  EXPECT_LT(error, 1e-12 * scale);
  // Symmetric, entry by entry.
  for (std::int64_t r = 0; r < K.rows; r += 7)
    for (std::int64_t q = K.row_start[static_cast<std::size_t>(r)]; q < K.row_start[static_cast<std::size_t>(r) + 1]; ++q) {
      const std::int64_t c = K.column[static_cast<std::size_t>(q)];
      double transposed = 0.0;
      for (std::int64_t p = K.row_start[static_cast<std::size_t>(c)]; p < K.row_start[static_cast<std::size_t>(c) + 1]; ++p)
        if (K.column[static_cast<std::size_t>(p)] == r) transposed = K.value[static_cast<std::size_t>(p)];
      EXPECT_NEAR(K.value[static_cast<std::size_t>(q)], transposed, 1e-12 * scale);
    }
}

TEST(QuasiStatic, PulledBarReachesEquilibriumEqualToOneDirectSolve) {
  // 1e-5: the stretches are resolved to ~1e-11 relative in double precision, and the geometric
  // nonlinearity that a linear solve leaves out is of the order of the strain.
  const double strain = 1e-5;
  pd::Model m = bar(strain);
  pd::ForceOperator op(m);
  pd::QuasiStatic qs(op);
  qs.configure(bar_case());
  pd::State s(m.nodes.size());
  double t = 0.0;
  qs.initialize(s, t);
  double dt = 1.0;  // one load step to the end (dt_max = end/10 caps it)
  while (t < 1.0 - 1e-12) {
    double h = std::min(dt, 1.0 - t);
    qs.step(s, t, h);
    dt = qs.last_step().next_dt;
    EXPECT_LE(qs.last_step().iterations, 4);  // a handful of Newton iterations per load step
  }
  EXPECT_DOUBLE_EQ(t, 1.0);
  const double applied = force_norm(m, s, false);
  EXPECT_GT(applied, 0.0);
  EXPECT_LT(force_norm(m, s, true), 1e-8 * applied);  // the round-off floor at this strain: ~1e-9
  EXPECT_LE(qs.factorisations(), 2);  // the linear response reuses one factorisation

  // One direct solve of the tangent at rest: K u_free = V f(u_prescribed only).
  pd::State lin(m.nodes.size());
  op.impose_prescribed_motion(lin, 1.0);
  op.evaluate(lin, 1.0);
  const pd::FreeDofs dofs = pd::FreeDofs::of(lin.size(), 3, m.conditions.fixed);
  pd::State rest(m.nodes.size());
  pd::SparseCholesky chol;
  ASSERT_TRUE(chol.factorize(op.assemble_stiffness(rest, 1.0, dofs)));
  std::vector<double> rhs(dofs.size()), u;
  for (std::size_t k = 0; k < dofs.size(); ++k) {
    const auto i = static_cast<std::size_t>(dofs.node[k]);
    rhs[k] = m.nodes.volume[i] * lin.f[dofs.component[k]][i];
  }
  chol.solve(rhs, u);
  double error = 0.0, scale = 0.0;
  for (std::size_t k = 0; k < dofs.size(); ++k) {
    const auto i = static_cast<std::size_t>(dofs.node[k]);
    error = std::max(error, std::fabs(s.u[dofs.component[k]][i] - u[k]));
    scale = std::max(scale, std::fabs(u[k]));
  }
  EXPECT_LT(error, 10 * strain * scale);
  std::printf("quasi-static bar, strain %g: residual %.3g of the applied force, %d factorisations, "
              "%.3g relative from one linear solve\n", strain, force_norm(m, s, true) / applied, qs.factorisations(),
              error / scale);
  // The middle of the bar stretches uniformly: the strain between two interior cross-sections
  // (x = 4dx and 7dx, on the axis) is within 20 % of the mean strain (PMB's surface effect and the
  // stiffer clamped ends make it differ, validation.md C3).
  const std::size_t a = pdtest::node_index(4, 1, 1, kNx, kNy), b = pdtest::node_index(7, 1, 1, kNx, kNy);
  const double interior = (s.u[0][b] - s.u[0][a]) / (3 * kDx);
  EXPECT_NEAR(interior / strain, 1.0, 0.2);
}

TEST(QuasiStatic, ABodyNothingHoldsIsRefusedWithTheReason) {
  pd::Model m = bar(0.0, false);  // only a body force: free in x, y and z
  pd::ForceOperator op(m);
  pd::QuasiStatic qs(op);
  qs.configure(bar_case());
  pd::State s(m.nodes.size());
  try {
    qs.initialize(s, 0.0);
    FAIL() << "no error";
  } catch (const pd::Error& e) {
    EXPECT_NE(std::string(e.what()).find("the body can move freely in x"), std::string::npos) << e.what();
  }
}

namespace {

// The stiffness of a chain of n unit springs, held at its left end or not (then singular).
pd::SparseMatrix chain(int n, bool held) {
  pd::SparseMatrix K;
  K.rows = n;
  K.row_start.push_back(0);
  for (int r = 0; r < n; ++r) {
    const double diagonal = (r > 0 || held ? 1.0 : 0.0) + (r + 1 < n ? 1.0 : 0.0);
    if (r > 0) K.column.push_back(r - 1), K.value.push_back(-1.0);
    K.column.push_back(r), K.value.push_back(diagonal);
    if (r + 1 < n) K.column.push_back(r + 1), K.value.push_back(-1.0);
    K.row_start.push_back(static_cast<std::int64_t>(K.column.size()));
  }
  return K;
}

}  // namespace

TEST(SparseCholesky, SolvesAHeldChainAndRefusesAFreeOne) {
  pd::SparseCholesky chol;
  const pd::SparseMatrix held = chain(200, true);
  ASSERT_TRUE(chol.factorize(held)) << chol.failure();
  std::vector<double> b(200, 0.0), x, kx;
  b.back() = 1.0;  // a unit pull at the free end: every spring carries 1, u_k = k + 1
  chol.solve(b, x);
  for (int k = 0; k < 200; ++k) EXPECT_NEAR(x[static_cast<std::size_t>(k)], k + 1.0, 1e-9 * (k + 1.0));
  held.multiply(x, kx);
  for (int k = 0; k < 200; ++k) EXPECT_NEAR(kx[static_cast<std::size_t>(k)], b[static_cast<std::size_t>(k)], 1e-9);
  ASSERT_TRUE(chol.factorize(held));
  EXPECT_EQ(chol.analyses(), 1);  // the same pattern: the ordering is reused
  EXPECT_FALSE(chol.factorize(chain(200, false)));  // free to translate: singular
  EXPECT_NE(chol.failure().find("not positive definite"), std::string::npos) << chol.failure();
}

TEST(QuasiStatic, DefiniteTangentLeavesOutOnlyTheCompressedBondsLateralStiffness) {
  // A bar squeezed by 1 % along x: its y and z bonds stretch (no Poisson effect in the lattice
  // without it) and its x bonds are in compression, whose lateral stiffness c s/y is negative.
  pd::Model m = bar(0.0);
  const pd::ForceOperator op(m);
  pd::State s(m.nodes.size());
  for (std::size_t i = 0; i < s.size(); ++i) s.u[0][i] = -1e-2 * m.nodes.x[0][i];
  const pd::FreeDofs dofs = pd::FreeDofs::of(s.size(), 3, m.conditions.fixed);
  const pd::SparseMatrix exact = op.assemble_stiffness(s, 0.0, dofs), definite = op.assemble_stiffness(s, 0.0, dofs, true);
  ASSERT_EQ(exact.column, definite.column);  // the same pattern: one symbolic analysis serves both
  double smallest = HUGE_VAL, differs = 0.0;
  for (unsigned salt = 0; salt < 20; ++salt) {
    const pd::Vec3Array v = pdtest::pseudo_random(s.size(), 100 + salt);
    std::vector<double> x, kx;
    dofs.gather(v, x);
    definite.multiply(x, kx);
    double xkx = 0.0, xx = 0.0;
    for (std::size_t k = 0; k < x.size(); ++k) xkx += x[k] * kx[k], xx += x[k] * x[k];
    smallest = std::min(smallest, xkx / xx);
  }
  for (std::size_t k = 0; k < exact.value.size(); ++k) differs = std::max(differs, std::fabs(exact.value[k] - definite.value[k]));
  EXPECT_GT(smallest, 0.0);  // positive on every probe
  EXPECT_GT(differs, 0.0);   // and not the exact tangent under compression
  // In tension (every bond stretched or at rest) the two are the same.
  for (std::size_t i = 0; i < s.size(); ++i) s.u[0][i] = 1e-3 * m.nodes.x[0][i], s.u[1][i] = 1e-3 * m.nodes.x[1][i],
                                             s.u[2][i] = 1e-3 * m.nodes.x[2][i];
  EXPECT_EQ(op.assemble_stiffness(s, 0.0, dofs).value, op.assemble_stiffness(s, 0.0, dofs, true).value);
}
