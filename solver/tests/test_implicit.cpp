// Implicit dynamics (integrators/implicit.hpp) on a small cantilever plate whose linearised modes are
// computed here (inverse and power iteration with the assembled tangent): at ρ∞ = 1 the energy is
// conserved at 20× the explicit step and a mode's period lengthens by the trapezoidal rule's
// ωΔt/(2 arctan(ωΔt/2)); ρ∞ < 1 removes the high frequencies and keeps the low one; the error falls
// 4× per halving of Δt and in proportion to implicit.tol; a free body is fine; restart and 1 vs 2
// threads are bitwise; bonds break after a converged step with the balance kept at its end.
#include <gtest/gtest.h>
#include <omp.h>

#include <cmath>
#include <cstring>

#include "core/stability.hpp"
#include "integrators/implicit.hpp"
#include "lattice.hpp"
#include "linalg/cholesky.hpp"

namespace {

constexpr double kDx = 1e-3;
constexpr int kNx = 16, kNy = 6;
constexpr double kRho = 1000.0, kThickness = 1e-3;

// A 16×6 plane-stress plate, δ = 3.015dx, E = 1 GPa: the left two columns clamped (a cantilever),
// or nothing held (`held` false). fracture_energy < 0: unbreakable.
pd::Model plate(bool held = true, double fracture_energy = -1.0) {
  pd::Case c = pdtest::lattice_case(2, "plane_stress", kDx, 3.015 * kDx, 1e9, kRho, fracture_energy, kThickness);
  pd::Nodes nodes = pdtest::cubic_lattice(kNx, kNy, 1, kDx, 2, kThickness);
  pd::NodeSet left{"left", std::vector<std::uint8_t>(nodes.size(), 0)};
  for (std::size_t i = 0; i < nodes.size(); ++i) left.member[i] = nodes.x[0][i] < 1.5 * kDx;
  nodes.sets = {left};
  if (held)
    for (int d = 0; d < 2; ++d) c.boundary_conditions.push_back({"left", "displacement", d, {0.0}, {0.0}});
  return pd::build_model(c, std::move(nodes));
}

// Settings for a fixed step h: dt_min = dt_max = h and no error control (tol = ∞ cannot be written in
// a case file; it turns the integrator into the plain generalized-α scheme these tests measure).
pd::Case fixed_step(double h, double rho_infinity, double end) {
  pd::Case c;
  c.time.end = end;
  c.implicit.rho_infinity = rho_infinity;
  c.implicit.tol = HUGE_VAL;
  c.implicit.newton_tol = 1e-7;
  c.implicit.dt_min = c.implicit.dt_max = h;
  return c;
}

// The linearised plate: free dofs, the tangent K at rest, the lumped mass m per dof.
struct Linear {
  pd::FreeDofs dofs;
  pd::SparseMatrix K;
  std::vector<double> mass;
  explicit Linear(pd::Model& m) {
    const pd::ForceOperator op(m);
    dofs = pd::FreeDofs::of(m.nodes.size(), 2, m.conditions.fixed);
    K = op.assemble_stiffness(pd::State(m.nodes.size()), 0.0, dofs);
    for (std::size_t q = 0; q < dofs.size(); ++q)
      mass.push_back(m.density[static_cast<std::size_t>(dofs.node[q])] * m.nodes.volume[static_cast<std::size_t>(dofs.node[q])]);
  }
  double m_dot(const std::vector<double>& a, const std::vector<double>& b) const {
    double s = 0.0;
    for (std::size_t q = 0; q < a.size(); ++q) s += mass[q] * a[q] * b[q];
    return s;
  }
  void normalise(std::vector<double>& x) const {
    const double norm = std::sqrt(m_dot(x, x));
    for (double& value : x) value /= norm;
  }
  double omega(const std::vector<double>& x) const {  // the Rayleigh quotient's √
    std::vector<double> kx;
    K.multiply(x, kx);
    double xkx = 0.0;
    for (std::size_t q = 0; q < x.size(); ++q) xkx += x[q] * kx[q];
    return std::sqrt(xkx / m_dot(x, x));
  }
  // The lowest mode, M-normalised (inverse iteration x ← K⁻¹Mx).
  std::vector<double> lowest(double& omega_1) const {
    pd::SparseCholesky chol;
    EXPECT_TRUE(chol.factorize(K));
    std::vector<double> x(dofs.size(), 1.0), b(dofs.size());
    for (int it = 0; it < 200; ++it) {
      for (std::size_t q = 0; q < x.size(); ++q) b[q] = mass[q] * x[q];
      chol.solve(b, x);
      normalise(x);
    }
    omega_1 = omega(x);
    return x;
  }
  // A vector of the highest frequencies (power iteration x ← M⁻¹Kx, 60 times, from a checkerboard).
  std::vector<double> highest(double& omega_high) const {
    std::vector<double> x(dofs.size()), kx;
    for (std::size_t q = 0; q < x.size(); ++q) x[q] = ((dofs.node[q] + dofs.component[q]) % 2) ? 1.0 : -1.0;
    for (int it = 0; it < 60; ++it) {
      K.multiply(x, kx);
      for (std::size_t q = 0; q < x.size(); ++q) x[q] = kx[q] / mass[q];
      normalise(x);
    }
    omega_high = omega(x);
    return x;
  }
};

// A run of the implicit integrator from u = u0 (free dofs), v = 0, stepped by hand.
struct PlateRun {
  pd::Model model;
  pd::ForceOperator op{model};
  pd::Implicit integrator{op};
  pd::State state{model.nodes.size()};
  double t = 0.0, dt = 0.0, end = 0.0;
  PlateRun(pd::Model m, const pd::Case& c, const pd::FreeDofs& dofs, const std::vector<double>& u0,
      const std::vector<double>* v0 = nullptr)
      : model(std::move(m)), end(c.time.end) {
    integrator.configure(c);
    dofs.scatter(u0, state.u);
    if (v0) dofs.scatter(*v0, state.v);
    integrator.initialize(state, 0.0);
    // Not value_or(*dt_max): its argument is evaluated even when dt_initial is set, and dt_max may be
    // empty then (caught by libstdc++'s assertions in the ASan build).
    dt = c.implicit.dt_initial ? *c.implicit.dt_initial : c.implicit.dt_max.value();
  }
  void step() {
    double h = std::min(dt, end - t);
    integrator.step(state, t, h);
    dt = integrator.last_step().next_dt;
  }
  double energy() const { return op.kinetic_energy(state) + op.strain_energy(state); }
};

std::vector<double> scaled(std::vector<double> x, double factor) {
  for (double& value : x) value *= factor;
  return x;
}

// The modal coordinates q = φᵀMu and q̇ = φᵀMv of an M-normalised φ.
double modal(const Linear& lin, const std::vector<double>& phi, const pd::Vec3Array& field) {
  std::vector<double> x;
  lin.dofs.gather(field, x);
  return lin.m_dot(phi, x);
}

bool same_bits(const pd::Vec3Array& a, const pd::Vec3Array& b) {
  for (std::size_t d = 0; d < 3; ++d)
    if (std::memcmp(a[d].data(), b[d].data(), a[d].size() * sizeof(double)) != 0) return false;
  return true;
}

// 1e-9 m of displacement per unit of the M-normalised mode's largest entry: strains ~1e-6, where
// PMB's geometric nonlinearity is far below what the tests measure.
double amplitude(const std::vector<double>& phi) {
  double largest = 0.0;
  for (double value : phi) largest = std::max(largest, std::fabs(value));
  return 1e-9 / largest;
}

}  // namespace

