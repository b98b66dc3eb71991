// Velocity Verlet (central difference, thesis eq. 2.4) with trapezoidal velocity damping.
#pragma once
#include "integrators/integrator.hpp"

namespace pd {

class VelocityVerlet : public Integrator {
 public:
  explicit VelocityVerlet(ForceOperator& op) : op_(op) {}
  std::string name() const override { return "verlet"; }
  void initialize(State& state, double t) override;
  // Takes exactly the dt it is given.
  void step(State& state, double& t, double& dt) override;

  // ---- What the run asks (integrator.hpp)
  bool explicit_step() const override { return true; }

 private:
  ForceOperator& op_;
};

}  // namespace pd
