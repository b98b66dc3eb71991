// A block's material as the case gives it (model name, density, the model's own parameters), the
// table of per-pair constants every bond model provides, and the analyses (3D, plane stress,
// plane strain). The laws themselves live in materials/<model>/ (materials/bond_model.hpp).
#pragma once
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "core/registry.hpp"

namespace pd {

struct BlockMaterial {
  std::string name;
  std::string model = "pmb";
  double density = 0.0;  // ρ [kg/m³]
  // The model's parameters by name (materials/<model>: e.g. PMB's youngs_modulus [Pa] and
  // fracture_energy [J/m²]); a parameter the case leaves out is absent.
  std::map<std::string, double> parameters;

  std::optional<double> parameter(const std::string& key) const {
    const auto it = parameters.find(key);
    return it == parameters.end() ? std::nullopt : std::optional<double>(it->second);
  }
  // The model's text parameters by name, each one of a closed list (materials/<model>: e.g. LPS's
  // influence function); the reader fills in the parameter's default (its first choice).
  std::map<std::string, std::string> choices;

  std::string choice(const std::string& key, const std::string& otherwise) const {
    const auto it = choices.find(key);
    return it == choices.end() ? otherwise : it->second;
  }
};

struct PairConstants {
  double micromodulus = 0.0;      // c [N/m⁶] (3D) so that c·s·V_j is a force density
  double critical_stretch = 0.0;  // s0; +inf for an unbreakable block
  // α of LAMMPS's critical-stretch rule s0_i = s0 − α·min_j s_ij (docs/theory.md T4; Parks et al.
  // 2008, the PERI package); 0: s0 stays fixed (the thesis).
  double critical_stretch_alpha = 0.0;
};

// c and s0 for every ordered pair of blocks (row-major, blocks × blocks). A bond between blocks
// a and b takes the arithmetic mean of the two micromoduli (a series-spring harmonic mean would
// also be defensible; the mean keeps c_ab = c when the blocks agree, as any rule must) and the
// smaller critical stretch, so the weaker material decides when an interface bond breaks — except
// that a bond with an end in an unbreakable block (no fracture energy) never breaks.
struct MaterialTable {
  int blocks = 0;
  std::vector<PairConstants> block;       // per block id − 1
  std::vector<double> micromodulus_pair;  // c_ab
  std::vector<double> critical_pair;      // s0_ab
  std::vector<double> alpha_pair;         // α_ab: the mean of the blocks' α, as c_ab

  // True when some α_ab > 0: then the critical stretch is a per-node state (materials/pmb/ declares it).
  bool node_rule() const;

  // False when no bond can ever break (every pair unbreakable): then no pass tests breaking.
  // The one place that answers "can anything break?".
  bool can_break() const;
};

// The pair table from the per-block constants, by the rule above.
MaterialTable make_pair_table(std::vector<PairConstants> per_block);

// The analyses a case may name, each with its dimension (3 for "3d", 2 for the plane ones).
const Registry<int>& analysis_registry();
int analysis_dimension(const std::string& analysis);

}  // namespace pd
