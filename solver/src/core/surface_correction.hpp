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
class Decomposed;  // parallel/decomposed.hpp

// none | energy | volume. A registry so that the reader's error and --describe list the same names.
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
// On a decomposed run's piece (d not null) each rank probes its owned rows — a node's W_d,i reads
// its own row only, summed in the serial order — and takes the ghosts' factors from their owners
// after every pass (the next pass's bond factors read both ends): the serial factors. Collective then.
std::vector<double> surface_direction_factors(Model& model, int passes, const Decomposed* d = nullptr);
constexpr int kSurfacePasses = 3;

// g of a bond with unit direction n whose ends have direction factors a and b (3 each):
//   s_d = (a_d + b_d)/2  (Le & Bobaru 2018: the mean of the two ends), and
//   g = [n_x²/s_x² + n_y²/s_y² + n_z²/s_z²]^(−1/2)  (the ellipsoid through the three axis
//   factors: Madenci & Oterkus 2014, "Peridynamic Theory and Its Applications", §4.2; Le & Bobaru
//   2018; as Peridynamics.jl combines them). Symmetric in a and b and in ±n, so both
//   stored copies of a bond get bitwise the same g.
double bond_surface_factor(const double* a, const double* b, double n0, double n1, double n2);

// The split method, for a law whose energy is a dilatational part (κ/2)θ² plus a deviatoric one
// (bond_model->dilatation not empty: LPS). Built to test whether correcting the two parts apart
// brings LPS's lateral strain in C3 within 2 % where the energy method misses it; it does not
// (validation/README.md, "Split surface correction and lattice anisotropy": the 3D bar's lateral
// error stays +11.7, +8.3 % at ν = 0.2, 0.3 and grows to +4.6 % at 0.45), so no case-file method
// uses it: apply_surface_correction's `energy` is the method above for every law. As the ordinary
// state-based surface corrections of Madenci & Oterkus 2014 ("Peridynamic Theory and Its
// Applications", Springer, §5.4: one set of factors for the dilatation from a uniform extension,
// another for the distortional term from its own probe) and the OSB code of Dorduncu, Ren, Zhuang,
// Silling, Madenci & Rabczuk 2024 (Comput. Struct. 299:107395, §5.1), the two parts get their own:
//   1. the dilatation: direction factors f_d,i (bond g = bond_surface_factor of the ends' f, which
//      weights the bond in every sum of the law) such that θ_i of a uniaxial strain along each axis
//      d is 1 (exact): f_d,i ← f_d,i / θ_d,i(g), `passes` times. A bulk node's θ is exact already
//      (θ is a weighted mean of n·ε·n over the family, exact where the family's second moment is
//      isotropic: the lattice's cubic symmetry), so its f stays 1; a node within δ of a face loses a
//      cap of its family and overweights the directions along the face, which f takes out.
//   2. the moduli, per node, from the probes of `shear_probes` with those g: the bulk factor
//      β_i = Σ W_bulk^cont / Σ ½κ θ_i² (1 where step 1 made θ exact) and the shear factor
//      γ_i = Σ W_dev^cont / Σ W_dev,i, W_dev,i = W_i − ½κ θ_i² the law's deviatoric energy.
//      A node's energy depends on its own moduli only, so one pass fits them exactly.
// Probes of the shear factor: `axes` the uniaxial stresses of surface_probe_strain (the state of a
// bar in tension, as the method above), or `isotropic` an orthonormal basis of deviatoric strains
// (ε^d:ε^d = 1 each: xx − yy, xx + yy − 2zz, xy, yz, zx; in 2D xx − yy, xy), whose sum weighs every
// direction alike. On a bulk node the `axes` probes give γ = 1/r_A (the lattice's shear along the
// axes, tests/lps_lattice.hpp: the correction then takes the cubic lattice's anisotropy out for
// loads along the axes, and leaves it in the diagonal shear), the `isotropic` ones give γ = 1 exactly
// wherever θ is exact (Σ over the basis of (n·E_k·n)² = 1 − 1/d for every unit n).
enum class ShearProbes { axes, isotropic };
struct SplitFactors {
  std::vector<double> direction;  // f_d,i, row-major [3 i + d]
  std::vector<double> moduli;     // β_i, γ_i: [2 i], [2 i + 1]
};
SplitFactors split_surface_factors(Model& model, int passes, ShearProbes shear_probes);
constexpr int kDilatationPasses = 6;

// g of every directed bond from per-node direction factors f (bond_surface_factor).
std::vector<double> bond_factors(const Model& model, const std::vector<double>& f);

// The volume method (Le & Bobaru 2018, "Surface corrections for peridynamic models in elasticity
// and fracture", Comput. Mech. 61:499–518, §3; PeriLab's "volume correction"): bond i–j's factor
//   g = 2 V0 / (V_i + V_j),  V_i = Σ_j V_j ν_j over i's intact family,
// V0 the continuum's family volume 4πδ³/3 (3D) or πδ²h (2D, h the thickness), so that a truncated
// family's bonds are stiffened by what it lacks. No probe: g comes from the geometry only (and
// includes the bulk lattice's own V_i/V0, as PeriLab's does). LPS takes g without moduli factors
// (both moduli times ḡ, lps.hpp). On a piece (d not null): V_i over the owned rows, the ghosts'
// from their owners. Collective then.
std::vector<double> volume_factors(const Model& model, const Decomposed* d = nullptr);

// Sets model.bonds.surface_factor for `method` (none: leaves it empty). Needs model.bond_model.
// On a decomposed run's piece (d not null): the factors of its owned rows, bitwise the serial
// ones (see above), without the whole bond list; the caller makes the law again with them, as
// build_model does. Collective then.
void apply_surface_correction(const std::string& method, Model& model, const Decomposed* d = nullptr);

}  // namespace pd
