// The linear peridynamic solid, LPS (Silling, Epton, Weckner, Xu & Askari 2007, "Peridynamic states
// and constitutive modeling", §15; Mitchell's ordinary state-based form as LAMMPS peri/lps and
// Peridigm's Elastic material compute it): any Poisson ratio, where bond-based PMB fixes it.
//
// Per node i, over its intact bonds j (e = |y_j − y_i| − |ξ| the extension, ω = ω(|ξ|) the
// influence function, V_j the neighbour's volume times its partial-volume share ν_j, d = 3 in 3D
// and 2 in the plane analyses):
//   m_i  = Σ_j ω |ξ|² V_j                     weighted volume, on the family at the start
//   θ_i  = (d/m_i) Σ_j ω |ξ| e V_j             dilatation (exact for an affine u: patch test)
//   e^d  = e − θ_i |ξ|/d                       deviatoric extension
//   W_i  = (κ/2) θ_i² + (α/(2 m_i)) Σ_j ω (e^d)² V_j,  α = 15μ (3D), 8μ (2D)
// with κ the bulk modulus K in 3D and the in-plane bulk modulus in 2D (plane strain K + μ/3 =
// E/(2(1+ν)(1−2ν)), plane stress E/(2(1−ν))), μ = E/(2(1+ν)). For a uniform small strain ε this
// is the continuum W = (κ/2)(tr ε)² + μ ε^d:ε^d: in 3D the average of (n·ε^d·n)² over the sphere is
// (2/15) ε^d:ε^d, hence 15μ/m; in 2D over the circle it is ε^d:ε^d/4 (in-plane deviator), hence
// 8μ/m — derived here from the energy; Le et al. 2014 (the 2D ordinary state-based model) state
// the plane forms with the 3D dilatation, which differ from these only in how θ is named.
//
// The force is the exact gradient of Σ_i V_i W_i: with t_ij = ∂W_i/∂e_ij / V_j,
//   t_ij = ω [ |ξ| P_i + a_i e ],  a_i = α_i/m_i,
//   P_i  = θ_i (dκ_i/m_i − a_i/d − a_i (m_i − m'_i)/(d m_i)),  m'_i = Σ_intact ω |ξ|² V_j,
//   f_i  = Σ_j (t_ij + t_ji) V_j (y_j − y_i)/|y_j − y_i|.
// While every bond of i's family is intact m'_i = m_i and t is Mitchell's form, in 3D
// (3Kθ/m) ω|ξ| + (15μ/m) ω e^d = ((3K − 5μ)θ|ξ| + 15μ e) ω/m (LAMMPS); once bonds break, the last term of P keeps f the gradient of the
// energy (so the energy balance holds exactly and the Jacobian stays symmetric) where LAMMPS and
// Peridigm, which keep m and drop it, are not.
//
// Surface correction (core/surface_correction, discretization.surface_correction: energy): bond q's
// factor g_q multiplies its weight V_j ν_j in every sum of the law — m_i, θ_i, the deviatoric sum and
// the force — and node i's moduli κ_i, α_i are multiplied by ḡ_i = m_i(g)/m_i(1), the factors' mean
// over i's family (the energy and volume methods). The split method (core/surface_correction.hpp,
// measured there, not a case-file choice) sets per-node factors of κ_i and α_i instead
// (BondList::surface_moduli). So a node whose bonds all carry one g has its energy W_i times g exactly (θ and
// the deviatoric shape do not change, the moduli do): the energy method's premise, and ν stays the
// material's; unequal factors reweight the family by direction (a truncated family's θ and
// deviatoric sum see the missing directions again). One symmetric weighting (g_ij = g_ji), so the
// force stays the exact gradient of Σ_i V_i W_i and J symmetric; the formulas above hold with
// V_j → g V_j.
#pragma once
#include <cfloat>
#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

#include "core/model.hpp"
#include "materials/bond_model.hpp"