TEST(Implicit, GeneralizedAlphaParameters) {
  const pd::GeneralizedAlpha trapezoidal = pd::GeneralizedAlpha::of(1.0);
  EXPECT_DOUBLE_EQ(trapezoidal.alpha_m, 0.5);
  EXPECT_DOUBLE_EQ(trapezoidal.alpha_f, 0.5);
  EXPECT_DOUBLE_EQ(trapezoidal.beta, 0.25);
  EXPECT_DOUBLE_EQ(trapezoidal.gamma, 0.5);
  EXPECT_DOUBLE_EQ(trapezoidal.error_coefficient(), 1.0 / 12.0);  // Zienkiewicz & Xie's (β − 1/6)
  const pd::GeneralizedAlpha strongest = pd::GeneralizedAlpha::of(0.0);  // Chung & Hulbert's table
  EXPECT_DOUBLE_EQ(strongest.alpha_m, -1.0);
  EXPECT_DOUBLE_EQ(strongest.alpha_f, 0.0);
  EXPECT_DOUBLE_EQ(strongest.beta, 1.0);
  EXPECT_DOUBLE_EQ(strongest.gamma, 1.5);
}

TEST(Implicit, TrapezoidalConservesEnergyAtTwentyTimesTheExplicitStep) {
  pd::Model m = plate();
  const Linear lin(m);
  const double h = 20.0 * pd::stable_time_step(m);
  // Many modes at once: the lowest, the highest and a pseudo-random field.
  double w1 = 0.0, wh = 0.0;
  const std::vector<double> low = lin.lowest(w1), high = lin.highest(wh);
  std::vector<double> u0(low.size());
  for (std::size_t q = 0; q < u0.size(); ++q)
    u0[q] = amplitude(low) * low[q] + 0.3 * amplitude(high) * high[q] + 2e-11 * std::sin(37.0 * static_cast<double>(q));
  PlateRun run(std::move(m), fixed_step(h, 1.0, 400 * h), lin.dofs, u0);
  const double e0 = run.energy();
  double drift = 0.0;
  for (int n = 0; n < 400; ++n) {
    run.step();
    drift = std::max(drift, std::fabs(run.energy() / e0 - 1.0));
  }
  std::printf("trapezoidal at %.0f× eq. 2.5 (ω_max Δt = %.1f): energy within %.3g over 400 steps, %d factorisations\n",
              20.0, wh * h, drift, run.integrator.factorisations());
  EXPECT_GT(wh * h, 10.0);  // far beyond the explicit limit ωΔt < 2
  EXPECT_LT(drift, 1e-6);
  EXPECT_LE(run.integrator.factorisations(), 5);  // one Δt, a nearly linear tangent: kept (measured 3 in 400 steps)
}

