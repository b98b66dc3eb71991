// The F1 formulas of validation.md for c and s0, registered by analysis name.
#include "core/material.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace pd {

namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kInf = std::numeric_limits<double>::infinity();

// Bond-based PMB fixes ν = 1/4 in 3D, so K = E/(3(1−2ν)) = 2E/3.
// c = 18K/(πδ⁴) (thesis eq. 1.11), s0 = √(5G0/(9Kδ)) (Silling & Askari 2005; validation.md F1 —
// thesis eq. 1.12 prints E where K belongs).
PmbConstants constants_3d(const BlockMaterial& m, double delta, double) {
  const double bulk = 2.0 * m.youngs_modulus / 3.0;
  PmbConstants out;
  out.micromodulus = 18.0 * bulk / (kPi * std::pow(delta, 4));
  out.critical_stretch = m.fracture_energy ? std::sqrt(5.0 * *m.fracture_energy / (9.0 * bulk * delta)) : kInf;
  return out;
}

// ν = 1/3: c = 9E/(πhδ³), s0 = √(4πG0/(9Eδ)) (validation.md F1; Peridigm, PDMATLAB2D).
PmbConstants constants_plane_stress(const BlockMaterial& m, double delta, double h) {
  PmbConstants out;
  out.micromodulus = 9.0 * m.youngs_modulus / (kPi * h * std::pow(delta, 3));
  out.critical_stretch =
      m.fracture_energy ? std::sqrt(4.0 * kPi * *m.fracture_energy / (9.0 * m.youngs_modulus * delta)) : kInf;
  return out;
}

// ν = 1/4: c = 48E/(5πhδ³), s0 = √(5πG0/(12Eδ)) (validation.md F1).
PmbConstants constants_plane_strain(const BlockMaterial& m, double delta, double h) {
  PmbConstants out;
  out.micromodulus = 48.0 * m.youngs_modulus / (5.0 * kPi * h * std::pow(delta, 3));
  out.critical_stretch =
      m.fracture_energy ? std::sqrt(5.0 * kPi * *m.fracture_energy / (12.0 * m.youngs_modulus * delta)) : kInf;
  return out;
}

}  // namespace

const Registry<PmbFormula>& analysis_registry() {
  static const Registry<PmbFormula> registry = [] {
    Registry<PmbFormula> r("analysis");
    r.add("3d", &constants_3d).add("plane_stress", &constants_plane_stress).add("plane_strain", &constants_plane_strain);
    return r;
  }();
  return registry;
}

int analysis_dimension(const std::string& analysis) { return analysis == "3d" ? 3 : 2; }

MaterialTable make_material_table(const std::vector<BlockMaterial>& blocks, const std::string& analysis,
                                  double horizon, double thickness) {
  const PmbFormula formula = analysis_registry().get(analysis);
  MaterialTable table;
  table.blocks = static_cast<int>(blocks.size());
  for (const auto& b : blocks) table.block.push_back(formula(b, horizon, thickness));
  const auto nb = blocks.size();
  table.micromodulus_pair.resize(nb * nb);
  table.critical_pair.resize(nb * nb);
  for (std::size_t a = 0; a < nb; ++a)
    for (std::size_t b = 0; b < nb; ++b) {
      table.micromodulus_pair[a * nb + b] = 0.5 * (table.block[a].micromodulus + table.block[b].micromodulus);
      // A bond with an end in an unbreakable block never breaks (s0 = ∞ wins over the minimum).
      const double sa = table.block[a].critical_stretch, sb = table.block[b].critical_stretch;
      table.critical_pair[a * nb + b] = (std::isinf(sa) || std::isinf(sb)) ? kInf : std::min(sa, sb);
    }
  return table;
}

}  // namespace pd
