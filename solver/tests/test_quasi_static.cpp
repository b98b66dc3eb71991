// The quasi-static integrator: a bar pulled at one end reaches equilibrium (residual far below the
// applied force) equal to one direct solve of the assembled tangent; the assembled tangent is the
// Jacobian–vector product; a body that nothing holds is refused with a message that says why.
#include <gtest/gtest.h>

#include <omp.h>

#include <cmath>
#include <cstring>

#include "integrators/quasi_static.hpp"
#include "jacobian_check.hpp"
#include "force_norm.hpp"
#include "lattice.hpp"
#include "one_thread.hpp"
#include "linalg/cholesky.hpp"
#include "forces/force_term.hpp"

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
  c.quasi_static.newton_tol = 1e-8;
  return c;
}

using pdtest::force_norm;

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
  // stiffer clamped ends make it differ, docs/theory.md C3).
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

// ---- The matrix-free path (quasi_static.linear_solver: cg, linalg/pcg.hpp).

namespace {

bool same_bits(const pd::Vec3Array& a, const pd::Vec3Array& b) {
  for (std::size_t d = 0; d < 3; ++d)
    if (a[d].size() != b[d].size() || std::memcmp(a[d].data(), b[d].data(), a[d].size() * sizeof(double)) != 0) return false;
  return true;
}

// max |a.u − b.u| / max |b.u| over every component.
double relative_difference(const pd::State& a, const pd::State& b) {
  double error = 0.0, scale = 0.0;
  for (std::size_t d = 0; d < 3; ++d)
    for (std::size_t i = 0; i < b.size(); ++i) {
      error = std::max(error, std::fabs(a.u[d][i] - b.u[d][i]));
      scale = std::max(scale, std::fabs(b.u[d][i]));
    }
  return error / scale;
}

// The pulled bar of PulledBarReachesEquilibriumEqualToOneDirectSolve to t = 1 with the given linear
// solver on `threads` threads; returns the final state, and the describe() line.
pd::State pull_bar(const std::string& solver, int threads, double strain, std::string* describe = nullptr,
                   std::int64_t* cg_iterations = nullptr, const std::string& preconditioner = "auto") {
  const int saved = omp_get_max_threads();
  omp_set_num_threads(threads);
  pd::Model m = bar(strain);
  pd::ForceOperator op(m);
  pd::QuasiStatic qs(op);
  pd::Case c = bar_case();
  c.quasi_static.linear_solver = solver;
  c.quasi_static.preconditioner = preconditioner;
  qs.configure(c);
  if (describe) *describe = qs.describe(0.0).front();
  pd::State s(m.nodes.size());
  double t = 0.0, dt = 1.0;
  qs.initialize(s, t);
  while (t < 1.0 - 1e-12) {
    double h = std::min(dt, 1.0 - t);
    qs.step(s, t, h);
    dt = qs.last_step().next_dt;
  }
  EXPECT_EQ(qs.uses_cg(), solver == "cg");
  EXPECT_EQ(qs.uses_amg(), solver == "cg" && preconditioner == "amg");
  if (qs.uses_amg()) EXPECT_GE(qs.amg_setups(), 1);
  EXPECT_LT(force_norm(m, s, true), 1e-8 * force_norm(m, s, false));  // equilibrium, as with direct
  if (cg_iterations) *cg_iterations = qs.cg_iterations();
  omp_set_num_threads(saved);
  return s;
}

}  // namespace

