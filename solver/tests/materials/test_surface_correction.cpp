// The energy surface correction (core/surface_correction; Le & Bobaru 2018) with PMB and LPS: its
// factors (the continuum's over the lattice's energy on a bulk node, the ellipsoid combination, one
// g per bond for both copies), the apparent stiffness of a thin bar and a plate in tension (within
// 2 % of E with it; the error without it printed and asserted larger), the force as the gradient of
// the corrected energy, J·x against a difference of the force, bitwise results for 1 and 2 threads,
// and the static tension of docs/theory.md C3 for LPS (interior strains against σ/E and −νσ/E).
#include <gtest/gtest.h>
#include <omp.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>

#include "core/stability.hpp"
#include "core/surface_correction.hpp"
#include "lattice.hpp"
#include "lps_lattice.hpp"
#include "materials/bond_model.hpp"
#include "static_tension.hpp"

namespace {

constexpr double kDx = 1e-3;
constexpr double kE = 1e9;
constexpr double kPi = 3.14159265358979323846;

struct Config {
  std::string model = "pmb";
  std::string analysis = "3d";
  double nu = 0.3;                       // LPS only
  std::string correction = "none";
  std::string partial_volume = "none";
  double horizon_factor = 3.015;
};

pd::Case case_of(const Config& s) {
  const int dim = s.analysis == "3d" ? 3 : 2;
  pd::Case c = pdtest::lattice_case(dim, s.analysis, kDx, s.horizon_factor * kDx, kE, 1000.0, -1.0, 1e-3);
  c.blocks[0].model = s.model;
  if (s.model == "lps") {
    c.blocks[0].parameters["poisson_ratio"] = s.nu;
    c.blocks[0].choices["influence"] = "one";
  }
  c.surface_correction = s.correction;
  c.partial_volume = s.partial_volume;
  return c;
}

pd::Model build(const Config& s, int nx, int ny, int nz) {
  const int dim = s.analysis == "3d" ? 3 : 2;
  return pd::build_model(case_of(s), pdtest::cubic_lattice(nx, ny, dim == 3 ? nz : 1, kDx, dim, 1e-3));
}

// Poisson's ratio the model has: PMB fixes it (1/4 in 3D and plane strain, 1/3 in plane stress).
double poisson(const Config& s) {
  if (s.model == "lps") return s.nu;
  return s.analysis == "plane_stress" ? 1.0 / 3.0 : 0.25;
}

// σ/ε of a uniaxial stress along x: E, or the plane-strain modulus E/(1 − ν²).
double axial_modulus(const Config& s) {
  const double nu = poisson(s);
  return s.analysis == "plane_strain" ? kE / (1.0 - nu * nu) : kE;
}
// −ε_yy/ε_xx in uniaxial stress: ν, or ν/(1 − ν) in plane strain.
double lateral_ratio(const Config& s) {
  const double nu = poisson(s);
  return s.analysis == "plane_strain" ? nu / (1.0 - nu) : nu;
}

}  // namespace

// A measurement table (not a test): PD_SURFACE_MEASURE=1 prints the static tension of every
// configuration of docs/theory.md C3 with and without the correction and partial volumes.
TEST(SurfaceCorrection, MeasureStaticTension) {
  if (!std::getenv("PD_SURFACE_MEASURE")) GTEST_SKIP() << "set PD_SURFACE_MEASURE=1 to print the table";
  const double sigma = 1e6;
  struct Row {
    const char* model;
    const char* analysis;
    double nu;
  };
  const Row rows[] = {{"pmb", "3d", 0.25},          {"pmb", "plane_stress", 0.0}, {"lps", "3d", 0.2},
                      {"lps", "3d", 0.3},           {"lps", "3d", 0.45},          {"lps", "plane_strain", 0.2},
                      {"lps", "plane_strain", 0.3}, {"lps", "plane_strain", 0.45}, {"lps", "plane_stress", 0.3}};
  const char* only = std::getenv("PD_SURFACE_ONLY");
  for (const Row& row : rows)
    for (const char* pv : {"none", "hhb"})
      for (const char* corr : {"none", "energy"}) {
        Config s{row.model, row.analysis, row.nu, corr, pv};
        if (only && std::string(only) != std::string(row.model) + "-" + row.analysis) continue;
        const bool plane = s.analysis != "3d";
        const int nx = 36, ny = plane ? 21 : 15, nz = plane ? 1 : 15;
        const pd::Model m = build(s, nx, ny, nz);
        const pdtest::Tension t = pdtest::static_tension(m, nx, ny, nz, kDx, sigma, plane ? 7 : 6);
        const double e = axial_modulus(s), r = lateral_ratio(s);
        std::printf("[ measure  ] %s %-12s nu=%.2f pv=%-4s corr=%-6s cg=%5d%s  interior: exx E/s=%.4f  -eyy/exx=%.4f "
                    "(target %.4f, err %+.2f%%)  section: exx E/s=%.4f -eyy/exx=%.4f\n",
                    row.model, row.analysis, poisson(s), pv, corr, t.iterations, t.converged ? "" : "!",
                    t.interior_xx * e / sigma, -t.interior_yy / t.interior_xx, r,
                    100.0 * (-t.interior_yy / t.interior_xx / r - 1.0), t.section_xx * e / sigma,
                    -t.section_yy / t.section_xx);
        std::fflush(stdout);
      }
}

