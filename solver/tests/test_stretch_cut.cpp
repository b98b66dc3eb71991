// The cut of a quasi-static load step to the first bond failure (integrators/quasi_static.hpp) and
// the reduction it rests on (materials/bond_model.hpp StretchRatio): the largest stretch ratio is a
// brute-force maximum over the bonds, bit for bit, and its count is what break_bonds breaks, for
// PMB (the thesis rule and LAMMPS's per-node rule) and LPS, on 1 and 2 threads; a bar pulled by one
// huge load step lands at the first-failure load of its linear response, and the cut step is bitwise
// the step asked for directly, on 1 and 2 threads.
#include <gtest/gtest.h>

#include <omp.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>

#include "integrators/quasi_static.hpp"
#include "jacobian_check.hpp"
#include "lattice.hpp"
#include "materials/pmb/pmb.hpp"
#include "one_thread.hpp"
#include "pmb_s0.hpp"

namespace {

constexpr double kDx = 1e-3;
constexpr int kNx = 12, kNy = 4, kNz = 4;

// The breakable bar of test_mixed.cpp (E = 1 GPa, G0 = 3.6 J/m², s0 ≈ 1e-3): the left two layers
// clamped, the right two pulled along x to `pull` of the length at t = 1 and held across.
pd::Model breakable_bar(const std::string& law = "pmb", double pull = 4e-3) {
  pd::Case c = pdtest::lattice_case(3, "3d", kDx, 3.015 * kDx, 1e9, 1000.0, 3.6);
  if (law == "lps") {
    c.blocks[0].model = "lps";
    c.blocks[0].parameters["poisson_ratio"] = 0.3;
    c.blocks[0].choices["influence"] = "one";
  }
  pdtest::clamp_left_pull_right(c, pull * (kNx - 1) * kDx, 1.0, true);
  c.time.integrator = "quasi_static";
  return pd::build_model(c, pdtest::bar_with_grips(kNx, kNy, kNz, kDx));
}

pd::Case one_step_case() {
  pd::Case c;
  c.time.end = 1.0;
  c.quasi_static.dt_max = 1.0;  // one load step may cover the whole pull
  c.quasi_static.dt_initial = 1.0;
  return c;
}

// A stretch of 1.2e-3 along x with a wiggle of some 3 % of the bond stretches: bonds on both sides of
// s0 ≈ 1e-3.
pd::Vec3Array stretched(const pd::Model& m) {
  pd::Vec3Array u = pdtest::pseudo_random(m.nodes.size(), 5);
  for (std::size_t d = 0; d < 3; ++d)
    for (std::size_t i = 0; i < m.nodes.size(); ++i) u[d][i] = 3e-5 * kDx * u[d][i] + (d == 0 ? 1.2e-3 * m.nodes.x[0][i] : 0.0);
  return u;
}

// The StretchRatio from its definition, bond by bond, serially: s = (|y| − |ξ|)/|ξ| as every pass
// computes it, over the intact bonds with no no-fail end, against the pair's s0 (or LAMMPS's
// min(s0_i, s0_j)); for LPS the ratio (|y| − |ξ|)/(s0 |ξ|) and the test y − |ξ| > s0 |ξ|.
pd::StretchRatio brute_force(const pd::Model& m, const pd::Vec3Array& u, bool lps) {
  pd::StretchRatio r;
  const auto& x = m.nodes.x;
  for (std::size_t i = 0; i < m.nodes.size(); ++i)
    for (std::int64_t k = m.bonds.offsets[i]; k < m.bonds.offsets[i + 1]; ++k) {
      const auto j = static_cast<std::size_t>(m.bonds.neighbour[static_cast<std::size_t>(k)]);
      if (m.bonds.broken[static_cast<std::size_t>(k)] || m.no_fail[i] || m.no_fail[j]) continue;
      const double d0 = x[0][j] - x[0][i], d1 = x[1][j] - x[1][i], d2 = x[2][j] - x[2][i];
      const double length = std::sqrt(d0 * d0 + d1 * d1 + d2 * d2);
      const double e0 = (x[0][j] + u[0][j]) - (x[0][i] + u[0][i]), e1 = (x[1][j] + u[1][j]) - (x[1][i] + u[1][i]),
                   e2 = (x[2][j] + u[2][j]) - (x[2][i] + u[2][i]);
      const double y = std::sqrt(e0 * e0 + e1 * e1 + e2 * e2);
      const std::vector<double>& s0_node = pdtest::s0_of(m);
      const double s0 = s0_node.empty()
                            ? m.material.critical_pair[static_cast<std::size_t>(m.block_index[i] * m.material.blocks + m.block_index[j])]
                            : std::min(s0_node[i], s0_node[j]);
      double ratio = 0.0;
      bool over = false;
      if (lps) {
        ratio = (y - length) / (s0 * length);
        over = y - length > s0 * length;
      } else {
        double s = (y - length) / length;
        if (!(std::fabs(s) > pd::kStretchZero)) s = 0.0;
        ratio = s / s0;
        over = s > s0;
      }
      r.largest = std::max(r.largest, ratio);
      if (i < j && over) ++r.over;
    }
  return r;
}

bool same_bits(const pd::Vec3Array& a, const pd::Vec3Array& b) {
  for (std::size_t d = 0; d < 3; ++d)
    if (a[d].size() != b[d].size() || std::memcmp(a[d].data(), b[d].data(), a[d].size() * sizeof(double)) != 0) return false;
  return true;
}

void expect_ratio_is_the_brute_force_and_counts_what_breaks(pd::Model& m, bool lps) {
  const pd::Vec3Array u = stretched(m);
  const pd::StretchRatio expected = brute_force(m, u, lps);
  ASSERT_GT(expected.over, 0);  // some bonds over s0 ...
  std::int64_t bonds = 0, candidates = 0;
  for (std::size_t i = 0; i < m.nodes.size(); ++i)
    for (std::int64_t k = m.bonds.offsets[i]; k < m.bonds.offsets[i + 1]; ++k)
      bonds += i < static_cast<std::size_t>(m.bonds.neighbour[static_cast<std::size_t>(k)]);
  for (std::uint8_t f : m.no_fail) candidates += f == 0;
  ASSERT_LT(expected.over, bonds);  // ... and some not
  ASSERT_GT(candidates, 0);
  for (const int threads : {1, 2}) {
    omp_set_num_threads(threads);
    const pd::StretchRatio got = m.bond_model->stretch_ratio(m, u);
    EXPECT_EQ(std::memcmp(&got.largest, &expected.largest, sizeof(double)), 0)
        << threads << " threads: " << got.largest << " vs " << expected.largest;
    EXPECT_EQ(got.over, expected.over) << threads << " threads";
  }
  omp_set_num_threads(1);
  // The count is what break_bonds breaks at this u; after it, no bond is over and the ratio ≤ 1.
  pd::Model copy = m;
  const pd::BreakReport broke = copy.bond_model->break_bonds(copy, u, false);
  EXPECT_EQ(broke.broken, expected.over);
  const pd::StretchRatio after = copy.bond_model->stretch_ratio(copy, u);
  EXPECT_EQ(after.over, 0);
  EXPECT_LE(after.largest, 1.0);
  EXPECT_GT(after.largest, 0.9);  // the bonds just below s0 are still there
}

struct LoadRun {
  explicit LoadRun(double pull = 4e-3) : model(breakable_bar("pmb", pull)) {
    qs.configure(one_step_case());
    qs.initialize(state, t);
  }
  pd::Model model;
  pd::ForceOperator op{model};
  pd::QuasiStatic qs{op};
  pd::State state{model.nodes.size()};
  double t = 0.0;
  double step(double dt) {
    double h = dt;
    qs.step(state, t, h);
    return h;
  }
};

}  // namespace

