// Static tension of LPS (docs/theory.md C3; issue 14, "Tests and validation"): the interior axial
// strain against σ/E' and the lateral one against −ν'σ/E' (E' = E, ν' = ν in 3D and plane stress;
// E/(1 − ν²), ν/(1 − ν) in plane strain), with the energy surface correction and without it, for
// ν = 0.2, 0.3, 0.45 (3D, plane strain) and 0.3 (plane stress). The static problem is solved by
// conjugate gradients on the matrix-free J(0)·x (static_tension.hpp).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <utility>

#include "core/surface_correction.hpp"
#include "lattice.hpp"
#include "lps_lattice.hpp"
#include "one_thread.hpp"
#include "materials/bond_model.hpp"
#include "static_tension.hpp"

namespace {

constexpr double kDx = 1e-3;
constexpr double kE = 1e9;
constexpr double kSigma = 1e6;

struct Bar {
  std::string analysis = "plane_strain";
  double nu = 0.3;
  std::string correction = "energy";  // none, energy, volume, or split (test only: split_surface_factors)
  double horizon_factor = 4.015;  // m = δ/dx
  int load_layers = 4;            // the traction σ spread over this many end layers
  int nx = 36, width = 25;        // width: ny (and nz in 3D) nodes
  std::string partial_volume = "none";
  std::string influence = "one";
  pd::ShearProbes shear = pd::ShearProbes::axes;  // the split correction's shear probes
  int passes = pd::kDilatationPasses;             // and its dilatation passes (0: moduli factors only)
  int inner = -1;  // the interior's distance from the lateral faces in spacings; −1: C3's (below)
};

struct Strains {
  double axial = 0.0;    // interior ε_xx E'/σ (1 in the continuum)
  double lateral = 0.0;  // interior −ε_yy/ε_xx / ν' (1 in the continuum)
  double bulk_factor = 1.0, shear_factor = 1.0;  // the correction's β, γ on a bulk node (1 uncorrected)
  int iterations = 0;
  bool converged = false;
  pdtest::Tension solve;  // the solve's profiles (MeasureProfile)
};

double modulus(const Bar& b) { return b.analysis == "plane_strain" ? kE / (1.0 - b.nu * b.nu) : kE; }
double ratio(const Bar& b) { return b.analysis == "plane_strain" ? b.nu / (1.0 - b.nu) : b.nu; }

Strains tension(const Bar& b) {
  const int dim = b.analysis == "3d" ? 3 : 2, nz = dim == 3 ? b.width : 1;
  pd::Case c = pdtest::lattice_case(dim, b.analysis, kDx, b.horizon_factor * kDx, kE, 1000.0, -1.0, 1e-3);
  c.blocks[0].model = "lps";
  c.blocks[0].parameters["poisson_ratio"] = b.nu;
  c.blocks[0].choices["influence"] = b.influence;
  const bool split = b.correction == "split";
  c.surface_correction = split ? "none" : b.correction;
  c.partial_volume = b.partial_volume;
  pd::Model m = pd::build_model(c, pdtest::cubic_lattice(b.nx, b.width, nz, kDx, dim, 1e-3));
  if (split) {  // the split method (core/surface_correction.hpp), set as build_model sets a correction
    pd::SplitFactors f = pd::split_surface_factors(m, b.passes, b.shear);
    m.bonds.surface_factor = pd::bond_factors(m, f.direction);
    m.bonds.surface_moduli = std::move(f.moduli);
    m.bond_model = pd::material_registry().get("lps").make(m);
  }
  // The interior: 2δ (rounded down to whole spacings) from every lateral face, but at least the three
  // middle rows (a fit of ε_yy needs more than one).
  const int inner = b.inner >= 0 ? b.inner : std::min(static_cast<int>(2.0 * b.horizon_factor), (b.width - 3) / 2);
  const pdtest::Tension t = pdtest::static_tension(m, b.nx, b.width, nz, kDx, kSigma, inner, b.load_layers);
  Strains s;
  // The correction's factors of both moduli on the middle node (a bulk node for W ≥ 2m + 1): the
  // split method's β, γ; the energy method's ḡ = its direction factor there (lps.hpp), found on the
  // uncorrected model.
  const std::size_t mid = pdtest::node_index(b.nx / 2, b.width / 2, nz / 2, b.nx, b.width);
  if (split) {
    s.bulk_factor = m.bonds.surface_moduli[2 * mid];
    s.shear_factor = m.bonds.surface_moduli[2 * mid + 1];
  } else if (m.bonds.corrected() && b.correction == "energy") {
    c.surface_correction = "none";
    pd::Model bare = pd::build_model(c, pdtest::cubic_lattice(b.nx, b.width, nz, kDx, dim, 1e-3));
    s.bulk_factor = s.shear_factor = pd::surface_direction_factors(bare, pd::kSurfacePasses)[3 * mid];
  }
  s.axial = t.interior_xx * modulus(b) / kSigma;
  s.lateral = -t.interior_yy / t.interior_xx / ratio(b);
  s.iterations = t.iterations;
  s.converged = t.converged;
  s.solve = t;
  return s;
}

void print(const char* what, const Bar& b, const Strains& s) {
  std::printf("[ c3 lps   ] %-22s %-12s nu=%.2f m=%.3f w=%s pv=%s load=%d L=%d W=%2d corr=%-6s%s cg=%5d%s: "
              "axial %+.2f %%, lateral %+.2f %%\n",
              what, b.analysis.c_str(), b.nu, b.horizon_factor, b.influence.c_str(), b.partial_volume.c_str(),
              b.load_layers, b.nx, b.width, b.correction.c_str(),
              b.correction != "split" ? "" : (b.shear == pd::ShearProbes::axes ? " (axes)" : " (isotropic)"),
              s.iterations, s.converged ? "" : " (not converged)", 100.0 * (s.axial - 1.0),
              100.0 * (s.lateral - 1.0));
  std::fflush(stdout);
}

}  // namespace

