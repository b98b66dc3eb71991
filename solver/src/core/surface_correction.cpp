// The energy surface correction of Le & Bobaru 2018 (core/surface_correction.hpp).
#include "core/surface_correction.hpp"

#include <cmath>

#include "core/model.hpp"

namespace pd {

const Registry<bool>& surface_correction_registry() {
  static const Registry<bool> registry = [] {
    Registry<bool> r("surface_correction method");
    r.add("none", false);
    r.add("energy", true);
    return r;
  }();
  return registry;
}

namespace {

// The extension of the probe: small enough that the mean of ±ε leaves O(ε²) = 1e-10 of the
// energy's finite-strain terms, large enough that round-off in y − |ξ| (≈ 1e-16 |ξ|) stays 1e-11
// of the extension.
constexpr double kProbeStrain = 1e-5;

}  // namespace

std::vector<double> surface_direction_factors(const Model& m) {
  const std::size_t n = m.nodes.size();
  const int dims = m.nodes.dimension == 2 ? 2 : 3;
  std::vector<double> factors(3 * n, 1.0);
  for (int d = 0; d < dims; ++d) {
    std::vector<double> w(n, 0.0);
    for (const double eps : {kProbeStrain, -kProbeStrain}) {
      Vec3Array u = make_vec3(n);
      for (std::size_t i = 0; i < n; ++i) u[static_cast<std::size_t>(d)][i] = eps * m.nodes.x[static_cast<std::size_t>(d)][i];
      const std::vector<double> wi = m.bond_model->strain_energy_density(m, u);
      for (std::size_t i = 0; i < n; ++i) w[i] += 0.5 * wi[i];
    }
    for (std::size_t i = 0; i < n; ++i)
      if (w[i] > 0.0) factors[3 * i + static_cast<std::size_t>(d)] = m.bond_model->uniaxial_energy_density(m, i, kProbeStrain) / w[i];
  }
  return factors;
}

double bond_surface_factor(const double* a, const double* b, double n0, double n1, double n2) {
  const double s0 = 0.5 * (a[0] + b[0]), s1 = 0.5 * (a[1] + b[1]), s2 = 0.5 * (a[2] + b[2]);
  return 1.0 / std::sqrt(n0 * n0 / (s0 * s0) + n1 * n1 / (s1 * s1) + n2 * n2 / (s2 * s2));
}

void apply_surface_correction(const std::string& method, Model& m) {
  m.bonds.surface_factor.clear();
  if (!surface_correction_registry().get(method)) return;
  const std::vector<double> f = surface_direction_factors(m);
  const auto& x = m.nodes.x;
  std::vector<double> g(m.bonds.directed(), 1.0);
  const auto n = static_cast<std::int64_t>(m.nodes.size());
#pragma omp parallel for schedule(static)
  for (std::int64_t i64 = 0; i64 < n; ++i64) {  // each row writes only its own bonds
    const auto i = static_cast<std::size_t>(i64);
    for (std::int64_t k = m.bonds.offsets[i]; k < m.bonds.offsets[i + 1]; ++k) {
      const auto ku = static_cast<std::size_t>(k);
      const auto j = static_cast<std::size_t>(m.bonds.neighbour[ku]);
      const double len = bond_length(x, i, j);
      g[ku] = bond_surface_factor(&f[3 * i], &f[3 * j], (x[0][j] - x[0][i]) / len, (x[1][j] - x[1][i]) / len,
                                  (x[2][j] - x[2][i]) / len);
    }
  }
  m.bonds.surface_factor = std::move(g);
}

}  // namespace pd