namespace {

// The energy of the probe along x (uniaxial stress: ε along x, −νε laterally) on a bulk node of the
// cubic (3D) or square (2D) lattice, from the stencil (independent of the solver's bond list and
// of its probe): PMB Σ ¼ c (n·ε·n)² |ξ| V_j with the linearised stretch n·ε·n.
double pmb_bulk_energy(const pd::Model& m, double eps, double nu) {
  const double c = m.material.micromodulus_pair[0];
  const int r = 4, dim = m.nodes.dimension;
  double w = 0.0;
  for (int p = -r; p <= r; ++p)
    for (int q = -r; q <= r; ++q)
      for (int s = (dim == 3 ? -r : 0); s <= (dim == 3 ? r : 0); ++s) {
        const double l = std::sqrt(double(p * p + q * q + s * s)) * kDx;
        if (l == 0.0 || l > m.horizon * (1 + 1e-12)) continue;
        const double stretch = eps * (double(p * p) - nu * double(q * q + s * s)) * kDx * kDx / (l * l);
        w += 0.25 * c * stretch * stretch * l * m.nodes.volume[0];
      }
  return w;
}

}  // namespace

TEST(SurfaceCorrection, ProbeIsTheUniaxialStressOfTheMaterial) {
  // The lateral ratio found from the continuum energy: ν for PMB (1/4 in 3D, 1/3 in plane stress)
  // and LPS 3D and plane stress, ν/(1 − ν) in plane strain (ε_zz = 0); the probe's continuum
  // energy is then ½ E' ε² (E' = E, or E/(1 − ν²) in plane strain).
  struct Row {
    Config s;
    double ratio, modulus;
  };
  const Row rows[] = {{{"pmb", "3d"}, 0.25, kE},
                      {{"pmb", "plane_stress"}, 1.0 / 3.0, kE},
                      {{"pmb", "plane_strain"}, 1.0 / 3.0, kE / (1.0 - 0.0625)},
                      {{"lps", "3d", 0.3}, 0.3, kE},
                      {{"lps", "plane_stress", 0.45}, 0.45, kE},
                      {{"lps", "plane_strain", 0.2}, 0.25, kE / 0.96}};
  for (const Row& row : rows) {
    const pd::Model m = build(row.s, 5, 5, 5);
    const int dims = m.nodes.dimension;
    for (int d = 0; d < dims; ++d) {
      const pd::StrainTensor p = pd::surface_probe_strain(m, 0, d);
      for (int a = 0; a < 3; ++a)
        for (int b = 0; b < 3; ++b) {
          const double expected = a != b || a >= dims ? 0.0 : (a == d ? 1.0 : -row.ratio);
          EXPECT_NEAR(p[static_cast<std::size_t>(3 * a + b)], expected, 1e-14) << row.s.model << " " << row.s.analysis;
        }
      EXPECT_NEAR(m.bond_model->continuum_energy_density(m, 0, p), 0.5 * row.modulus, 1e-12 * kE)
          << row.s.model << " " << row.s.analysis;
    }
  }
}