TEST(Implicit, PeriodElongationIsTheTrapezoidalRules) {
  pd::Model m = plate();
  const Linear lin(m);
  double w = 0.0;
  const std::vector<double> phi = lin.lowest(w);
  for (double wdt : {0.5, 1.0}) {
    const double h = wdt / w;
    PlateRun run(plate(), fixed_step(h, 1.0, 60 * h), lin.dofs, scaled(phi, amplitude(phi)));
    std::vector<double> q{modal(lin, phi, run.state.u)};
    for (int n = 0; n < 60; ++n) run.step(), q.push_back(modal(lin, phi, run.state.u));
    // q_{n+1} + q_{n−1} = 2 cos(ΩΔt) q_n for any solution of a two-step recurrence of frequency Ω.
    double num = 0.0, den = 0.0;
    for (std::size_t n = 1; n + 1 < q.size(); ++n) num += q[n] * (q[n + 1] + q[n - 1]), den += 2.0 * q[n] * q[n];
    const double measured = w / (std::acos(num / den) / h);  // T_numerical / T
    const double expected = wdt / (2.0 * std::atan(0.5 * wdt));
    std::printf("ωΔt = %.1f: period ratio %.8f, trapezoidal rule %.8f\n", wdt, measured, expected);
    EXPECT_NEAR(measured, expected, 1e-5);
    EXPECT_GT(measured - 1.0, 0.8 * wdt * wdt / 12.0);  // the elongation is really there
  }
}