// A measurement table (not a test): PD_LPS_TENSION_MEASURE=1 prints every row at m = 3 and 4, with
// and without the correction, loaded on one layer or on m layers, and the 3D bar at several widths.
TEST(LpsTension, MeasureTable) {
  if (!std::getenv("PD_LPS_TENSION_MEASURE")) GTEST_SKIP() << "set PD_LPS_TENSION_MEASURE=1 to print the table";
  const char* only = std::getenv("PD_LPS_TENSION_ONLY");  // e.g. 3d, plane_strain
  struct Row {
    const char* analysis;
    double nu;
  };
  const Row rows[] = {{"plane_strain", 0.2}, {"plane_strain", 0.3}, {"plane_strain", 0.45}, {"plane_stress", 0.3},
                      {"3d", 0.2},           {"3d", 0.3},           {"3d", 0.45}};
  for (const Row& r : rows) {
    if (only && std::string(only) != r.analysis) continue;
    const bool solid = std::string(r.analysis) == "3d";
    const char* nu_only = std::getenv("PD_LPS_TENSION_NU");
    if (nu_only && std::fabs(std::atof(nu_only) - r.nu) > 1e-9) continue;
    const char* m_only = std::getenv("PD_LPS_TENSION_M");
    const char* layers_only = std::getenv("PD_LPS_TENSION_LAYERS");  // 1, or 0: m layers
    const char* corr_only = std::getenv("PD_LPS_TENSION_CORR");
    for (const double m : {3.015, 4.015})
      for (const int layers : {1, 0})
        for (const char* corr : {"none", "energy", "split"}) {
          if ((m_only && std::fabs(std::atof(m_only) - m) > 1e-9) || (layers_only && std::atoi(layers_only) != layers) ||
              (corr_only && std::string(corr_only) != corr))
            continue;
          Bar b{r.analysis, r.nu, corr, m, layers == 0 ? static_cast<int>(m) : 1};
          if (const char* pv = std::getenv("PD_LPS_TENSION_PV")) b.partial_volume = pv;
          if (const char* w = std::getenv("PD_LPS_TENSION_INFLUENCE")) b.influence = w;
          if (const char* sp = std::getenv("PD_LPS_TENSION_SHEAR"))
            b.shear = std::string(sp) == "isotropic" ? pd::ShearProbes::isotropic : pd::ShearProbes::axes;
          if (const char* p = std::getenv("PD_LPS_TENSION_PASSES")) b.passes = std::atoi(p);
          if (solid) b.width = 15;
          if (const char* w = std::getenv(solid ? "PD_LPS_TENSION_W3" : "PD_LPS_TENSION_W2")) b.width = std::atoi(w);
          if (const char* l = std::getenv("PD_LPS_TENSION_NX")) b.nx = std::atoi(l);
          print("measure", b, tension(b));
        }
  }
}