TEST(StretchRatio, IsTheBruteForceMaximumAndCountsWhatBreakBondsBreaksForPmb) {
  pd::Model m = breakable_bar();
  expect_ratio_is_the_brute_force_and_counts_what_breaks(m, false);
}

TEST(StretchRatio, IsTheBruteForceMaximumAndCountsWhatBreakBondsBreaksForLammpsRule) {
  // LAMMPS's α rule: each bond against min(s0_i, s0_j) of the previous pass, here set per node.
  pd::Model m = breakable_bar();
  const double s0 = m.material.critical_pair[0];
  const pd::Vec3Array spread = pdtest::pseudo_random(m.nodes.size(), 9);
  std::vector<double>& s0_node = pdtest::declare_s0(m, s0);
  for (std::size_t i = 0; i < m.nodes.size(); ++i) s0_node[i] = s0 * (1.0 + 0.05 * spread[0][i]);
  ASSERT_TRUE(pd::uses_lammps_rules(m));
  expect_ratio_is_the_brute_force_and_counts_what_breaks(m, false);
}

TEST(StretchRatio, IsTheBruteForceMaximumAndCountsWhatBreakBondsBreaksForLps) {
  pd::Model m = breakable_bar("lps");
  ASSERT_EQ(m.bond_model->name(), "lps");
  expect_ratio_is_the_brute_force_and_counts_what_breaks(m, true);
}