TEST(Implicit, RhoInfinityBelowOneDampsTheHighFrequenciesOnly) {
  pd::Model m = plate();
  const Linear lin(m);
  double w1 = 0.0, wh = 0.0;
  const std::vector<double> low = lin.lowest(w1), high = lin.highest(wh);
  const double h = 0.2 / w1;  // the low mode resolved, ω_high Δt ≫ 1
  std::vector<double> u0(low.size());
  for (std::size_t q = 0; q < u0.size(); ++q) u0[q] = amplitude(low) * low[q] + 0.3 * amplitude(high) * high[q];
  for (double rho_infinity : {1.0, 0.5}) {
    PlateRun run(plate(), fixed_step(h, rho_infinity, 20 * h), lin.dofs, u0);
    // The lowest mode's energy ½(q̇² + ω₁²q²); the rest is the other modes' (M- and K-orthogonal).
    const auto low_energy = [&] {
      const double q = modal(lin, low, run.state.u), qdot = modal(lin, low, run.state.v);
      return 0.5 * (qdot * qdot + w1 * w1 * q * q);
    };
    const double low0 = low_energy(), rest0 = run.energy() - low0;
    for (int n = 0; n < 20; ++n) run.step();
    const double low_kept = low_energy() / low0, rest_kept = (run.energy() - low_energy()) / rest0;
    std::printf("ρ∞ = %.1f, ω₁Δt = 0.2, ω_high Δt = %.0f: after 20 steps the low mode keeps %.6f of its energy, "
                "the high ones %.3g\n", rho_infinity, wh * h, low_kept, rest_kept);
    // Measured: ρ∞ = 0.5 takes 0.16 % from the low mode (third-order dissipation, ω₁Δt = 0.2) and
    // leaves 1.5e-6 of the rest (ρ∞² per step for the highest, 0.25^20 ~ 1e-12; the power iterate
    // holds some lower modes too).
    EXPECT_NEAR(low_kept, 1.0, 5e-3);
    if (rho_infinity == 1.0) EXPECT_NEAR(rest_kept, 1.0, 1e-6);
    else EXPECT_LT(rest_kept, 1e-5);
  }
}

TEST(Implicit, SecondOrderAndTheErrorFollowsTol) {
  pd::Model m = plate();
  const Linear lin(m);
  double w = 0.0;
  const std::vector<double> phi = lin.lowest(w);
  const double a = amplitude(phi), end = 1.25 * 2.0 * M_PI / w;  // q(end) = 0 exactly: all phase error
  const auto error_of = [&](const pd::Case& c) {
    PlateRun run(plate(), c, lin.dofs, scaled(phi, a));
    int steps = 0;
    while (run.t < end * (1 - 1e-14)) run.step(), ++steps;
    return std::make_pair(std::fabs(modal(lin, phi, run.state.u) / a - std::cos(w * end)), steps);
  };
  double previous = 0.0;
  for (int steps : {20, 40, 80}) {  // fixed steps
    const double error = error_of(fixed_step(end / steps, 1.0, end)).first;
    std::printf("fixed Δt = T/%d: error %.4g%s\n", steps, error,
                previous > 0.0 ? (", ratio " + std::to_string(previous / error)).c_str() : "");
    if (previous > 0.0) EXPECT_NEAR(previous / error, 4.0, 0.4);
    previous = error;
  }
  previous = 0.0;
  for (double tol : {4e-4, 2e-4, 1e-4}) {  // the step chosen by the error estimate
    pd::Case c;
    c.time.end = end;
    c.implicit.tol = tol;
    c.implicit.newton_tol = 1e-7;
    c.implicit.dt_initial = 0.01 / w;
    const auto [error, steps] = error_of(c);
    std::printf("tol %.0e: error %.4g in %d steps%s\n", tol, error, steps,
                previous > 0.0 ? (", ratio " + std::to_string(previous / error)).c_str() : "");
    if (previous > 0.0) EXPECT_NEAR(previous / error, 2.0, 0.5);
    EXPECT_LT(error, 30.0 * tol);  // the estimate bounds the error per step, the phase adds up over a period
    previous = error;
  }
}