namespace {

// The bulk lattice's interior strains for bar b (lps_lattice.hpp), scaled by the correction's ḡ:
// both moduli times ḡ divide the axial strain by ḡ and leave −ε_yy/ε_xx alone. Relative to σ/E'
// and ν' as Strains.
Strains bulk_lattice(const Bar& b, const Strains& corrected) {
  const int dim = b.analysis == "3d" ? 3 : 2;
  const pdtest::BulkStrains k = pdtest::lps_bulk_tension(
      kE, b.nu, b.analysis, pdtest::axis_shear_factor(dim, b.horizon_factor, b.influence, b.partial_volume),
      corrected.bulk_factor, corrected.shear_factor);
  Strains s;
  s.axial = k.axial;
  s.lateral = k.lateral / ratio(b);
  return s;
}

// One row of the C3 table: the bar with and without the correction, printed beside the bulk
// lattice's values and the continuum's verdict (2 %); returns {corrected, uncorrected, lattice}.
struct Row {
  Strains with, without, lattice;
};
Row c3_row(const Bar& corrected) {
  Bar uncorrected = corrected;
  uncorrected.correction = "none";
  Row r{tension(corrected), tension(uncorrected), {}};
  r.lattice = bulk_lattice(corrected, r.with);
  EXPECT_TRUE(r.with.converged && r.without.converged) << corrected.analysis << " ν=" << corrected.nu;
  print("corrected", corrected, r.with);
  print("uncorrected", uncorrected, r.without);
  std::printf("[ c3 lps   ] %-22s %-12s nu=%.2f m=%.3f beta=%.4f gamma=%.4f: axial %+.2f %%, lateral %+.2f %%; C3 "
              "(2 %%) with the correction: axial %s, lateral %s\n",
              "bulk lattice", corrected.analysis.c_str(), corrected.nu, corrected.horizon_factor, r.with.bulk_factor,
              r.with.shear_factor,
              100.0 * (r.lattice.axial - 1.0), 100.0 * (r.lattice.lateral - 1.0),
              std::fabs(r.with.axial - 1.0) <= 0.02 ? "met" : "NOT met",
              std::fabs(r.with.lateral - 1.0) <= 0.02 ? "met" : "NOT met");
  return r;
}

}  // namespace

