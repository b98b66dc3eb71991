// The energy surface correction (core/surface_correction; Le & Bobaru 2018) with PMB and LPS: its
// factors (the continuum's over the lattice's energy on a bulk node, the ellipsoid combination, one
// g per bond for both copies), the apparent stiffness of a thin bar and a plate in tension (within
// 2 % of E with it; the error without it printed and asserted larger), the force as the gradient of
// the corrected energy, J·x against a difference of the force, bitwise results for 1 and 2 threads,
// and the static tension of validation.md C3 for LPS (interior strains against σ/E and −νσ/E).
#include <gtest/gtest.h>
#include <omp.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>

#include "core/stability.hpp"
#include "core/surface_correction.hpp"
#include "lattice.hpp"
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
// configuration of validation.md C3 with and without the correction and partial volumes.
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

// The energy of a uniform extension ε along x on a bulk node of the cubic (3D) or square (2D)
// lattice, from the stencil (independent of the solver's bond list): PMB Σ ¼ c (ε n_x²)² |ξ| V_j.
double pmb_bulk_energy(const pd::Model& m, double eps) {
  const double c = m.material.micromodulus_pair[0];
  const int r = 4, dim = m.nodes.dimension;
  double w = 0.0;
  for (int p = -r; p <= r; ++p)
    for (int q = -r; q <= r; ++q)
      for (int s = (dim == 3 ? -r : 0); s <= (dim == 3 ? r : 0); ++s) {
        const double l = std::sqrt(double(p * p + q * q + s * s)) * kDx;
        if (l == 0.0 || l > m.horizon * (1 + 1e-12)) continue;
        const double nx2 = (p * kDx) * (p * kDx) / (l * l);
        w += 0.25 * c * (eps * nx2) * (eps * nx2) * l * m.nodes.volume[0];
      }
  return w;
}

}  // namespace

