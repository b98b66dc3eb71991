// Surface correction (Le & Bobaru 2018, the energy method; issue 14 item 2): per-bond factors g_k
// that make each node's strain energy under a uniaxial stress along each axis equal to the
// continuum's, computed once in the set-up and stored in BondList::surface_factor.
#pragma once
#include <string>
#include <vector>

#include "core/registry.hpp"
#include "materials/bond_model.hpp"

namespace pd {

struct Model;

// none | energy. A registry so that the reader's error and --describe list the same names.
const Registry<bool>& surface_correction_registry();

// The probe of direction d on node i: the uniaxial stress along axis d of i's material, ε along d
// and −r·ε along the other axes of the analysis, r the lateral ratio that makes the lateral stress
// zero (ν; ν/(1 − ν) in plane strain), found from the material's own continuum energy: with
// W(ε_dd = a, lateral = b) = ½A a² + B a b + ½C b², r = B/C. A bar or plate in tension is in this
// state, so the factors fit its energy, not that of a uniaxial strain (which also weighs the
// lattice's error in λ). Returns the strain tensor for ε = 1 (StrainTensor: row-major 3×3).
StrainTensor surface_probe_strain(const Model& model, std::size_t i, int d);

// The per-node, per-direction factors m_d,i (d = x, y(, z); Le & Bobaru 2018, the energy method):
//   pass 0: m_d,i = W_d,i^continuum / W_d,i, W_d,i the law's own strain-energy density of node i
//           (bond_model->strain_energy_density on i's intact family, no factors) under the probe
//           u = ε_d·x of surface_probe_strain, the mean of +ε and −ε (which cancels the odd terms
//           of the finite-strain energy, leaving O(ε²) = 1e-10 relative);
//   passes 1…kSurfacePasses: with the bond factors g of the current m applied (and the law made
//           again with them), m_d,i ← m_d,i · W_d,i^continuum / W_d,i(g).
// One pass leaves each node's corrected energy off by what its neighbours' factors change in the
// bonds it shares with them (the mean of the two ends): a node beside a surface shares bonds with
// one on it. The passes drive every node's corrected probe energy to the continuum's (a fixed
// point; measured in tests/materials/test_surface_correction.cpp). Row-major factors[3 i + d]; 1
// for d = z in 2D and for a node whose W_d,i is 0 (no bonds). Leaves model.bonds.surface_factor
// and model.bond_model as they were.
std::vector<double> surface_direction_factors(Model& model, int passes);
constexpr int kSurfacePasses = 3;

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