TEST(LpsTension, PlaneInteriorIsTheBulkLatticesAndTheCorrectionTakesOutTheSurfaceStiffening) {
  // A 72 × 41 plate (dx = 1 mm), σ = 1 MPa spread over the last 4 layers, ω = 1, full volumes,
  // m = 4 (MeasureTable has m = 3 too); interior = 2δ from the lateral faces, middle third of the length. The square
  // lattice's shear is anisotropic (r_A = 1.0353 at m = 3, 1.0468 at m = 4: lps_lattice.hpp), and
  // the energy correction matches the uniaxial-strain energy C11, not E: these, not the surfaces,
  // set the interior's error once the correction is on, so the test asserts the interior against
  // the bulk lattice (to 1.5 % of σ/E' and of ν': the residual surface effect of a 41-node width,
  // measured ≤ 0.9 and ≤ 1.3 points) and prints the continuum's verdict. Measured (load ≈ 20):
  //   m = 4, corrected axial −1.70 −2.15 −2.76 −1.84 %, lateral −7.37 −3.39 −0.28 −5.82 %;
  //   uncorrected axial −5.52 −6.09 −7.17 −5.69 % (plane strain ν = 0.2, 0.3, 0.45; plane stress 0.3).
  const pdtest::OneThread one;  // small CG solves: OpenMP barriers would cost more than they save
  for (const auto& [analysis, nu] : {std::pair<const char*, double>{"plane_strain", 0.2}, {"plane_strain", 0.3},
                                     {"plane_strain", 0.45}, {"plane_stress", 0.3}}) {
    const Row r = c3_row(Bar{analysis, nu, "energy", 4.015, 4, 72, 41});
    EXPECT_NEAR(r.with.axial, r.lattice.axial, 0.015) << analysis << " ν=" << nu;
    EXPECT_NEAR(r.with.lateral, r.lattice.lateral, 0.015) << analysis << " ν=" << nu;
    // Without the correction the plate's surface layers stiffen it: 5.5–7.2 % measured, about
    // three times the corrected error.
    EXPECT_GT(std::fabs(r.without.axial - 1.0), 0.04) << analysis << " ν=" << nu;
    EXPECT_GT(std::fabs(r.without.axial - 1.0), 2.0 * std::fabs(r.with.axial - 1.0)) << analysis << " ν=" << nu;
  }
}

TEST(LpsTension, BarInteriorAxialStrainMeetsC3WithTheCorrectionItsLateralStrainDoesNot) {
  // A 36 × 13 × 13 bar (dx = 1 mm, m = 4, ω = 1, σ = 1 MPa over the last 4 layers; interior: the
  // middle 3 × 3 rows). With the energy correction probing uniaxial stress (core/surface_correction,
  // 3 refinement passes) the interior axial strain is σ/E to 2 % for ν = 0.2, 0.3, 0.45 (measured
  // +0.67, +0.95, +1.34 %; uncorrected −9.7, −10.5, −12.3 %): C3's axial half is met at this width.
  // The lateral half is not: the direction factors, fitted to the axial energy of each face layer,
  // make the section's shear stiffness uneven, and the interior lateral strain is off by +12.1,
  // +8.6, +1.2 % (the earlier uniaxial-strain probe: +3.6, +2.5, −1.6 %; the bulk lattice +3.5,
  // +1.7, +0.3 %). Asserted as measured, so that a change of the correction shows here. Neither hhb
  // partial volumes (+4.0, +3.2, −3.1 %) nor the split method (+11.7, +8.3, +4.6 %) meets 2 % here
  // (validation/README.md, "Split surface correction and lattice anisotropy"). Why: this bar's
  // "interior" is 1.25δ from the faces, inside the surface layer, and its middle third within reach
  // of the ends; measured as C3 defines it (2δ in, L = 108) the 3D bar meets C3 on both halves:
  // BarMeetsC3In3dWithItsInteriorTwoHorizonsFromEveryFace (make validate), validation/README.md,
  // "C3 for LPS in 3D: why the lateral strain missed".
  const pdtest::OneThread one;
  const Row rows[] = {c3_row(Bar{"3d", 0.2, "energy", 4.015, 4, 36, 13}),
                      c3_row(Bar{"3d", 0.3, "energy", 4.015, 4, 36, 13}),
                      c3_row(Bar{"3d", 0.45, "energy", 4.015, 4, 36, 13})};
  for (const Row& r : rows) {
    EXPECT_LT(std::fabs(r.with.axial - 1.0), 0.02);
    EXPECT_GT(std::fabs(r.without.axial - 1.0), 4.0 * std::fabs(r.with.axial - 1.0));
  }
  EXPECT_GT(rows[0].with.lateral - 1.0, 0.10);  // ν = 0.2: lateral +12.1 %, C3 not met
  EXPECT_GT(rows[1].with.lateral - 1.0, 0.07);  // ν = 0.3: +8.6 %
  EXPECT_LT(std::fabs(rows[2].with.lateral - 1.0), 0.02);  // ν = 0.45: +1.2 %, met
}