TEST(SurfaceCorrection, BulkFactorIsTheContinuumOverTheLatticeEnergy) {
  // Le & Bobaru's factor compares with the continuum, so on a bulk node the first pass gives
  // W_cont/W_lattice of the probe, not 1: the correction takes out the bulk's quadrature error as
  // well as the surface's. Every bulk node has the same factors.
  for (const char* analysis : {"3d", "plane_stress"}) {
    const Config s{"pmb", analysis};
    const int n = 13;
    pd::Model m = build(s, n, n, n);
    const bool plane = m.nodes.dimension == 2;
    const double nu = plane ? 1.0 / 3.0 : 0.25, eps = 1e-5;
    const std::vector<double> f = pd::surface_direction_factors(m, 0);
    EXPECT_FALSE(m.bonds.corrected());  // left as it was
    const double expected = 0.5 * kE * eps * eps / pmb_bulk_energy(m, eps, nu);
    const std::size_t centre = pdtest::node_index(6, 6, plane ? 0 : 6, n, n);
    for (int d = 0; d < (plane ? 2 : 3); ++d) EXPECT_NEAR(f[3 * centre + d], expected, 1e-9) << analysis << " d=" << d;
    if (plane) EXPECT_EQ(f[3 * centre + 2], 1.0);
    std::printf("[ surface  ] PMB %s bulk factor of the probe (continuum/lattice, m = 3, full volumes) = %.6f\n",
                analysis, expected);
    // A corner node's family is an eighth (a quarter) of the whole: its factors are far above.
    EXPECT_GT(f[0], 1.5 * expected) << analysis;
  }
}

TEST(SurfaceCorrection, PassesBringEveryNodesCorrectedProbeEnergyToTheContinuum) {
  // With the factors applied, each node's probe energy against the continuum's: after one pass the
  // neighbours' factors (the mean of the two ends) leave per cents near the surfaces; the
  // refinement passes shrink that on the whole (the mean of |W_i(g)/W_cont − 1| over nodes and
  // axes), though not at every corner node (the largest, printed too).
  for (const Config& s : {Config{"pmb", "3d", 0.25, "energy"}, Config{"lps", "plane_stress", 0.3, "energy"}}) {
    pd::Model m = build(s, 10, 8, 7);
    const std::size_t n = m.nodes.size();
    const int dims = m.nodes.dimension;
    double worst[2] = {0.0, 0.0}, mean[2] = {0.0, 0.0};
    for (int k = 0; k < 2; ++k) {
      const int passes = k == 0 ? 0 : pd::kSurfacePasses;
      m.bonds.surface_factor.clear();
      const std::vector<double> f = pd::surface_direction_factors(m, passes);
      // g from f as apply_surface_correction sets it, then the law again with them.
      pd::Model c = build(s, 10, 8, 7);
      for (std::size_t i = 0; i < n; ++i)
        for (std::int64_t q = c.bonds.offsets[i]; q < c.bonds.offsets[i + 1]; ++q) {
          const auto j = static_cast<std::size_t>(c.bonds.neighbour[static_cast<std::size_t>(q)]);
          const double l = std::sqrt(std::pow(c.nodes.x[0][j] - c.nodes.x[0][i], 2) + std::pow(c.nodes.x[1][j] - c.nodes.x[1][i], 2) +
                                     std::pow(c.nodes.x[2][j] - c.nodes.x[2][i], 2));
          c.bonds.surface_factor[static_cast<std::size_t>(q)] = pd::bond_surface_factor(
              &f[3 * i], &f[3 * j], (c.nodes.x[0][j] - c.nodes.x[0][i]) / l, (c.nodes.x[1][j] - c.nodes.x[1][i]) / l,
              (c.nodes.x[2][j] - c.nodes.x[2][i]) / l);
        }
      c.bond_model = pd::material_registry().get(s.model).make(c);
      for (int d = 0; d < dims; ++d) {
        const pd::StrainTensor p = pd::surface_probe_strain(c, 0, d);
        const double eps = 1e-5;
        pd::Vec3Array u = pd::make_vec3(n);
        for (std::size_t i = 0; i < n; ++i)
          for (std::size_t a = 0; a < 3; ++a) u[a][i] = eps * p[4 * a] * c.nodes.x[a][i];
        const std::vector<double> w = c.bond_model->strain_energy_density(c, u);
        pd::StrainTensor scaled = p;
        for (double& v : scaled) v *= eps;
        for (std::size_t i = 0; i < n; ++i) {
          const double e = std::fabs(w[i] / c.bond_model->continuum_energy_density(c, i, scaled) - 1.0);
          worst[k] = std::max(worst[k], e);
          mean[k] += e / static_cast<double>(n * static_cast<std::size_t>(dims));
        }
      }
    }
    std::printf("[ surface  ] %s %s: |W_i(g)/W_cont - 1| over the nodes and axes: mean %.4f, largest %.4f after one "
                "pass; mean %.4f, largest %.4f after %d more\n", s.model.c_str(), s.analysis.c_str(), mean[0], worst[0],
                mean[1], worst[1], pd::kSurfacePasses);
    // Measured: mean 0.1851 → 0.1056 (PMB 3D), 0.0726 → 0.0378 (LPS plane stress); largest 0.41 →
    // 0.51 and 0.16 → 0.10 (a corner's three factors cannot fit all its bonds' shares).
    EXPECT_LT(mean[1], 0.75 * mean[0]) << s.model;
  }
}