TEST(Implicit, AFreeBodyMovesAndVibratesWithoutSupports) {
  pd::Model m = plate(false);
  const pd::FreeDofs dofs = pd::FreeDofs::of(m.nodes.size(), 2, m.conditions.fixed);
  ASSERT_EQ(dofs.size(), 2 * m.nodes.size());  // nothing held: K alone is singular
  std::vector<double> u0(dofs.size()), v0(dofs.size());
  for (std::size_t q = 0; q < dofs.size(); ++q) {
    u0[q] = 1e-9 * std::sin(0.7 * static_cast<double>(q));
    v0[q] = dofs.component[q] == 0 ? 0.1 : -0.05;  // a rigid translation
  }
  const double h = 20.0 * pd::stable_time_step(m);
  PlateRun run(std::move(m), fixed_step(h, 1.0, 50 * h), dofs, u0, &v0);
  const auto momentum = [&](std::size_t d) {
    double p = 0.0;
    for (std::size_t i = 0; i < run.state.size(); ++i) p += run.model.density[i] * run.model.nodes.volume[i] * run.state.v[d][i];
    return p;
  };
  const auto centre = [&](std::size_t d) {
    double sum = 0.0;
    for (std::size_t i = 0; i < run.state.size(); ++i) sum += run.state.u[d][i];
    return sum / static_cast<double>(run.state.size());
  };
  const double px = momentum(0), py = momentum(1), x0 = centre(0), e0 = run.energy();
  for (int n = 0; n < 50; ++n) ASSERT_NO_THROW(run.step());
  EXPECT_NEAR(momentum(0) / px, 1.0, 1e-9);
  EXPECT_NEAR(momentum(1) / py, 1.0, 1e-9);
  EXPECT_NEAR((centre(0) - x0) / (0.1 * run.t), 1.0, 1e-9);  // the centre moves at the translation's speed
  EXPECT_NEAR(run.energy() / e0, 1.0, 1e-6);
}

TEST(Implicit, DampingIsIntegratedImplicitlyAndItsWorkBooked) {
  // A free plate translating at 0.1 m/s with damping α: no force, so the trapezoidal rule on
  // ρ v̇ = −αρv gives v_{n+1} = v_n (1 − αΔt/2)/(1 + αΔt/2) exactly, stable at αΔt = 4 (Verlet's
  // damping term is the same Crank–Nicolson, forces/damping.hpp); at a small αΔt the kinetic energy
  // lost is the damping work of the ledger (trapezoidal in the power: O((αΔt)²) apart).
  for (double alpha_dt : {4.0, 0.01}) {
    pd::Case lattice = pdtest::lattice_case(2, "plane_stress", kDx, 3.015 * kDx, 1e9, kRho, -1.0, kThickness);
    lattice.damping = 1e5;
    pd::Model m = pd::build_model(lattice, pdtest::cubic_lattice(kNx, kNy, 1, kDx, 2, kThickness));
    const pd::FreeDofs dofs = pd::FreeDofs::of(m.nodes.size(), 2, m.conditions.fixed);
    std::vector<double> u0(dofs.size(), 0.0), v0(dofs.size());
    for (std::size_t q = 0; q < dofs.size(); ++q) v0[q] = dofs.component[q] == 0 ? 0.1 : 0.0;
    const double h = alpha_dt / lattice.damping;
    PlateRun run(std::move(m), fixed_step(h, 1.0, 10 * h), dofs, u0, &v0);
    const double e0 = run.energy();
    for (int n = 0; n < 10; ++n) run.step();
    EXPECT_NEAR(run.state.v[0][7] / 0.1, std::pow((1 - alpha_dt / 2) / (1 + alpha_dt / 2), 10), 1e-12);
    if (alpha_dt < 1.0) EXPECT_NEAR(run.state.damping_work / (e0 - run.energy()), 1.0, 1e-4);
  }
}

namespace {

// The cantilever, set swinging in its lowest mode plus some high-frequency content, stepped by the
// error control (the factorisation is reused across steps and remade when Δt changes).
pd::Case controlled(double w1) {
  pd::Case c;
  c.time.end = 1.0;
  c.implicit.tol = 1e-3;
  c.implicit.rho_infinity = 0.8;
  c.implicit.dt_initial = 0.02 / w1;
  return c;
}

std::vector<double> swing(const Linear& lin, double& w1) {
  double wh = 0.0;
  const std::vector<double> low = lin.lowest(w1), high = lin.highest(wh);
  std::vector<double> u0(low.size());
  for (std::size_t q = 0; q < u0.size(); ++q) u0[q] = amplitude(low) * low[q] + 0.05 * amplitude(high) * high[q];
  return u0;
}

}  // namespace

