// PmbModel: PMB behind the BondModel interface, its linearisation, and its registry entry.
#include <algorithm>
#include <cmath>
#include <memory>

#include "core/model.hpp"
#include "materials/pmb/pmb.hpp"

namespace pd {

void PmbModel::add_force(const Model& model, const Vec3Array& u, Vec3Array& f, double* w) const {
  add_pmb_force(model, u, f, w);
}

BreakReport PmbModel::break_bonds_and_add_force(Model& model, const Vec3Array& u, Vec3Array& f, double* w,
                                                bool want_energy, double* lost_per_node) const {
  BreakReport r;
  double* energy = want_energy && !lost_per_node ? &r.energy : nullptr;
  if (uses_lammps_rules(model)) r.broken = break_bonds_lammps_rules(model, u, &f, w, energy, lost_per_node);
  else r.broken = break_bonds_and_add_pmb_force(model, u, f, w, energy, lost_per_node);
  return r;
}

void PmbModel::add_force_overlapped(const Model& model, const Vec3Array& u, Vec3Array& f, double* w,
                                    const GhostsInFlight& u_ghosts) const {
  sweep_overlapped(u_ghosts, [&](RowSubset rows) { add_pmb_force(model, u, f, w, rows); });
}

BreakReport PmbModel::break_bonds_and_add_force_overlapped(Model& model, const Vec3Array& u, Vec3Array& f, double* w,
                                                           bool want_energy, double* lost_per_node,
                                                           const GhostsInFlight& u_ghosts) const {
  // Without lost_per_node the energy of the broken bonds is summed over every row at once:
  // not a split sweep's (a decomposed run always passes it, operator/force_operator).
  if (!lost_per_node)
    return BondModel::break_bonds_and_add_force_overlapped(model, u, f, w, want_energy, lost_per_node, u_ghosts);
  BreakReport r;
  // LAMMPS's rules: the pass splits itself around the wait (break_bonds_lammps_rules).
  if (uses_lammps_rules(model)) {
    r.broken = break_bonds_lammps_rules(model, u, &f, w, nullptr, lost_per_node, &u_ghosts);
    return r;
  }
  // A row breaks only its own copies of its bonds (both copies of a crossing bond see the same
  // stretch), so the interior rows may break theirs before the boundary rows have u's ghosts.
  r.broken = sweep_overlapped(u_ghosts, [&](RowSubset rows) {
    return break_bonds_and_add_pmb_force(model, u, f, w, nullptr, lost_per_node, rows);
  });
  return r;
}

BreakReport PmbModel::break_bonds(Model& model, const Vec3Array& u, bool want_energy) const {
  BreakReport r;
  if (uses_lammps_rules(model)) r.broken = break_bonds_lammps_rules(model, u, nullptr, nullptr, want_energy ? &r.energy : nullptr);
  else r.broken = update_broken_bonds(model, u, want_energy ? &r.energy : nullptr);
  return r;
}

std::vector<double> PmbModel::strain_energy_density(const Model& model, const Vec3Array& u) const {
  return pd::strain_energy_density(model, u);
}

double PmbModel::bond_stiffness(const Model& m, std::size_t i, std::size_t j, double length) const {
  const auto nb = static_cast<std::size_t>(m.material.blocks);
  const double micromodulus = m.material.micromodulus_pair[static_cast<std::size_t>(m.block_index[i]) * nb +
                                                           static_cast<std::size_t>(m.block_index[j])];
  // thesis eq. 2.5 with the linearised PMB stiffness |C(ξ)| = c/|ξ| (Silling & Askari 2005).
  return m.nodes.volume[j] * m.bonds.volume_weight(length) * micromodulus / length;
}

double PmbModel::continuum_energy_density(const Model& m, std::size_t i, const StrainTensor& strain) const {
  constexpr double kPi = 3.14159265358979323846;
  const auto nb = static_cast<std::size_t>(m.material.blocks);
  const auto bi = static_cast<std::size_t>(m.block_index[i]);
  const double c = m.material.micromodulus_pair[bi * nb + bi];
  const double delta = m.horizon;
  const int dims = m.nodes.dimension == 3 ? 3 : 2;
  const double tr = strain_trace(strain, dims);
  const double quartic = tr * tr + 2.0 * strain_contraction(strain, dims);  // ∫(n·ε·n)² over directions ÷ (4π/15 or π/4)
  // ∫ r³ dr = δ⁴/4, ∫ r² dr = δ³/3 (times h in 2D); ¼ c of the bond energy (pmb.hpp).
  if (dims == 3) return c * kPi * std::pow(delta, 4) / 60.0 * quartic;
  return c * m.thickness * kPi * std::pow(delta, 3) / 48.0 * quartic;
}

namespace {

// Minimum image of a bond component on a periodic axis (period p > 0); unchanged otherwise.
inline double wrap(double d, double p) { return p > 0.0 ? d - p * std::nearbyint(d / p) : d; }

}  // namespace

void PmbModel::apply_reference_stiffness(const Model& m, const std::array<double, 3>& period, const Vec3Array& x,
                                         Vec3Array& y) const {
  const auto n = static_cast<std::int64_t>(m.nodes.size());
  const auto nb = static_cast<std::size_t>(m.material.blocks);
#pragma omp parallel for schedule(static)
  for (std::int64_t i64 = 0; i64 < n; ++i64) {
    const auto i = static_cast<std::size_t>(i64);
    const double inv_sqrt_mi = 1.0 / std::sqrt(m.density[i] * m.nodes.volume[i]);
    const std::size_t bi = static_cast<std::size_t>(m.block_index[i]);
    double y0 = 0.0, y1 = 0.0, y2 = 0.0;
    for (std::int64_t k = m.bonds.offsets[i]; k < m.bonds.offsets[i + 1]; ++k) {
      const auto ku = static_cast<std::size_t>(k);
      if (m.bonds.broken[ku]) continue;
      const auto j = static_cast<std::size_t>(m.bonds.neighbour[ku]);
      // |ξ| of the minimum image (core/bonds.hpp stores no lengths; without a period this is
      // bitwise bond_length).
      const double xi0 = wrap(m.nodes.x[0][j] - m.nodes.x[0][i], period[0]);
      const double xi1 = wrap(m.nodes.x[1][j] - m.nodes.x[1][i], period[1]);
      const double xi2 = wrap(m.nodes.x[2][j] - m.nodes.x[2][i], period[2]);
      const double len = std::sqrt(xi0 * xi0 + xi1 * xi1 + xi2 * xi2);
      const double e0 = xi0 / len, e1 = xi1 / len, e2 = xi2 / len;
      const double inv_sqrt_mj = 1.0 / std::sqrt(m.density[j] * m.nodes.volume[j]);
      // bond stiffness k_ij = c ν V_i V_j/|ξ| (force per unit relative displacement along e; ν the
      // partial-volume factor of docs/theory.md T5, from |ξ|)
      const double nu = m.bonds.volume_weight(len);
      const double kij = m.material.micromodulus_pair[bi * nb + static_cast<std::size_t>(m.block_index[j])] * nu *
                         m.nodes.volume[i] * m.nodes.volume[j] / len * m.bonds.factor(ku);  // g: surface correction
      const double d0 = x[0][i] * inv_sqrt_mi - x[0][j] * inv_sqrt_mj;
      const double d1 = x[1][i] * inv_sqrt_mi - x[1][j] * inv_sqrt_mj;
      const double d2 = x[2][i] * inv_sqrt_mi - x[2][j] * inv_sqrt_mj;
      const double along = kij * (e0 * d0 + e1 * d1 + e2 * d2);
      y0 += along * e0;
      y1 += along * e1;
      y2 += along * e2;
    }
    y[0][i] = y0 * inv_sqrt_mi;
    y[1][i] = y1 * inv_sqrt_mi;
    y[2][i] = y2 * inv_sqrt_mi;
  }
}

namespace {

// ∂f_i/∂u_j of one intact bond at the current state (row-major 3×3):
//   c ν V_j·[(1/|ξ|)·n nᵀ + (s/y)·(I − n nᵀ)],  n = e/y, e = y_j − y_i.
// A bond crushed to a point (y = 0) has no direction: the kernel gives it no force, and no stiffness here.
inline void bond_block(double c_vj, double length, double e0, double e1, double e2, double block[9],
                       bool definite = false) {
  const double len_y = std::sqrt(e0 * e0 + e1 * e1 + e2 * e2);
  if (!(len_y > 0.0)) {
    for (int q = 0; q < 9; ++q) block[q] = 0.0;
    return;
  }
  const double n[3] = {e0 / len_y, e1 / len_y, e2 / len_y};
  const double raw_s = (len_y - length) / length;
  const double s = std::fabs(raw_s) > kStretchZero ? raw_s : 0.0;  // as the kernel (thesis §2.2)
  const double axial = c_vj / length, lateral = c_vj * (definite ? std::max(s, 0.0) : s) / len_y;
  for (int a = 0; a < 3; ++a)
    for (int b = 0; b < 3; ++b) block[3 * a + b] = (axial - lateral) * n[a] * n[b] + (a == b ? lateral : 0.0);
}

}  // namespace

namespace {

// y += J(u)·x over `rows` (every row by default; parallel/row_split.hpp).
void add_jacobian_rows(const Model& m, const Vec3Array& u, const Vec3Array& x, Vec3Array& y, RowSubset rows) {
  const std::int64_t count = rows.size(static_cast<std::int64_t>(m.nodes.size()));
  const auto nb = static_cast<std::size_t>(m.material.blocks);
  const auto& X = m.nodes.x;
#pragma omp parallel for schedule(static)
  for (std::int64_t r = 0; r < count; ++r) {
    const auto i = static_cast<std::size_t>(rows.at(r));
    const std::size_t bi = static_cast<std::size_t>(m.block_index[i]);
    const double yi0 = X[0][i] + u[0][i], yi1 = X[1][i] + u[1][i], yi2 = X[2][i] + u[2][i];
    double s0 = 0.0, s1 = 0.0, s2 = 0.0;  // in bond order: the same for any thread count
    for (std::int64_t k = m.bonds.offsets[i]; k < m.bonds.offsets[i + 1]; ++k) {
      const auto ku = static_cast<std::size_t>(k);
      if (m.bonds.broken[ku]) continue;
      const auto j = static_cast<std::size_t>(m.bonds.neighbour[ku]);
      const double length = bond_length(X, i, j);
      const double c_vj = m.material.micromodulus_pair[bi * nb + static_cast<std::size_t>(m.block_index[j])] *
                          m.nodes.volume[j] * m.bonds.volume_weight(length) * m.bonds.factor(ku);
      double b[9];
      bond_block(c_vj, length, (X[0][j] + u[0][j]) - yi0, (X[1][j] + u[1][j]) - yi1, (X[2][j] + u[2][j]) - yi2, b);
      // δf_i = B (δu_j − δu_i)
      const double d0 = x[0][j] - x[0][i], d1 = x[1][j] - x[1][i], d2 = x[2][j] - x[2][i];
      s0 += b[0] * d0 + b[1] * d1 + b[2] * d2;
      s1 += b[3] * d0 + b[4] * d1 + b[5] * d2;
      s2 += b[6] * d0 + b[7] * d1 + b[8] * d2;
    }
    y[0][i] += s0;
    y[1][i] += s1;
    y[2][i] += s2;
  }
}

}  // namespace

void PmbModel::add_jacobian_product(const Model& m, const Vec3Array& u, const Vec3Array& x, Vec3Array& y) const {
  add_jacobian_rows(m, u, x, y, RowSubset{});
}

void PmbModel::add_jacobian_product_overlapped(const Model& m, const Vec3Array& u, const Vec3Array& x, Vec3Array& y,
                                               const GhostsInFlight& x_ghosts) const {
  sweep_overlapped(x_ghosts, [&](RowSubset rows) { add_jacobian_rows(m, u, x, y, rows); });
}

bool PmbModel::bond_tangent_row(const Model& m, const Vec3Array& u, std::size_t i, double* blocks,
                                bool definite) const {
  const auto nb = static_cast<std::size_t>(m.material.blocks);
  const std::size_t bi = static_cast<std::size_t>(m.block_index[i]);
  const auto& X = m.nodes.x;
  const double yi0 = X[0][i] + u[0][i], yi1 = X[1][i] + u[1][i], yi2 = X[2][i] + u[2][i];
  for (std::int64_t k = m.bonds.offsets[i]; k < m.bonds.offsets[i + 1]; ++k) {
    const auto ku = static_cast<std::size_t>(k);
    double* b = blocks + 9 * (k - m.bonds.offsets[i]);
    if (m.bonds.broken[ku]) {
      for (int q = 0; q < 9; ++q) b[q] = 0.0;
      continue;
    }
    const auto j = static_cast<std::size_t>(m.bonds.neighbour[ku]);
    const double length = bond_length(X, i, j);
    const double c_vj = m.material.micromodulus_pair[bi * nb + static_cast<std::size_t>(m.block_index[j])] *
                        m.nodes.volume[j] * m.bonds.volume_weight(length) * m.bonds.factor(ku);
    bond_block(c_vj, length, (X[0][j] + u[0][j]) - yi0, (X[1][j] + u[1][j]) - yi1, (X[2][j] + u[2][j]) - yi2, b,
               definite);
  }
  return true;
}

// The registry entry (materials/bond_model.hpp): the parameters PMB reads from a block.
void register_material_pmb(MaterialRegistry& registry) {
  MaterialDefinition d;
  d.doc = "prototype microelastic brittle, bond-based (Silling & Askari 2005); fixes Poisson's ratio "
          "(1/4 in 3D and plane strain, 1/3 in plane stress)";
  // E and G0 (c and s0 from the F1 formulas), or c and s0 directly as a LAMMPS pair_coeff gives
  // them; pmb_check rejects a mix.
  MaterialParameter alpha{"critical_stretch_alpha", "", "α of s0_i = s0 − α·min_j s_ij (LAMMPS); null: 0", false};
  alpha.lower_inclusive = true;
  d.parameters = {
      {"youngs_modulus", "Pa", "Young's modulus E; or give micromodulus", false},
      {"fracture_energy", "J/m²", "null: unbreakable", false},
      {"micromodulus", "N/m⁶", "c directly, instead of youngs_modulus", false},
      {"critical_stretch", "", "s0 directly, with micromodulus; null: unbreakable", false},
      alpha,
  };
  d.constants = &pmb_constants;
  d.check = &pmb_check;
  d.make = [](const Model&) -> std::shared_ptr<const BondModel> { return std::make_shared<PmbModel>(); };
  registry.add("pmb", d);
}

}  // namespace pd
