// Partial-volume rules (docs/theory.md T5): the share ν of a neighbour's volume V_j that lies
// inside the horizon, applied to every bond so that results can be compared with other codes.
#pragma once
#include <string>

#include "core/bonds.hpp"
#include "core/registry.hpp"

namespace pd {

struct PartialVolumeRule {
  // How far beyond δ the family reaches, in units of dx (HHB takes nodes whose cell reaches in).
  double family_extension_dx = 0.0;
  // false: full volumes (ν = 1); true: ν = clamp((δ + dx/2 − |ξ|)/dx, 0, 1), the share of a
  // node's cell of width dx inside δ (LAMMPS's and HHB's shell weight, core/bonds.hpp VolumeWeight).
  bool shell_weight = false;
  // The weight the bond list carries for horizon δ and grid spacing dx.
  VolumeWeight weight(double horizon, double dx) const;
  // ν for a bond of reference length |ξ|, horizon δ and grid spacing dx.
  double factor(double length, double horizon, double dx) const { return weight(horizon, dx)(length); }
};

// none | lammps | hhb; an unknown name gets the registry's keys in the error.
const Registry<PartialVolumeRule>& partial_volume_registry();

// Bond cut-off of a rule: δ + family_extension_dx·dx.
double bond_cutoff(const PartialVolumeRule& rule, double horizon, double dx);

// Sets bonds.volume_weight, so that every bond's ν follows from its |ξ|.
void apply_partial_volume(const PartialVolumeRule& rule, double horizon, double dx, BondList& bonds);

}  // namespace pd
