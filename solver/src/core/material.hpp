// PMB material constants: micromodulus c and critical stretch s0 per block (validation.md F1),
// and the per-pair table used by bonds whose ends lie in different blocks.
#pragma once
#include <optional>
#include <string>
#include <vector>

#include "core/registry.hpp"

namespace pd {

struct BlockMaterial {
  std::string name;
  std::string model = "pmb";
  double density = 0.0;                   // ρ [kg/m³]
  double youngs_modulus = 0.0;            // E [Pa]
  std::optional<double> fracture_energy;  // G0 [J/m²]; empty: the block never breaks
};

struct PmbConstants {
  double micromodulus = 0.0;      // c [N/m⁶] (3D) so that c·s·V_j is a force density
  double critical_stretch = 0.0;  // s0; +inf for an unbreakable block
};

// One formula per analysis ("3d", "plane_stress", "plane_strain"); thickness h is ignored in 3D.
using PmbFormula = PmbConstants (*)(const BlockMaterial&, double horizon, double thickness);
const Registry<PmbFormula>& analysis_registry();

// The dimension an analysis belongs to (3 for "3d", 2 for the plane ones).
int analysis_dimension(const std::string& analysis);

// c and s0 for every ordered pair of blocks (row-major, blocks × blocks). A bond between blocks
// a and b takes the arithmetic mean of the two micromoduli (a series-spring harmonic mean would
// also be defensible; the mean keeps c_ab = c when the blocks agree, as any rule must) and the
// smaller critical stretch, so the weaker material decides when an interface bond breaks — except
// that a bond with an end in an unbreakable block (no fracture energy) never breaks.
struct MaterialTable {
  int blocks = 0;
  std::vector<PmbConstants> block;        // per block id − 1
  std::vector<double> micromodulus_pair;  // c_ab
  std::vector<double> critical_pair;      // s0_ab
};

MaterialTable make_material_table(const std::vector<BlockMaterial>& blocks, const std::string& analysis,
                                  double horizon, double thickness);

}  // namespace pd
