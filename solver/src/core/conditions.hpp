// Boundary and initial conditions on node sets: piecewise-linear tables in time, resolved to
// per-node lists so that each prescribed degree of freedom belongs to exactly one condition.
#pragma once
#include <array>
#include <cstdint>
#include <vector>

#include "core/case.hpp"
#include "core/nodes.hpp"

namespace pd {

// v(t) through (times[k], values[k]), linear in between and constant outside the table.
struct PiecewiseLinear {
  std::vector<double> times, values;

  double value(double t) const;
  // dv/dt on the segment that contains t (right derivative; 0 outside the table).
  double slope(double t) const;
  // ∫_a^b v(t) dt, exact for the piecewise-linear function.
  double integral(double a, double b) const;
};

enum class Kinematic : std::uint8_t { displacement, velocity };

struct PrescribedMotion {
  Kinematic kind = Kinematic::displacement;
  int component = 0;
  PiecewiseLinear table;
  std::vector<std::int32_t> nodes;  // the nodes this condition owns for `component`
};

struct BodyForce {
  int component = 0;
  PiecewiseLinear table;  // b [N/m³]
  std::vector<std::int32_t> nodes;
};

struct Conditions {
  std::vector<PrescribedMotion> prescribed;
  std::vector<BodyForce> body_forces;
  std::array<std::vector<std::uint8_t>, 3> fixed;  // 1 where the component is prescribed
};

// Later entries of case.boundary_conditions win where two kinematic conditions share a node and
// component (e.g. the corner shared by two clamped edges); body forces add up.
Conditions make_conditions(const Case& c, const Nodes& nodes);

// Initial velocity and displacement (value + gradient·x per set); the rest of the body starts at rest.
void apply_initial_conditions(const Case& c, const Nodes& nodes, Vec3Array& u, Vec3Array& v);

}  // namespace pd
