// The energy surface correction of Le & Bobaru 2018 (core/surface_correction.hpp).
#include "core/surface_correction.hpp"

#include <cmath>

#include "core/model.hpp"
#include "materials/bond_model.hpp"
#include "parallel/decomposed.hpp"

namespace pd {

const Registry<bool>& surface_correction_registry() {
  static const Registry<bool> registry = [] {
    Registry<bool> r("surface_correction method");
    r.add("none", false);
    r.add("energy", true);
    r.add("volume", true);
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

StrainTensor surface_probe_strain(const Model& m, std::size_t i, int d) {
  const int dims = m.nodes.dimension == 2 ? 2 : 3;
  StrainTensor axial{}, lateral{}, both{};
  axial[static_cast<std::size_t>(4 * d)] = 1.0;
  for (int e = 0; e < dims; ++e)
    if (e != d) lateral[static_cast<std::size_t>(4 * e)] = 1.0;
  for (std::size_t q = 0; q < 9; ++q) both[q] = axial[q] + lateral[q];
  const BondModel& law = *m.bond_model;
  const double w_axial = law.continuum_energy_density(m, i, axial), w_lateral = law.continuum_energy_density(m, i, lateral);
  // B = W(1,1) − W(1,0) − W(0,1), C = 2 W(0,1): the lateral stress B a + C b vanishes at b = −(B/C) a.
  const double ratio = (law.continuum_energy_density(m, i, both) - w_axial - w_lateral) / (2.0 * w_lateral);
  StrainTensor probe = axial;
  for (std::size_t q = 0; q < 9; ++q) probe[q] -= ratio * lateral[q];
  return probe;
}

// Each row writes only its own bonds.
std::vector<double> bond_factors(const Model& m, const std::vector<double>& f) {
  const auto& x = m.nodes.x;
  std::vector<double> g(m.bonds.directed(), 1.0);
  const auto n = static_cast<std::int64_t>(m.nodes.size());
#pragma omp parallel for schedule(static)
  for (std::int64_t i64 = 0; i64 < n; ++i64) {
    const auto i = static_cast<std::size_t>(i64);
    for (std::int64_t k = m.bonds.offsets[i]; k < m.bonds.offsets[i + 1]; ++k) {
      const auto ku = static_cast<std::size_t>(k);
      const auto j = static_cast<std::size_t>(m.bonds.neighbour[ku]);
      const double len = bond_length(x, i, j);
      g[ku] = bond_surface_factor(&f[3 * i], &f[3 * j], (x[0][j] - x[0][i]) / len, (x[1][j] - x[1][i]) / len,
                                  (x[2][j] - x[2][i]) / len);
    }
  }
  return g;
}

namespace {

// The law again with the bonds' current factors (LPS precomputes m_i and its moduli from them).
void remake_law(Model& m) { m.bond_model = material_registry().get(m.bond_model->name()).make(m); }

// The ghosts' entries of per-node factors, `width` per node (row-major), from their owners.
void fill_ghosts(const Decomposed* d, std::vector<double>& per_node, std::size_t width) {
  if (!d) return;
  const std::size_t n = per_node.size() / width;
  std::vector<std::vector<double>> column(width, std::vector<double>(n));
  NodeColumns columns;
  for (std::size_t c = 0; c < width; ++c) {
    for (std::size_t i = 0; i < n; ++i) column[c][i] = per_node[width * i + c];
    columns.add(column[c]);
  }
  d->update_ghosts(columns);
  for (std::size_t c = 0; c < width; ++c)
    for (std::size_t i = 0; i < n; ++i) per_node[width * i + c] = column[c][i];
}

}  // namespace

std::vector<double> surface_direction_factors(Model& m, int passes, const Decomposed* dec) {
  const std::size_t n = m.nodes.size();
  const int dims = m.nodes.dimension == 2 ? 2 : 3;
  std::vector<double> factors(3 * n, 1.0);
  std::vector<double> saved = std::move(m.bonds.surface_factor), saved_moduli = std::move(m.bonds.surface_moduli);
  const std::shared_ptr<const BondModel> saved_law = m.bond_model;
  m.bonds.surface_factor.clear();
  m.bonds.surface_moduli.clear();
  if (!saved.empty()) remake_law(m);
  // Each node's probe (its block's lateral ratio), and the continuum energy of it; a cloud has few
  // distinct probes (one per material), each one affine field over all nodes.
  std::vector<StrainTensor> probe(3 * n);
  std::vector<double> continuum(3 * n, 0.0);
  for (std::size_t i = 0; i < n; ++i)
    for (int d = 0; d < dims; ++d) {
      const std::size_t q = 3 * i + static_cast<std::size_t>(d);
      probe[q] = surface_probe_strain(m, i, d);
      StrainTensor scaled = probe[q];
      for (double& v : scaled) v *= kProbeStrain;
      continuum[q] = m.bond_model->continuum_energy_density(m, i, scaled);
    }
  for (int pass = 0; pass <= passes; ++pass) {
    if (pass > 0) {
      m.bonds.surface_factor = bond_factors(m, factors);
      remake_law(m);
    }
    for (int d = 0; d < dims; ++d) {
      std::vector<double> w(n, 0.0);
      std::vector<char> done(n, 0);
      for (std::size_t first = 0; first < n; ++first) {
        if (done[first]) continue;
        const StrainTensor& strain = probe[3 * first + static_cast<std::size_t>(d)];
        for (const double eps : {kProbeStrain, -kProbeStrain}) {
          Vec3Array u = make_vec3(n);
          for (std::size_t i = 0; i < n; ++i)
            for (std::size_t a = 0; a < 3; ++a) u[a][i] = eps * strain[4 * a] * m.nodes.x[a][i];  // diagonal
          const std::vector<double> wi = m.bond_model->strain_energy_density(m, u);
          for (std::size_t i = first; i < n; ++i)
            if (probe[3 * i + static_cast<std::size_t>(d)] == strain) w[i] += 0.5 * wi[i];
        }
        for (std::size_t i = first; i < n; ++i)
          if (probe[3 * i + static_cast<std::size_t>(d)] == strain) done[i] = 1;
      }
      for (std::size_t i = 0; i < n; ++i)
        if (w[i] > 0.0) factors[3 * i + static_cast<std::size_t>(d)] *= continuum[3 * i + static_cast<std::size_t>(d)] / w[i];
    }
    fill_ghosts(dec, factors, 3);  // a ghost's row is empty here (w = 0): its owner's factors
  }
  m.bonds.surface_factor = std::move(saved);
  m.bonds.surface_moduli = std::move(saved_moduli);
  m.bond_model = saved_law;
  return factors;
}

namespace {

// u = ε·x for a symmetric strain ε (row-major 3×3).
Vec3Array affine_displacement(const Model& m, const StrainTensor& strain, double eps) {
  const std::size_t n = m.nodes.size();
  Vec3Array u = make_vec3(n);
  for (std::size_t i = 0; i < n; ++i)
    for (std::size_t a = 0; a < 3; ++a)
      u[a][i] = eps * (strain[3 * a] * m.nodes.x[0][i] + strain[3 * a + 1] * m.nodes.x[1][i] + strain[3 * a + 2] * m.nodes.x[2][i]);
  return u;
}

// θ_i and W_i (per unit strain²) of the law under u = ±ε·x: θ from the odd part (θ(ε) − θ(−ε))/(2ε),
// W from the even part (W(ε) + W(−ε))/(2ε²), which cancel the finite-strain terms to O(ε²).
void probe_response(const Model& m, const StrainTensor& strain, std::vector<double>& theta, std::vector<double>& w) {
  const std::vector<double> tp = m.bond_model->dilatation(m, affine_displacement(m, strain, kProbeStrain));
  const std::vector<double> tm = m.bond_model->dilatation(m, affine_displacement(m, strain, -kProbeStrain));
  const std::vector<double> wp = m.bond_model->strain_energy_density(m, affine_displacement(m, strain, kProbeStrain));
  const std::vector<double> wm = m.bond_model->strain_energy_density(m, affine_displacement(m, strain, -kProbeStrain));
  theta.resize(tp.size());
  w.resize(wp.size());
  for (std::size_t i = 0; i < tp.size(); ++i) theta[i] = (tp[i] - tm[i]) / (2.0 * kProbeStrain);
  for (std::size_t i = 0; i < wp.size(); ++i) w[i] = (wp[i] + wm[i]) / (2.0 * kProbeStrain * kProbeStrain);
}

// (θ/d) times the identity over the d axes of the analysis: the hydrostatic strain of dilatation θ.
StrainTensor hydrostatic(double theta, int dims) {
  StrainTensor e{};
  for (int a = 0; a < dims; ++a) e[static_cast<std::size_t>(4 * a)] = theta / dims;
  return e;
}

}  // namespace

SplitFactors split_surface_factors(Model& m, int passes, ShearProbes shear_probes) {
  const std::size_t n = m.nodes.size();
  const int dims = m.nodes.dimension == 2 ? 2 : 3;
  SplitFactors out;
  out.direction.assign(3 * n, 1.0);
  out.moduli.assign(2 * n, 1.0);
  std::vector<double> saved = std::move(m.bonds.surface_factor), saved_moduli = std::move(m.bonds.surface_moduli);
  const std::shared_ptr<const BondModel> saved_law = m.bond_model;
  // The law with the bond factors of f and unit moduli factors.
  const auto apply = [&]() {
    m.bonds.surface_factor = bond_factors(m, out.direction);
    m.bonds.surface_moduli.assign(2 * n, 1.0);
    remake_law(m);
  };
  std::vector<double> theta, w;
  // 1. The dilatation: θ of a uniaxial strain along each axis to 1.
  for (int pass = 0; pass < passes; ++pass) {
    apply();
    for (int d = 0; d < dims; ++d) {
      StrainTensor axial{};
      axial[static_cast<std::size_t>(4 * d)] = 1.0;
      probe_response(m, axial, theta, w);
      for (std::size_t i = 0; i < n; ++i)
        if (theta[i] > 0.0) out.direction[3 * i + static_cast<std::size_t>(d)] /= theta[i];
    }
  }
  apply();
  // 2. The moduli from the probes' bulk and deviatoric energies. The probes of `axes` depend on the
  // node's block (its ν); a cloud has few blocks, each one affine field over all nodes.
  std::vector<StrainTensor> probes;
  if (shear_probes == ShearProbes::isotropic) {
    const double r2 = 1.0 / std::sqrt(2.0), r6 = 1.0 / std::sqrt(6.0);
    probes.push_back(StrainTensor{r2, 0, 0, 0, -r2, 0, 0, 0, 0});
    probes.push_back(StrainTensor{0, r2, 0, r2, 0, 0, 0, 0, 0});  // ε_xy = ε_yx = 1/√2: ε:ε = 1
    if (dims == 3) {
      probes.push_back(StrainTensor{r6, 0, 0, 0, r6, 0, 0, 0, -2 * r6});
      probes.push_back(StrainTensor{0, 0, 0, 0, 0, r2, 0, r2, 0});
      probes.push_back(StrainTensor{0, 0, r2, 0, 0, 0, r2, 0, 0});
    }
  }
  std::vector<double> cont_bulk(n, 0.0), cont_dev(n, 0.0), law_bulk(n, 0.0), law_dev(n, 0.0);
  const auto add_probe = [&](const StrainTensor& strain, const std::vector<char>& uses) {
    probe_response(m, strain, theta, w);
    for (std::size_t i = 0; i < n; ++i) {
      if (!uses[i]) continue;
      const double cb = m.bond_model->continuum_energy_density(m, i, hydrostatic(strain_trace(strain, dims), dims));
      const double lb = m.bond_model->continuum_energy_density(m, i, hydrostatic(theta[i], dims));  // ½κθ²
      cont_bulk[i] += cb;
      cont_dev[i] += m.bond_model->continuum_energy_density(m, i, strain) - cb;
      law_bulk[i] += lb;
      law_dev[i] += w[i] - lb;
    }
  };
  if (shear_probes == ShearProbes::isotropic) {
    const std::vector<char> all(n, 1);
    for (const StrainTensor& p : probes) add_probe(p, all);
  } else {
    for (int d = 0; d < dims; ++d) {
      std::vector<char> done(n, 0);
      for (std::size_t first = 0; first < n; ++first) {
        if (done[first]) continue;
        const StrainTensor strain = surface_probe_strain(m, first, d);
        std::vector<char> uses(n, 0);
        for (std::size_t i = first; i < n; ++i)
          if (!done[i] && surface_probe_strain(m, i, d) == strain) uses[i] = done[i] = 1;
        add_probe(strain, uses);
      }
    }
  }
  for (std::size_t i = 0; i < n; ++i) {
    if (law_bulk[i] > 0.0 && cont_bulk[i] > 0.0) out.moduli[2 * i] = cont_bulk[i] / law_bulk[i];
    if (law_dev[i] > 0.0) out.moduli[2 * i + 1] = cont_dev[i] / law_dev[i];
  }
  m.bonds.surface_factor = std::move(saved);
  m.bonds.surface_moduli = std::move(saved_moduli);
  m.bond_model = saved_law;
  return out;
}

double bond_surface_factor(const double* a, const double* b, double n0, double n1, double n2) {
  const double s0 = 0.5 * (a[0] + b[0]), s1 = 0.5 * (a[1] + b[1]), s2 = 0.5 * (a[2] + b[2]);
  return 1.0 / std::sqrt(n0 * n0 / (s0 * s0) + n1 * n1 / (s1 * s1) + n2 * n2 / (s2 * s2));
}

std::vector<double> volume_factors(const Model& m, const Decomposed* d) {
  const std::size_t n = m.nodes.size();
  const auto& x = m.nodes.x;
  std::vector<double> family(n, 0.0);
  for (std::size_t i = 0; i < n; ++i)
    for (std::int64_t k = m.bonds.offsets[i]; k < m.bonds.offsets[i + 1]; ++k) {
      const auto ku = static_cast<std::size_t>(k);
      if (m.bonds.broken[ku]) continue;
      const auto j = static_cast<std::size_t>(m.bonds.neighbour[ku]);
      family[i] += m.nodes.volume[j] * m.bonds.volume_weight(bond_length(x, i, j));
    }
  fill_ghosts(d, family, 1);  // a ghost's row is empty here: its owner's V_i
  constexpr double kPi = 3.14159265358979323846;
  const double bulk = m.nodes.dimension == 2 ? kPi * m.horizon * m.horizon * m.thickness
                                             : 4.0 / 3.0 * kPi * m.horizon * m.horizon * m.horizon;
  std::vector<double> g(m.bonds.directed(), 1.0);
  for (std::size_t i = 0; i < n; ++i)
    for (std::int64_t k = m.bonds.offsets[i]; k < m.bonds.offsets[i + 1]; ++k) {
      const auto j = static_cast<std::size_t>(m.bonds.neighbour[static_cast<std::size_t>(k)]);
      // The same for both copies; 1 when neither end has an intact family left (two nodes cut off
      // by pre-cracks), where 2·bulk/0 would be infinite and eq. 2.5's step zero.
      const double both = family[i] + family[j];
      g[static_cast<std::size_t>(k)] = both > 0.0 ? 2.0 * bulk / both : 1.0;
    }
  return g;
}

void apply_surface_correction(const std::string& method, Model& m, const Decomposed* d) {
  m.bonds.surface_factor.clear();
  if (!surface_correction_registry().get(method)) return;
  if (method == "volume") {
    m.bonds.surface_factor = volume_factors(m, d);
    return;
  }
  m.bonds.surface_factor = bond_factors(m, surface_direction_factors(m, kSurfacePasses, d));
}

}  // namespace pd