namespace pd {

// ω(|ξ|) (Peridigm's names: One, and Gaussian exp(−|ξ|²/δ²); 1/|ξ| as CabanaPD's second choice).
enum class Influence { one, inverse_length, gaussian };
Influence influence_named(const std::string& name);
// Inline and in one expression per kind, so that the constructor's m_i and the kernel's m'_i are
// computed by the same operations (bitwise equal while a family is whole).
template <Influence kKind>
inline double influence_of(double length, double horizon) {
  if constexpr (kKind == Influence::inverse_length) return 1.0 / length;
  else if constexpr (kKind == Influence::gaussian) return std::exp(-(length * length) / (horizon * horizon));
  else return 1.0;
}
inline double influence(Influence kind, double length, double horizon) {
  switch (kind) {
    case Influence::inverse_length: return influence_of<Influence::inverse_length>(length, horizon);
    case Influence::gaussian: return influence_of<Influence::gaussian>(length, horizon);
    case Influence::one: break;
  }
  return influence_of<Influence::one>(length, horizon);
}

// The moduli of one block for the analysis: κ (3D bulk, or in-plane bulk in 2D) and μ [Pa].
struct LpsModuli {
  double kappa = 0.0;
  double mu = 0.0;
};
LpsModuli lps_moduli(double youngs_modulus, double poisson_ratio, const std::string& analysis);

// c and s0 of one block. s0: the Silling–Askari (2005) fracture-plane integral of the energy the
// bonds crossing a plane hold at an isotropic stretch s0, with the LPS bond energy of that state
// (lps_constants.cpp): 3D s0 = √(4 G0 I4 / (9 K I5)), 2D s0 = √(π G0 I3 / (4 κ I4)),
// I_k = ∫₀^δ ω(r) r^k dr. This is CabanaPD's LPS critical stretch (√(8G0/(15Kδ)) for ω = 1,
// √(5G0/(9Kδ)) for ω = 1/|ξ|, PMB's) for any ω and in 2D. c: the bond-based micromodulus of the
// same κ, 18K/(πδ⁴) (3D) or 12κ/(πhδ³) (2D), used by contact (docs/theory.md T8) and run.log.
PairConstants lps_constants(const BlockMaterial& block, const std::string& analysis, double horizon, double thickness);

class LpsModel : public BondModel {
 public:
  // Precomputes m_i on the bonds intact now (pre-cracks are free surfaces) and the per-node moduli.
  explicit LpsModel(const Model& model);

  std::string name() const override { return "lps"; }
  void add_force(const Model& model, const Vec3Array& u, Vec3Array& f, double* w) const override;
  BreakReport break_bonds_and_add_force(Model& model, const Vec3Array& u, Vec3Array& f, double* w,
                                        bool want_energy, double* lost_per_node = nullptr) const override;
  // Both sweeps overlapped with the exchanges they need, u's and then P's (lps_kernel.cpp
  // overlapped_sweeps; parallel/row_split.hpp says why).
  void add_force_overlapped(const Model& model, const Vec3Array& u, Vec3Array& f, double* w,
                            const GhostsInFlight& u_ghosts) const override;
  BreakReport break_bonds_and_add_force_overlapped(Model& model, const Vec3Array& u, Vec3Array& f, double* w,
                                                   bool want_energy, double* lost_per_node,
                                                   const GhostsInFlight& u_ghosts) const override;
  BreakReport break_bonds(Model& model, const Vec3Array& u, bool want_energy) const override;
  // PMB's criterion on y − |ξ| > s0 |ξ| (LpsKernel::Bond::over), the ratio (y − |ξ|)/(s0 |ξ|).
  StretchRatio stretch_ratio(const Model& model, const Vec3Array& u) const override;
  std::vector<double> strain_energy_density(const Model& model, const Vec3Array& u) const override;
  std::vector<double> damage(const Model& model) const override;
  double bond_stiffness(const Model& model, std::size_t i, std::size_t j, double length) const override;
  // (κ/2)(tr ε)² + μ ε^d:ε^d with i's block's κ, μ (uncorrected), ε^d = ε − (tr ε/d) I over the d
  // axes of the analysis: the energy this law reproduces for a uniform strain (header comment).
  double continuum_energy_density(const Model& model, std::size_t i, const StrainTensor& strain) const override;
  void apply_reference_stiffness(const Model& model, const std::array<double, 3>& period, const Vec3Array& x,
                                 Vec3Array& y) const override;
  void add_jacobian_product(const Model& model, const Vec3Array& u, const Vec3Array& x, Vec3Array& y) const override;
  // Both sweeps of J·x overlapped with the exchanges they need, x's and then P's with δP's
  // (lps_kernel.cpp; parallel/row_split.hpp says why).
  void add_jacobian_product_overlapped(const Model& model, const Vec3Array& u, const Vec3Array& x, Vec3Array& y,
                                       const GhostsInFlight& x_ghosts) const override;
  bool bond_tangent_row(const Model&, const Vec3Array&, std::size_t, double*, bool = false) const override {
    return false;  // state-based: f_i depends on the neighbours' neighbours; solvers stay matrix-free
  }