TEST(QuasiStatic, CgReachesTheEquilibriumOfTheDirectSolveBitwiseOnOneAndTwoThreads) {
  // 1e-3: geometrically nonlinear enough that Newton takes several iterations per load step.
  const double strain = 1e-3;
  std::string direct_line, cg_line, auto_line;
  std::int64_t cg_iterations = 0;
  const pd::State direct = pull_bar("direct", 1, strain, &direct_line);
  const pd::State cg1 = pull_bar("cg", 1, strain, &cg_line, &cg_iterations);
  const pd::State cg2 = pull_bar("cg", 2, strain);
  pull_bar("auto", 1, strain, &auto_line);
  const double error = relative_difference(cg1, direct);
  EXPECT_LT(error, 1e-8);
  EXPECT_TRUE(same_bits(cg1.u, cg2.u));
  EXPECT_TRUE(same_bits(cg1.f, cg2.f));
  EXPECT_GT(cg_iterations, 0);
  // The choice and its reason are in the describe() line (run.log's work plan).
  EXPECT_NE(direct_line.find("CHOLMOD (direct, as the case file asks)"), std::string::npos) << direct_line;
  EXPECT_NE(cg_line.find("matrix-free CG"), std::string::npos) << cg_line;
  EXPECT_NE(auto_line.find("(direct, auto: 448 free dofs, below 20000 in 3D)"), std::string::npos) << auto_line;
  std::printf("pulled bar, strain %g: cg %.3g relative from direct, %lld CG iterations in all\n", strain, error,
              static_cast<long long>(cg_iterations));
}

TEST(QuasiStatic, AmgPreconditionedCgReachesTheBlockJacobiEquilibrium) {
  if (!pd::AmgPreconditioner::available()) GTEST_SKIP() << "built without hypre (PD_HYPRE off)";
  const double strain = 1e-3;
  std::string jacobi_line, amg_line;
  std::int64_t jacobi_iterations = 0, amg_iterations = 0;
  const pd::State jacobi = pull_bar("cg", 1, strain, &jacobi_line, &jacobi_iterations, "block_jacobi");
  const pd::State amg = pull_bar("cg", 1, strain, &amg_line, &amg_iterations, "amg");
  const pd::State amg2 = pull_bar("cg", 2, strain, nullptr, nullptr, "amg");
  const double error = relative_difference(amg, jacobi);
  EXPECT_LT(error, 1e-8);
  EXPECT_TRUE(same_bits(amg.u, amg2.u));  // hypre's cycle is serial: the same bits on 2 threads
  EXPECT_NE(jacobi_line.find("preconditioner block_jacobi: as the case file asks"), std::string::npos) << jacobi_line;
  EXPECT_NE(amg_line.find("algebraic multigrid"), std::string::npos) << amg_line;
  EXPECT_NE(amg_line.find("preconditioner amg: as the case file asks"), std::string::npos) << amg_line;
  std::string auto_line;
  pull_bar("cg", 1, strain, &auto_line);
  EXPECT_NE(auto_line.find("preconditioner block_jacobi: auto, 448 free dofs, below 20000 in 3D"), std::string::npos)
      << auto_line;
  std::printf("pulled bar: amg %.3g relative from block_jacobi; CG iterations %lld (block-Jacobi) and %lld (AMG)\n",
              error, static_cast<long long>(jacobi_iterations), static_cast<long long>(amg_iterations));
}

