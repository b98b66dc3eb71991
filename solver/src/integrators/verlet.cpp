// One velocity-Verlet step: half kick, drift, bond breaking, force, half kick (with damping).
#include "integrators/verlet.hpp"

#include "forces/damping.hpp"

namespace pd {

void VelocityVerlet::initialize(State& state, double t) {
  op_.start(state, t);
  report_ = StepReport{};
}

void VelocityVerlet::step(State& state, double& t, double& dt) {
  const auto n = static_cast<std::int64_t>(state.size());
  const double t1 = t + dt;
  const DampingFactors damp = damping_factors(op_.damping(), dt);
  const double* rho = op_.density().data();
  const auto& fixed = op_.fixed();

  // Half kick and drift of the free components (see forces/damping.hpp for the damping terms).
  for (std::size_t d = 0; d < 3; ++d) {
    double* u = state.u[d].data();
    double* v = state.v[d].data();
    const double* f = state.f[d].data();
    const std::uint8_t* fx = fixed[d].data();
#pragma omp parallel for schedule(static)
    for (std::int64_t i = 0; i < n; ++i) {
      if (fx[i]) continue;
      v[i] = damp.explicit_half * v[i] + 0.5 * dt * f[i] / rho[i];
      u[i] += dt * v[i];
    }
  }
  // Prescribed components follow their tables; v^{n+½} is the mean velocity over the step, so
  // u^{n+1} = u^n + Δt·v^{n+½} holds for them too.
  op_.advance_prescribed_motion(state.u, state.u, state.v, t, t1, dt, false);

  // Bonds break after the state update, before the force at t^{n+1} is evaluated.
  report_ = StepReport{};
  const BreakReport broke = op_.break_bonds_and_evaluate(state, t1);
  report_.broken_now += broke.broken;
  report_.broken_energy_now += broke.energy;

  for (std::size_t d = 0; d < 3; ++d) {
    double* v = state.v[d].data();
    const double* f = state.f[d].data();
    const std::uint8_t* fx = fixed[d].data();
#pragma omp parallel for schedule(static)
    for (std::int64_t i = 0; i < n; ++i) {
      if (fx[i]) continue;
      v[i] = (v[i] + 0.5 * dt * f[i] / rho[i]) * damp.implicit_half;
    }
  }
  op_.impose_prescribed_velocity(state.v, t1);
  // (a prescribed displacement keeps the mean velocity of the step as its v^{n+1})

  op_.update_work(state, t1, dt);
  t = t1;
}

}  // namespace pd
