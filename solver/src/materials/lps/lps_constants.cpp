// LPS's per-block constants: the moduli of each analysis, the influence functions, and the
// critical stretch from the fracture energy (materials/lps/lps.hpp).
#include <cmath>
#include <limits>

#include "core/error.hpp"
#include "materials/lps/lps.hpp"

namespace pd {

namespace {

constexpr double kPi = 3.14159265358979323846;

// I_k = ∫₀^δ ω(r) r^k dr by composite Simpson on 2000 panels: exact for ω = 1 and 1/r (polynomials
// of degree ≤ 5), and to round-off for the Gaussian (smooth on [0, δ]).
double influence_moment(Influence kind, int k, double delta) {
  const int panels = 2000;
  const double h = delta / panels;
  double sum = 0.0;
  for (int q = 0; q <= panels; ++q) {
    const double r = q * h;
    const double f = r > 0.0 ? influence(kind, r, delta) * std::pow(r, k) : 0.0;  // k ≥ 2: 0 at r = 0
    sum += f * (q == 0 || q == panels ? 1.0 : (q % 2 ? 4.0 : 2.0));
  }
  return sum * h / 3.0;
}

}  // namespace

Influence influence_named(const std::string& name) {
  if (name == "one") return Influence::one;
  if (name == "inverse_length") return Influence::inverse_length;
  if (name == "gaussian") return Influence::gaussian;
  throw Error("unknown influence function '" + name + "'; known: one, inverse_length, gaussian");
}

LpsModuli lps_moduli(double e, double nu, const std::string& analysis) {
  LpsModuli out;
  out.mu = e / (2.0 * (1.0 + nu));
  if (analysis == "plane_strain") out.kappa = e / (2.0 * (1.0 + nu) * (1.0 - 2.0 * nu));  // λ + μ
  else if (analysis == "plane_stress") out.kappa = e / (2.0 * (1.0 - nu));  // λ* + μ, λ* = 2λμ/(λ + 2μ)
  else out.kappa = e / (3.0 * (1.0 - 2.0 * nu));  // K
  return out;
}

// The fracture-plane integral (Silling & Askari 2005, §6) counts every bond crossing a plane with
// its energy w per V_i V_j: G0 = π ∫₀^δ w r³ dr (3D), G0 = 2h ∫₀^δ w r² dr (2D, per thickness h).
// At an isotropic stretch s (θ = d s, e^d = 0) W_i = (κ/2)(d s)² = (d²κ/(2m)) Σ_j ω |ξ|² s² V_j, so
// a bond holds w = (d²κ/m) ω r² s² between its two ends, with the continuum m = 4π I4 (3D) or
// 2πh I3 (2D). Hence G0 = 9K s0² I5/(4 I4) (3D) and G0 = 4κ s0² I4/(π I3) (2D).
PairConstants lps_constants(const BlockMaterial& block, const std::string& analysis, double horizon,
                            double thickness) {
  const LpsModuli k = lps_moduli(block.parameter("youngs_modulus").value_or(0.0),
                                 block.parameter("poisson_ratio").value_or(0.0), analysis);
  const Influence w = influence_named(block.choice("influence", "one"));
  const std::optional<double> g0 = block.parameter("fracture_energy");
  PairConstants out;
  out.critical_stretch = std::numeric_limits<double>::infinity();
  if (analysis == "3d") {
    out.micromodulus = 18.0 * k.kappa / (kPi * std::pow(horizon, 4));
    if (g0)
      out.critical_stretch = std::sqrt(4.0 * *g0 * influence_moment(w, 4, horizon) /
                                       (9.0 * k.kappa * influence_moment(w, 5, horizon)));
  } else {
    out.micromodulus = 12.0 * k.kappa / (kPi * thickness * std::pow(horizon, 3));
    if (g0)
      out.critical_stretch = std::sqrt(kPi * *g0 * influence_moment(w, 3, horizon) /
                                       (4.0 * k.kappa * influence_moment(w, 4, horizon)));
  }
  return out;
}

}  // namespace pd
