// The PMB bond-force kernel and the bond-level quantities derived from stretches.
#include "forces/pmb.hpp"

#include <algorithm>
#include <cmath>

namespace pd {

PmbArrays pmb_arrays(const Model& m, const Vec3Array& u) {
  PmbArrays a;
  a.offsets = m.bonds.offsets.data();
  a.neighbour = m.bonds.neighbour.data();
  a.length = m.bonds.length.data();
  a.broken = m.bonds.broken.data();
  a.volume_factor = m.bonds.volume_factor.data();
  for (int d = 0; d < 3; ++d) {
    a.x[d] = m.nodes.x[static_cast<std::size_t>(d)].data();
    a.u[d] = u[static_cast<std::size_t>(d)].data();
  }
  a.volume = m.nodes.volume.data();
  a.block = m.block_index.data();
  a.c_pair = m.material.micromodulus_pair.data();
  a.blocks = m.material.blocks;
  a.nodes = static_cast<std::int64_t>(m.nodes.size());
  return a;
}

namespace {

// Stretch of bond k from node i: thesis eq. 1.9, zeroed near machine precision (thesis §2.2).
// Also returns the current bond vector y_j − y_i and its length.
inline double bond_stretch(const PmbArrays& a, std::int64_t i, std::int64_t k, double& e0, double& e1,
                           double& e2, double& y) {
  const std::int64_t j = a.neighbour[k];
  e0 = (a.x[0][j] + a.u[0][j]) - (a.x[0][i] + a.u[0][i]);
  e1 = (a.x[1][j] + a.u[1][j]) - (a.x[1][i] + a.u[1][i]);
  e2 = (a.x[2][j] + a.u[2][j]) - (a.x[2][i] + a.u[2][i]);
  y = std::sqrt(e0 * e0 + e1 * e1 + e2 * e2);
  const double s = (y - a.length[k]) / a.length[k];
  return std::fabs(s) > kStretchZero ? s : 0.0;
}

}  // namespace

void add_pmb_force_density(const PmbArrays& a, double* f0, double* f1, double* f2, double* w) {
#pragma omp parallel for schedule(static)
  for (std::int64_t i = 0; i < a.nodes; ++i) {
    const double* c_row = a.c_pair + a.block[i] * a.blocks;
    double s0 = 0.0, s1 = 0.0, s2 = 0.0, energy = 0.0;
    for (std::int64_t k = a.offsets[i]; k < a.offsets[i + 1]; ++k) {
      double e0, e1, e2, y;
      const double s = bond_stretch(a, i, k, e0, e1, e2, y);
      const std::int64_t j = a.neighbour[k];
      // Broken bonds are multiplied by 0 rather than skipped: no branch, so the loop vectorises.
      // y > 0 always for an intact bond that has not been crushed to a point; a crushed bond
      // (y = 0) would give 0/0, so it is guarded by the same select.
      const double intact = a.broken[k] ? 0.0 : 1.0;
      const double c_vj = intact * c_row[a.block[j]] * a.volume[j] * a.volume_factor[k];
      const double scale = (y > 0.0) ? c_vj * s / y : 0.0;
      energy += 0.25 * c_vj * s * s * a.length[k];
      s0 += scale * e0;
      s1 += scale * e1;
      s2 += scale * e2;
    }
    f0[i] += s0;
    f1[i] += s1;
    f2[i] += s2;
    if (w) w[i] = energy;
  }
}

void PmbBondForce::AddMult(const Vec3Array& u, Vec3Array& f, double* energy_density) const {
  add_pmb_force_density(pmb_arrays(model_, u), f[0].data(), f[1].data(), f[2].data(), energy_density);
}

std::int64_t update_broken_bonds(Model& m, const Vec3Array& u) {
  // Nothing can break when every block pair is unbreakable: skip the pass over the bonds.
  if (std::all_of(m.material.critical_pair.begin(), m.material.critical_pair.end(),
                  [](double s0) { return std::isinf(s0); }))
    return 0;
  const PmbArrays a = pmb_arrays(m, u);
  std::uint8_t* broken = m.bonds.broken.data();
  const double* s0_pair = m.material.critical_pair.data();
  const std::uint8_t* no_fail = m.no_fail.data();
  std::int64_t newly = 0;  // integer sum: exact, so the reduction order does not matter
#pragma omp parallel for schedule(static) reduction(+ : newly)
  for (std::int64_t i = 0; i < a.nodes; ++i) {
    if (no_fail[i]) continue;
    const double* s0_row = s0_pair + a.block[i] * a.blocks;
    for (std::int64_t k = a.offsets[i]; k < a.offsets[i + 1]; ++k) {
      if (broken[k]) continue;
      const std::int64_t j = a.neighbour[k];
      if (no_fail[j]) continue;
      double e0, e1, e2, y;
      const double s = bond_stretch(a, i, k, e0, e1, e2, y);
      if (s > s0_row[a.block[j]]) {
        broken[k] = 1;
        if (i < j) ++newly;
      }
    }
  }
  return newly;
}

std::vector<double> strain_energy_density(const Model& m, const Vec3Array& u) {
  const PmbArrays a = pmb_arrays(m, u);
  std::vector<double> w(static_cast<std::size_t>(a.nodes), 0.0);
#pragma omp parallel for schedule(static)
  for (std::int64_t i = 0; i < a.nodes; ++i) {
    const double* c_row = a.c_pair + a.block[i] * a.blocks;
    double sum = 0.0;
    for (std::int64_t k = a.offsets[i]; k < a.offsets[i + 1]; ++k) {
      if (a.broken[k]) continue;
      double e0, e1, e2, y;
      const double s = bond_stretch(a, i, k, e0, e1, e2, y);
      const std::int64_t j = a.neighbour[k];
      // ¼ c s² |ξ| V_j: each bond is visited from both ends, so each end takes half of the
      // bond's ½ c s² |ξ| V_i V_j (validation.md C4).
      sum += 0.25 * c_row[a.block[j]] * s * s * a.length[k] * a.volume[j] * a.volume_factor[k];
    }
    w[static_cast<std::size_t>(i)] = sum;
  }
  return w;
}

double strain_energy(const Model& m, const Vec3Array& u) {
  const std::vector<double> w = strain_energy_density(m, u);
  double total = 0.0;
  for (std::size_t i = 0; i < w.size(); ++i) total += w[i] * m.nodes.volume[i];
  return total;
}

std::vector<double> damage(const Model& m) {
  const auto n = static_cast<std::int64_t>(m.nodes.size());
  std::vector<double> out(static_cast<std::size_t>(n), 0.0);
#pragma omp parallel for schedule(static)
  for (std::int64_t i = 0; i < n; ++i) {
    double all = 0.0, intact = 0.0;
    for (std::int64_t k = m.bonds.offsets[static_cast<std::size_t>(i)]; k < m.bonds.offsets[static_cast<std::size_t>(i) + 1]; ++k) {
      const double vj = m.nodes.volume[static_cast<std::size_t>(m.bonds.neighbour[static_cast<std::size_t>(k)])];
      all += vj;
      if (!m.bonds.broken[static_cast<std::size_t>(k)]) intact += vj;
    }
    out[static_cast<std::size_t>(i)] = all > 0.0 ? 1.0 - intact / all : 0.0;
  }
  return out;
}

std::int64_t broken_bond_count(const Model& m) {
  std::int64_t count = 0;
  for (std::uint8_t b : m.bonds.broken) count += b;
  return count / 2;
}

}  // namespace pd