namespace {

// Two 8×4×4 bars along x, 4dx apart (no bond across), in two blocks (contact between them, auto):
// the first clamped at its left two layers, the second's right two layers pushed 3.2dx towards it
// at t = 1 and held in y and z, so that the facing layers end 0.8dx apart, inside the contact
// distance 1.35dx.
pd::Model pressed_bars() {
  pd::Case c = pdtest::lattice_case(3, "3d", kDx, 3.015 * kDx, 1e9, 1000.0, -1.0);
  pd::BlockMaterial second = c.blocks[0];
  second.name = "second";
  c.blocks.push_back(second);
  const int nx = 8;
  pd::Nodes a = pdtest::cubic_lattice(nx, kNy, kNz, kDx, 3), nodes = a;
  const double shift = (nx - 1) * kDx + 4 * kDx;
  for (std::size_t i = 0; i < a.size(); ++i) {
    for (std::size_t d = 0; d < 3; ++d) nodes.x[d].push_back(a.x[d][i] + (d == 0 ? shift : 0.0));
    nodes.volume.push_back(a.volume[i]);
    nodes.block.push_back(2);
  }
  pd::NodeSet left{"left", std::vector<std::uint8_t>(nodes.size(), 0)}, right{"right", left.member};
  for (std::size_t i = 0; i < nodes.size(); ++i) {
    left.member[i] = nodes.x[0][i] < 1.5 * kDx;
    right.member[i] = nodes.x[0][i] > shift + (nx - 2.5) * kDx;
  }
  nodes.sets = {left, right};
  for (int d = 0; d < 3; ++d) c.boundary_conditions.push_back({"left", "displacement", d, {0.0}, {0.0}});
  c.boundary_conditions.push_back({"right", "displacement", 0, {0.0, 1.0}, {0.0, -3.2 * kDx}});
  for (int d = 1; d < 3; ++d) c.boundary_conditions.push_back({"right", "displacement", d, {0.0}, {0.0}});
  c.time.integrator = "quasi_static";
  return pd::build_model(c, std::move(nodes));
}

}  // namespace

TEST(QuasiStatic, ContactSolvesWithCgAndDirectIsRefusedWithTheReason) {
  pdtest::OneThread one;
  pd::Model m = pressed_bars();
  ASSERT_TRUE(m.contact.pairs);
  pd::ForceOperator op(m);
  {
    pd::QuasiStatic direct(op);
    pd::Case c = bar_case();
    c.file = "pressed.yaml";
    c.quasi_static.linear_solver = "direct";
    try {
      direct.configure(c);
      FAIL() << "no error";
    } catch (const pd::Error& e) {
      EXPECT_NE(std::string(e.what()).find("pressed.yaml: quasi_static.linear_solver: direct needs an assembled tangent"),
                std::string::npos) << e.what();
    }
  }
  pd::QuasiStatic qs(op);
  pd::Case c = bar_case();
  c.quasi_static.residual_tol = 1e-9;
  qs.configure(c);  // auto
  ASSERT_TRUE(qs.uses_cg());
  EXPECT_NE(qs.describe(0.0).front().find("auto: a term (contact) has no assembled tangent"), std::string::npos);
  pd::State s(m.nodes.size());
  double t = 0.0, dt = 1.0;
  qs.initialize(s, t);
  while (t < 1.0 - 1e-12) {
    double h = std::min(dt, 1.0 - t);
    qs.step(s, t, h);
    dt = qs.last_step().next_dt;
  }
  // The push reaches the clamp through contact only: equal and opposite reactions in x, the free
  // nodes in equilibrium, the contact holding energy.
  double left = 0.0, right = 0.0;
  for (std::size_t i = 0; i < s.size(); ++i) {
    const double r = m.nodes.volume[i] * s.f[0][i];
    if (m.nodes.sets[0].member[i]) left += r;
    if (m.nodes.sets[1].member[i]) right += r;
  }
  EXPECT_GT(pd::term_energy(s, "contact"), 0.0);
  EXPECT_GT(right, 0.0);  // the squeezed bars push the pusher back (+x) and the clamp (−x)
  EXPECT_NEAR(left, -right, 1e-6 * std::fabs(right));
  EXPECT_LT(force_norm(m, s, true), 1e-8 * force_norm(m, s, false));
  // The facing layers are apart by more than half the contact distance: contact held them.
  double gap = HUGE_VAL;
  for (std::size_t i = 0; i < s.size(); ++i)
    for (std::size_t j = 0; j < s.size(); ++j)
      if (m.block_index[i] == 0 && m.block_index[j] == 1)
        gap = std::min(gap, (m.nodes.x[0][j] + s.u[0][j]) - (m.nodes.x[0][i] + s.u[0][i]));
  EXPECT_GT(gap, 0.8 * kDx);
  std::printf("pressed bars with contact (cg): reactions %.6g and %.6g N, closest layers %.3g dx, %lld CG iterations\n",
              left, right, gap / kDx, static_cast<long long>(qs.cg_iterations()));
}

