// Body-force density from the piecewise-linear tables of the case.
#include "forces/body_force.hpp"

#include <algorithm>
#include <memory>

#include "parallel/node_sum.hpp"

namespace pd {

void BodyForceTerm::AddMult(double t, Vec3Array& f) const {
  for (const auto& b : model_.conditions.body_forces) {
    const double value = b.table.value(t);
    auto& fc = f[static_cast<std::size_t>(b.component)];
    for (std::int32_t i : b.nodes) fc[static_cast<std::size_t>(i)] += value;
  }
}

double BodyForceTerm::power(double t, const Vec3Array& v, const Decomposed* d) const {
  // One exact sum per condition, continuing the last (parallel/node_sum.hpp): the same bits for
  // any rank and thread count.
  double p = 0.0;
  for (const auto& b : model_.conditions.body_forces) {
    const double value = b.table.value(t);
    const auto& vc = v[static_cast<std::size_t>(b.component)];
    p = sum_over_set(d, b.nodes, p,
                     [&](std::size_t i) { return model_.nodes.volume[i] * value * vc[i]; });
  }
  return p;
}

}  // namespace pd

namespace pd {

namespace {

// The body force as a term of the operator (forces/force_term.hpp): it does not depend on u.
class BodyForceOnSets : public ForceTerm {
 public:
  explicit BodyForceOnSets(const Model& model) : model_(model) {}
  void add_force(State& s, double t) const override { BodyForceTerm(model_).AddMult(t, s.f); }
  void add_power(const State& s, double t, double& p) const override {
    p += BodyForceTerm(model_).power(t, s.v, decomposed_);
  }
  void add_jacobian_product(const State&, double, const Vec3Array&, Vec3Array&) const override {}
  bool add_tangent_diagonal(const State&, double, std::size_t, double*) const override { return true; }
  std::vector<std::string> work_plan() const override { return {}; }

 private:
  const Model& model_;
};

}  // namespace

std::unique_ptr<ForceTerm> make_body_force_term(const Model& model) {
  if (model.conditions.body_forces.empty()) return nullptr;
  return std::make_unique<BodyForceOnSets>(model);
}

}  // namespace pd
