// The short-range contact kernel over the Verlet list (see contact.hpp).
#include "forces/contact.hpp"

#include <algorithm>
#include <cmath>
#include <vector>

namespace pd {

void add_contact_force_density(const ContactArrays& a, double* f0, double* f1, double* f2, double* e) {
#pragma omp parallel for schedule(static)
  for (std::int64_t i = 0; i < a.nodes; ++i) {
    const double* c_row = a.c_pair + a.block[i] * a.blocks;
    const double yi0 = a.x[0][i] + a.u[0][i], yi1 = a.x[1][i] + a.u[1][i], yi2 = a.x[2][i] + a.u[2][i];
    double s0 = 0.0, s1 = 0.0, s2 = 0.0, energy = 0.0;
    for (std::int64_t k = a.offsets[i]; k < a.offsets[i + 1]; ++k) {
      const std::int64_t j = a.neighbour[k];
      // y_j − y_i: the exact negative of what j computes for i, so r is bitwise symmetric.
      const double e0 = (a.x[0][j] + a.u[0][j]) - yi0;
      const double e1 = (a.x[1][j] + a.u[1][j]) - yi1;
      const double e2 = (a.x[2][j] + a.u[2][j]) - yi2;
      const double r = std::sqrt(e0 * e0 + e1 * e1 + e2 * e2);
      // Repulsive only (the min{0, ·} of eq. 1.13): the gap d_ij − r counts only where positive.
      // Selects rather than branches, so the loop vectorises like the bond kernel; two nodes at
      // one point have no direction and get no force.
      const double gap = std::max(a.distance[k] - r, 0.0);
      const double k_vj = a.stiffness_over_horizon * c_row[a.block[j]] * a.volume[j];
      const double scale = r > 0.0 ? k_vj * gap / r : 0.0;
      s0 -= scale * e0;
      s1 -= scale * e1;
      s2 -= scale * e2;
      energy += 0.25 * k_vj * gap * gap;
    }
    f0[i] += s0;
    f1[i] += s1;
    f2[i] += s2;
    if (e) e[i] = energy;
  }
}

double ShortRangeForce::AddMult(const Vec3Array& u, Vec3Array& f) const {
  model_.contact_list.update(model_.nodes.x, u, model_.block_index, model_.contact);
  return AddMult(model_.contact_list.pairs(), u, f);
}

double ShortRangeForce::AddMult(const ContactPairs& pairs, const Vec3Array& u, Vec3Array& f) const {
  const Model& m = model_;
  ContactArrays a;
  a.offsets = pairs.offsets.data();
  a.neighbour = pairs.neighbour.data();
  a.distance = pairs.distance.data();
  for (std::size_t d = 0; d < 3; ++d) {
    a.x[d] = m.nodes.x[d].data();
    a.u[d] = u[d].data();
  }
  a.volume = m.nodes.volume.data();
  a.block = m.block_index.data();
  a.c_pair = m.material.micromodulus_pair.data();
  a.blocks = m.material.blocks;
  a.nodes = static_cast<std::int64_t>(m.nodes.size());
  a.stiffness_over_horizon = m.contact.stiffness_factor / m.horizon;
  std::vector<double> e(m.nodes.size());
  add_contact_force_density(a, f[0].data(), f[1].data(), f[2].data(), e.data());
  double total = 0.0;
  for (std::size_t i = 0; i < e.size(); ++i) total += e[i] * m.nodes.volume[i];
  return total;
}

}  // namespace pd