namespace {

// keep_from_checkpoint: the restored run is configured with linear_solver and preconditioner auto,
// which on this bar would factorise, and keeps the saved run's CG as a restart does
// (Integrator::keep_linear_solver, run/start.cpp).
void restart_continues_bitwise(const std::string& preconditioner, bool keep_from_checkpoint = false) {
  pdtest::OneThread one;
  // The pulled bar (strain 1e-3 by t = 1) with half of the cross-section at x = 5.5dx cut (its bonds
  // broken before the start): the tangent is shifted as after damage, and the notch makes the
  // response nonlinear in the load steps' Newton iterations.
  struct Run {
    pd::Model m = bar(1e-3);
    pd::ForceOperator op{m};
    pd::QuasiStatic qs{op};
    pd::State s{m.nodes.size()};
    double t = 0.0, dt = 0.0;
    explicit Run(const std::string& preconditioner, const std::string& keep = "") {
      for (std::size_t i = 0; i < m.nodes.size(); ++i)
        for (std::int64_t k = m.bonds.offsets[i]; k < m.bonds.offsets[i + 1]; ++k) {
          const auto j = static_cast<std::size_t>(m.bonds.neighbour[static_cast<std::size_t>(k)]);
          const double xi = m.nodes.x[0][i], xj = m.nodes.x[0][j];
          if ((xi - 5.5 * kDx) * (xj - 5.5 * kDx) < 0.0 && m.nodes.x[1][i] < 1.5 * kDx && m.nodes.x[1][j] < 1.5 * kDx)
            m.bonds.broken[static_cast<std::size_t>(k)] = 1;
        }
      pd::Case c = bar_case();
      c.quasi_static.linear_solver = "cg";
      c.quasi_static.preconditioner = preconditioner;
      c.quasi_static.dt_max = 0.1;
      if (!keep.empty()) c.quasi_static.linear_solver = c.quasi_static.preconditioner = "auto";
      qs.configure(c);
      if (!keep.empty()) {
        EXPECT_EQ(qs.linear_solver(), "direct");
        EXPECT_EQ(qs.keep_linear_solver(keep), "");
        EXPECT_EQ(qs.linear_solver(), keep);
      }
      qs.initialize(s, 0.0);
      dt = *qs.initial_dt();
    }
    void step() {
      double h = std::min(dt, 1.0 - t);
      qs.step(s, t, h);
      dt = qs.last_step().next_dt;
    }
  };
  Run a(preconditioner);
  for (int k = 0; k < 4; ++k) a.step();
  const std::vector<char> saved = a.qs.save_state();
  Run b(preconditioner, keep_from_checkpoint ? a.qs.linear_solver() : "");
  b.s = a.s;
  b.t = a.t;
  b.dt = a.dt;
  b.m.bonds.broken = a.m.bonds.broken;
  b.qs.load_state(saved);
  int steps = 0;
  while (a.t < 1.0 - 1e-12) a.step(), b.step(), ++steps;
  EXPECT_GT(steps, 2);
  EXPECT_EQ(a.t, b.t);
  EXPECT_TRUE(same_bits(a.s.u, b.s.u));
  EXPECT_TRUE(same_bits(a.s.f, b.s.f));
  EXPECT_EQ(a.qs.last_step().iterations, b.qs.last_step().iterations);
  EXPECT_LT(force_norm(a.m, a.s, true), 1e-8 * force_norm(a.m, a.s, false));
}

}  // namespace

TEST(QuasiStatic, CgRunSavedAndRestoredMidRunContinuesBitwise) { restart_continues_bitwise("block_jacobi"); }

