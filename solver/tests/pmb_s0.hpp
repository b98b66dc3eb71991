// LAMMPS's per-node critical stretch s0_i of a test's model: PMB's declared state
// (materials/pmb/pmb.hpp), which its law declares when some α > 0.
#pragma once
#include <vector>

#include "materials/pmb/pmb.hpp"

namespace pdtest {

// The model's s0_i (empty when its law declared none).
inline const std::vector<double>& s0_of(const pd::Model& m) {
  static const std::vector<double> none;
  const std::vector<double>* s0 = pd::node_critical_stretch(m);
  return s0 ? *s0 : none;
}

// A hand-made model given PMB's per-node s0 whatever its α (the declaration PMB makes when some
// α > 0), every entry `value`.
inline std::vector<double>& declare_s0(pd::Model& m, double value) {
  m.state_arrays = pd::StateArrays({pd::node_critical_stretch_declaration()}, m.nodes.size(), 0);
  std::vector<double>& s0 = *pd::node_critical_stretch(m);
  s0.assign(m.nodes.size(), value);
  return s0;
}

}  // namespace pdtest
