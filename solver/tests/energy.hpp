// The mechanical energy of a state, kinetic + bond strain energy [J], for the integrator tests
// (energy conservation, blow-up bounds).
#pragma once
#include "core/model.hpp"
#include "core/state.hpp"
#include "materials/pmb/pmb.hpp"

namespace pdtest {

inline double mechanical_energy(const pd::Model& m, const pd::State& s) {
  double e = pd::strain_energy(m, s.u);
  for (std::size_t i = 0; i < s.size(); ++i)
    e += 0.5 * m.density[i] * m.nodes.volume[i] * (s.v[0][i] * s.v[0][i] + s.v[1][i] * s.v[1][i] + s.v[2][i] * s.v[2][i]);
  return e;
}

}  // namespace pdtest
