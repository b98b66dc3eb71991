// The adaptive step of thesis §2.2 (integrators/adaptive): it settles from a start far above the
// stable step without a non-finite value and with bounded energy, accepts only converged steps,
// has the order of the θ-method with θ = φ, fails cleanly at dt_min, and is bitwise the
// same for any thread count.
#include <gtest/gtest.h>
#include <omp.h>

#include <cmath>
#include <cstdio>
#include <cstring>

#include "core/stability.hpp"
#include "materials/pmb/pmb.hpp"
#include "integrators/adaptive.hpp"
#include "energy.hpp"
#include "lattice.hpp"
#include "one_thread.hpp"

namespace {

using pdtest::OneThread;

constexpr double kPi = 3.14159265358979323846;

pd::Case plate_case() {
  const double dx = 1e-3;
  return pdtest::lattice_case(2, "plane_stress", dx, 3.015 * dx, 1e9, 1000.0, -1.0, 1e-3);
}

pd::Model plate(const pd::Case& c, int n = 12) { return pd::build_model(c, pdtest::cubic_lattice(n, n, 1, 1e-3, 2, 1e-3)); }

pd::State smooth_state(const pd::Model& m) {
  pd::State s(m.nodes.size());
  double lx = 0.0;
  for (double x : m.nodes.x[0]) lx = std::max(lx, x);
  for (std::size_t i = 0; i < s.size(); ++i) {
    s.v[0][i] = std::sin(kPi * m.nodes.x[0][i] / lx) * std::cos(kPi * m.nodes.x[1][i] / lx);
    s.v[2][i] = std::sin(kPi * m.nodes.x[0][i] / lx) * std::sin(kPi * m.nodes.x[1][i] / lx);
  }
  return s;
}

double energy(const pd::Model& m, const pd::State& s) { return pdtest::mechanical_energy(m, s); }

bool finite(const pd::State& s) {
  for (std::size_t d = 0; d < 3; ++d)
    for (std::size_t i = 0; i < s.size(); ++i)
      if (!std::isfinite(s.u[d][i]) || !std::isfinite(s.v[d][i])) return false;
  return true;
}

struct AdaptiveRun {
  pd::State state;
  double t = 0.0, last_dt = 0.0;
  int steps = 0, rejected = 0, max_k = 0;
  std::int64_t evaluations = 0;
  double max_energy_ratio = 0.0;
};

// Adaptive steps to t_end, proposing the controller's dt each time and landing on t_end.
AdaptiveRun run_adaptive(pd::Model& m, const pd::Case& c, double dt0, double t_end, pd::State s) {
  pd::ForceOperator op_integrator(m);
  pd::AdaptiveStep integrator(op_integrator);
  integrator.configure(c);
  AdaptiveRun r;
  const double e0 = energy(m, s);
  integrator.initialize(s, r.t);
  double dt = dt0;
  while (r.t < t_end * (1 - 1e-12)) {
    double h = std::min(dt, t_end - r.t);
    integrator.step(s, r.t, h);
    r.last_dt = h;
    dt = integrator.last_step().next_dt;
    ++r.steps;
    r.rejected += integrator.last_step().rejected;
    r.max_k = std::max(r.max_k, integrator.last_step().iterations);
    r.evaluations += integrator.last_step().force_evaluations;
    EXPECT_TRUE(finite(s)) << "step " << r.steps;
    if (!finite(s)) break;
    r.max_energy_ratio = std::max(r.max_energy_ratio, energy(m, s) / e0);
  }
  r.state = std::move(s);
  return r;
}

}  // namespace

TEST(Adaptive, SettlesFromAHundredTimesTheStableStep) {
  const OneThread one_thread;
  for (double phi : {1.0, 0.5}) {
    pd::Case c = plate_case();
    pd::Model m = plate(c);
    const double dt_sa = pd::stable_time_step(m), dt_exact = pd::exact_time_step(m);
    c.adaptive.phi = phi;
    c.adaptive.dt_initial = c.adaptive.dt_max = 100.0 * dt_sa;  // nothing but the controller holds it back
    const AdaptiveRun r = run_adaptive(m, c, 100.0 * dt_sa, 200 * dt_sa, smooth_state(m));
    EXPECT_GT(r.rejected, 0) << "phi " << phi;
    // Energy bounded: φ = 1 dissipates, φ = ½ conserves up to the iteration tolerance.
    EXPECT_LT(r.max_energy_ratio, 1.05) << "phi " << phi;
    // It settled where the fixed-point iteration contracts, φ²Δt²ω_max² < 1 (plus the controller's overshoot).
    EXPECT_LT(r.last_dt, 1.5 * dt_exact / (2.0 * phi)) << "phi " << phi;
    EXPECT_LE(r.max_k, c.adaptive.kd);
  }
}

