// The state-based LPS law in the Newton-solved integrators (issue 13): quasi_static by matrix-free
// CG with the law's diagonal blocks (materials/lps/lps_tangent.cpp) — a pulled bar reaches
// equilibrium, the damped explicit run of the same bar comes to the same state, bitwise for 1 and
// 2 threads — what factorises the tangent refused with the reason, and mixed switching when an LPS
// bar snaps.
#include <gtest/gtest.h>
#include <omp.h>

#include <algorithm>
#include <cmath>
#include <cstring>

#include "core/error.hpp"
#include "integrators/implicit.hpp"
#include "integrators/mixed.hpp"
#include "integrators/quasi_static.hpp"
#include "integrators/verlet.hpp"
#include "force_norm.hpp"
#include "lattice.hpp"

namespace {

constexpr double kDx = 1e-3;
constexpr int kNx = 12, kNy = 4, kNz = 4;
constexpr double kStrain = 1e-3;  // of the bar's length: geometrically nonlinear enough for several Newton iterations

// A 12×4×4 LPS bar (ν = 0.3, ω = 1), δ = 3.015dx, E = 1 GPa: the left two layers clamped, the right
// two pulled along x to kStrain·L at t = end and held across. fracture_energy < 0: unbreakable.
pd::Model lps_bar(double end, double fracture_energy = -1.0, double damping = 0.0) {
  pd::Case c = pdtest::lattice_case(3, "3d", kDx, 3.015 * kDx, 1e9, 1000.0, fracture_energy);
  c.blocks[0].model = "lps";
  c.blocks[0].parameters["poisson_ratio"] = 0.3;
  c.blocks[0].choices["influence"] = "one";
  c.damping = damping;
  pdtest::clamp_left_pull_right(c, (fracture_energy > 0 ? 4e-3 : kStrain) * (kNx - 1) * kDx, end, true);
  return pd::build_model(c, pdtest::bar_with_grips(kNx, kNy, kNz, kDx));
}

pd::Case quasi_static_case(const std::string& solver) {
  pd::Case c;
  c.file = "lps_bar.yaml";
  c.time.end = 1.0;
  c.quasi_static.residual_tol = 1e-10;
  c.quasi_static.newton_tol = 1e-8;
  c.quasi_static.linear_solver = solver;
  return c;
}

using pdtest::force_norm;

bool same_bits(const pd::Vec3Array& a, const pd::Vec3Array& b) {
  for (std::size_t d = 0; d < 3; ++d)
    if (a[d].size() != b[d].size() || std::memcmp(a[d].data(), b[d].data(), a[d].size() * sizeof(double)) != 0) return false;
  return true;
}

struct Pulled {
  pd::State state{0};
  int max_iterations = 0, steps = 0;
  std::int64_t cg_iterations = 0;
  std::string describe;
  double residual = 0.0, load = 0.0;
};

// The bar pulled quasi-statically to t = 1 on `threads` threads.
Pulled pull(int threads) {
  const int saved = omp_get_max_threads();
  omp_set_num_threads(threads);
  pd::Model m = lps_bar(1.0);
  pd::ForceOperator op(m);
  pd::QuasiStatic qs(op);
  qs.configure(quasi_static_case("auto"));
  Pulled out;
  out.describe = qs.describe(0.0).front();
  out.state = pd::State(m.nodes.size());
  double t = 0.0, dt = 1.0;
  qs.initialize(out.state, t);
  while (t < 1.0 - 1e-12) {
    double h = std::min(dt, 1.0 - t);
    qs.step(out.state, t, h);
    dt = qs.last_step().next_dt;
    out.max_iterations = std::max(out.max_iterations, qs.last_step().iterations);
    ++out.steps;
  }
  EXPECT_TRUE(qs.uses_cg());
  out.cg_iterations = qs.cg_iterations();
  out.residual = force_norm(m, out.state, true);
  out.load = force_norm(m, out.state, false);
  omp_set_num_threads(saved);
  return out;
}

}  // namespace