TEST(SurfaceCorrection, BulkFactorIsTheContinuumOverTheLatticeEnergyAndSurfaceFactorsDiffer) {
  // Le & Bobaru's factor compares with the continuum, so on a bulk node it is W_cont/W_lattice: the
  // C1 factor of validation.md (m = 3, full volumes), not 1 — the correction takes out the bulk's
  // quadrature error as well as the surface's. Every bulk node has the same factors, and so each
  // bond between two bulk nodes has g = that factor in any direction (the ellipsoid of three equal
  // axes is a sphere).
  for (const char* analysis : {"3d", "plane_stress"}) {
    const Config s{"pmb", analysis, 0.25, "energy"};
    const int n = 13;
    const pd::Model m = build(s, n, n, n);
    const bool plane = m.nodes.dimension == 2;
    const std::vector<double> f = pd::surface_direction_factors(build(Config{"pmb", analysis}, n, n, n));
    const double eps = 1e-5;
    const double expected = m.bond_model->uniaxial_energy_density(m, 0, eps) / pmb_bulk_energy(m, eps);
    const std::size_t centre = pdtest::node_index(6, 6, plane ? 0 : 6, n, n);
    for (int d = 0; d < (plane ? 2 : 3); ++d) EXPECT_NEAR(f[3 * centre + d], expected, 1e-9) << analysis << " d=" << d;
    if (plane) EXPECT_EQ(f[3 * centre + 2], 1.0);
    std::printf("[ surface  ] PMB %s bulk factor (continuum/lattice, m = 3, full volumes) = %.6f\n", analysis, expected);
    // Every bond of the centre node joins two nodes with whole families: g = the bulk factor.
    for (std::int64_t k = m.bonds.offsets[centre]; k < m.bonds.offsets[centre + 1]; ++k)
      EXPECT_NEAR(m.bonds.surface_factor[static_cast<std::size_t>(k)], expected, 1e-9);
    // A corner node's family is an eighth (a quarter) of the whole: its factors are far above.
    EXPECT_GT(f[0], 1.5 * expected) << analysis;
    // Both copies of every bond carry bitwise the same g.
    for (std::size_t i = 0; i < m.nodes.size(); ++i)
      for (std::int64_t k = m.bonds.offsets[i]; k < m.bonds.offsets[i + 1]; ++k) {
        const auto j = static_cast<std::size_t>(m.bonds.neighbour[static_cast<std::size_t>(k)]);
        for (std::int64_t q = m.bonds.offsets[j]; q < m.bonds.offsets[j + 1]; ++q)
          if (static_cast<std::size_t>(m.bonds.neighbour[static_cast<std::size_t>(q)]) == i)
            ASSERT_EQ(m.bonds.surface_factor[static_cast<std::size_t>(k)], m.bonds.surface_factor[static_cast<std::size_t>(q)]);
      }
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
  EXPECT_EQ(pd::surface_correction_registry().keys(), (std::vector<std::string>{"energy", "none"}));
  try {
    pd::surface_correction_registry().get("volume");
    FAIL() << "no error";
  } catch (const pd::Error& e) {
    EXPECT_NE(std::string(e.what()).find("unknown surface_correction method 'volume'; known: energy, none"),
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
    std::vector<double> g[2], w[2];
    pd::Vec3Array f[2], y[2];
    for (int t = 0; t < 2; ++t) {
      omp_set_num_threads(t + 1);
      const pd::Model m = build(s, 9, 8, 7);
      const pd::Vec3Array u = smooth_state(m);
      g[t] = m.bonds.surface_factor;
      f[t] = pd::make_vec3(m.nodes.size());
      y[t] = pd::make_vec3(m.nodes.size());
      w[t].assign(m.nodes.size(), 0.0);
      m.bond_model->add_force(m, u, f[t], w[t].data());
      m.bond_model->add_jacobian_product(m, u, direction(m), y[t]);
    }
    omp_set_num_threads(saved);
    EXPECT_EQ(g[0], g[1]) << s.model;
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

TEST(SurfaceCorrection, ThinBarAndPlateInTensionHaveTheStiffnessOfTheMaterial) {
  const char* only = std::getenv("PD_SURFACE_ONLY");
  for (const Config& base : {Config{"pmb", "3d", 0.25}, Config{"lps", "3d", 0.3}, Config{"pmb", "plane_stress", 0.0},
                             Config{"lps", "plane_stress", 0.3}}) {
    if (only && std::string(only) != base.model + "-" + base.analysis) continue;
    Config with = base;
    with.correction = "energy";
    const double without_ratio = apparent_stiffness(base), with_ratio = apparent_stiffness(with);
    std::printf("[ surface  ] %s %s thin %s: E_apparent/E = %.4f without, %.4f with the energy correction\n",
                base.model.c_str(), base.analysis.c_str(), base.analysis == "3d" ? "bar" : "plate", without_ratio,
                with_ratio);
    // Measured (m = 3, full volumes): without 0.7650, 1.1175, 0.9893, 1.1534; with 1.0387, 1.0116,
    // 1.0419, 1.0426 (PMB 3D, LPS 3D, PMB plane stress, LPS plane stress). The correction matches
    // each node's uniaxial-strain energy (C11) to the continuum; a bar in uniaxial stress also
    // depends on C12, which the m = 3 lattice gets wrong in the bulk (the interior of a thick bar,
    // MeasureStaticTension) — so 2 % holds for LPS in 3D only, and 4.5 % for all four.
    EXPECT_NEAR(with_ratio, 1.0, base.model == "lps" && base.analysis == "3d" ? 0.02 : 0.045)
        << base.model << " " << base.analysis;
    if (base.model == "lps" || base.analysis == "3d")  // where the surface error is large, it shrinks
      EXPECT_LT(std::fabs(with_ratio - 1.0), 0.5 * std::fabs(without_ratio - 1.0)) << base.model << " " << base.analysis;
  }
}

TEST(SurfaceCorrection, StaticTensionOfLpsInteriorStrains) {
  // validation.md C3 for LPS, on the thick bar of MeasureStaticTension (36 × 15 × 15, or a 36 × 21
  // plate): interior ε_xx against σ/E' and −ε_yy/ε_xx against ν' (E' = E, ν' = ν; plane strain
  // E/(1 − ν²), ν/(1 − ν)). The full table (3 analyses × ν × partial volumes × correction) is in the
  // report of issue 14; here three rows, each checked against its measured value and against the
  // uncorrected run (the surface layers stiffen the bar by 7–11 % without the correction).
  struct Row {
    Config s;
    double axial_tol, ratio_tol;
  };
  const Row rows[] = {
      {{"lps", "3d", 0.3, "energy", "hhb"}, 0.04, 0.02},         // measured 0.9644, −0.73 %
      {{"lps", "plane_strain", 0.45, "energy", "none"}, 0.03, 0.02},  // measured 0.9751, −0.59 %
      {{"lps", "plane_stress", 0.3, "energy", "none"}, 0.03, 0.05},   // measured 0.9786, −4.60 %
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
