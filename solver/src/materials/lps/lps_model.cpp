// LpsModel: its per-node constants, damage, stable-step term, reference stiffness and registry entry.
#include <cmath>
#include <memory>

#include "core/model.hpp"
#include "materials/lps/lps.hpp"
#include "parallel/decomposed.hpp"

namespace pd {

LpsModel::LpsModel(const Model& model) {
  const std::size_t n = model.nodes.size();
  d_ = model.analysis == "3d" ? 3 : 2;
  horizon_ = model.horizon;
  const BlockMaterial first = model.block_materials.empty() ? BlockMaterial{} : model.block_materials[0];
  influence_ = influence_named(first.choice("influence", "one"));
  std::vector<LpsModuli> per_block;
  for (const BlockMaterial& b : model.block_materials)
    per_block.push_back(lps_moduli(b.parameter("youngs_modulus").value_or(0.0),
                                   b.parameter("poisson_ratio").value_or(0.0), model.analysis));
  const double alpha_factor = d_ == 3 ? 15.0 : 8.0;  // α = 15μ (3D), 8μ (2D): lps.hpp
  // A decomposed run's skeleton (run/prepare.cpp: per-node data and each row's length, but no rows,
  // which the ranks build on their pieces) gets no per-node constants: only the law's name and
  // for_piece are asked of it there.
  if (model.bonds.neighbour.size() != static_cast<std::size_t>(model.bonds.offsets.empty() ? 0 : model.bonds.offsets.back())) {
    return;
  }
  m_.assign(n, 0.0);
  kappa_.assign(n, 0.0);
  alpha_.assign(n, 0.0);
  a_.assign(n, 0.0);
  b_.assign(n, 0.0);
  kappa0_.assign(n, 0.0);
  mu0_.assign(n, 0.0);
  const auto& X = model.nodes.x;
#pragma omp parallel for schedule(static)
  for (std::int64_t i64 = 0; i64 < static_cast<std::int64_t>(n); ++i64) {
    const auto i = static_cast<std::size_t>(i64);
    // m_i in row order over the intact bonds, exactly as the kernel sums m'_i: equal bitwise while
    // the family is whole.
    // With surface factors the weights are g V_j ν_j (lps.hpp), m_i too (as the kernel's m'_i), and
    // m0 is the uncorrected m_i: the node's moduli are scaled by ḡ_i = m_i/m0.
    double m = 0.0, m0 = 0.0;
    for (std::int64_t k = model.bonds.offsets[i]; k < model.bonds.offsets[i + 1]; ++k) {
      const auto ku = static_cast<std::size_t>(k);
      if (model.bonds.broken[ku]) continue;
      const auto j = static_cast<std::size_t>(model.bonds.neighbour[ku]);
      const double len = bond_length(X, i, j);
      if (model.bonds.corrected()) {
        const double w = influence(influence_, len, horizon_) * len * len;
        m += w * (model.nodes.volume[j] * model.bonds.volume_weight(len) * model.bonds.surface_factor[ku]);
        m0 += w * (model.nodes.volume[j] * model.bonds.volume_weight(len));
      } else {
        m += influence(influence_, len, horizon_) * len * len *
             (model.nodes.volume[j] * model.bonds.volume_weight(len));
      }
    }
    m_[i] = m;
    const LpsModuli& mod = per_block.empty() ? LpsModuli{} : per_block[static_cast<std::size_t>(model.block_index[i])];
    kappa0_[i] = mod.kappa;
    mu0_[i] = mod.mu;
    // The split correction gives the two moduli their own factors (core/surface_correction.hpp);
    // bond factors alone (set by hand) scale both by ḡ.
    const bool split = model.bonds.corrected() && !model.bonds.surface_moduli.empty();
    const double gbar = model.bonds.corrected() && m0 > 0.0 ? m / m0 : 1.0;
    kappa_[i] = mod.kappa * (split ? model.bonds.surface_moduli[2 * i] : gbar);
    alpha_[i] = alpha_factor * mod.mu * (split ? model.bonds.surface_moduli[2 * i + 1] : gbar);
    if (m > 0.0) {
      a_[i] = alpha_[i] / m;
      b_[i] = d_ * kappa_[i] / m;
    }
  }
}

std::shared_ptr<const BondModel> LpsModel::for_piece(const Model& local, const std::vector<std::int32_t>& global,
                                                     std::shared_ptr<const BondModel> (*registry_make)(const Model&)) const {
  // A skeleton's law (no constants): the piece's own rows give its owned nodes' (ghosts: set_decomposed).
  if (m_.empty()) return registry_make(local);
  auto piece = std::make_shared<LpsModel>(*this);
  const auto pick = [&](const std::vector<double>& a) {
    std::vector<double> out(global.size());
    for (std::size_t l = 0; l < global.size(); ++l) out[l] = a[static_cast<std::size_t>(global[l])];
    return out;
  };
  piece->m_ = pick(m_);
  piece->kappa_ = pick(kappa_);
  piece->alpha_ = pick(alpha_);
  piece->a_ = pick(a_);
  piece->b_ = pick(b_);
  piece->kappa0_ = pick(kappa0_);
  piece->mu0_ = pick(mu0_);
  piece->decomposed_ = nullptr;
  piece->ghost_constants_ = true;  // the ghosts' too, from the whole model
  return piece;
}

void LpsModel::set_decomposed(const Decomposed* d) const {
  if (d && !ghost_constants_) {
    NodeColumns constants;
    constants.add(m_).add(kappa_).add(alpha_).add(a_).add(b_);
    d->update_ghosts(constants);
    ghost_constants_ = true;
  }
  decomposed_ = d;
}

std::vector<double> LpsModel::damage(const Model& m) const { return bond_damage(m); }  // as PMB's

// Eq. 2.5's term for bond i→j, V_j ν C_ij, with a C_ij whose bond-based (PMB) stiffness dominates the
// LPS stiffness, so that eq. 2.5, a Gershgorin bound for PMB, bounds LPS's ω_max too. By
// Cauchy–Schwarz θ_i² ≤ (d²/m_i) Σ_j ω e² V_j, and e^d is e minus its projection on |ξ| in the
// inner product Σ ω V_j (·)(·), so Σ ω (e^d)² V_j ≤ Σ ω e² V_j; hence
//   W_i ≤ ((d²κ_i + α_i)/(2m_i)) Σ_j ω e² V_j
// and Σ_i V_i W_i is at most the PMB energy with C_ij = ω (d²κ_i + α_i)/m_i + ω (d²κ_j + α_j)/m_j.
// This holds with bonds broken too (m'_i ≤ m_i), so the step found at the start stays stable.
// Neither Peridigm's nor CabanaPD's LPS step (PMB's with c = 18K/(πδ⁴), K only) is a bound for
// every ν: it exceeds the exact limit for ν below about −0.2 (3D), where μ dominates
// (tests/materials/test_lps.cpp measures both against the exact limit).
// With surface factors the same bound holds for the weights g V_j (m_i, κ_i, α_i the corrected
// ones, lps.hpp), and node_stiffness multiplies the bond's term by g.
double LpsModel::bond_stiffness(const Model& m, std::size_t i, std::size_t j, double length) const {
  const double dd = static_cast<double>(d_) * d_;
  const auto node_term = [&](std::size_t q) {
    return m_[q] > 0.0 ? (dd * kappa_[q] + alpha_[q]) / m_[q] : 0.0;  // (d²κ + α)/m
  };
  return m.nodes.volume[j] * m.bonds.volume_weight(length) * influence(influence_, length, horizon_) *
         (node_term(i) + node_term(j));
}

double LpsModel::continuum_energy_density(const Model&, std::size_t i, const StrainTensor& strain) const {
  const double tr = strain_trace(strain, d_);
  // ε^d:ε^d = ε:ε − (tr ε)²/d
  const double deviatoric = strain_contraction(strain, d_) - tr * tr / d_;
  return 0.5 * kappa0_[i] * tr * tr + mu0_[i] * deviatoric;
}

namespace {

// Minimum image of a bond component on a periodic axis (period p > 0); unchanged otherwise.
inline double wrap(double d, double p) { return p > 0.0 ? d - p * std::nearbyint(d / p) : d; }

}  // namespace

// y = M^{-1/2} K M^{-1/2} x about the reference configuration, K = −∂F/∂u (F_i = V_i f_i). At u = 0
// every t vanishes, so only the change of t acts: δf_i = Σ_j V_j ω[|ξ|(γ_i δθ_i + γ_j δθ_j) +
// (a_i + a_j) n·δη] n with n = ξ/|ξ|, γ = dκ/m − α/(d m) and δθ_i = (d/m_i) Σ ω|ξ| n·δη V_j. m is
// taken on the bonds intact now with the minimum-image |ξ|, so that a hand-made periodic bond
// list (the tests' infinite lattice) has the m of its own family.
void LpsModel::apply_reference_stiffness(const Model& m, const std::array<double, 3>& period, const Vec3Array& x,
                                         Vec3Array& y) const {
  const auto n = static_cast<std::int64_t>(m.nodes.size());
  const auto& X = m.nodes.x;
  const double d = d_;
  std::vector<double> scale(static_cast<std::size_t>(n)), gamma_dtheta(static_cast<std::size_t>(n)),
      a(static_cast<std::size_t>(n));
  const auto bond = [&](std::size_t i, std::size_t j, double xi[3]) {
    for (int q = 0; q < 3; ++q) xi[q] = wrap(X[static_cast<std::size_t>(q)][j] - X[static_cast<std::size_t>(q)][i],
                                              period[static_cast<std::size_t>(q)]);
    return std::sqrt(xi[0] * xi[0] + xi[1] * xi[1] + xi[2] * xi[2]);
  };
  const auto z = [&](int q, std::size_t i) {  // M^{-1/2} x
    return x[static_cast<std::size_t>(q)][i] * scale[i];
  };
  for (std::size_t i = 0; i < static_cast<std::size_t>(n); ++i) scale[i] = 1.0 / std::sqrt(m.density[i] * m.nodes.volume[i]);
#pragma omp parallel for schedule(static)
  for (std::int64_t i64 = 0; i64 < n; ++i64) {
    const auto i = static_cast<std::size_t>(i64);
    double mi = 0.0, sd = 0.0;
    for (std::int64_t k = m.bonds.offsets[i]; k < m.bonds.offsets[i + 1]; ++k) {
      const auto ku = static_cast<std::size_t>(k);
      if (m.bonds.broken[ku]) continue;
      const auto j = static_cast<std::size_t>(m.bonds.neighbour[ku]);
      double xi[3];
      const double len = bond(i, j, xi);
      const double w = influence(influence_, len, horizon_) * m.nodes.volume[j] * m.bonds.volume_weight(len);
      const double wg = w * m.bonds.factor(ku);  // the surface-corrected weight (lps.hpp); w without one
      mi += wg * len * len;
      sd += wg * (xi[0] * (z(0, j) - z(0, i)) + xi[1] * (z(1, j) - z(1, i)) + xi[2] * (z(2, j) - z(2, i)));  // ω|ξ| n·δη V
    }
    a[i] = mi > 0.0 ? alpha_[i] / mi : 0.0;
    const double gamma = mi > 0.0 ? d * kappa_[i] / mi - a[i] / d : 0.0;
    gamma_dtheta[i] = mi > 0.0 ? gamma * (d / mi * sd) : 0.0;
  }
#pragma omp parallel for schedule(static)
  for (std::int64_t i64 = 0; i64 < n; ++i64) {
    const auto i = static_cast<std::size_t>(i64);
    double s0 = 0.0, s1 = 0.0, s2 = 0.0;
    for (std::int64_t k = m.bonds.offsets[i]; k < m.bonds.offsets[i + 1]; ++k) {
      const auto ku = static_cast<std::size_t>(k);
      if (m.bonds.broken[ku]) continue;
      const auto j = static_cast<std::size_t>(m.bonds.neighbour[ku]);
      double xi[3];
      const double len = bond(i, j, xi);
      const double n0 = xi[0] / len, n1 = xi[1] / len, n2 = xi[2] / len;
      const double along = n0 * (z(0, j) - z(0, i)) + n1 * (z(1, j) - z(1, i)) + n2 * (z(2, j) - z(2, i));
      const double t = influence(influence_, len, horizon_) *
                       (len * (gamma_dtheta[i] + gamma_dtheta[j]) + (a[i] + a[j]) * along) * m.nodes.volume[j] *
                       m.bonds.volume_weight(len) * m.bonds.factor(ku);
      s0 += t * n0;
      s1 += t * n1;
      s2 += t * n2;
    }
    // K z = −V_i δf_i; then M^{-1/2}.
    y[0][i] = -m.nodes.volume[i] * s0 * scale[i];
    y[1][i] = -m.nodes.volume[i] * s1 * scale[i];
    y[2][i] = -m.nodes.volume[i] * s2 * scale[i];
  }
}

// The registry entry (materials/bond_model.hpp): the parameters LPS reads from a block.
void register_material_lps(MaterialRegistry& registry) {
  MaterialDefinition def;
  def.doc = "linear peridynamic solid, ordinary state-based (Silling et al. 2007; Mitchell's form as LAMMPS peri/lps "
            "and Peridigm Elastic): any Poisson's ratio";
  MaterialParameter e{"youngs_modulus", "Pa", "Young's modulus E", true};
  MaterialParameter nu{"poisson_ratio", "", "Poisson's ratio ν of the isotropic solid (LPS)", true, -1.0, 0.5};
  nu.bounds_reason = "an isotropic solid needs a positive bulk modulus K = E/(3(1−2ν)) and shear modulus "
                     "G = E/(2(1+ν)), so −1 < ν < 1/2; plane strain needs the same (its in-plane bulk modulus "
                     "E/(2(1+ν)(1−2ν)) is infinite at ν = 1/2), and plane stress is a thin plate of such a solid";
  MaterialParameter g0{"fracture_energy", "J/m²", "null: unbreakable", false};
  MaterialParameter w{"influence", "", "LPS influence function ω(|ξ|): one, inverse_length (1/|ξ|) or gaussian "
                                       "(exp(−|ξ|²/δ²))", false};
  w.choices = {"one", "inverse_length", "gaussian"};
  def.parameters = {e, nu, g0, w};
  def.constants = &lps_constants;
  def.make = [](const Model& model) -> std::shared_ptr<const BondModel> { return std::make_shared<LpsModel>(model); };
  registry.add("lps", def);
}

}  // namespace pd
