// Piecewise-linear tables and the resolution of case conditions to node lists.
#include "core/conditions.hpp"

#include <algorithm>

#include "core/error.hpp"

namespace pd {

double PiecewiseLinear::value(double t) const {
  if (t <= times.front()) return values.front();
  if (t >= times.back()) return values.back();
  const auto k = static_cast<std::size_t>(std::upper_bound(times.begin(), times.end(), t) - times.begin());
  const double w = (t - times[k - 1]) / (times[k] - times[k - 1]);
  return values[k - 1] + w * (values[k] - values[k - 1]);
}

double PiecewiseLinear::slope(double t) const {
  if (times.size() < 2 || t < times.front() || t >= times.back()) return 0.0;
  const auto k = static_cast<std::size_t>(std::upper_bound(times.begin(), times.end(), t) - times.begin());
  return (values[k] - values[k - 1]) / (times[k] - times[k - 1]);
}

double PiecewiseLinear::integral(double a, double b) const {
  // Trapezoids between a, the table's breakpoints inside (a, b), and b: exact for this function.
  double sum = 0.0, t0 = a, v0 = value(a);
  for (double tk : times) {
    if (tk <= a || tk >= b) continue;
    const double vk = value(tk);
    sum += 0.5 * (v0 + vk) * (tk - t0);
    t0 = tk;
    v0 = vk;
  }
  return sum + 0.5 * (v0 + value(b)) * (b - t0);
}

namespace {

const NodeSet& require_set(const Nodes& nodes, const std::string& name) {
  const NodeSet* set = nodes.find_set(name);
  if (!set) throw Error("node set '" + name + "' is not in the node file");
  return *set;
}

}  // namespace

Conditions make_conditions(const Case& c, const Nodes& nodes) {
  const std::size_t n = nodes.size();
  Conditions out;
  // owner[d][i]: index in out.prescribed of the condition that prescribes component d of node i.
  std::array<std::vector<std::int32_t>, 3> owner;
  for (auto& o : owner) o.assign(n, -1);
  for (const auto& bc : c.boundary_conditions) {
    const NodeSet& set = require_set(nodes, bc.set);
    if (bc.kind == "body_force") {
      BodyForce b{bc.component, {bc.times, bc.values}, {}};
      for (std::size_t i = 0; i < n; ++i)
        if (set.member[i]) b.nodes.push_back(static_cast<std::int32_t>(i));
      out.body_forces.push_back(std::move(b));
      continue;
    }
    PrescribedMotion p;
    p.kind = bc.kind == "displacement" ? Kinematic::displacement : Kinematic::velocity;
    p.component = bc.component;
    p.table = {bc.times, bc.values};
    const auto index = static_cast<std::int32_t>(out.prescribed.size());
    for (std::size_t i = 0; i < n; ++i)
      if (set.member[i]) owner[static_cast<std::size_t>(bc.component)][i] = index;
    out.prescribed.push_back(std::move(p));
  }
  for (int d = 0; d < 3; ++d) {
    out.fixed[static_cast<std::size_t>(d)].assign(n, 0);
    for (std::size_t i = 0; i < n; ++i) {
      const std::int32_t k = owner[static_cast<std::size_t>(d)][i];
      if (k < 0) continue;
      out.prescribed[static_cast<std::size_t>(k)].nodes.push_back(static_cast<std::int32_t>(i));
      out.fixed[static_cast<std::size_t>(d)][i] = 1;
    }
  }
  return out;
}

void apply_initial_conditions(const Case& c, const Nodes& nodes, Vec3Array& u, Vec3Array& v) {
  for (const auto& ic : c.initial_conditions) {
    const NodeSet& set = require_set(nodes, ic.set);
    auto& target = ic.kind == "velocity" ? v : u;
    const auto d = static_cast<std::size_t>(ic.component);
    // value + gradient·x: an affine displacement, e.g. the uniform pre-strain of cases/drum.
    for (std::size_t i = 0; i < nodes.size(); ++i)
      if (set.member[i]) target[d][i] = ic.value + ic.gradient * nodes.x[d][i];
  }
}

}  // namespace pd