TEST(SurfaceCorrection, EllipsoidCombinationOfTheEndsFactors) {
  // s = mean of the ends' factors per axis; along an axis g is that axis's s, and between, the
  // ellipsoid [Σ n_d²/s_d²]^(−½) (Madenci & Oterkus 2014; Le & Bobaru 2018).
  const double a[3] = {1.0, 2.0, 4.0}, b[3] = {3.0, 2.0, 2.0};
  EXPECT_DOUBLE_EQ(pd::bond_surface_factor(a, b, 1, 0, 0), 2.0);
  EXPECT_DOUBLE_EQ(pd::bond_surface_factor(a, b, 0, -1, 0), 2.0);
  EXPECT_DOUBLE_EQ(pd::bond_surface_factor(a, b, 0, 0, 1), 3.0);
  const double h = std::sqrt(0.5);
  EXPECT_NEAR(pd::bond_surface_factor(a, b, h, 0, h), 1.0 / std::sqrt(0.5 / 4.0 + 0.5 / 9.0), 1e-15);
  EXPECT_EQ(pd::bond_surface_factor(a, b, h, 0, h), pd::bond_surface_factor(b, a, -h, 0, -h));
}

TEST(SurfaceCorrection, NoneLeavesNoFactorsAndUnknownMethodsAreListed) {
  const pd::Model m = build(Config{"lps", "3d"}, 8, 8, 8);
  EXPECT_FALSE(m.bonds.corrected());
  EXPECT_EQ(pd::surface_correction_registry().keys(), (std::vector<std::string>{"energy", "none", "volume"}));
  try {
    pd::surface_correction_registry().get("area");
    FAIL() << "no error";
  } catch (const pd::Error& e) {
    EXPECT_NE(std::string(e.what()).find("unknown surface_correction method 'area'; known: energy, none, volume"),
              std::string::npos);
  }
}

namespace {

double total_energy(const pd::Model& m, const pd::Vec3Array& u) {
  const std::vector<double> w = m.bond_model->strain_energy_density(m, u);
  double s = 0.0;
  for (std::size_t i = 0; i < w.size(); ++i) s += w[i] * m.nodes.volume[i];
  return s;
}

pd::Vec3Array smooth_state(const pd::Model& m) {
  pd::Vec3Array u = pd::make_vec3(m.nodes.size());
  for (std::size_t i = 0; i < m.nodes.size(); ++i) {
    const double x = m.nodes.x[0][i], y = m.nodes.x[1][i];
    u[0][i] = 2e-3 * x + 3e-1 * x * y;
    u[1][i] = -5e-4 * y + 2e-1 * x * x;
    if (m.nodes.dimension == 3) u[2][i] = 1e-3 * m.nodes.x[2][i] * (1.0 + 50.0 * x);
  }
  return u;
}

pd::Vec3Array direction(const pd::Model& m) {
  pd::Vec3Array x = pd::make_vec3(m.nodes.size());
  for (std::size_t i = 0; i < m.nodes.size(); ++i) {
    x[0][i] = 1e-6 * std::sin(1.0 + 3.0 * static_cast<double>(i));
    x[1][i] = 1e-6 * std::cos(2.0 + 5.0 * static_cast<double>(i));
    if (m.nodes.dimension == 3) x[2][i] = 1e-6 * std::sin(0.5 + 7.0 * static_cast<double>(i));
  }
  return x;
}

}  // namespace

