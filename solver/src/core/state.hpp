// The time-dependent state: displacement u, velocity v, force density f, and the energy ledger.
#pragma once
#include <array>
#include <vector>

#include "core/nodes.hpp"

namespace pd {

struct State {
  Vec3Array u;  // displacement [m]
  Vec3Array v;  // velocity [m/s]
  Vec3Array f;  // force density at u of every operator term (bonds, contact, indenters, body force; damping acts in the integrator) [N/m³]
  std::vector<double> w;  // strain-energy density W_i at u, from the last force evaluation [J/m³]
  // The potential energy at u of each force term that has one [J], in the force-term registry's
  // order (forces/force_term.hpp term_energy_names: contact pairs, rigid indenters Σ V K h³/3): a
  // list, so that a new term's energy needs no field here. The operator sets it at every force
  // evaluation; empty before the first.
  std::vector<double> term_energies;
  std::vector<std::array<double, 3>> indenter_force;  // force of each indenter on the body at u [N]

  // Work ledger, integrated with the trapezoidal rule over each step.
  double external_power = 0.0;  // body-force + reaction power at the current state [W]
  double damping_power = 0.0;   // Σ ρ α V |v|² over free components [W]
  double external_work = 0.0;   // [J]
  double damping_work = 0.0;    // [J]

  explicit State(std::size_t n = 0) : u(make_vec3(n)), v(make_vec3(n)), f(make_vec3(n)), w(n, 0.0) {}
  std::size_t size() const { return u[0].size(); }
  // start + every term's energy, added one after the other in the list's order: the energy held
  // beside the kinetic and strain energy (run/loop.cpp's balance), the same bits wherever it is summed.
  double plus_term_energies(double start) const {
    for (double e : term_energies) start += e;
    return start;
  }

  // Copies every whole-body value (the energies, the indenters' forces, the work ledger) of `from`,
  // not the per-node fields: what a decomposed run's pieces and its gathered state share (run/).
  // A new whole-body member belongs here, so that output and restarts under MPI carry it.
  void copy_totals(const State& from) {
    term_energies = from.term_energies;
    indenter_force = from.indenter_force;
    external_power = from.external_power;
    damping_power = from.damping_power;
    external_work = from.external_work;
    damping_work = from.damping_work;
  }
};

}  // namespace pd