TEST(QuasiStatic, AmgRunSavedAndRestoredMidRunContinuesBitwise) {
  if (!pd::AmgPreconditioner::available()) GTEST_SKIP() << "built without hypre (PD_HYPRE off)";
  restart_continues_bitwise("amg");
}

// Issue 36, item 9: auto's choice depends on the rank count (CG on several ranks, CHOLMOD on one
// for this bar), so a restart keeps the solver and preconditioner its checkpoint recorded; the run
// then continues bitwise (before, a 2-rank run resumed on 1 rank switched to CHOLMOD unsaid).
TEST(QuasiStatic, ARestartKeepsTheCheckpointsCgWhereAutoWouldFactorise) { restart_continues_bitwise("block_jacobi", true); }

TEST(QuasiStatic, ARestartKeepsTheCheckpointsAmgWhereAutoWouldFactorise) {
  if (!pd::AmgPreconditioner::available()) GTEST_SKIP() << "built without hypre (PD_HYPRE off)";
  restart_continues_bitwise("amg", true);
}

// What a restart is told when it cannot keep the recorded solver, and what run.log says when it can.
TEST(QuasiStatic, KeepLinearSolverSaysWhyItCannotAndDescribeSaysWhereItCameFrom) {
  pd::Model m = bar(1e-3);
  pd::ForceOperator op(m);
  pd::QuasiStatic qs(op);
  qs.configure(bar_case());
  EXPECT_EQ(qs.linear_solver(), "direct");
  EXPECT_EQ(qs.keep_linear_solver("direct"), "");  // the same: nothing to do
  EXPECT_FALSE(qs.uses_cg());
  EXPECT_EQ(qs.keep_linear_solver("lu"), "the checkpoint names a linear solver this pdsolve does not know ('lu')");
  EXPECT_FALSE(qs.uses_cg());
  EXPECT_EQ(qs.keep_linear_solver("cg block_jacobi"), "");
  EXPECT_TRUE(qs.uses_cg());
  EXPECT_NE(qs.describe(0.0).front().find("(cg, as the checkpoint was written; this run alone would take direct, auto: "),
            std::string::npos) << qs.describe(0.0).front();
  EXPECT_NE(qs.describe(0.0).front().find("; preconditioner block_jacobi: as the checkpoint was written"), std::string::npos)
      << qs.describe(0.0).front();
  if (!pd::AmgPreconditioner::available())
    EXPECT_EQ(qs.keep_linear_solver("cg amg"), "amg needs hypre's BoomerAMG, which this pdsolve was built without");
}

TEST(QuasiStatic, PredictorFromTheLastLoadStepReachesTheSameEquilibriumInFewerIterations) {
  // Newton from u_n + Δt·v_n (the default) against Newton from u_n, over ten equal load steps of the
  // bar at strain 1e-3 (geometrically nonlinear, so Newton iterates): the same equilibria to the
  // Newton tolerances (1e-8 of the motion), reached with fewer iterations.
  struct Pull {
    int iterations = 0;
    pd::State s;
  };
  const auto pull = [](bool predictor) {
    pd::Model m = bar(1e-3);
    pd::ForceOperator op(m);
    pd::QuasiStatic qs(op);
    pd::Case c = bar_case();
    c.quasi_static.dt_initial = 0.1;
    c.quasi_static.dt_max = 0.1;
    qs.configure(c);
    Pull out{0, pd::State(m.nodes.size())};
    qs.initialize(out.s, 0.0);
    qs.guess_from_velocity(predictor);
    double t = 0.0, dt = 0.1;
    int steps = 0;
    while (t < 1.0 - 1e-12) {
      double h = std::min(dt, 1.0 - t);
      qs.step(out.s, t, h);
      EXPECT_EQ(qs.last_step().rejected, 0);
      out.iterations += qs.last_step().iterations;
      dt = qs.last_step().next_dt;
      ++steps;
    }
    EXPECT_EQ(steps, 10);
    EXPECT_LT(force_norm(m, out.s, true), 1e-8 * force_norm(m, out.s, false));
    return out;
  };
  const Pull from_u = pull(false), predicted = pull(true);
  double difference = 0.0, scale = 0.0;
  for (std::size_t d = 0; d < 3; ++d)
    for (std::size_t i = 0; i < from_u.s.size(); ++i) {
      difference = std::max(difference, std::fabs(predicted.s.u[d][i] - from_u.s.u[d][i]));
      scale = std::max(scale, std::fabs(from_u.s.u[d][i]));
    }
  EXPECT_LT(difference, 1e-8 * scale);
  EXPECT_LT(predicted.iterations, from_u.iterations);
  std::printf("bar at strain 1e-3, 10 load steps: %d Newton iterations from u_n, %d from u_n + dt v_n; "
              "equilibria %.2g apart relative\n", from_u.iterations, predicted.iterations, difference / scale);
}