TEST(SurfaceCorrection, ForceIsTheGradientOfTheCorrectedEnergyAndJacobianItsDerivative) {
  // With factors, PMB's c → g c per bond and LPS's weights V_j → g V_j (but m_i): both stay one
  // energy whose gradient the kernel computes, and J·x is the derivative of that force.
  for (const Config& s : {Config{"pmb", "3d", 0.25, "energy"}, Config{"lps", "3d", 0.3, "energy"},
                         Config{"lps", "plane_strain", 0.45, "energy"}, Config{"pmb", "plane_stress", 0.0, "energy"}}) {
    const pd::Model m = build(s, 7, 6, 5);
    ASSERT_TRUE(m.bonds.corrected());
    const pd::Vec3Array u = smooth_state(m), x = direction(m);
    pd::Vec3Array f = pd::make_vec3(m.nodes.size());
    m.bond_model->add_force(m, u, f, nullptr);
    double fx = 0.0;  // Σ V_i f_i·x_i = −dU/dh along x
    for (int d = 0; d < 3; ++d)
      for (std::size_t i = 0; i < m.nodes.size(); ++i) fx += m.nodes.volume[i] * f[d][i] * x[d][i];
    const double h = 1e-3;
    pd::Vec3Array up = u, um = u;
    for (int d = 0; d < 3; ++d)
      for (std::size_t i = 0; i < m.nodes.size(); ++i) {
        up[d][i] += h * x[d][i];
        um[d][i] -= h * x[d][i];
      }
    const double du = (total_energy(m, up) - total_energy(m, um)) / (2 * h);
    EXPECT_NEAR(-du, fx, 1e-6 * std::fabs(fx)) << s.model << " " << s.analysis;
    // J·x against the central difference of the force.
    pd::Vec3Array jx = pd::make_vec3(m.nodes.size()), fp = pd::make_vec3(m.nodes.size()), fm = fp;
    m.bond_model->add_jacobian_product(m, u, x, jx);
    m.bond_model->add_force(m, up, fp, nullptr);
    m.bond_model->add_force(m, um, fm, nullptr);
    double err = 0.0, ref = 0.0;
    for (int d = 0; d < 3; ++d)
      for (std::size_t i = 0; i < m.nodes.size(); ++i) {
        const double fd = (fp[d][i] - fm[d][i]) / (2 * h);
        err += (fd - jx[d][i]) * (fd - jx[d][i]);
        ref += fd * fd;
      }
    EXPECT_LT(std::sqrt(err / ref), 1e-6) << s.model << " " << s.analysis;
  }
}

TEST(SurfaceCorrection, FactorsForceAndEnergyAreBitwiseTheSameForOneAndTwoThreads) {
  for (const Config& s : {Config{"pmb", "3d", 0.25, "energy"}, Config{"lps", "3d", 0.3, "energy"}}) {
    const int saved = omp_get_max_threads();
    std::vector<double> g[2], w[2], moduli[2];
    pd::Vec3Array f[2], y[2];
    for (int t = 0; t < 2; ++t) {
      omp_set_num_threads(t + 1);
      const pd::Model m = build(s, 9, 8, 7);
      const pd::Vec3Array u = smooth_state(m);
      g[t] = m.bonds.surface_factor;
      moduli[t] = m.bonds.surface_moduli;
      f[t] = pd::make_vec3(m.nodes.size());
      y[t] = pd::make_vec3(m.nodes.size());
      w[t].assign(m.nodes.size(), 0.0);
      m.bond_model->add_force(m, u, f[t], w[t].data());
      m.bond_model->add_jacobian_product(m, u, direction(m), y[t]);
    }
    omp_set_num_threads(saved);
    EXPECT_EQ(g[0], g[1]) << s.model;
    EXPECT_TRUE(moduli[0].empty() && moduli[1].empty()) << s.model;  // only the split method sets them
    EXPECT_EQ(w[0], w[1]) << s.model;
    for (int d = 0; d < 3; ++d) {
      EXPECT_EQ(f[0][d], f[1][d]) << s.model;
      EXPECT_EQ(y[0][d], y[1][d]) << s.model;
    }
  }
}

TEST(SurfaceCorrection, StableStepStillBoundsTheExactLimit) {
  // Eq. 2.5 with the corrected bond terms (node_stiffness × g; LPS's bound with m'_i/m_i) stays
  // below the exact limit 2/ω_max of the corrected operator (Lanczos on J about the reference).
  for (const Config& s : {Config{"pmb", "3d", 0.25, "energy"}, Config{"lps", "3d", 0.3, "energy"},
                         Config{"lps", "3d", 0.45, "energy"}}) {
    const pd::Model m = build(s, 8, 7, 6);
    const double stable = pd::stable_time_step(m);
    const pd::LanczosReport r = pd::largest_eigenvalue(m, {0.0, 0.0, 0.0});
    ASSERT_TRUE(r.converged);
    const double exact = 2.0 / std::sqrt(r.lambda_max);
    std::printf("[ surface  ] %s ν=%.2f corrected: eq. 2.5 step / exact limit = %.3f\n", s.model.c_str(), poisson(s),
                stable / exact);
    EXPECT_LT(stable, exact) << s.model;
    EXPECT_GT(stable, 0.2 * exact) << s.model;
  }
}

