// The integrator registry and what every integrator shares: forces, prescribed motion, work.
#include "integrators/integrator.hpp"

#include <algorithm>

#include "forces/body_force.hpp"
#include "forces/contact.hpp"
#include "forces/damping.hpp"
#include "forces/indenter.hpp"
#include "forces/pmb.hpp"
#include "integrators/adaptive.hpp"
#include "integrators/verlet.hpp"

namespace pd {

const Registry<IntegratorFactory>& integrator_registry() {
  static const Registry<IntegratorFactory> registry = [] {
    Registry<IntegratorFactory> r("integrator");
    r.add("verlet", [](Model& m) -> std::unique_ptr<Integrator> { return std::make_unique<VelocityVerlet>(m); });
    r.add("adaptive", [](Model& m) -> std::unique_ptr<Integrator> { return std::make_unique<AdaptiveStep>(m); });
    return r;
  }();
  return registry;
}

namespace {

// Every force term after the bonds, added into f that already holds the bond forces.
void add_non_bond_forces(const Model& model, State& state, double t) {
  state.contact_energy = 0.0;
  if (model.contact.pairs) state.contact_energy += ShortRangeForce(model).AddMult(state.u, state.f);
  if (!model.indenters.empty())
    state.contact_energy += IndenterForce(model).AddMult(t, state.u, state.f, state.indenter_force);
  BodyForceTerm(model).AddMult(t, state.f);
}

}  // namespace

void evaluate_forces(const Model& model, State& state, double t) {
  for (auto& fc : state.f) std::fill(fc.begin(), fc.end(), 0.0);
  PmbBondForce(model).AddMult(state.u, state.f, state.w.data());
  add_non_bond_forces(model, state, t);
}

void break_bonds_and_evaluate_forces(Model& model, State& state, double t, StepReport& report) {
  for (auto& fc : state.f) std::fill(fc.begin(), fc.end(), 0.0);
  report.broken_now +=
      break_bonds_and_add_pmb_force(model, state.u, state.f, state.w.data(), &report.broken_energy_now);
  add_non_bond_forces(model, state, t);
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
  // A moving indenter works on the body at the rate (force on the body)·(indenter velocity): the
  // contact potential depends on y − c(t), so d(KE + potential)/dt = F·ċ.
  for (std::size_t k = 0; k < model.indenters.size() && k < state.indenter_force.size(); ++k)
    for (std::size_t d = 0; d < 3; ++d) p += state.indenter_force[k][d] * model.indenters[k].velocity[d];
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