namespace {

// r_A of the solver's LPS on the middle node of a lattice block: its strain energy under the axis
// shear ε_xx = −ε_yy = ε (θ = 0) over the continuum's 2με² (the mean of ±ε cancels the odd
// finite-strain terms).
double solver_axis_shear_factor(int dim, double horizon_factor, const std::string& w, const std::string& pv) {
  const int half = static_cast<int>(horizon_factor + 0.5) + 1, n = 2 * half + 1, nz = dim == 3 ? n : 1;
  pd::Case c = pdtest::lattice_case(dim, dim == 3 ? "3d" : "plane_strain", kDx, horizon_factor * kDx, kE, 1000.0, -1.0,
                                    1e-3);
  c.blocks[0].model = "lps";
  c.blocks[0].parameters["poisson_ratio"] = 0.3;
  c.blocks[0].choices["influence"] = w;
  c.partial_volume = pv;
  const pd::Model m = pd::build_model(c, pdtest::cubic_lattice(n, n, nz, kDx, dim, 1e-3));
  const std::size_t mid = pdtest::node_index(half, half, nz / 2, n, n);
  const double eps = 1e-5;
  double w_mid = 0.0;
  for (const double e : {eps, -eps}) {
    pd::Vec3Array u = pd::make_vec3(m.nodes.size());
    for (std::size_t i = 0; i < m.nodes.size(); ++i) {
      u[0][i] = e * m.nodes.x[0][i];
      u[1][i] = -e * m.nodes.x[1][i];
    }
    w_mid += 0.5 * m.bond_model->strain_energy_density(m, u)[mid];
  }
  pd::StrainTensor shear{};
  shear[0] = eps;
  shear[4] = -eps;
  return w_mid / m.bond_model->continuum_energy_density(m, mid, shear);
}

}  // namespace

TEST(LpsTension, BulkLatticeLateralStrainByInfluencePartialVolumeAndHorizon) {
  // The square and cubic lattices' shear along the axes is μ·r_A, not μ (lps_lattice.hpp): a
  // discretisation property that no surface correction should hide. Which settings make it small?
  // r_A from the solver's energy on a bulk node (checked against the lattice sum of lps_lattice.hpp
  // to 1e-9), and from it the bulk lattice's lateral strain in C3's uniaxial stress, for ω = 1,
  // 1/|ξ|, Gaussian, partial volumes none, lammps, hhb, m = 3, 4, 5 (m + 0.015). Measured: only
  // hhb at m = 4 and 5 keeps every row (plane strain ν = 0.2, 0.3, 0.45, plane stress 0.3, 3D 0.2,
  // 0.3, 0.45) within 2 % of ν', for every ω (worst: ω = 1/|ξ| m = 4, −1.39 %); full volumes and
  // lammps miss it at every m (3D ν = 0.2: +2.6 to +20.5 %), and hhb at m = 3 (2D ν = 0.2: −7.1 %).
  const pdtest::OneThread one;
  struct Analysis {
    const char* name;
    double nu;
  };
  const Analysis rows[] = {{"plane_strain", 0.2}, {"plane_strain", 0.3}, {"plane_strain", 0.45}, {"plane_stress", 0.3},
                           {"3d", 0.2},           {"3d", 0.3},           {"3d", 0.45}};
  int meeting = 0;
  for (const char* w : {"one", "inverse_length", "gaussian"})
    for (const char* pv : {"none", "lammps", "hhb"})
      for (const double m : {3.015, 4.015, 5.015}) {
        const double r2 = pdtest::axis_shear_factor(2, m, w, pv), r3 = pdtest::axis_shear_factor(3, m, w, pv);
        if (m < 5.0) {  // the solver's r_A on the bulk node (m = 5 in 3D: a 13³ block, left to the sum)
          EXPECT_NEAR(solver_axis_shear_factor(2, m, w, pv), r2, 1e-9) << w << " " << pv << " m=" << m;
          EXPECT_NEAR(solver_axis_shear_factor(3, m, w, pv), r3, 1e-9) << w << " " << pv << " m=" << m;
        }
        double worst = 0.0;
        std::string line;
        for (const Analysis& a : rows) {
          const double err = bulk_lattice(Bar{a.name, a.nu, "none", m, 1, 36, 25, pv, w}, Strains{}).lateral - 1.0;
          worst = std::max(worst, std::fabs(err));
          char cell[16];
          std::snprintf(cell, sizeof cell, " %+6.2f", 100.0 * err);
          line += cell;
        }
        std::printf("[ c3 lps   ] bulk lattice w=%-14s pv=%-6s m=%.3f r_A 2D %.4f 3D %.4f lateral %%:%s%s\n", w, pv, m, r2,
                    r3, line.c_str(), worst <= 0.02 ? "  (all within 2 %)" : "");
        const bool hhb = std::string(pv) == "hhb";
        EXPECT_EQ(worst <= 0.02, hhb && m > 4.0) << w << " " << pv << " m=" << m;
        meeting += worst <= 0.02;
      }
  EXPECT_EQ(meeting, 6);  // hhb × m = 4, 5 × three ω
}

