// Partial-volume rules (validation.md F3): the share ν of a neighbour's volume V_j that lies
// inside the horizon, applied to every bond so that results can be compared with other codes.
#pragma once
#include <string>

#include "core/bonds.hpp"
#include "core/registry.hpp"

namespace pd {

struct PartialVolumeRule {
  // How far beyond δ the family reaches, in units of dx (HHB takes nodes whose cell reaches in).
  double family_extension_dx = 0.0;
  // ν for a bond of reference length |ξ|, horizon δ and grid spacing dx.
  double (*factor)(double length, double horizon, double dx) = nullptr;
};

// none | lammps | hhb; an unknown name gets the registry's keys in the error.
const Registry<PartialVolumeRule>& partial_volume_registry();

// Bond cut-off of a rule: δ + family_extension_dx·dx.
double bond_cutoff(const PartialVolumeRule& rule, double horizon, double dx);

// Fills bonds.volume_factor from bonds.length.
void apply_partial_volume(const PartialVolumeRule& rule, double horizon, double dx, BondList& bonds);

}  // namespace pd
