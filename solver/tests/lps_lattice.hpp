// Test helper: what the LPS law gives on a bulk node of the cubic (3D) or square (2D) lattice. The
// dilatation is exact on the discrete family, so the bulk modulus κ is the continuum's; the shear
// is not: for the "axis" shear ε_xx = −ε_yy the deviatoric energy (α/2) Σ ω (e^d)² V_j is the
// continuum's times r_A = Σ ω|ξ|² (n_x² − n_y²)² V / (c_d m), c_d = 4/15 (3D) or 1/2 (2D), the
// isotropic mean of (n_x² − n_y²)² on the sphere or circle. So the bulk's C11 − C12 = 2 μ r_A, and a
// bar's uniaxial stress along x has the compliances below (docs/theory.md C3; the static tension of
// test_lps.cpp and test_lps_tension.cpp measure them).
#pragma once
#include <algorithm>
#include <cmath>
#include <string>

#include "materials/lps/lps.hpp"

namespace pdtest {

// r_A for a horizon of horizon_factor spacings with influence `w` and the partial-volume rule
// `partial_volume` (core/partial_volume.cpp): none, every node within the horizon counts whole;
// lammps, the same family with the outer shell weighted by ν = clamp(m + ½ − |ξ|/dx, 0, 1); hhb,
// that weight on the family |ξ| − dx/2 ≤ δ.
inline double axis_shear_factor(int dimension, double horizon_factor, const std::string& w,
                                const std::string& partial_volume = "none") {
  const int r = static_cast<int>(horizon_factor) + 2, rz = dimension == 3 ? r : 0;
  const bool shell = partial_volume != "none";
  const double reach = horizon_factor + (partial_volume == "hhb" ? 0.5 : 0.0);
  double a = 0.0, m = 0.0;
  for (int p = -r; p <= r; ++p)
    for (int q = -r; q <= r; ++q)
      for (int s = -rz; s <= rz; ++s) {
        const double l2 = p * p + q * q + s * s, l = std::sqrt(l2);
        if (l2 == 0 || l > reach) continue;
        const double nu = shell ? std::min(1.0, std::max(0.0, horizon_factor + 0.5 - l)) : 1.0;
        const double wt = pd::influence(pd::influence_named(w), l, horizon_factor) * l2 * nu;
        const double c = (p * p - q * q) / l2;
        a += wt * c * c;
        m += wt;
      }
  return a / ((dimension == 3 ? 4.0 / 15.0 : 0.5) * m);
}

// The bulk lattice's strains under a uniaxial stress σ along x (in the analysis's sense: σ_yy = 0,
// and σ_zz = 0 in 3D; plane strain holds ε_zz = 0 in its 2D κ and μ): ε_xx E'/σ and −ε_yy/ε_xx,
// for the LPS moduli κ, μ of (E, ν, analysis) and the lattice's μ r_A. E' = E/(1 − ν²) in plane
// strain, E otherwise. Continuum: r_A = 1 gives ε_xx E'/σ = 1 and −ε_yy/ε_xx = ν' (ν/(1 − ν) in plane
// strain, ν otherwise).
struct BulkStrains {
  double axial = 0.0;    // ε_xx E'/σ
  double lateral = 0.0;  // −ε_yy/ε_xx
};
// bulk_factor, shear_factor: a surface correction's factors of κ and μ on the bulk node (the split
// method's β, γ; core/surface_correction.hpp).
inline BulkStrains lps_bulk_tension(double youngs_modulus, double nu, const std::string& analysis, double r_a,
                                    double bulk_factor = 1.0, double shear_factor = 1.0) {
  pd::LpsModuli k = pd::lps_moduli(youngs_modulus, nu, analysis);
  k.kappa *= bulk_factor;
  const double shear = k.mu * r_a * shear_factor;
  const double e_prime = analysis == "plane_strain" ? youngs_modulus / (1.0 - nu * nu) : youngs_modulus;
  BulkStrains out;
  if (analysis == "3d") {  // S11 = 1/(9κ) + 1/(3μ r_A), S12 = 1/(9κ) − 1/(6μ r_A)
    const double s11 = 1.0 / (9 * k.kappa) + 1.0 / (3 * shear), s12 = 1.0 / (9 * k.kappa) - 1.0 / (6 * shear);
    out.axial = s11 * e_prime;
    out.lateral = -s12 / s11;
  } else {  // C11 = κ + μ r_A, C12 = κ − μ r_A: ε_xx = σ C11/(C11² − C12²), −ε_yy/ε_xx = C12/C11
    const double c11 = k.kappa + shear, c12 = k.kappa - shear;
    out.axial = c11 / (c11 * c11 - c12 * c12) * e_prime;
    out.lateral = c12 / c11;
  }
  return out;
}

}  // namespace pdtest
