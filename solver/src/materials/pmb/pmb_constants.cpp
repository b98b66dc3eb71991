// PMB's micromodulus c and critical stretch s0 per analysis: the formulas of docs/theory.md T2.
#include <cmath>
#include <limits>

#include "core/registry.hpp"
#include "materials/pmb/pmb.hpp"

namespace pd {

namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kInf = std::numeric_limits<double>::infinity();

using PmbFormula = PairConstants (*)(double youngs_modulus, std::optional<double> fracture_energy, double delta,
                                     double thickness);

// Bond-based PMB fixes ν = 1/4 in 3D, so K = E/(3(1−2ν)) = 2E/3.
// c = 18K/(πδ⁴) (thesis eq. 1.11), s0 = √(5G0/(9Kδ)) (Silling & Askari 2005; docs/theory.md T2 —
// thesis eq. 1.12 prints E where K belongs).
PairConstants constants_3d(double e, std::optional<double> g0, double delta, double) {
  const double bulk = 2.0 * e / 3.0;
  PairConstants out;
  out.micromodulus = 18.0 * bulk / (kPi * std::pow(delta, 4));
  out.critical_stretch = g0 ? std::sqrt(5.0 * *g0 / (9.0 * bulk * delta)) : kInf;
  return out;
}

// ν = 1/3: c = 9E/(πhδ³), s0 = √(4πG0/(9Eδ)) (docs/theory.md T2; Peridigm, PDMATLAB2D).
PairConstants constants_plane_stress(double e, std::optional<double> g0, double delta, double h) {
  PairConstants out;
  out.micromodulus = 9.0 * e / (kPi * h * std::pow(delta, 3));
  out.critical_stretch = g0 ? std::sqrt(4.0 * kPi * *g0 / (9.0 * e * delta)) : kInf;
  return out;
}

// ν = 1/4: c = 48E/(5πhδ³), s0 = √(5πG0/(12Eδ)) (docs/theory.md T2).
PairConstants constants_plane_strain(double e, std::optional<double> g0, double delta, double h) {
  PairConstants out;
  out.micromodulus = 48.0 * e / (5.0 * kPi * h * std::pow(delta, 3));
  out.critical_stretch = g0 ? std::sqrt(5.0 * kPi * *g0 / (12.0 * e * delta)) : kInf;
  return out;
}

// One formula per name of core/material.hpp's analysis_registry().
const Registry<PmbFormula>& pmb_formulas() {
  static const Registry<PmbFormula> registry = [] {
    Registry<PmbFormula> r("analysis");
    r.add("3d", &constants_3d).add("plane_stress", &constants_plane_stress).add("plane_strain", &constants_plane_strain);
    return r;
  }();
  return registry;
}

}  // namespace

PairConstants pmb_constants(const BlockMaterial& block, const std::string& analysis, double horizon, double thickness) {
  PairConstants out;
  if (const std::optional<double> c = block.parameter("micromodulus")) {
    // c and s0 as a LAMMPS pair_coeff gives them (docs/theory.md T4): taken as they are.
    out.micromodulus = *c;
    out.critical_stretch = block.parameter("critical_stretch").value_or(kInf);
  } else {
    out = pmb_formulas().get(analysis)(block.parameter("youngs_modulus").value_or(0.0),
                                       block.parameter("fracture_energy"), horizon, thickness);
  }
  out.critical_stretch_alpha = block.parameter("critical_stretch_alpha").value_or(0.0);
  return out;
}

ParameterProblem pmb_check(const BlockMaterial& b) {
  const bool e = b.parameter("youngs_modulus").has_value(), g0 = b.parameter("fracture_energy").has_value();
  const bool c = b.parameter("micromodulus").has_value(), s0 = b.parameter("critical_stretch").has_value();
  const std::string pairs = "give youngs_modulus (and fracture_energy) or micromodulus (and critical_stretch), not a mix";
  if (e && c) return {"micromodulus", "is given beside youngs_modulus: " + pairs};
  if (!e && !c) return {"youngs_modulus", "is missing: " + pairs};
  if (e && s0) return {"critical_stretch", "is given with youngs_modulus: " + pairs + " (fracture_energy gives s0 from E)"};
  if (c && g0) return {"fracture_energy", "is given with micromodulus: " + pairs + " (critical_stretch is s0 itself)"};
  if (b.parameter("critical_stretch_alpha").value_or(0.0) > 0.0 && !g0 && !s0)
    return {"critical_stretch_alpha", "needs a breakable material: give fracture_energy or critical_stretch"};
  return {};
}

}  // namespace pd