TEST(QuasiStatic, FromAnExplicitStepsStateTheFirstTangentFactorisedIsTheDefiniteVariant) {
  // mixed's return (guess_from_velocity(false): the state is an explicit step's, ringing): the
  // first factorisation of the step is the definite variant at once, not the full tangent first,
  // which the compressed bonds of such a state make indefinite and CHOLMOD then refuses after a
  // whole factorisation's work. The bar with a bond broken (the rule is for damaged bodies, where the
  // definite variant is the fallback anyway) and its inside squeezed by 20 % along x: the full
  // tangent is refused there, as the step from the same state with the predictor on shows.
  int refused[2] = {0, 0}, factorised[2] = {0, 0};
  for (const bool cold : {false, true}) {
    pd::Model m = bar(0.0);
    m.bonds.broken[0] = 1;
    pd::ForceOperator op(m);
    pd::QuasiStatic qs(op);
    qs.configure(bar_case());
    pd::State s(m.nodes.size());
    qs.initialize(s, 0.0);
    for (std::size_t i = 0; i < s.size(); ++i)
      if (!m.conditions.fixed[0][i]) s.u[0][i] = -0.2 * (m.nodes.x[0][i] - m.nodes.x[0][0]);
    qs.guess_from_velocity(!cold);
    qs.try_once(3);  // the first iterations are what is asked about
    double t = 0.0, dt = 1e-3;
    try {
      qs.step(s, t, dt);
    } catch (const pd::StepFailed&) {
    }
    refused[cold] = qs.refused_factorisations();
    factorised[cold] = qs.factorisations();
  }
  EXPECT_GE(refused[false], 1);  // with the predictor on, the full tangent was tried and refused
  EXPECT_EQ(refused[true], 0);   // from an explicit state it was not tried
  EXPECT_GE(factorised[true], 1);
}

// A load step that finds no equilibrium, halved down to dt_min, stops the run with the step, the
// attempts and what to change; one whose bonds keep breaking through the re-solves too. The run
// keeps the displacements of the last equilibrium (the run loop writes them as its last state).
void expect_stop_saying(pd::Model& m, const pd::Case& settings, double h, std::initializer_list<const char*> words) {
  pd::ForceOperator op(m);
  pd::QuasiStatic qs(op);
  qs.configure(settings);
  pd::State s(m.nodes.size());
  double t = 0.0;
  qs.initialize(s, t);
  const pd::State before = s;
  try {
    qs.step(s, t, h);
    FAIL() << "no error";
  } catch (const pd::StepFailed& e) {
    const std::string what = e.what();
    for (const char* w : words) EXPECT_NE(what.find(w), std::string::npos) << w << " not in: " << what;
  }
  EXPECT_EQ(t, 0.0);
  EXPECT_TRUE(same_bits(s.u, before.u));
}

