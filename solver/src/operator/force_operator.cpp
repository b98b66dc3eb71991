// The operator: the scene's force, breaking, linearisation, prescribed motion and energy ledger.
#include "operator/force_operator.hpp"

#include <algorithm>

#include "core/stability.hpp"
#include "forces/damping.hpp"

namespace pd {

ForceOperator::ForceOperator(Model& model) : model_(model) {
  // Build the terms the scene needs, once; remember the power order beside the force order.
  std::vector<std::pair<int, const ForceTerm*>> by_power;
  for (const ForceTermEntry& entry : force_term_registry()) {
    std::unique_ptr<ForceTerm> term = entry.make(model_);
    built_.push_back(term.get());
    if (term) {
      by_power.emplace_back(entry.power_order, term.get());
      terms_.push_back(std::move(term));
    }
  }
  std::stable_sort(by_power.begin(), by_power.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
  for (const auto& item : by_power) power_terms_.push_back(item.second);
}

void ForceOperator::evaluate(State& s, double t) const {
  for (auto& fc : s.f) std::fill(fc.begin(), fc.end(), 0.0);
  model_.bond_model->add_force(model_, s.u, s.f, s.w.data());
  s.contact_energy = 0.0;
  for (const auto& term : terms_) term->add_force(s, t);
}

BreakReport ForceOperator::break_bonds_and_evaluate(State& s, double t) {
  for (auto& fc : s.f) std::fill(fc.begin(), fc.end(), 0.0);
  const BreakReport report = model_.bond_model->break_bonds_and_add_force(model_, s.u, s.f, s.w.data(), true);
  s.contact_energy = 0.0;
  for (const auto& term : terms_) term->add_force(s, t);
  return report;
}

void ForceOperator::apply_jacobian(const State& s, double t, const Vec3Array& x, Vec3Array& y) const {
  for (auto& yc : y) std::fill(yc.begin(), yc.end(), 0.0);
  model_.bond_model->add_jacobian_product(model_, s.u, x, y);
  for (const auto& term : terms_) term->add_jacobian_product(s, t, x, y);
}

void ForceOperator::impose_prescribed_motion(State& s, double t) const {
  for (const auto& p : model_.conditions.prescribed) {
    auto& u = s.u[static_cast<std::size_t>(p.component)];
    auto& v = s.v[static_cast<std::size_t>(p.component)];
    const bool disp = p.kind == Kinematic::displacement;
    const double value = p.table.value(t);
    const double rate = disp ? p.table.slope(t) : value;
    for (std::int32_t i : p.nodes) {
      if (disp) u[static_cast<std::size_t>(i)] = value;
      v[static_cast<std::size_t>(i)] = rate;
    }
  }
}

void ForceOperator::advance_prescribed_motion(const Vec3Array& u_from, Vec3Array& u_to, Vec3Array& v_to, double t,
                                              double t1, double dt, bool end_velocity) const {
  for (const auto& p : model_.conditions.prescribed) {
    const auto c = static_cast<std::size_t>(p.component);
    if (p.kind == Kinematic::displacement) {
      const double u1 = p.table.value(t1), mean_v = (u1 - p.table.value(t)) / dt;
      for (std::int32_t i : p.nodes) {
        u_to[c][static_cast<std::size_t>(i)] = u1;
        v_to[c][static_cast<std::size_t>(i)] = mean_v;
      }
    } else {
      // Velocity table: u^{n+1} = u^n + ∫v dt exactly; v is the mean over the step, so that
      // u^{n+1} = u^n + Δt·v^{n+½} holds for it as for the free components of Verlet.
      const double du = p.table.integral(t, t1), v_step = end_velocity ? p.table.value(t1) : du / dt;
      for (std::int32_t i : p.nodes) {
        u_to[c][static_cast<std::size_t>(i)] = u_from[c][static_cast<std::size_t>(i)] + du;
        v_to[c][static_cast<std::size_t>(i)] = v_step;
      }
    }
  }
}

void ForceOperator::impose_prescribed_velocity(Vec3Array& v, double t1) const {
  for (const auto& p : model_.conditions.prescribed)
    if (p.kind == Kinematic::velocity) {
      auto& vc = v[static_cast<std::size_t>(p.component)];
      const double v1 = p.table.value(t1);
      for (std::int32_t i : p.nodes) vc[static_cast<std::size_t>(i)] = v1;
    }
}

double ForceOperator::kinetic_energy(const State& s) const {
  const Model& m = model_;
  double sum = 0.0;  // serial, node order: the same for any thread count
  for (std::size_t i = 0; i < s.size(); ++i)
    sum += 0.5 * m.density[i] * m.nodes.volume[i] *
           (s.v[0][i] * s.v[0][i] + s.v[1][i] * s.v[1][i] + s.v[2][i] * s.v[2][i]);
  return sum;
}

double ForceOperator::strain_energy(const State& s) const {
  double sum = 0.0;
  for (std::size_t i = 0; i < s.size(); ++i) sum += s.w[i] * model_.nodes.volume[i];
  return sum;
}

double ForceOperator::external_power(const State& s, double t) const {
  double p = 0.0;
  for (const ForceTerm* term : power_terms_) term->add_power(s, t, p);
  for (const auto& bc : model_.conditions.prescribed) {
    const auto c = static_cast<std::size_t>(bc.component);
    const double a = bc.kind == Kinematic::velocity ? bc.table.slope(t) : 0.0;
    for (std::int32_t i32 : bc.nodes) {
      const auto i = static_cast<std::size_t>(i32);
      const double reaction = model_.density[i] * a - s.f[c][i];  // force density the support applies
      p += model_.nodes.volume[i] * reaction * s.v[c][i];
    }
  }
  return p;
}

void ForceOperator::update_work(State& s, double t, double dt) const {
  const double pe = external_power(s, t);
  const double pd = damping_power(model_.damping, model_.density, model_.nodes.volume, s.v, model_.conditions.fixed);
  s.external_work += 0.5 * dt * (s.external_power + pe);
  s.damping_work += 0.5 * dt * (s.damping_power + pd);
  s.external_power = pe;
  s.damping_power = pd;
}

double ForceOperator::stable_time_step() const { return pd::stable_time_step(model_); }
double ForceOperator::exact_time_step() const { return pd::exact_time_step(model_); }

std::vector<std::string> ForceOperator::work_plan(const Case& c) const {
  std::vector<std::string> lines;
  lines.push_back("work: bond forces over " + std::to_string(model_.bonds.directed() / 2) + " bonds, partial volume " +
                  c.partial_volume + (c.dimension == 2 ? "; 2D (cell grids one bin thick)" : "; 3D"));
  const auto& registry = force_term_registry();
  for (std::size_t k = 0; k < registry.size(); ++k) {
    if (built_[k]) {
      for (const auto& line : built_[k]->work_plan()) lines.push_back(line);
    } else if (const std::string line = registry[k].absent(model_, c); !line.empty()) {
      lines.push_back(line);
    }
  }
  lines.push_back(can_break() ? "work: breakage test after every step"
                              : "work: no breakage test (every block unbreakable)");
  return lines;
}

}  // namespace pd