TEST(LpsTension, PlatesMeetC3WithHhbPartialVolumesAndTheEnergyCorrection) {
  // The plates of PlaneInterior… with partial_volume hhb, whose shell weight makes the square
  // lattice's shear nearly isotropic (r_A = 1.0041 at m = 4, against 1.0468 with full volumes:
  // BulkLatticeLateralStrain…): with the energy correction the interior meets C3 on both halves.
  // Measured (validation/README.md, "Split surface correction and lattice anisotropy"): axial
  // +0.32, +0.59, +1.38, +0.40 %, lateral +0.01, +0.37, +0.51, +0.16 % (plane strain ν = 0.2,
  // 0.3, 0.45; plane stress 0.3); uncorrected axial −2.90 to −3.44 %. 4 static solves, 3.5 s each at load ≈ 8.
  const pdtest::OneThread one;
  for (const auto& [analysis, nu] : {std::pair<const char*, double>{"plane_strain", 0.2}, {"plane_strain", 0.3},
                                     {"plane_strain", 0.45}, {"plane_stress", 0.3}}) {
    Bar b{analysis, nu, "energy", 4.015, 4, 72, 41};
    b.partial_volume = "hhb";
    const Strains s = tension(b);
    print("hhb, corrected", b, s);
    EXPECT_TRUE(s.converged) << analysis << " ν=" << nu;
    EXPECT_NEAR(s.axial, 1.0, 0.02) << analysis << " ν=" << nu;
    EXPECT_NEAR(s.lateral, 1.0, 0.02) << analysis << " ν=" << nu;
  }
}

// A measurement (not a test): PD_LPS_TENSION_PROFILE=1 prints, for one bar, where its interior
// strain comes from: the interior fit, then per x layer the interior's ε_xx E'/σ and lateral ratio
// −ε_yy/ε_xx(fit)/ν', and per gap between y rows the lateral ratio (validation/README.md, "Why 3D
// lateral misses"). Selectors: PD_LPS_TENSION_ANALYSIS (3d), _NU, _M, _CORR, _PV, _INFLUENCE, _NX,
// _W, _LAYERS, _INNER.
TEST(LpsTension, MeasureProfile) {
  if (!std::getenv("PD_LPS_TENSION_PROFILE")) GTEST_SKIP() << "set PD_LPS_TENSION_PROFILE=1 to print the profile";
  const auto env = [](const char* name, const char* fallback) {
    const char* v = std::getenv(name);
    return std::string(v ? v : fallback);
  };
  Bar b;
  b.analysis = env("PD_LPS_TENSION_ANALYSIS", "3d");
  b.nu = std::atof(env("PD_LPS_TENSION_NU", "0.3").c_str());
  b.horizon_factor = std::atof(env("PD_LPS_TENSION_M", "4.015").c_str());
  b.correction = env("PD_LPS_TENSION_CORR", "energy");
  b.partial_volume = env("PD_LPS_TENSION_PV", "hhb");
  b.influence = env("PD_LPS_TENSION_INFLUENCE", "one");
  b.nx = std::atoi(env("PD_LPS_TENSION_NX", "36").c_str());
  b.width = std::atoi(env("PD_LPS_TENSION_W", "13").c_str());
  b.load_layers = std::atoi(env("PD_LPS_TENSION_LAYERS", "4").c_str());
  b.inner = std::atoi(env("PD_LPS_TENSION_INNER", "-1").c_str());
  const Strains s = tension(b);
  print("profile", b, s);
  const pdtest::Tension& t = s.solve;
  std::string line;
  for (std::size_t i = 0; i < t.layer_yy.size(); ++i) {
    char cell[64];
    std::snprintf(cell, sizeof cell, " %zu:%+.2f/%+.2f", i, 100.0 * (t.layer_xx[i] * modulus(b) / kSigma - 1.0),
                  100.0 * (-t.layer_yy[i] / t.interior_xx / ratio(b) - 1.0));
    line += cell;
  }
  std::printf("[ c3 lps   ] layers (x: axial %%/lateral %%):%s\n", line.c_str());
  line.clear();
  for (std::size_t j = 0; j < t.gap_yy.size(); ++j) {
    char cell[32];
    std::snprintf(cell, sizeof cell, " %zu:%+.2f", j, 100.0 * (-t.gap_yy[j] / t.interior_xx / ratio(b) - 1.0));
    line += cell;
  }
  std::printf("[ c3 lps   ] gaps across y (lateral %%):%s\n", line.c_str());
}

