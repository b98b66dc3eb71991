// The partial-volume rules of validation.md F3 and their registry.
#include "core/partial_volume.hpp"

#include <algorithm>

namespace pd {

namespace {

// Full volumes (FA): every neighbour within δ counts wholly.
double full_volume(double, double, double) { return 1.0; }

// LAMMPS peri/pmb: ν = (δ − |ξ|)/dx + ½ on [δ − dx/2, δ], else 1, so ν = ½ at |ξ| = δ
// (validation.md F3/F5; LAMMPS pair_peri_pmb documentation).
double lammps(double length, double horizon, double dx) {
  if (length < horizon - 0.5 * dx) return 1.0;
  return std::clamp((horizon - length) / dx + 0.5, 0.0, 1.0);
}

// PA-HHB: the family is |ξ| − dx/2 ≤ δ; on the outer shell the weight is (δ − |ξ| + dx/2)/dx
// (validation.md F3), i.e. the part of the node's cell, of width dx, that lies inside δ.
double hhb(double length, double horizon, double dx) {
  if (length <= horizon - 0.5 * dx) return 1.0;
  return std::clamp((horizon - length + 0.5 * dx) / dx, 0.0, 1.0);
}

}  // namespace

const Registry<PartialVolumeRule>& partial_volume_registry() {
  static const Registry<PartialVolumeRule> registry = [] {
    Registry<PartialVolumeRule> r("partial_volume rule");
    r.add("none", {0.0, &full_volume});
    r.add("lammps", {0.0, &lammps});
    r.add("hhb", {0.5, &hhb});
    return r;
  }();
  return registry;
}

double bond_cutoff(const PartialVolumeRule& rule, double horizon, double dx) {
  return horizon + rule.family_extension_dx * dx;
}

void apply_partial_volume(const PartialVolumeRule& rule, double horizon, double dx, BondList& bonds) {
  bonds.volume_factor.resize(bonds.length.size());
  for (std::size_t k = 0; k < bonds.length.size(); ++k)
    bonds.volume_factor[k] = rule.factor(bonds.length[k], horizon, dx);
}

}  // namespace pd