namespace {

// E_apparent/E of a thin lattice bar (3D, 30 × 6 × 6 nodes: every node within δ of a lateral face)
// or a plate (2D, 30 × 10) in static tension: σ over the strain of the whole cross-section.
double apparent_stiffness(const Config& s) {
  const bool plane = s.analysis != "3d";
  const int nx = 30, ny = plane ? 10 : 6, nz = plane ? 1 : 6;
  const pd::Model m = build(s, nx, ny, nz);
  const double sigma = 1e6;
  const pdtest::Tension t = pdtest::static_tension(m, nx, ny, nz, kDx, sigma, 0);
  EXPECT_TRUE(t.converged) << s.model << " " << s.analysis;
  return sigma / t.section_xx / axial_modulus(s);
}

}  // namespace

namespace {

// The correction's apparent stiffness within 2 % of E, and the error without it printed and
// asserted larger. Measured (m = 3, full volumes): without 0.7650, 1.1175, 0.9893, 1.1534; with
// 0.9960, 0.9948, 0.9946, 0.9979 (PMB 3D, LPS 3D, PMB plane stress, LPS plane stress). The probe
// is the uniaxial stress the bar is in, and the refinement passes fit each node's corrected energy
// (core/surface_correction.hpp); with one uniaxial-strain probe and no passes it was 1.039, 1.012,
// 1.042, 1.043.
void expect_stiffness_of_the_material(const Config& base) {
  Config with = base;
  with.correction = "energy";
  const double without_ratio = apparent_stiffness(base), with_ratio = apparent_stiffness(with);
  std::printf("[ surface  ] %s %s thin %s: E_apparent/E = %.4f without, %.4f with the energy correction\n",
              base.model.c_str(), base.analysis.c_str(), base.analysis == "3d" ? "bar" : "plate", without_ratio,
              with_ratio);
  EXPECT_NEAR(with_ratio, 1.0, 0.02) << base.model << " " << base.analysis;
  EXPECT_LT(std::fabs(with_ratio - 1.0), std::fabs(without_ratio - 1.0)) << base.model << " " << base.analysis;
  if (std::fabs(without_ratio - 1.0) > 0.05)  // where the surface error is large, it shrinks tenfold
    EXPECT_LT(std::fabs(with_ratio - 1.0), 0.1 * std::fabs(without_ratio - 1.0)) << base.model << " " << base.analysis;
}

}  // namespace

TEST(SurfaceCorrection, ThinBarInTensionHasTheStiffnessOfThePmbMaterial) {
  expect_stiffness_of_the_material(Config{"pmb", "3d", 0.25});
}
TEST(SurfaceCorrection, ThinBarInTensionHasTheStiffnessOfTheLpsMaterial) {
  expect_stiffness_of_the_material(Config{"lps", "3d", 0.3});
}
TEST(SurfaceCorrection, PlateInTensionHasTheStiffnessOfThePmbMaterial) {
  expect_stiffness_of_the_material(Config{"pmb", "plane_stress", 0.0});
}
TEST(SurfaceCorrection, PlateInTensionHasTheStiffnessOfTheLpsMaterial) {
  expect_stiffness_of_the_material(Config{"lps", "plane_stress", 0.3});
}

