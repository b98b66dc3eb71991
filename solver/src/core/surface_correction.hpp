// Surface correction (Le & Bobaru 2018, the energy method; issue 14 item 2): per-bond factors g_k
// that make each node's strain energy under a uniform extension equal to the continuum's, computed
// once in the set-up and stored in BondList::surface_factor.
#pragma once
#include <string>
#include <vector>

#include "core/registry.hpp"

namespace pd {

struct Model;

// none | energy. A registry so that the reader's error and --describe list the same names.
const Registry<bool>& surface_correction_registry();

// The per-node, per-direction factors m_d,i = W_d^continuum / W_d,i^discrete (d = x, y(, z)):
// W_d,i is the material's own strain-energy density of node i (bond_model->strain_energy_density,
// on i's intact family, without correction) under u = ε x_d e_d, the mean of +ε and −ε (which
// cancels the odd terms of the finite-strain energy, leaving O(ε²) = 1e-10 relative), and
// W_d^continuum the material's continuum value (BondModel::uniaxial_energy_density). Row-major:
// factors[3 i + d]; 1 for d = z in 2D and for a node whose W_d,i is 0 (no bonds).
std::vector<double> surface_direction_factors(const Model& model);

// g of a bond with unit direction n whose ends have direction factors a and b (3 each):
//   s_d = (a_d + b_d)/2  (Le & Bobaru 2018: the mean of the two ends), and
//   g = [n_x²/s_x² + n_y²/s_y² + n_z²/s_z²]^(−1/2)  (the ellipsoid through the three axis
//   factors: Madenci & Oterkus 2014, "Peridynamic Theory and Its Applications", §4.2; Le & Bobaru
//   2018; as Peridynamics.jl combines them). Symmetric in a and b and in ±n, so both
//   stored copies of a bond get bitwise the same g.
double bond_surface_factor(const double* a, const double* b, double n0, double n1, double n2);

// Sets model.bonds.surface_factor for `method` (none: leaves it empty). Needs model.bond_model.
void apply_surface_correction(const std::string& method, Model& model);

}  // namespace pd