TEST(QuasiStatic, NoEquilibriumAndUnstableGrowthStopWithWhatToChange) {
  pd::Model held = bar(1e-5);
  pd::Case settings = bar_case();
  settings.quasi_static.max_iterations = 1;  // Newton accepts from its second iteration on: never here
  expect_stop_saying(held, settings, 0.1,
                     {"did not reach equilibrium at dt_min", "attempts", "use time.integrator: mixed", "or verlet",
                      "raise quasi_static.max_iterations"});

  // The bar made breakable (G0 = 3.6 J/m², s0 ≈ 1e-3) and pulled to 20 s0 in one load step: its
  // first re-solve breaks more bonds, over the one round allowed.
  pd::Case c = pdtest::lattice_case(3, "3d", kDx, 3.015 * kDx, 1e9, 1000.0, 3.6);
  pd::Nodes nodes = pdtest::bar_with_grips(kNx, kNy, kNz, kDx);
  pdtest::clamp_left_pull_right(c, 2e-2 * (kNx - 1) * kDx, 1.0, true);
  c.time.integrator = "quasi_static";
  pd::Model breakable = pd::build_model(c, std::move(nodes));
  settings = bar_case();
  settings.quasi_static.max_breaking_rounds = 1;
  settings.quasi_static.cut_to_first_failure = false;
  expect_stop_saying(breakable, settings, 1.0,
                     {"bonds kept breaking", "the crack grows unstably", "use time.integrator: mixed", "or verlet",
                      "raise quasi_static.max_breaking_rounds"});
}

// Bonds broken by an attempt that then fails to converge stay broken (breaking is irreversible);
// the attempt that is accepted reports them with its own, so that history.csv's count and energy of
// broken bonds are the model's. The breakable bar pulled in a few long load steps with few Newton
// iterations allowed: attempts break bonds and fail, halved ones are accepted.
TEST(QuasiStatic, BondsBrokenByAFailedAttemptAreReportedByTheAcceptedOne) {
  pd::Case c = pdtest::lattice_case(3, "3d", kDx, 3.015 * kDx, 1e9, 1000.0, 3.6);
  pd::Nodes nodes = pdtest::bar_with_grips(kNx, kNy, kNz, kDx);
  pdtest::clamp_left_pull_right(c, 4e-3 * (kNx - 1) * kDx, 1.0, true);
  c.time.integrator = "quasi_static";
  pd::Model m = pd::build_model(c, std::move(nodes));
  pd::ForceOperator op(m);
  pd::QuasiStatic qs(op);
  pd::Case settings = bar_case();
  settings.quasi_static.cut_to_first_failure = false;
  settings.quasi_static.max_iterations = 4;
  settings.quasi_static.dt_initial = settings.quasi_static.dt_max = 0.3;
  qs.configure(settings);
  pd::State s(m.nodes.size());
  double t = 0.0, dt = *settings.quasi_static.dt_max;
  qs.initialize(s, t);
  std::int64_t reported = 0, failed_then_broken = 0;
  try {
    while (t < 1.0 - 1e-12) {
      double h = std::min(dt, 1.0 - t);
      qs.step(s, t, h);
      dt = qs.last_step().next_dt;
      reported += qs.last_step().broken_now;
      std::int64_t once = 0;
      for (std::size_t i = 0; i < m.nodes.size(); ++i)
        for (std::int64_t k = m.bonds.offsets[i]; k < m.bonds.offsets[i + 1]; ++k)
          once += m.bonds.broken[static_cast<std::size_t>(k)] != 0 && static_cast<std::size_t>(m.bonds.neighbour[static_cast<std::size_t>(k)]) > i;
      EXPECT_EQ(reported, once) << "t = " << t;
      if (qs.last_step().rejected > 0 && qs.last_step().broken_now > 0) ++failed_then_broken;
    }
  } catch (const pd::StepFailed&) {
    // The bar comes apart: where the run stops does not matter here.
  }
  // The case this is about happened (at t = 0.377: 4 attempts, 612 bonds; 8 of them reported
  // before the fix, which this test caught).
  EXPECT_GT(failed_then_broken, 0);
}