TEST(SurfaceCorrection, StaticTensionOfLpsInteriorStrains) {
  // docs/theory.md C3 for LPS, on the thick bar of MeasureStaticTension (36 × 15 × 15, or a 36 × 21
  // plate): interior ε_xx against σ/E' and −ε_yy/ε_xx against ν' (E' = E, ν' = ν; plane strain
  // E/(1 − ν²), ν/(1 − ν)). The full table (3 analyses × ν × partial volumes × correction) is in the
  // report of issue 14; here three rows, each checked against its measured value and against the
  // uncorrected run (the surface layers stiffen the bar by 7–11 % without the correction).
  struct Row {
    Config s;
    double axial_tol, ratio_tol;
  };
  const Row rows[] = {
      // measured 1.0059, −0.50 % (0.9644, −0.73 % with the uniaxial-strain probe and no passes)
      {{"lps", "3d", 0.3, "energy", "hhb"}, 0.02, 0.02},
      // measured 1.0099, −0.81 % (0.9751, −0.59 % before)
      {{"lps", "plane_strain", 0.45, "energy", "none"}, 0.02, 0.02},
      // measured 1.0033, −5.36 % (0.9786, −4.60 % before: the lateral strain is what the probe's
      // lateral part trades for the axial fit; its tolerance went from 5 % to 6 %)
      {{"lps", "plane_stress", 0.3, "energy", "none"}, 0.02, 0.06},
  };
  const double sigma = 1e6;
  for (const Row& row : rows) {
    const bool plane = row.s.analysis != "3d";
    const int nx = 36, ny = plane ? 21 : 15, nz = plane ? 1 : 15;
    Config without = row.s;
    without.correction = "none";
    const pdtest::Tension t = pdtest::static_tension(build(row.s, nx, ny, nz), nx, ny, nz, kDx, sigma, plane ? 7 : 6);
    const pdtest::Tension u = pdtest::static_tension(build(without, nx, ny, nz), nx, ny, nz, kDx, sigma, plane ? 7 : 6);
    ASSERT_TRUE(t.converged && u.converged);
    const double e = axial_modulus(row.s), r = lateral_ratio(row.s);
    const double axial = t.interior_xx * e / sigma, axial0 = u.interior_xx * e / sigma;
    const double ratio = -t.interior_yy / t.interior_xx / r;
    std::printf("[ surface  ] C3 LPS %s ν=%.2f pv=%s: ε_xx E'/σ = %.4f (%.4f uncorrected), −ε_yy/ε_xx / ν' = %.4f\n",
                row.s.analysis.c_str(), row.s.nu, row.s.partial_volume.c_str(), axial, axial0, ratio);
    EXPECT_NEAR(axial, 1.0, row.axial_tol) << row.s.analysis;
    EXPECT_NEAR(ratio, 1.0, row.ratio_tol) << row.s.analysis;
    EXPECT_GT(std::fabs(axial0 - 1.0), 0.06) << row.s.analysis;  // the correction is what brings it in
  }
}

TEST(SurfaceCorrection, SplitMethodMakesLpsDilatationNearlyExactAndFitsItsTwoModuli) {
  // The split method (core/surface_correction.hpp; not a case-file choice): with its bond factors
  // θ of a uniaxial strain along each axis comes much closer to 1 on every node (not to round-off:
  // the mean of the two ends' factors and a corner's off-diagonal second moment leave a residue);
  // the moduli factors: β ≈ 1 where θ is right, γ on the middle node near the lattice's 1/r_A (the
  // axes probes compare with the continuum; lps_lattice.hpp), not equal to it: its neighbours'
  // factors reach into its bonds on a 13-node block at m = 3. Measured: max |θ − 1| 0.238 → 0.077
  // (3D), 0.196 → 0.017 (plane strain); max |β − 1| 0.030, 0.0018; γ 1.2074 (1/r_A 1.1980), 0.9779
  // (0.9659). 4.7 s with one thread at load ≈ 9.
  for (const char* analysis : {"3d", "plane_strain"}) {
    const Config s{"lps", analysis, 0.3, "none"};
    const bool plane = std::string(analysis) != "3d";
    const int n = 13, nz = plane ? 1 : n;
    const pd::Model bare = build(s, n, n, nz);
    pd::Model m = build(s, n, n, nz);
    const pd::SplitFactors f = pd::split_surface_factors(m, pd::kDilatationPasses, pd::ShearProbes::axes);
    EXPECT_FALSE(m.bonds.corrected());  // left as it was
    m.bonds.surface_factor = pd::bond_factors(m, f.direction);
    m.bonds.surface_moduli = f.moduli;
    m.bond_model = pd::material_registry().get("lps").make(m);
    double worst[2] = {0.0, 0.0};  // |θ − 1| without and with the factors
    for (int d = 0; d < (plane ? 2 : 3); ++d) {
      pd::Vec3Array u = pd::make_vec3(m.nodes.size());
      const double eps = 1e-6;
      for (std::size_t i = 0; i < m.nodes.size(); ++i)
        u[static_cast<std::size_t>(d)][i] = eps * m.nodes.x[static_cast<std::size_t>(d)][i];
      const std::vector<double> t0 = bare.bond_model->dilatation(bare, u), t1 = m.bond_model->dilatation(m, u);
      for (std::size_t i = 0; i < m.nodes.size(); ++i) {
        worst[0] = std::max(worst[0], std::fabs(t0[i] / eps - 1.0));
        worst[1] = std::max(worst[1], std::fabs(t1[i] / eps - 1.0));
      }
    }
    const std::size_t centre = pdtest::node_index(n / 2, n / 2, nz / 2, n, n);
    double beta_worst = 0.0;
    for (std::size_t i = 0; i < m.nodes.size(); ++i) beta_worst = std::max(beta_worst, std::fabs(f.moduli[2 * i] - 1.0));
    const double r_a = pdtest::axis_shear_factor(plane ? 2 : 3, s.horizon_factor, "one");
    std::printf("[ surface  ] LPS %s split: max |θ − 1| of a uniaxial strain %.4f without, %.4f with; max |β − 1| "
                "%.4f; middle node's γ %.4f (1/r_A = %.4f)\n", analysis, worst[0], worst[1], beta_worst,
                f.moduli[2 * centre + 1], 1.0 / r_a);
    EXPECT_GT(worst[0], 0.15) << analysis;
    EXPECT_LT(worst[1], 0.4 * worst[0]) << analysis;
    EXPECT_LT(beta_worst, 0.035) << analysis;
    EXPECT_NEAR(f.moduli[2 * centre + 1], 1.0 / r_a, 0.015) << analysis;
  }
}