TEST(Adaptive, PhiHalfIsSecondOrderAndPhiOneFirstOrder) {
  const OneThread one_thread;
  // With TOL tight enough that the iteration error is negligible, the scheme is the θ-method
  // (θ = φ): halving Δt (held by dt_max; a smooth motion always sits there) cuts the error ≈4×
  // for φ = ½; φ = 1 is first order. Reference: Verlet at 1/64 of the coarse step.
  pd::Case c = plate_case();
  pd::Model m = plate(c, 10);
  const double dt_sa = pd::stable_time_step(m), dt0 = 0.5 * dt_sa, t_end = 50 * dt0;
  pd::State ref = smooth_state(m);
  {
    pd::ForceOperator op_verlet(m);
    auto verlet = pd::integrator_registry().get("verlet")(op_verlet);
    double t = 0.0;
    verlet->initialize(ref, t);
    for (int k = 0; k < 50 * 64; ++k) {
      double h = t_end / (50 * 64);
      verlet->step(ref, t, h);
    }
  }
  double scale = 0.0;
  for (std::size_t d = 0; d < 3; ++d)
    for (std::size_t i = 0; i < ref.size(); ++i) scale = std::max(scale, std::fabs(ref.u[d][i]));
  double error_half[2] = {0.0, 0.0};
  for (double phi : {0.5, 1.0}) {
    double error[2];
    for (int r = 0; r < 2; ++r) {
      pd::Model mk = plate(c, 10);
      c.adaptive.phi = phi;
      c.adaptive.tol = 1e-9;
      c.adaptive.dt_max = dt0 / (1 << r);
      const AdaptiveRun run = run_adaptive(mk, c, dt0 / (1 << r), t_end, smooth_state(mk));
      EXPECT_EQ(run.rejected, 0);
      double e = 0.0;
      for (std::size_t d = 0; d < 3; ++d)
        for (std::size_t i = 0; i < ref.size(); ++i) e = std::max(e, std::fabs(run.state.u[d][i] - ref.u[d][i]));
      error[r] = e / scale;
    }
    std::printf("adaptive phi %.1f: error %.3g at dt, %.3g at dt/2, ratio %.2f\n", phi, error[0], error[1],
                error[0] / error[1]);
    if (phi == 0.5) {
      EXPECT_GT(error[0] / error[1], 3.5);
      EXPECT_LT(error[0] / error[1], 4.5);
    } else {
      // First order, and still pre-asymptotic at these steps (measured ratio 1.26): it must fall,
      // and stay well above the second-order φ = ½ error.
      EXPECT_LT(error[1], error[0]);
      EXPECT_GT(error[1], 5.0 * error_half[0]);
    }
    if (phi == 0.5) error_half[0] = error[0], error_half[1] = error[1];
  }
}

TEST(Adaptive, AtRestTheStepIsExactAndGrowsToDtMax) {
  pd::Case c = plate_case();
  pd::Model m = plate(c);
  pd::ForceOperator op_integrator(m);
  pd::AdaptiveStep integrator(op_integrator);
  integrator.configure(c);
  pd::State s(m.nodes.size());
  double t = 0.0, h = 1e-9;
  integrator.initialize(s, t);
  integrator.step(s, t, h);
  EXPECT_EQ(integrator.last_step().iterations, 1);
  EXPECT_EQ(integrator.last_step().rejected, 0);
  EXPECT_EQ(integrator.last_step().next_dt, integrator.dt_max());
  // The documented default: eq. 2.5, lowered to 0.9 × Δt_exact/(2φ) where the fixed-point iteration
  // stops contracting; on this 2D lattice with φ = 1 the second is the smaller (0.77 × eq. 2.5).
  const double contraction = 0.9 * pd::exact_time_step(m) / (2.0 * c.adaptive.phi);
  EXPECT_EQ(integrator.dt_max(), std::min(pd::stable_time_step(m), contraction));
  EXPECT_LT(contraction, pd::stable_time_step(m));
}

TEST(Adaptive, NoConvergenceAtDtMinThrowsAndKeepsTheState) {
  pd::Case c = plate_case();
  pd::Model m = plate(c);
  const double dt_sa = pd::stable_time_step(m);
  c.adaptive.dt_min = c.adaptive.dt_max = 100.0 * dt_sa;
  pd::ForceOperator op_integrator(m);
  pd::AdaptiveStep integrator(op_integrator);
  integrator.configure(c);
  pd::State s = smooth_state(m);
  double t = 0.0;
  integrator.initialize(s, t);
  const pd::State before = s;
  double h = 100.0 * dt_sa;
  EXPECT_THROW(integrator.step(s, t, h), pd::StepFailed);
  EXPECT_EQ(t, 0.0);
  EXPECT_EQ(s.u[0], before.u[0]);
  EXPECT_EQ(s.v[2], before.v[2]);
  EXPECT_EQ(s.f[0], before.f[0]);
}

TEST(Adaptive, BitwiseIdenticalWithOneAndTwoThreads) {
  pd::State result[2];
  const int saved = omp_get_max_threads();
  for (int r = 0; r < 2; ++r) {
    omp_set_num_threads(r + 1);
    pd::Case c = plate_case();
    pd::Model m = plate(c);
    c.adaptive.dt_max = 10.0 * pd::stable_time_step(m);
    result[r] = run_adaptive(m, c, 10.0 * pd::stable_time_step(m), 20 * pd::stable_time_step(m), smooth_state(m)).state;
  }
  omp_set_num_threads(saved);
  for (std::size_t d = 0; d < 3; ++d) {
    const std::size_t bytes = result[0].u[d].size() * sizeof(double);
    EXPECT_EQ(std::memcmp(result[0].u[d].data(), result[1].u[d].data(), bytes), 0);
    EXPECT_EQ(std::memcmp(result[0].v[d].data(), result[1].v[d].data(), bytes), 0);
  }
}