TEST(LpsQuasiStatic, PulledBarReachesEquilibriumThatTheDampedExplicitRunApproaches) {
  const Pulled qs = pull(1);
  // Equilibrium: the free dofs' residual below 1e-10 of the applied (reaction) force, in a handful
  // of Newton iterations per load step.
  EXPECT_LT(qs.residual, 1e-10 * qs.load);
  EXPECT_LE(qs.max_iterations, 6);
  EXPECT_NE(qs.describe.find("matrix-free CG with block-Jacobi, Eisenstat-Walker forcing (cg, auto: the material lps "
                             "has no assembled tangent)"),
            std::string::npos)
      << qs.describe;
  // The same bar pulled explicitly over 20 µs, then held, with mass damping α near the lowest mode's
  // critical value: Verlet comes to rest in the same state.
  pd::Model m = lps_bar(2e-5, -1.0, 3e5);
  pd::ForceOperator op(m);
  pd::VelocityVerlet verlet(op);
  pd::State s(m.nodes.size());
  double t = 0.0;
  op.start(s, t);
  const double dt = 0.8 * op.stable_time_step();
  int steps = 0;
  for (; steps < 40000; ++steps) {
    double h = dt;
    verlet.step(s, t, h);
    if (t > 1e-4 && op.kinetic_energy(s) < 1e-24 * op.strain_energy(s)) break;
  }
  double error = 0.0, scale = 0.0;
  for (std::size_t d = 0; d < 3; ++d)
    for (std::size_t i = 0; i < s.size(); ++i) {
      error = std::max(error, std::fabs(s.u[d][i] - qs.state.u[d][i]));
      scale = std::max(scale, std::fabs(qs.state.u[d][i]));
    }
  // The interior strain: the mean u_x slope between the grips (layers 3 to 8) of both runs.
  const auto interior_strain = [](const pd::State& state) {
    double sum = 0.0;
    for (int k = 0; k < kNz; ++k)
      for (int j = 0; j < kNy; ++j)
        sum += state.u[0][pdtest::node_index(8, j, k, kNx, kNy)] - state.u[0][pdtest::node_index(3, j, k, kNx, kNy)];
    return sum / (kNy * kNz * 5 * kDx);
  };
  const double e_qs = interior_strain(qs.state), e_explicit = interior_strain(s);
  std::printf("[ lps qs   ] %d load steps, ≤ %d Newton iterations each, %lld CG iterations; residual %.2e of the load; "
              "damped Verlet after %d steps: max |Δu| %.2e of max |u|, interior strain %.6e (qs) %.6e (explicit)\n",
              qs.steps, qs.max_iterations, static_cast<long long>(qs.cg_iterations), qs.residual / qs.load, steps,
              error / scale, e_qs, e_explicit);
  EXPECT_LT(steps, 40000) << "the damped run did not come to rest";
  EXPECT_LT(error, 1e-6 * scale);
  EXPECT_NEAR(e_qs, e_explicit, 1e-6 * e_qs);
  EXPECT_GT(e_qs, 0.5 * kStrain);  // the grips' share taken, most of the pull strains the interior
}

TEST(LpsQuasiStatic, BitwiseTheSameOnOneAndTwoThreads) {
  const Pulled one = pull(1), two = pull(2);
  EXPECT_TRUE(same_bits(one.state.u, two.state.u));
  EXPECT_TRUE(same_bits(one.state.f, two.state.f));
  EXPECT_EQ(one.cg_iterations, two.cg_iterations);
}