TEST(SurfaceCorrection, VolumeMethodFactorsAndTheStiffnessTheyGive) {
  // The volume method (core/surface_correction.hpp volume_factors; Le & Bobaru 2018, PeriLab's
  // volume correction): g = 2 V0/(V_i + V_j). On the middle node of a block every bond's g is
  // V0/V_bulk (the continuum's family volume over the lattice's, 4πδ³/3 against 122 dx³ at m = 3 in
  // 3D), both copies of a bond carry the same g; and the apparent stiffness of the thin bar and the
  // plate of expect_stiffness_of_the_material, asserted as measured (the method has no probe: it does
  // not aim at E and is not held to 2 %). Measured E_app/E with it: PMB 3D 1.1188, LPS 3D (ν = 0.3)
  // 1.7395, PMB plane stress 1.1761, LPS plane stress 1.4188 (without: 0.7650, 1.1175, 0.9893,
  // 1.1534): it overcorrects PMB's 3D bar and stiffens further the LPS surfaces, which are stiff
  // already (LPS's discrete m keeps a truncated family's energy whole; the factor's volume deficit
  // then multiplies it again through ḡ). 12 s with one thread at load ≈ 9.
  {
    const pd::Model m = build(Config{"pmb", "3d", 0.25, "volume"}, 13, 13, 13);
    ASSERT_TRUE(m.bonds.corrected());
    const std::size_t centre = pdtest::node_index(6, 6, 6, 13, 13);
    const double expected = 4.0 / 3.0 * kPi * std::pow(3.015 * kDx, 3) / (122.0 * kDx * kDx * kDx);
    ASSERT_EQ(m.bonds.offsets[centre + 1] - m.bonds.offsets[centre], 122);
    for (std::int64_t k = m.bonds.offsets[centre]; k < m.bonds.offsets[centre + 1]; ++k)
      EXPECT_NEAR(m.bonds.surface_factor[static_cast<std::size_t>(k)], expected, 1e-12);
    for (std::size_t i = 0; i < m.nodes.size(); ++i)
      for (std::int64_t k = m.bonds.offsets[i]; k < m.bonds.offsets[i + 1]; ++k) {
        const auto j = static_cast<std::size_t>(m.bonds.neighbour[static_cast<std::size_t>(k)]);
        const std::int32_t* row = m.bonds.neighbour.data();
        const auto back = std::lower_bound(row + m.bonds.offsets[j], row + m.bonds.offsets[j + 1], static_cast<std::int32_t>(i));
        ASSERT_EQ(m.bonds.surface_factor[static_cast<std::size_t>(k)],
                  m.bonds.surface_factor[static_cast<std::size_t>(back - row)]);
      }
  }
  const struct {
    Config s;
    double measured;
  } rows[] = {{{"pmb", "3d", 0.25, "volume"}, 1.1188},
              {{"lps", "3d", 0.3, "volume"}, 1.7395},
              {{"pmb", "plane_stress", 0.0, "volume"}, 1.1761},
              {{"lps", "plane_stress", 0.3, "volume"}, 1.4188}};
  for (const auto& row : rows) {
    const double with = apparent_stiffness(row.s);
    std::printf("[ surface  ] %s %s thin %s: E_apparent/E = %.4f with the volume correction\n", row.s.model.c_str(),
                row.s.analysis.c_str(), row.s.analysis == "3d" ? "bar" : "plate", with);
    EXPECT_NEAR(with, row.measured, 1e-3) << row.s.model << " " << row.s.analysis;
  }
}