// docs/theory.md C3 in 3D for LPS, the bar measured as C3 defines it (`make validate`, validation/
// c3_lps.py; PD_LPS_TENSION_VALIDATE=1, else skipped: six solves of 47 628 nodes, 1–2 min each on
// one thread). The bar of BarInterior… (36 × 13²) cannot show C3's lateral strain: its "interior"
// (the middle 3 × 3 rows) is 5 spacings = 1.25δ from the faces, inside the surface layer, whose
// lateral strain oscillates with depth (gaps from the face +111, −4, −51, −7, −11, −2, +7, +2 % at
// ν = 0.2, measured by MeasureProfile) and decays only beyond 2δ; and its middle third is within
// 12 spacings of the ends, where the loaded and held faces disturb the uniaxial stress (the layer
// profile has no plateau at L = 36; at L = 108, W = 21 it is flat from x = 28 to 72 within 0.03 points).
// Here: W = 21 (interior 2δ = 8 spacings from every face, 5 × 5 rows), L = 108 (the middle third
// 36 spacings from either end), hhb partial volumes (the cubic lattice's shear nearly isotropic,
// r_A = 1.0003: BulkLatticeLateralStrain…), ω = 1, m = 4, σ over the last 4 layers. Measured
// (3 Dec 2026, load ≈ 14): energy-corrected axial +0.30, +0.38, +0.42 %, lateral −0.36, +0.07,
// +0.78 % (ν = 0.2, 0.3, 0.45); uncorrected axial −7.96, −8.77 %, lateral −0.84, +0.39 % (0.2, 0.3).
TEST(LpsTension, BarMeetsC3In3dWithItsInteriorTwoHorizonsFromEveryFace) {
  if (!std::getenv("PD_LPS_TENSION_VALIDATE"))
    GTEST_SKIP() << "set PD_LPS_TENSION_VALIDATE=1 (make validate: validation/c3_lps.py)";
  const pdtest::OneThread one;
  for (const double nu : {0.2, 0.3, 0.45}) {
    Bar b{"3d", nu, "energy", 4.015, 4, 108, 21};
    b.partial_volume = "hhb";
    ASSERT_GE(std::min(static_cast<int>(2.0 * b.horizon_factor), (b.width - 3) / 2), 8);  // 2δ from the faces
    const Row r = c3_row(b);
    EXPECT_NEAR(r.with.axial, 1.0, 0.02) << "ν=" << nu;
    EXPECT_NEAR(r.with.lateral, 1.0, 0.02) << "ν=" << nu;
    // Without the correction the surface layers stiffen the bar: axial error > 4 %.
    EXPECT_GT(std::fabs(r.without.axial - 1.0), 0.04) << "ν=" << nu;
  }
}
