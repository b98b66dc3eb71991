// The partial-volume rules of docs/theory.md T5 and their registry.
#include "core/partial_volume.hpp"

namespace pd {

// none: full volumes (FA), every neighbour within δ counts wholly.
// lammps: LAMMPS peri/pmb, ν = (δ − |ξ|)/dx + ½ on [δ − dx/2, δ], else 1, so ν = ½ at |ξ| = δ
//   (docs/theory.md T5/T4; LAMMPS pair_peri_pmb documentation).
// hhb: PA-HHB, the family is |ξ| − dx/2 ≤ δ; on the outer shell the weight is (δ − |ξ| + dx/2)/dx
//   (docs/theory.md T5), i.e. the part of the node's cell, of width dx, that lies inside δ.
// lammps and hhb share ν = clamp((δ + dx/2 − |ξ|)/dx, 0, 1) and differ only in the family.
VolumeWeight PartialVolumeRule::weight(double horizon, double dx) const {
  VolumeWeight w;
  if (shell_weight) {
    w.outer = horizon + 0.5 * dx;
    w.inv_dx = 1.0 / dx;
  }
  return w;
}

const Registry<PartialVolumeRule>& partial_volume_registry() {
  static const Registry<PartialVolumeRule> registry = [] {
    Registry<PartialVolumeRule> r("partial_volume rule");
    r.add("none", {0.0, false});
    r.add("lammps", {0.0, true});
    r.add("hhb", {0.5, true});
    return r;
  }();
  return registry;
}

double bond_cutoff(const PartialVolumeRule& rule, double horizon, double dx) {
  return horizon + rule.family_extension_dx * dx;
}

void apply_partial_volume(const PartialVolumeRule& rule, double horizon, double dx, BondList& bonds) {
  bonds.volume_weight = rule.weight(horizon, dx);
}

}  // namespace pd
