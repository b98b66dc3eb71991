// The integrator registry: the one list of integrators, chosen by time.integrator.
#include "integrators/integrator.hpp"

#include "integrators/adaptive.hpp"
#include "integrators/implicit.hpp"
#include "integrators/mixed.hpp"
#include "integrators/quasi_static.hpp"
#include "integrators/verlet.hpp"

namespace pd {

const Registry<IntegratorFactory>& integrator_registry() {
  static const Registry<IntegratorFactory> registry = [] {
    Registry<IntegratorFactory> r("integrator");
    r.add("verlet", [](ForceOperator& op) -> std::unique_ptr<Integrator> { return std::make_unique<VelocityVerlet>(op); });
    r.add("quasi_static", [](ForceOperator& op) -> std::unique_ptr<Integrator> { return std::make_unique<QuasiStatic>(op); });
    r.add("implicit", [](ForceOperator& op) -> std::unique_ptr<Integrator> { return std::make_unique<Implicit>(op); });
    r.add("mixed", [](ForceOperator& op) -> std::unique_ptr<Integrator> { return std::make_unique<Mixed>(op); });
    r.add("adaptive", [](ForceOperator& op) -> std::unique_ptr<Integrator> { return std::make_unique<AdaptiveStep>(op); });
    return r;
  }();
  return registry;
}

}  // namespace pd
