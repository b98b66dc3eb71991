// The integrator registry and what every integrator shares: forces, prescribed motion, work.
#include "integrators/integrator.hpp"

#include <algorithm>

#include "forces/body_force.hpp"
#include "forces/damping.hpp"
#include "forces/pmb.hpp"
#include "integrators/verlet.hpp"

namespace pd {

const Registry<IntegratorFactory>& integrator_registry() {
  static const Registry<IntegratorFactory> registry = [] {
    Registry<IntegratorFactory> r("integrator");
    r.add("verlet", [](Model& m) -> std::unique_ptr<Integrator> { return std::make_unique<VelocityVerlet>(m); });
    return r;
  }();
  return registry;
}

void evaluate_forces(const Model& model, State& state, double t) {
  for (auto& fc : state.f) std::fill(fc.begin(), fc.end(), 0.0);
  PmbBondForce(model).AddMult(state.u, state.f, state.w.data());
  BodyForceTerm(model).AddMult(t, state.f);
}

void impose_prescribed_motion(const Model& model, State& state, double t) {
  for (const auto& p : model.conditions.prescribed) {
    auto& u = state.u[static_cast<std::size_t>(p.component)];
    auto& v = state.v[static_cast<std::size_t>(p.component)];
    const bool disp = p.kind == Kinematic::displacement;
    const double value = p.table.value(t);
    const double rate = disp ? p.table.slope(t) : value;
    for (std::int32_t i : p.nodes) {
      if (disp) u[static_cast<std::size_t>(i)] = value;
      v[static_cast<std::size_t>(i)] = rate;
    }
  }
}

double external_power(const Model& model, const State& state, double t) {
  double p = BodyForceTerm(model).power(t, state.v);
  for (const auto& bc : model.conditions.prescribed) {
    const auto c = static_cast<std::size_t>(bc.component);
    const double a = bc.kind == Kinematic::velocity ? bc.table.slope(t) : 0.0;
    for (std::int32_t i32 : bc.nodes) {
      const auto i = static_cast<std::size_t>(i32);
      const double reaction = model.density[i] * a - state.f[c][i];  // force density the support applies
      p += model.nodes.volume[i] * reaction * state.v[c][i];
    }
  }
  return p;
}

void update_work(const Model& model, State& state, double t, double dt) {
  const double pe = external_power(model, state, t);
  const double pd = damping_power(model.damping, model.density, model.nodes.volume, state.v, model.conditions.fixed);
  state.external_work += 0.5 * dt * (state.external_power + pe);
  state.damping_work += 0.5 * dt * (state.damping_power + pd);
  state.external_power = pe;
  state.damping_power = pd;
}

}  // namespace pd
