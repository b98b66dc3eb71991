// One velocity-Verlet step: half kick, drift, bond breaking, force, half kick (with damping).
#include "integrators/verlet.hpp"

#include "forces/damping.hpp"
#include "forces/pmb.hpp"

namespace pd {

void VelocityVerlet::initialize(State& state, double t) {
  impose_prescribed_motion(model_, state, t);
  evaluate_forces(model_, state, t);
  update_work(model_, state, t, 0.0);
  report_ = StepReport{};
}

void VelocityVerlet::step(State& state, double& t, double& dt) {
  const auto n = static_cast<std::int64_t>(state.size());
  const double t1 = t + dt;
  const DampingFactors damp = damping_factors(model_.damping, dt);
  const double* rho = model_.density.data();
  const auto& fixed = model_.conditions.fixed;

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
  for (const auto& p : model_.conditions.prescribed) {
    auto& u = state.u[static_cast<std::size_t>(p.component)];
    auto& v = state.v[static_cast<std::size_t>(p.component)];
    if (p.kind == Kinematic::displacement) {
      const double u1 = p.table.value(t1), mean_v = (u1 - p.table.value(t)) / dt;
      for (std::int32_t i : p.nodes) {
        u[static_cast<std::size_t>(i)] = u1;
        v[static_cast<std::size_t>(i)] = mean_v;
      }
    } else {
      const double du = p.table.integral(t, t1);
      for (std::int32_t i : p.nodes) {
        u[static_cast<std::size_t>(i)] += du;
        v[static_cast<std::size_t>(i)] = du / dt;
      }
    }
  }

  // Bonds break after the state update, before the force at t^{n+1} is evaluated.
  report_ = StepReport{};
  break_bonds_and_evaluate_forces(model_, state, t1, report_);

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
  for (const auto& p : model_.conditions.prescribed)
    if (p.kind == Kinematic::velocity) {
      auto& v = state.v[static_cast<std::size_t>(p.component)];
      const double v1 = p.table.value(t1);
      for (std::int32_t i : p.nodes) v[static_cast<std::size_t>(i)] = v1;
    }
  // (a prescribed displacement keeps the mean velocity of the step as its v^{n+1})

  update_work(model_, state, t1, dt);
  t = t1;
}

}  // namespace pd