TEST(LpsQuasiStatic, WhatFactorisesTheTangentIsRefusedWithTheReason) {
  pd::Model m = lps_bar(1.0);
  pd::ForceOperator op(m);
  pd::QuasiStatic qs(op);
  try {
    qs.configure(quasi_static_case("direct"));
    FAIL() << "direct accepted";
  } catch (const pd::Error& e) {
    EXPECT_NE(std::string(e.what()).find("lps_bar.yaml: quasi_static.linear_solver: direct needs an assembled tangent, "
                                         "which the state-based material lps"),
              std::string::npos)
        << e.what();
  }
  // implicit: auto takes the matrix-free path for lps; direct is refused with what to do.
  pd::Case c = quasi_static_case("auto");
  {
    pd::Implicit implicit(op);
    implicit.configure(c);
    EXPECT_TRUE(implicit.uses_cg());
    EXPECT_NE(implicit.describe(0.0)[1].find("(cg, auto: the material lps has no assembled tangent"), std::string::npos)
        << implicit.describe(0.0)[1];
  }
  pd::Implicit implicit(op);
  c.implicit.linear_solver = "direct";
  try {
    implicit.configure(c);
    FAIL() << "implicit with linear_solver: direct accepted";
  } catch (const pd::Error& e) {
    EXPECT_NE(std::string(e.what()).find("lps_bar.yaml: implicit.linear_solver: direct needs an assembled tangent, "
                                         "which the state-based material lps"),
              std::string::npos)
        << e.what();
  }
  pd::Mixed mixed(op);
  c.mixed.start = "implicit";
  EXPECT_THROW(mixed.configure(c), pd::Error);
}

TEST(LpsMixed, QuasiStaticUntilTheBarSnapsThenExplicit) {
  // The breakable LPS bar (G0 = 3.6 J/m²) pulled to 4e-3 of its length in 1 ms by the mixed scheme:
  // CG load steps until the bar snaps, then Verlet.
  constexpr double kEnd = 1e-3;
  pd::Model m = lps_bar(kEnd, 3.6);
  pd::ForceOperator op(m);
  pd::Mixed mixed(op);
  pd::Case c;
  c.time.end = kEnd;
  c.time.integrator = "mixed";
  c.quasi_static.dt_max = kEnd / 40;
  c.quasi_static.dt_initial = kEnd / 40;
  c.mixed.arrest_steps = 50;
  mixed.configure(c);
  EXPECT_NE(mixed.describe(0.0).front().find("(cg, auto: the material lps has no assembled tangent)"), std::string::npos);
  pd::State s(m.nodes.size());
  double t = 0.0, dt = *mixed.initial_dt();
  mixed.initialize(s, t);
  std::vector<int> modes;
  std::vector<std::string> log;
  while (t < kEnd * (1 - 1e-12)) {
    double h = std::min(dt, kEnd - t);
    mixed.step(s, t, h);
    dt = mixed.last_step().next_dt;
    modes.push_back(*mixed.step_mode());
    for (auto& line : mixed.take_log_lines()) log.push_back(line);
    ASSERT_LT(modes.size(), 100000u);
  }
  EXPECT_EQ(modes.front(), pd::Mixed::kQuasiStatic);
  const auto first_explicit = std::find(modes.begin(), modes.end(), static_cast<int>(pd::Mixed::kExplicit));
  ASSERT_NE(first_explicit, modes.end()) << "the bar never went explicit";
  EXPECT_GE(first_explicit - modes.begin(), 3);
  std::int64_t broken = 0;
  for (auto b : m.bonds.broken) broken += b;
  EXPECT_GT(broken, 0);
  ASSERT_FALSE(log.empty());
  EXPECT_NE(log.front().find("quasi-static → explicit"), std::string::npos) << log.front();
  for (std::size_t d = 0; d < 3; ++d)
    for (double u : s.u[d]) ASSERT_TRUE(std::isfinite(u));
  std::printf("[ lps mix  ] %zu steps, %td quasi-static before the first explicit one, %lld bonds broken; %s\n",
              modes.size(), first_explicit - modes.begin(), static_cast<long long>(broken), log.front().c_str());
}