  // ∂f_i/∂u_i per node (lps_tangent.cpp): the bond terms and the dilatation's, derived there.
  bool jacobian_diagonal_blocks(const Model& model, const Vec3Array& u, std::vector<double>& blocks,
                                bool definite = false) const override;
  // A decomposed run (issue 15): the piece's law. Made from the whole model's law (every rank
  // holds the whole list: run/prepare whole_bonds_reason), it takes m_i, κ, α, a, b of every local
  // node, ghosts too, from it — the constants as that law was made (a test may break bonds after).
  // From a skeleton's law (no rows, no constants), it is made on the piece: its owned rows give the
  // owned nodes' constants, and set_decomposed the ghosts'.
  std::shared_ptr<const BondModel> for_piece(const Model& local, const std::vector<std::int32_t>& global,
                                             std::shared_ptr<const BondModel> (*registry_make)(const Model&)) const override;
  // Between the sweeps the law fills the ghosts' P_j from their owners through d (one scalar per
  // ghost: the force sweep's t_ij + t_ji needs P of both ends). On a piece made on its own rows a
  // ghost's row is empty, so its m_j could not be summed there: the first call with d also takes
  // the ghosts' m, κ, α, a, b from their owners, in one exchange — each owner summed its own row in
  // the serial order, so these are the serial bits. Collective; the piece's maker calls it before
  // any sweep (parallel/mpi_decomposed), the operator again (no exchange then).
  void set_decomposed(const Decomposed* d) const override;
  // The dilatation θ_i at u over the intact bonds (for tests and output).
  std::vector<double> dilatation(const Model& model, const Vec3Array& u) const override;
  const std::vector<double>& weighted_volume() const { return m_; }

 private:
  int d_ = 3;                  // 3, or 2 in the plane analyses
  Influence influence_ = Influence::one;
  double horizon_ = 0.0;
  // Per node. Mutable for set_decomposed only, which fills a piece's ghosts' entries once.
  mutable std::vector<double> m_;      // m_i
  mutable std::vector<double> kappa_;  // κ of i's block
  mutable std::vector<double> alpha_;  // α of i's block (15μ in 3D, 8μ in 2D)
  mutable std::vector<double> a_;      // α_i / m_i
  mutable std::vector<double> b_;      // d κ_i / m_i
  std::vector<double> kappa0_, mu0_;  // κ, μ of i's block, uncorrected (continuum_energy_density)
  // Set once by the operator of a decomposed run (set_decomposed), before any sweep; null: serial.
  mutable const Decomposed* decomposed_ = nullptr;
  mutable bool ghost_constants_ = false;  // set_decomposed has filled the ghosts' m, κ, α, a, b

  friend struct LpsKernel;
};

}  // namespace pd