TEST(Implicit, RestartContinuesBitwiseWithTheFactorisationRebuilt) {
  pd::Model m = plate();
  const Linear lin(m);
  double w1 = 0.0;
  const std::vector<double> u0 = swing(lin, w1);
  PlateRun whole(plate(), controlled(w1), lin.dofs, u0);
  for (int n = 0; n < 40; ++n) whole.step();

  PlateRun first(plate(), controlled(w1), lin.dofs, u0);
  for (int n = 0; n < 20; ++n) first.step();
  const std::vector<char> saved = first.integrator.save_state();
  const pd::State state = first.state;
  PlateRun second(plate(), controlled(w1), lin.dofs, std::vector<double>(u0.size(), 0.0));
  second.model.bonds.broken = first.model.bonds.broken;
  second.state = state;
  // a_n travels in the checkpoint's pieces, not in save_state's bytes (run/state_checkpoint.hpp).
  *second.integrator.checkpointed_node_arrays().at(0) = *first.integrator.checkpointed_node_arrays().at(0);
  second.integrator.load_state(saved);
  second.t = first.t;
  second.dt = first.dt;
  for (int n = 0; n < 20; ++n) second.step();
  EXPECT_EQ(second.t, whole.t);
  EXPECT_TRUE(same_bits(second.state.u, whole.state.u));
  EXPECT_TRUE(same_bits(second.state.v, whole.state.v));
  EXPECT_TRUE(same_bits(second.integrator.acceleration(), whole.integrator.acceleration()));
  EXPECT_EQ(second.integrator.factorisations(), whole.integrator.factorisations());
  EXPECT_LT(whole.integrator.factorisations(), 30);  // reused across steps
  EXPECT_THROW(second.integrator.load_state(std::vector<char>(saved.begin(), saved.end() - 1)), std::runtime_error);
}

TEST(Implicit, BitwiseIdenticalWithOneAndTwoThreads) {
  pd::Model m = plate();
  const Linear lin(m);
  double w1 = 0.0;
  const std::vector<double> u0 = swing(lin, w1);
  pd::State result[2];
  const int saved = omp_get_max_threads();
  for (int r = 0; r < 2; ++r) {
    omp_set_num_threads(r + 1);
    PlateRun run(plate(), controlled(w1), lin.dofs, u0);
    for (int n = 0; n < 30; ++n) run.step();
    result[r] = run.state;
  }
  omp_set_num_threads(saved);
  EXPECT_TRUE(same_bits(result[0].u, result[1].u));
  EXPECT_TRUE(same_bits(result[0].v, result[1].v));
}

TEST(Implicit, BondsBreakAfterTheConvergedStepAndTheBalanceHoldsAtItsEnd) {
  // The free plate torn apart: its right half given 20 m/s to the right, breakable bonds.
  pd::Model m = plate(false, 0.01);
  const pd::FreeDofs dofs = pd::FreeDofs::of(m.nodes.size(), 2, m.conditions.fixed);
  std::vector<double> u0(dofs.size(), 0.0), v0(dofs.size(), 0.0);
  for (std::size_t q = 0; q < dofs.size(); ++q)
    if (dofs.component[q] == 0 && m.nodes.x[0][static_cast<std::size_t>(dofs.node[q])] > 7.5 * kDx) v0[q] = 20.0;
  const double h = 2.0 * pd::stable_time_step(m);
  PlateRun run(std::move(m), fixed_step(h, 1.0, 40 * h), dofs, u0, &v0);
  std::int64_t broken = 0;
  for (int n = 0; n < 40 && broken == 0; ++n) run.step(), broken += run.integrator.last_step().broken_now;
  ASSERT_GT(broken, 0);
  // The force in the state is the one with the bonds left, and at ρ∞ = 1 a = f/ρ at the step end.
  pd::State check = run.state;
  run.op.evaluate(check, run.t);
  EXPECT_TRUE(same_bits(check.f, run.state.f));
  double worst = 0.0, scale = 0.0;
  for (std::size_t i = 0; i < check.size(); ++i)
    for (std::size_t d = 0; d < 2; ++d) {
      worst = std::max(worst, std::fabs(run.integrator.acceleration()[d][i] - check.f[d][i] / kRho));
      scale = std::max(scale, std::fabs(check.f[d][i] / kRho));
    }
  EXPECT_LT(worst, 1e-6 * scale);
}