TEST(StretchCut, OneHugeLoadStepLandsAtTheFirstFailureLoadOfTheLinearResponse) {
  pdtest::OneThread one;
  // The first-failure load from the linear response: the largest ratio at a small load t_p, where the
  // body is elastic, scaled to 1: t_f = t_p / r(t_p) (the stretch per unit grip displacement times
  // the grip displacement reaches s0).
  LoadRun probe;
  const double t_p = 0.02;
  probe.step(t_p);
  const pd::StretchRatio r_p = probe.op.stretch_ratio(probe.state);
  ASSERT_EQ(r_p.over, 0);
  const double t_f = t_p / r_p.largest;
  ASSERT_GT(t_f, 0.1);  // 4e-3 at t = 1 against s0 ≈ 1e-3: the first failure well inside the pull
  ASSERT_LT(t_f, 0.5);

  // One load step asked for the whole pull: cut to just below the first failure (1 − κ/2), nothing broken.
  LoadRun run;
  const double h = run.step(1.0);
  const double kappa = pd::QuasiStatic::kCutMargin;
  EXPECT_EQ(run.qs.cuts(), 1);
  EXPECT_EQ(h, run.t);
  EXPECT_LT(std::fabs(run.t - t_f * (1.0 - 0.5 * kappa)), 0.5 * kappa * t_f) << run.t << " vs t_f = " << t_f;
  EXPECT_EQ(run.qs.last_step().broken_now, 0);
  const pd::StretchRatio r = run.op.stretch_ratio(run.state);
  EXPECT_EQ(r.over, 0);
  EXPECT_GT(r.largest, 1.0 - kappa);
  // The next huge step: cut to cross the first failure by about κ/2, the first bonds break there.
  const double t_before = run.t;
  run.step(1.0);
  EXPECT_EQ(run.qs.cuts(), 2);
  EXPECT_GT(run.qs.last_step().broken_now, 0);
  EXPECT_LT(run.t - t_before, 2.0 * kappa * t_f) << run.t;  // a short step (linear: κ t_f)
  EXPECT_LT(std::fabs(run.t - t_f), kappa * t_f) << run.t << " vs t_f = " << t_f;
}

TEST(StretchCut, TheCutStepIsBitwiseTheStepAskedForDirectlyOnOneAndTwoThreads) {
  pd::State first;
  for (const int threads : {1, 2}) {
    omp_set_num_threads(threads);
    // A: a small load step (a factorisation in use), then one huge one, cut (below the first
    // failure, then past it). B: the same small step, then the cut steps' lengths asked for
    // directly. Pulled to 0.2 of the length at t = 1: the huge trial is so far into the geometric
    // nonlinearity that it factorises anew, which the cut must undo.
    LoadRun a(0.2), b(0.2);
    a.step(0.001), b.step(0.001);
    const int factorisations = a.qs.factorisations();
    const double h1 = a.step(1.0);
    const int cuts = a.qs.cuts();
    ASSERT_GE(cuts, 1);
    b.step(h1);
    EXPECT_EQ(b.qs.cuts(), 0);
    EXPECT_EQ(a.t, b.t);
    EXPECT_TRUE(same_bits(a.state.u, b.state.u)) << threads << " threads";
    EXPECT_TRUE(same_bits(a.state.v, b.state.v)) << threads << " threads";
    EXPECT_TRUE(same_bits(a.state.f, b.state.f)) << threads << " threads";
    const int before = a.qs.factorisations();
    const double h2 = a.step(1.0);
    ASSERT_GT(a.qs.cuts(), cuts);
    // The trial, at a pull of 0.2, made a new factorisation before the cut: what restore_solver
    // must undo. The redone step then breaks bonds (taken out of the factor it started with,
    // bonds_out_of_factor.hpp) exactly as the direct step does: one factorisation more than it.
    (void)factorisations;
    const int b_before = b.qs.factorisations();
    b.step(h2);
    EXPECT_EQ(a.qs.factorisations() - before, b.qs.factorisations() - b_before + 1);
    EXPECT_EQ(b.qs.cuts(), 0);
    EXPECT_EQ(a.t, b.t);
    EXPECT_TRUE(same_bits(a.state.u, b.state.u)) << threads << " threads";
    EXPECT_TRUE(same_bits(a.state.f, b.state.f)) << threads << " threads";
    EXPECT_EQ(a.model.bonds.broken, b.model.bonds.broken);
    std::printf("[ cut      ] %d threads: %d cuts; factorisations %d (cut) and %d (direct), %lld bonds broken at t = %.6g\n",
                threads, a.qs.cuts(), a.qs.factorisations(), b.qs.factorisations(),
                static_cast<long long>(a.qs.last_step().broken_now), a.t);
    // And the same bits on 1 and 2 threads.
    if (threads == 1) first = a.state;
    else EXPECT_TRUE(same_bits(first.u, a.state.u));
  }
  omp_set_num_threads(1);
}
