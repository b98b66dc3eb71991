// The LPS material (materials/lps): its constants, the patch tests on a bulk node (affine motion →
// no force, θ exact on the discrete family, the continuum strain energy with the discrete m), its
// force as the gradient of its energy, its linearisation (J·x against a central difference,
// symmetry, rigid motions, the reference stiffness), bitwise results for any thread count, its
// stable step against the exact limit of an infinite lattice, and static tension (docs/theory.md C3).
#include <gtest/gtest.h>
#include <omp.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <random>

#include "core/stability.hpp"
#include "jacobian_check.hpp"
#include "lattice.hpp"
#include "lps_lattice.hpp"
#include "materials/bond_model.hpp"
#include "core/avx2.hpp"
#include "materials/lps/lps.hpp"
#include "materials/lps/lps_kernel.hpp"
#include "integrators/integrator.hpp"
#include "one_thread.hpp"
#include "static_tension.hpp"

namespace {

constexpr double kDx = 1e-3;
constexpr double kE = 1e9;
constexpr double kPi = 3.14159265358979323846;

struct Lps {
  double nu = 0.3;
  std::string influence = "one";
  double fracture_energy = -1.0;  // < 0: unbreakable
};

pd::Case lps_case(int dimension, const std::string& analysis, const Lps& p) {
  pd::Case c = pdtest::lattice_case(dimension, analysis, kDx, 3.015 * kDx, kE, 1000.0, p.fracture_energy, 1e-3);
  c.blocks[0].model = "lps";
  c.blocks[0].parameters["poisson_ratio"] = p.nu;
  c.blocks[0].choices["influence"] = p.influence;
  return c;
}

// n^dim nodes (n = 13: the centre node is 2δ from every edge, so its neighbours' families are whole).
pd::Model lattice(int dimension, const std::string& analysis, const Lps& p, int n = 13, int nz = -1) {
  const int z = dimension == 3 ? (nz > 0 ? nz : n) : 1;
  return pd::build_model(lps_case(dimension, analysis, p), pdtest::cubic_lattice(n, n, z, kDx, dimension, 1e-3));
}

std::size_t centre(const pd::Model& m, int n = 13) {
  return pdtest::node_index(n / 2, n / 2, m.nodes.dimension == 3 ? n / 2 : 0, n, n);
}

const pd::LpsModel& law(const pd::Model& m) { return dynamic_cast<const pd::LpsModel&>(*m.bond_model); }

// u = G x for a 3×3 displacement gradient G (row-major).
pd::Vec3Array affine(const pd::Model& m, const double g[9]) {
  pd::Vec3Array u = pd::make_vec3(m.nodes.size());
  for (std::size_t i = 0; i < m.nodes.size(); ++i)
    for (int a = 0; a < 3; ++a)
      for (int b = 0; b < 3; ++b) u[a][i] += g[3 * a + b] * m.nodes.x[b][i];
  return u;
}

pd::Vec3Array force(const pd::Model& m, const pd::Vec3Array& u, double* w = nullptr) {
  pd::Vec3Array f = pd::make_vec3(m.nodes.size());
  m.bond_model->add_force(m, u, f, w);
  return f;
}

double total_energy(const pd::Model& m, const pd::Vec3Array& u) {
  const std::vector<double> w = m.bond_model->strain_energy_density(m, u);
  double s = 0.0;
  for (std::size_t i = 0; i < w.size(); ++i) s += w[i] * m.nodes.volume[i];
  return s;
}

struct Analysis {
  int dimension;
  const char* name;
};
const Analysis kAnalyses[] = {{3, "3d"}, {2, "plane_strain"}, {2, "plane_stress"}};

}  // namespace

TEST(Lps, IsRegisteredWithItsParameters) {
  const pd::MaterialDefinition& lps = pd::material_registry().get("lps");
  ASSERT_EQ(lps.parameters.size(), 4u);
  EXPECT_EQ(lps.parameters[1].name, "poisson_ratio");
  EXPECT_EQ(lps.parameters[1].lower, -1.0);
  EXPECT_EQ(lps.parameters[1].upper, 0.5);
  EXPECT_EQ(lps.parameters[3].choices, (std::vector<std::string>{"one", "inverse_length", "gaussian"}));
}

TEST(Lps, CriticalStretchIsCabanaPdsAndPmbsForTheirInfluenceFunctions) {
  pd::BlockMaterial b;
  b.model = "lps";
  b.parameters = {{"youngs_modulus", 1.0}, {"poisson_ratio", 0.25}, {"fracture_energy", 1.0}};
  const double delta = 2.0, k3 = 2.0 / 3.0;  // K = E/(3(1−2ν))
  b.choices["influence"] = "inverse_length";  // ω = 1/|ξ|: PMB's s0 (docs/theory.md T2: 0.6454972243679028)
  EXPECT_NEAR(pd::lps_constants(b, "3d", delta, 0.0).critical_stretch, 0.6454972243679028, 1e-13);
  EXPECT_NEAR(pd::lps_constants(b, "3d", delta, 0.0).micromodulus, 18.0 * k3 / (kPi * 16.0), 1e-15);
  // 2D with ν = 1/4: plane strain is PMB's √(5πG0/(12Eδ)); plane stress with ν = 1/3 √(4πG0/(9Eδ)).
  EXPECT_NEAR(pd::lps_constants(b, "plane_strain", delta, 1.0).critical_stretch, std::sqrt(5 * kPi / 24.0), 1e-13);
  b.parameters["poisson_ratio"] = 1.0 / 3.0;
  EXPECT_NEAR(pd::lps_constants(b, "plane_stress", delta, 1.0).critical_stretch, std::sqrt(4 * kPi / 18.0), 1e-13);
  b.parameters["poisson_ratio"] = 0.25;
  b.choices["influence"] = "one";  // CabanaPD's √(8G0/(15Kδ))
  EXPECT_NEAR(pd::lps_constants(b, "3d", delta, 0.0).critical_stretch, std::sqrt(8.0 / (15.0 * k3 * delta)), 1e-13);
  b.parameters.erase("fracture_energy");
  EXPECT_TRUE(std::isinf(pd::lps_constants(b, "3d", delta, 0.0).critical_stretch));
}

TEST(Lps, AffineDisplacementGivesNoForceOnABulkNode) {
  const double g[9] = {1e-3, 2e-4, -3e-4, 5e-4, -7e-4, 1e-4, -2e-4, 3e-4, 6e-4};
  for (const Analysis& a : kAnalyses)
    for (const char* w : {"one", "inverse_length", "gaussian"}) {
      const pd::Model m = lattice(a.dimension, a.name, {0.3, w});
      double g2[9];
      for (int q = 0; q < 9; ++q) g2[q] = (a.dimension == 2 && (q % 3 == 2 || q >= 6)) ? 0.0 : g[q];
      const pd::Vec3Array f = force(m, affine(m, g2));
      const std::size_t i = centre(m);
      const double scale = kE * 1e-3 / kDx;  // E·|∇u|/dx: a force density of this strain over one spacing
      // The same deformation is not in equilibrium on the surface, so the force there is far from zero.
      EXPECT_GT(std::hypot(f[0][0], f[1][0], f[2][0]), 1e-3 * scale) << a.name << " " << w;
      EXPECT_LT(std::hypot(f[0][i], f[1][i], f[2][i]), 1e-12 * scale) << a.name << " " << w;
    }
}

TEST(Lps, UniformDilatationIsExactOnTheDiscreteFamilyOfEveryNode) {
  const double eps = 1e-3;
  for (const Analysis& a : kAnalyses)
    for (const char* w : {"one", "inverse_length", "gaussian"}) {
      const pd::Model m = lattice(a.dimension, a.name, {0.3, w}, 9);
      const double g[9] = {eps, 0, 0, 0, eps, 0, 0, 0, a.dimension == 3 ? eps : 0.0};
      const std::vector<double> theta = law(m).dilatation(m, affine(m, g));
      double worst = 0.0;  // θ = 3ε (3D), 2ε (2D) on every node, surface and corner nodes too
      for (double t : theta) worst = std::max(worst, std::fabs(t - a.dimension * eps));
      EXPECT_LT(worst, 1e-12 * a.dimension * eps) << a.name << " " << w;
    }
}

TEST(Lps, StrainEnergyOfAUniformDeformationIsTheContinuumValueWithTheDiscreteWeightedVolume) {
  for (const Analysis& a : kAnalyses)
    for (const char* w : {"one", "inverse_length", "gaussian"}) {
      const double nu = 0.3;
      const pd::Model m = lattice(a.dimension, a.name, {nu, w});
      const pd::LpsModuli k = pd::lps_moduli(kE, nu, a.name);
      const std::size_t i = centre(m);
      // Dilatation: e^d = 0 exactly, W = κθ²/2 with θ = dε on every node.
      const double eps = 1e-3;
      const double gd[9] = {eps, 0, 0, 0, eps, 0, 0, 0, a.dimension == 3 ? eps : 0.0};
      const double expected = 0.5 * k.kappa * (a.dimension * eps) * (a.dimension * eps);
      const std::vector<double> wd = m.bond_model->strain_energy_density(m, affine(m, gd));
      EXPECT_NEAR(wd[i], expected, 1e-10 * expected) << a.name << " " << w;
      EXPECT_NEAR(wd[0], expected, 1e-10 * expected) << a.name << " " << w << " (a corner node)";
      // Shear: the lattice's two shears (along the axes, ε = diag(γ, −γ, 0), and at 45°, ε_xy = γ)
      // average to the continuum μ ε^d:ε^d = 2μγ² over orientations: (2W_A + 3W_B)/5 for the cubic
      // lattice (the Voigt average), (W_A + W_B)/2 for the square one. The mean of ±γ cancels the
      // odd terms of the large-deformation extension, leaving O(γ²) relative.
      const double gamma = 2e-6;
      double wa = 0.0, wb = 0.0;
      for (double sgn : {1.0, -1.0}) {
        const double ga[9] = {sgn * gamma, 0, 0, 0, -sgn * gamma, 0, 0, 0, 0};
        const double gb[9] = {0, sgn * gamma, 0, sgn * gamma, 0, 0, 0, 0, 0};
        wa += 0.5 * m.bond_model->strain_energy_density(m, affine(m, ga))[i];
        wb += 0.5 * m.bond_model->strain_energy_density(m, affine(m, gb))[i];
      }
      const double average = a.dimension == 3 ? (2 * wa + 3 * wb) / 5 : (wa + wb) / 2;
      const double continuum = 2.0 * k.mu * gamma * gamma;
      EXPECT_NEAR(average, continuum, 1e-10 * continuum) << a.name << " " << w;
      std::printf("[ lps      ] %s ω=%s: lattice shear factors W_A/W = %.6f, W_B/W = %.6f\n", a.name, w,
                  wa / continuum, wb / continuum);
    }
}

namespace {

// A 6×5×4 brick (or 6×5 plate), breakable, with one bond broken (both copies) and a smooth
// stretch plus a wiggle: a state where the variational term of a broken family matters.
pd::Model brick(int dimension, const std::string& analysis, const std::string& w = "gaussian") {
  pd::Model m = pd::build_model(lps_case(dimension, analysis, {0.3, w, 1.0}),
                                pdtest::cubic_lattice(6, 5, dimension == 3 ? 4 : 1, kDx, dimension, 1e-3));
  const auto j = static_cast<std::size_t>(m.bonds.neighbour[3]);
  m.bonds.broken[3] = 1;
  for (std::int64_t k = m.bonds.offsets[j]; k < m.bonds.offsets[j + 1]; ++k)
    if (m.bonds.neighbour[static_cast<std::size_t>(k)] == 0) m.bonds.broken[static_cast<std::size_t>(k)] = 1;
  return m;
}

pd::State deformed(const pd::Model& m) {
  pd::State s(m.nodes.size());
  const pd::Vec3Array wiggle = pdtest::pseudo_random(s.size(), 7);
  for (std::size_t i = 0; i < s.size(); ++i) {
    s.u[0][i] = 2e-3 * m.nodes.x[0][i] + 1e-6 * wiggle[0][i];
    s.u[1][i] = -5e-4 * m.nodes.x[1][i] + 1e-6 * wiggle[1][i];
    if (m.nodes.dimension == 3) s.u[2][i] = 1e-6 * wiggle[2][i];
  }
  return s;
}

pd::Vec3Array jacobian_product(const pd::Model& m, const pd::Vec3Array& u, const pd::Vec3Array& x) {
  pd::Vec3Array y = pd::make_vec3(m.nodes.size());
  m.bond_model->add_jacobian_product(m, u, x, y);
  return y;
}

}  // namespace

TEST(Lps, ForceIsTheGradientOfTheStrainEnergyWithABrokenBond) {
  for (const Analysis& a : kAnalyses) {
    const pd::Model m = brick(a.dimension, a.name);
    const pd::State s = deformed(m);
    const pd::Vec3Array x = pdtest::pseudo_random(m.nodes.size(), 3);
    const double h = 1e-7 * kDx;
    pd::Vec3Array plus = s.u, minus = s.u;
    for (int d = 0; d < 3; ++d)
      for (std::size_t i = 0; i < m.nodes.size(); ++i) {
        plus[d][i] += h * x[d][i];
        minus[d][i] -= h * x[d][i];
      }
    const double du = (total_energy(m, plus) - total_energy(m, minus)) / (2 * h);
    const double work = pdtest::volume_dot(m.nodes.volume, force(m, s.u), x);  // Σ V_i f_i·x_i = −dU
    EXPECT_NEAR(du, -work, 1e-7 * std::fabs(work)) << a.name;
  }
}

TEST(Lps, JacobianProductEqualsTheFiniteDifferenceOfTheForce) {
  for (const Analysis& a : kAnalyses)
    for (const char* w : {"one", "gaussian"}) {
      pd::Model m = brick(a.dimension, a.name, w);
      const pd::ForceOperator op(m);
      const pd::State s = deformed(m);
      const pd::Vec3Array x = pdtest::pseudo_random(m.nodes.size(), 11);
      const pd::Vec3Array jx = jacobian_product(m, s.u, x);
      const pd::Vec3Array fd = pdtest::force_difference(op, s, 0.0, x, 1e-9);
      EXPECT_LT(pdtest::distance(jx, fd), 1e-7 * pdtest::norm(fd)) << a.name << " " << w;
    }
}

TEST(Lps, JacobianIsSymmetricAndZeroOnRigidMotions) {
  for (const Analysis& a : kAnalyses) {
    const pd::Model m = brick(a.dimension, a.name);
    const pd::State s = deformed(m);
    const std::size_t n = m.nodes.size();
    const pd::Vec3Array x = pdtest::pseudo_random(n, 5), z = pdtest::pseudo_random(n, 6);
    // Σ V x·(J z) = Σ V z·(J x): J is the Hessian of −U (up to the volumes), at a deformed state with a broken bond.
    const double xjz = pdtest::volume_dot(m.nodes.volume, x, jacobian_product(m, s.u, z));
    const double zjx = pdtest::volume_dot(m.nodes.volume, z, jacobian_product(m, s.u, x));
    EXPECT_NEAR(xjz, zjx, 1e-12 * std::fabs(xjz)) << a.name;
    // A translation at any state, and an infinitesimal rotation about the reference, move no force.
    pd::Vec3Array shift = pd::make_vec3(n), turn = pd::make_vec3(n);
    for (std::size_t i = 0; i < n; ++i) {
      shift[0][i] = 1.0, shift[1][i] = -2.0, shift[2][i] = 0.5;
      turn[0][i] = -m.nodes.x[1][i], turn[1][i] = m.nodes.x[0][i];  // about z
    }
    const pd::Vec3Array zero = pd::make_vec3(n);
    const double scale = pdtest::norm(jacobian_product(m, zero, x)) / pdtest::norm(x);
    EXPECT_LT(pdtest::norm(jacobian_product(m, s.u, shift)), 1e-12 * scale * pdtest::norm(shift)) << a.name;
    EXPECT_LT(pdtest::norm(jacobian_product(m, zero, turn)), 1e-12 * scale * pdtest::norm(turn)) << a.name;
  }
}

TEST(Lps, ReferenceStiffnessIsMinusTheMassScaledJacobianAtRest) {
  for (const Analysis& a : kAnalyses) {
    pd::Model m = pd::build_model(lps_case(a.dimension, a.name, {0.3, "gaussian"}),
                                  pdtest::cubic_lattice(6, 5, a.dimension == 3 ? 4 : 1, kDx, a.dimension, 1e-3));
    const std::size_t n = m.nodes.size();
    const pd::Vec3Array x = pdtest::pseudo_random(n, 9);
    pd::Vec3Array y = pd::make_vec3(n), z = pd::make_vec3(n);
    m.bond_model->apply_reference_stiffness(m, {0, 0, 0}, x, y);
    for (int d = 0; d < 3; ++d)
      for (std::size_t i = 0; i < n; ++i) z[d][i] = x[d][i] / std::sqrt(m.density[i] * m.nodes.volume[i]);
    pd::Vec3Array jz = jacobian_product(m, pd::make_vec3(n), z);
    for (int d = 0; d < 3; ++d)
      for (std::size_t i = 0; i < n; ++i) jz[d][i] *= -m.nodes.volume[i] / std::sqrt(m.density[i] * m.nodes.volume[i]);
    EXPECT_LT(pdtest::distance(y, jz), 1e-12 * pdtest::norm(y)) << a.name;
  }
}

TEST(Lps, ForceEnergyAndBreakingAreBitwiseTheSameForOneAndTwoThreads) {
  const int saved = omp_get_max_threads();
  struct Result {
    pd::Vec3Array f;
    std::vector<double> w;
    std::vector<std::uint8_t> broken;
    pd::BreakReport report;
  };
  const auto run = [](int threads) {
    omp_set_num_threads(threads);
    pd::Model m = pd::build_model(lps_case(3, "3d", {0.3, "gaussian", 1e-4}), pdtest::cubic_lattice(11, 9, 7, kDx, 3));
    pd::State s = deformed(m);
    for (std::size_t i = 0; i < s.size(); ++i) s.u[0][i] += 4e-3 * m.nodes.x[0][i] * m.nodes.x[0][i] / kDx;  // some bonds break
    Result r;
    r.f = pd::make_vec3(s.size());
    r.w.assign(s.size(), 0.0);
    r.report = m.bond_model->break_bonds_and_add_force(m, s.u, r.f, r.w.data(), true);
    r.broken = m.bonds.broken;
    return r;
  };
  const Result one = run(1), two = run(2);
  omp_set_num_threads(saved);
  ASSERT_GT(one.report.broken, 0);
  EXPECT_EQ(one.report.broken, two.report.broken);
  EXPECT_EQ(one.report.energy, two.report.energy);
  EXPECT_EQ(one.broken, two.broken);
  EXPECT_EQ(one.w, two.w);
  for (int d = 0; d < 3; ++d) EXPECT_EQ(one.f[d], two.f[d]);
}

TEST(Lps, BreakingReportsTheStrainEnergyTheBodyLoses) {
  pd::Model m = pd::build_model(lps_case(3, "3d", {0.3, "one", 1e-4}), pdtest::cubic_lattice(8, 6, 5, kDx, 3));
  pd::State s = deformed(m);
  for (std::size_t i = 0; i < s.size(); ++i) s.u[0][i] += 4e-3 * m.nodes.x[0][i] * m.nodes.x[0][i] / kDx;
  const double before = total_energy(m, s.u);
  const pd::BreakReport r = m.bond_model->break_bonds(m, s.u, true);
  ASSERT_GT(r.broken, 0);
  EXPECT_NEAR(before - total_energy(m, s.u), r.energy, 1e-12 * before);
}

namespace {

// An n³ periodic simple-cubic lattice with δ = 3.015 dx, its bond list made by hand with minimum
// images (as test_stability.cpp does for PMB): every node has the whole family of 122 bonds.
struct Periodic {
  pd::Model model;
  std::array<double, 3> period;
};

Periodic periodic_lattice(int n, const Lps& p) {
  Periodic out;
  out.model = pd::build_model(lps_case(3, "3d", p), pdtest::cubic_lattice(n, n, n, kDx, 3));
  out.period = {n * kDx, n * kDx, n * kDx};
  pd::BondList& bonds = out.model.bonds;
  bonds = pd::BondList{};
  bonds.offsets.push_back(0);
  const auto wrap = [n](int i) { return ((i % n) + n) % n; };
  for (int k = 0; k < n; ++k)
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i) {
        for (int a = -3; a <= 3; ++a)
          for (int b = -3; b <= 3; ++b)
            for (int c = -3; c <= 3; ++c)
              if (a * a + b * b + c * c > 0 && a * a + b * b + c * c <= 9) {
                bonds.neighbour.push_back(static_cast<std::int32_t>(pdtest::node_index(wrap(i + a), wrap(j + b), wrap(k + c), n, n)));
                bonds.broken.push_back(0);
              }
        bonds.offsets.push_back(static_cast<std::int64_t>(bonds.neighbour.size()));
      }
  return out;
}

// √(2ρ / Σ_j term_j) over one node's whole family for a per-bond stiffness term(|ξ|, ω).
template <class Term>
double family_step(const Periodic& p, Term term) {
  double sum = 0.0;
  for (int a = -3; a <= 3; ++a)
    for (int b = -3; b <= 3; ++b)
      for (int c = -3; c <= 3; ++c)
        if (a * a + b * b + c * c > 0 && a * a + b * b + c * c <= 9) sum += term(kDx * std::sqrt(double(a * a + b * b + c * c)));
  return std::sqrt(2.0 * p.model.density[0] / sum);
}

}  // namespace

TEST(Lps, StableStepBoundsTheExactLimitForEveryPoissonRatio) {
  // The exact limit 2/ω_max of the infinite lattice (Lanczos on the periodic operator) against the
  // step of our bound (LpsModel::bond_stiffness) and Peridigm's/CabanaPD's (PMB's eq. 2.5 with
  // c = 18K/(πδ⁴)). Ours is below the limit for every ν; theirs is not below ν ≈ −0.2.
  for (const char* w : {"one", "gaussian"})
    for (double nu : {-0.5, 0.0, 0.25, 0.45}) {
      const Periodic p = periodic_lattice(8, {nu, w});
      const pd::LanczosReport r = pd::largest_eigenvalue(p.model, p.period);
      ASSERT_TRUE(r.converged);
      const double exact = 2.0 / std::sqrt(r.lambda_max);
      const double delta = 3.015 * kDx, v = kDx * kDx * kDx;
      const pd::LpsModuli k = pd::lps_moduli(kE, nu, "3d");
      double mw = 0.0;  // m of the whole family
      family_step(p, [&](double len) {
        mw += pd::influence(pd::influence_named(w), len, delta) * len * len * v;
        return 1.0;
      });
      const double ours = family_step(p, [&](double len) {
        return v * pd::influence(pd::influence_named(w), len, delta) * 2.0 * (9.0 * k.kappa + 15.0 * k.mu) / mw;
      });
      const double peridigm = family_step(p, [&](double len) { return v * 18.0 * k.kappa / (kPi * std::pow(delta, 4)) / len; });
      std::printf("[ lps      ] ω=%s ν=%5.2f: exact/ours %.3f, exact/Peridigm %.3f (Lanczos %d iterations)\n", w, nu,
                  exact / ours, exact / peridigm, r.iterations);
      EXPECT_LT(ours, exact) << w << " ν=" << nu;
      EXPECT_GT(ours, 0.2 * exact) << w << " ν=" << nu;  // and not absurdly small
      if (nu == -0.5) EXPECT_GT(peridigm, exact) << "Peridigm's bound was expected to fail at ν = −0.5";
    }
}

TEST(Lps, StableStepOfTheModelIsItsBondStiffnessSum) {
  // stable_time_step (core/model.cpp) sums LpsModel::bond_stiffness: on a bulk node of a finite
  // lattice it is the family formula above with the node's own m.
  const pd::Model m = lattice(3, "3d", {0.3, "one"}, 13);
  const std::size_t i = centre(m);
  const pd::LpsModuli k = pd::lps_moduli(kE, 0.3, "3d");
  const double mi = law(m).weighted_volume()[i];
  double sum = 0.0;
  for (std::int64_t q = m.bonds.offsets[i]; q < m.bonds.offsets[i + 1]; ++q) sum += m.nodes.volume[0] * 2.0 * (9 * k.kappa + 15 * k.mu) / mi;
  EXPECT_NEAR(pd::node_stiffness(m, i), sum, 1e-12 * sum);
}

TEST(Lps, StaticTensionGivesTheLatticesPoissonRatio) {
  // docs/theory.md C3 in 3D with ν = 0.3: a 36 × 15 × 15 bar (dx = 1 mm, δ = 3.015 dx), u_x = 0 on its
  // left face (and three components more against rigid motion), σ = 1 MPa as the body force σ/dx on
  // its right face. The linearised problem −J(0) u = b is solved by conjugate gradients with the
  // matrix-free J·x (the implicit integrators' path for a state-based law). Interior strains are
  // fitted 2δ from the lateral faces over the middle third of the length.
  const int nx = 36, ny = 15, nz = 15;
  const char* env_nu = std::getenv("PD_LPS_NU");  // a measurement at another ν (default 0.3)
  const double nu = env_nu ? std::atof(env_nu) : 0.3, sigma = 1e6;
  const char* env = std::getenv("PD_LPS_INFLUENCE");  // the influence function (default one)
  const std::string w = env ? env : "one";
  const pd::Model m = pd::build_model(lps_case(3, "3d", {nu, w}), pdtest::cubic_lattice(nx, ny, nz, kDx, 3));
  // The fit's interior: y and z indices 6..8, i.e. 2δ from the lateral faces (static_tension.hpp).
  const pdtest::Tension tension = pdtest::static_tension(m, nx, ny, nz, kDx, sigma, 6);
  ASSERT_TRUE(tension.converged) << tension.iterations << " iterations";
  const int iterations = tension.iterations;
  const double exx = tension.interior_xx, eyy = tension.interior_yy;
  // The cubic lattice's prediction: K exact (the dilatation is, on the discrete family), the axis
  // shear modulus μ·r_A: S11 = 1/(9K) + 1/(3μ r_A), S12 = 1/(9K) − 1/(6μ r_A).
  // (lps_lattice.hpp)
  const pdtest::BulkStrains bulk = pdtest::lps_bulk_tension(kE, nu, "3d", pdtest::axis_shear_factor(3, 3.015, w));
  const double lattice_xx = bulk.axial * sigma / kE, lattice_yy = -bulk.lateral * lattice_xx;
  std::printf("[ lps      ] static tension ν = %.2f, ω = %s, %d CG iterations: ε_xx E/σ = %.4f (lattice %.4f), "
              "ε_yy E/σ = %.4f (lattice %.4f, continuum −ν = %.4f); apparent ν = %.4f (lattice %.4f)\n",
              nu, w.c_str(), iterations, exx * kE / sigma, lattice_xx * kE / sigma, eyy * kE / sigma,
              lattice_yy * kE / sigma, -nu, -eyy / exx, -lattice_yy / lattice_xx);
  // The apparent Poisson ratio is the lattice's to 2 % (measured 0.3345 against 0.3293: the cubic
  // family's shear anisotropy at m = 3, not the continuum's 0.3); the axial strain lies between the
  // continuum's σ/E and the lattice's (measured 1.054 σ/E: a 15-node cross-section is stiffened by its
  // surface layers, the C1 factor of docs/theory.md C3).
  EXPECT_NEAR(-eyy / exx, -lattice_yy / lattice_xx, 0.02 * (-lattice_yy / lattice_xx));
  EXPECT_GT(exx, sigma / kE);
  EXPECT_LT(exx, lattice_xx);
  if (!env_nu) EXPECT_LT(std::fabs(-eyy / exx - nu), 0.15 * nu);  // 11.5 % above ν, measured
}

TEST(Lps, FusedBreakingAndForceEqualBreakingThenForceBitwise) {
  // The integrators' path (breaking fused into the dilatation sweep, W from the force sweep) against
  // breaking alone, then the force, then the strain energy of the slow exact row code.
  const auto make = [] {
    pd::Model m = pd::build_model(lps_case(3, "3d", {0.3, "gaussian", 1e-4}), pdtest::cubic_lattice(9, 8, 7, kDx, 3));
    return m;
  };
  pd::Model a = make(), b = make();
  pd::State s = deformed(a);
  for (std::size_t i = 0; i < s.size(); ++i) s.u[0][i] += 4e-3 * a.nodes.x[0][i] * a.nodes.x[0][i] / kDx;
  pd::Vec3Array fa = pd::make_vec3(s.size()), fb = pd::make_vec3(s.size());
  std::vector<double> wa(s.size()), wb(s.size());
  const pd::BreakReport ra = a.bond_model->break_bonds_and_add_force(a, s.u, fa, wa.data(), true);
  const pd::BreakReport rb = b.bond_model->break_bonds(b, s.u, true);
  b.bond_model->add_force(b, s.u, fb, wb.data());
  ASSERT_GT(ra.broken, 0);
  EXPECT_EQ(ra.broken, rb.broken);
  EXPECT_EQ(ra.energy, rb.energy);
  EXPECT_EQ(a.bonds.broken, b.bonds.broken);
  for (int d = 0; d < 3; ++d) EXPECT_EQ(fa[d], fb[d]);
  EXPECT_EQ(wa, wb);
  EXPECT_EQ(wa, b.bond_model->strain_energy_density(b, s.u));
}

namespace {

bool same_bits(const std::vector<double>& a, const std::vector<double>& b) {
  return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof(double)) == 0;
}

}  // namespace

TEST(Lps, Avx2RowsAreBitwiseThePortableRows) {
  // The AVX2 rows of both sweeps (materials/lps/lps_row_avx2.hpp) give the portable rows' bits
  // (lps_row.hpp) for every influence function and every variant of the kernel's input: one block
  // of equal full volumes, partial volumes (ν from |ξ|), two blocks with a no-fail set, unequal
  // volumes, an energy surface correction (g per bond) with HHB's partial volumes; rows whose
  // lengths are not multiples of 4 (a 9×8×7 brick: the portable tail); a bond crushed to a point;
  // three rounds of random displacements that break bonds. Compared bit for bit: θ (the sweep
  // without breaking), f and W without breaking, then with breaking: the counts, flags, f, W and
  // the lost energy per node.
  if (!pd::avx2_rows()) GTEST_SKIP() << "no AVX2 rows here (a CPU without AVX2, or a build other than GCC on x86-64)";
  struct Restore {  // the AVX2 rows on again for the tests after this one, even if an ASSERT ends it
    ~Restore() { pd::set_avx2_rows(true); }
  } restore;
  struct Variant {
    const char* name;
    bool two_blocks;
    const char* partial_volume;
    bool unequal_volumes;
    const char* correction;
  };
  const Variant variants[] = {
      {"uniform", false, "none", false, "none"},       {"partial volumes", false, "lammps", false, "none"},
      {"two blocks", true, "none", false, "none"},     {"unequal volumes", false, "none", true, "none"},
      {"surface correction", false, "hhb", false, "energy"},
  };
  std::int64_t rows_not_multiple_of_4 = 0;
  for (const char* w : {"one", "inverse_length", "gaussian"})
    for (const Variant& v : variants) {
      const std::string what = std::string(w) + ", " + v.name;
      const auto make = [&] {
        // s0 of a few 1e-3 (G0 = 100 J/m²): the random stretches below break a part of the bonds per round.
        pd::Case c = lps_case(3, "3d", {0.3, w, 100.0});
        c.partial_volume = v.partial_volume;
        c.surface_correction = v.correction;
        pd::Nodes nodes = pdtest::cubic_lattice(9, 8, 7, kDx, 3, 1e-3);
        if (v.unequal_volumes)
          for (std::size_t i = 0; i < nodes.size(); ++i) nodes.volume[i] *= 1.0 + 0.01 * static_cast<double>(i % 7);
        if (v.two_blocks)  // the upper half stiffer and tougher; the bottom layer a no-fail set
          pdtest::add_stiff_top_and_no_fail_bottom(c, nodes, kDx, 3 * kE, 400.0);
        return pd::build_model(c, std::move(nodes));
      };
      pd::Model models[2] = {make(), make()};  // [0] AVX2 rows, [1] portable rows
      const std::size_t n = models[0].nodes.size();
      ASSERT_EQ(models[0].bonds.corrected(), std::string(v.correction) != "none") << what;
      for (std::size_t i = 0; i < n; ++i)
        rows_not_multiple_of_4 += (models[0].bonds.offsets[i + 1] - models[0].bonds.offsets[i]) % 4 != 0;
      std::int64_t broke[3] = {0, 0, 0};
      for (unsigned round = 0; round < 3; ++round) {
        std::mt19937 rng(31 + round);
        std::uniform_real_distribution<double> d(-(0.001 + 0.002 * round) * kDx, (0.001 + 0.002 * round) * kDx);
        pd::Vec3Array u = pd::make_vec3(n);
        for (auto& c : u)
          for (double& x : c) x = d(rng);
        if (round == 1) {  // node 100's first neighbour moved onto it: y = 0, 1/y replaced by 1
          const auto j = static_cast<std::size_t>(models[0].bonds.neighbour[static_cast<std::size_t>(models[0].bonds.offsets[100])]);
          for (std::size_t c = 0; c < 3; ++c) u[c][j] = models[0].nodes.x[c][100] + u[c][100] - models[0].nodes.x[c][j];
        }
        std::vector<double> theta[2], w_plain[2], w_break[2], lost[2];
        pd::Vec3Array f_plain[2], f_break[2];
        pd::BreakReport report[2];
        for (int r = 0; r < 2; ++r) {
          pd::set_avx2_rows(r == 0);
          pd::Model& m = models[r];
          ASSERT_EQ(pd::LpsKernel(law(m), m, u).avx2, r == 0) << what;
          theta[r] = m.bond_model->dilatation(m, u);
          f_plain[r] = pd::make_vec3(n);
          w_plain[r].assign(n, 0.0);
          m.bond_model->add_force(m, u, f_plain[r], w_plain[r].data());
          f_break[r] = pd::make_vec3(n);
          w_break[r].assign(n, 0.0);
          lost[r].assign(n, 0.0);
          report[r] = m.bond_model->break_bonds_and_add_force(m, u, f_break[r], w_break[r].data(), true, lost[r].data());
        }
        broke[round] = report[0].broken;
        const std::string at = what + ", round " + std::to_string(round);
        EXPECT_TRUE(same_bits(theta[0], theta[1])) << at << ": θ";
        for (std::size_t c = 0; c < 3; ++c) {
          EXPECT_TRUE(same_bits(f_plain[0][c], f_plain[1][c])) << at << ": f without breaking, component " << c;
          EXPECT_TRUE(same_bits(f_break[0][c], f_break[1][c])) << at << ": f with breaking, component " << c;
        }
        EXPECT_TRUE(same_bits(w_plain[0], w_plain[1])) << at << ": W without breaking";
        EXPECT_TRUE(same_bits(w_break[0], w_break[1])) << at << ": W with breaking";
        EXPECT_TRUE(same_bits(lost[0], lost[1])) << at << ": lost energy";
        EXPECT_EQ(report[0].broken, report[1].broken) << at;
        EXPECT_EQ(models[0].bonds.broken, models[1].bonds.broken) << at << ": flags";
      }
      std::int64_t intact = 0;
      for (std::uint8_t b : models[0].bonds.broken) intact += b == 0;
      EXPECT_GT(broke[1], 0) << what << ": nothing broke in round 1, the rounds would not test the flags";
      EXPECT_GT(broke[2], 0) << what << ": nothing broke in round 2, the rounds would not test the flags";
      EXPECT_GT(intact, 0) << what << ": everything broke, the last rounds tested nothing";
      std::printf("[ lps      ] %s: bonds broken per round %lld %lld %lld; %lld of %zu directed bonds intact\n",
                  what.c_str(), static_cast<long long>(broke[0]), static_cast<long long>(broke[1]),
                  static_cast<long long>(broke[2]), static_cast<long long>(intact), models[0].bonds.broken.size());
    }
  EXPECT_GT(rows_not_multiple_of_4, 0) << "every row a multiple of 4 bonds: the portable tail went untested";
}

TEST(Lps, VerletFreeVibrationConservesEnergyToSecondOrder) {
  // docs/theory.md C4 with LPS: a free 12 × 12 plane-stress plate (ν = 0.3) vibrating in its lowest
  // modes under velocity Verlet at 0.8 × the stable step: KE + U does not drift, and halving Δt
  // cuts its oscillation about 4× (second order) — the force is the gradient of U.
  const pdtest::OneThread one_thread;
  pd::Model m = pd::build_model(lps_case(2, "plane_stress", {0.3, "one"}), pdtest::cubic_lattice(12, 12, 1, kDx, 2, 1e-3));
  const double dt0 = 0.8 * pd::stable_time_step(m);
  const double lx = 11 * kDx;
  const auto energy = [&](const pd::State& s) {
    double e = total_energy(m, s.u);
    for (std::size_t i = 0; i < s.size(); ++i)
      e += 0.5 * m.density[i] * m.nodes.volume[i] * (s.v[0][i] * s.v[0][i] + s.v[1][i] * s.v[1][i]);
    return e;
  };
  double oscillation[2], drift[2];
  for (int r = 0; r < 2; ++r) {
    pd::State s(m.nodes.size());
    for (std::size_t i = 0; i < s.size(); ++i) {
      s.v[0][i] = std::sin(kPi * m.nodes.x[0][i] / lx) * std::cos(kPi * m.nodes.x[1][i] / lx);
      s.v[1][i] = 0.5 * std::cos(2 * kPi * m.nodes.x[0][i] / lx);
    }
    const double e0 = energy(s);
    pd::ForceOperator op(m);
    auto integrator = pd::integrator_registry().get("verlet")(op);
    double t = 0.0, worst = 0.0, early = 0.0, late = 0.0;
    int samples = 0;
    integrator->initialize(s, t);
    const int steps = 3000 << r;
    for (int k = 1; k <= steps; ++k) {
      double h = dt0 / (1 << r);
      integrator->step(s, t, h);
      if (k % (10 << r) == 0) {
        const double e = energy(s);
        worst = std::max(worst, std::fabs(e - e0) / e0);
        if (k <= steps / 10) early += e / e0, ++samples;
        if (k > steps - steps / 10) late += e / e0;
      }
    }
    oscillation[r] = worst;
    drift[r] = std::fabs(late - early) / samples;
  }
  std::printf("[ lps      ] energy: drift %.3g (dt/2: %.3g), oscillation %.3g (dt/2: %.3g), ratio %.3f\n", drift[0],
              drift[1], oscillation[0], oscillation[1], oscillation[0] / oscillation[1]);
  EXPECT_LT(drift[0], 1e-3);
  EXPECT_LT(drift[1], 1e-3);
  EXPECT_GT(oscillation[0] / oscillation[1], 3.5);
  EXPECT_LT(oscillation[0] / oscillation[1], 4.5);
}

namespace {

// An nx × ny × nz lattice periodic along every axis with more than one node (δ = 3.015 dx, so an
// axis of n ≥ 7 nodes gives each bond one minimum image), its bond list made by hand as
// periodic_lattice's: every node has the whole family (3D: 122 bonds, 2D: 28).
Periodic periodic_box(int dimension, const char* analysis, int nx, int ny, int nz, const Lps& p) {
  Periodic out;
  out.model = pd::build_model(lps_case(dimension, analysis, p), pdtest::cubic_lattice(nx, ny, nz, kDx, dimension, 1e-3));
  out.period = {nx * kDx, ny * kDx, nz > 1 ? nz * kDx : 0.0};
  pd::BondList& bonds = out.model.bonds;
  bonds = pd::BondList{};
  bonds.offsets.push_back(0);
  const auto wrap = [](int i, int n) { return ((i % n) + n) % n; };
  const int cz = nz > 1 ? 3 : 0;
  for (int k = 0; k < nz; ++k)
    for (int j = 0; j < ny; ++j)
      for (int i = 0; i < nx; ++i) {
        for (int a = -3; a <= 3; ++a)
          for (int b = -3; b <= 3; ++b)
            for (int c = -cz; c <= cz; ++c)
              if (a * a + b * b + c * c > 0 && a * a + b * b + c * c <= 9) {
                bonds.neighbour.push_back(static_cast<std::int32_t>(
                    pdtest::node_index(wrap(i + a, nx), wrap(j + b, ny), wrap(k + c, nz), nx, ny)));
                bonds.broken.push_back(0);
              }
        bonds.offsets.push_back(static_cast<std::int64_t>(bonds.neighbour.size()));
      }
  return out;
}

}  // namespace

TEST(Lps, PlaneWavesOnTheInfiniteLatticeFollowTheDiscreteDispersionRelation) {
  // The discrete LPS dispersion relation of a bulk lattice (validation/wave.py chain_omega_squared
  // derives it from the linearised energy, Silling et al. 2007): a plane wave u = U cos(k·x) is an
  // eigenvector of the stiffness with ρω²U = D(k)U,
  //   D(k) = (κ − α/d²)(d/m)² S Sᵀ + (α/m) Σ_j ω V 2(1 − cos k·ξ_j) n_j n_jᵀ,  S = Σ_j ω|ξ_j| V n_j sin(k·ξ_j),
  // D diagonal for k along a lattice axis. Here the solver's own linear operator (the reference
  // stiffness, whose largest eigenvalue sets the exact stable step) is applied to the wave on a
  // periodic 3D and plane-stress lattice, long (kδ = 0.53) and shorter (kδ = 1.58) waves,
  // longitudinal and transverse: it returns ω²·u to 1e-12, and the shorter wave is slower. The
  // printed long-wave speeds differ from the continuum's √((K + 4μ/3)/ρ), √(μ/ρ) (3D) and
  // √((κ + μ)/ρ), √(μ/ρ) (plane stress) by the lattice's anisotropy at m = 3 (the discrete family's
  // fourth moments are not isotropic, as for PMB in docs/theory.md C1/C3): measured −3.9 % and +5.0 %
  // (3D), +0.01 % and −2.2 % (plane stress) at kδ = 0.53.
  struct Setup {
    int dimension;
    const char* analysis;
    int nx, ny, nz;
  };
  const double rho = 1000.0, delta = 3.015 * kDx;
  for (const Setup& s : {Setup{3, "3d", 36, 7, 7}, Setup{2, "plane_stress", 36, 7, 1}}) {
    const Periodic p = periodic_box(s.dimension, s.analysis, s.nx, s.ny, s.nz, {0.3, "one"});
    const std::size_t n = p.model.nodes.size();
    const pd::LpsModuli mod = pd::lps_moduli(kE, 0.3, s.analysis);
    const double d = s.dimension, alpha = (s.dimension == 3 ? 15.0 : 8.0) * mod.mu;
    const double v = p.model.nodes.volume[0];
    const double continuum[2] = {
        std::sqrt((s.dimension == 3 ? mod.kappa + 4.0 * mod.mu / 3.0 : mod.kappa + mod.mu) / rho),
        std::sqrt(mod.mu / rho)};
    double long_speed[2] = {0, 0}, short_speed[2] = {0, 0};
    for (int q : {1, 3}) {
      const double k = 2.0 * kPi * q / (s.nx * kDx);
      // D's diagonal from the family of one node (lattice sums, independent of the solver's code)
      double m = 0.0, sx = 0.0, dxx = 0.0, dyy = 0.0;
      const int cz = s.dimension == 3 ? 3 : 0;
      for (int a = -3; a <= 3; ++a)
        for (int b = -3; b <= 3; ++b)
          for (int c = -cz; c <= cz; ++c) {
            const int r2 = a * a + b * b + c * c;
            if (r2 == 0 || r2 > 9) continue;
            const double len = kDx * std::sqrt(double(r2)), nx = a * kDx / len, ny = b * kDx / len;
            m += len * len * v;
            sx += len * v * nx * std::sin(k * a * kDx);
            dxx += v * 2.0 * (1.0 - std::cos(k * a * kDx)) * nx * nx;
            dyy += v * 2.0 * (1.0 - std::cos(k * a * kDx)) * ny * ny;
          }
      const double omega2[2] = {((mod.kappa - alpha / (d * d)) * (d / m) * (d / m) * sx * sx + alpha / m * dxx) / rho,
                                alpha / m * dyy / rho};
      for (int polar = 0; polar < 2; ++polar) {
        pd::Vec3Array x = pd::make_vec3(n), y = pd::make_vec3(n);
        for (std::size_t i = 0; i < n; ++i) x[polar][i] = std::cos(k * p.model.nodes.x[0][i]);
        p.model.bond_model->apply_reference_stiffness(p.model, p.period, x, y);
        for (std::size_t i = 0; i < n; ++i) x[polar][i] *= omega2[polar];
        EXPECT_LT(pdtest::distance(y, x), 1e-12 * pdtest::norm(x)) << s.analysis << " q=" << q << " polar " << polar;
        const double speed = std::sqrt(omega2[polar]) / k;
        (q == 1 ? long_speed : short_speed)[polar] = speed;
        std::printf("[ lps      ] %s %s kδ=%.3f: phase speed %.2f m/s (continuum %.2f, %+.4f)\n", s.analysis,
                    polar ? "transverse" : "longitudinal", k * delta, speed, continuum[polar],
                    speed / continuum[polar] - 1.0);
      }
    }
    for (int polar = 0; polar < 2; ++polar) EXPECT_LT(short_speed[polar], long_speed[polar]) << s.analysis;
  }
}

namespace {

// ∂f_i/∂u_i by central differences of the force: node i alone moved by ±h along each axis.
std::array<double, 9> node_block_by_difference(const pd::Model& m, const pd::Vec3Array& u, std::size_t i, double h) {
  std::array<double, 9> out{};
  for (int c = 0; c < 3; ++c) {
    pd::Vec3Array plus = u, minus = u;
    plus[c][i] += h;
    minus[c][i] -= h;
    const pd::Vec3Array fp = force(m, plus), fm = force(m, minus);
    for (int r = 0; r < 3; ++r) out[static_cast<std::size_t>(3 * r + c)] = (fp[r][i] - fm[r][i]) / (2 * h);
  }
  return out;
}

// The smallest eigenvalue's sign of a symmetric 3×3 block, by its principal minors: true when
// −block is positive semi-definite (every principal minor of −block ≥ −tol·scale^k).
bool minus_is_semi_definite(const double* b, double scale) {
  const auto at = [b](int r, int c) { return -b[3 * r + c]; };
  const double tol = 1e-12;
  for (int r = 0; r < 3; ++r)
    if (at(r, r) < -tol * scale) return false;
  for (int r = 0; r < 3; ++r)
    for (int c = r + 1; c < 3; ++c)
      if (at(r, r) * at(c, c) - at(r, c) * at(c, r) < -tol * scale * scale) return false;
  const double det = at(0, 0) * (at(1, 1) * at(2, 2) - at(1, 2) * at(2, 1)) -
                     at(0, 1) * (at(1, 0) * at(2, 2) - at(1, 2) * at(2, 0)) +
                     at(0, 2) * (at(1, 0) * at(2, 1) - at(1, 1) * at(2, 0));
  return det >= -tol * scale * scale * scale;
}

}  // namespace

TEST(Lps, DiagonalBlocksAreTheFiniteDifferenceOfTheForce) {
  // The block-Jacobi preconditioner's blocks (lps_tangent.cpp) at a deformed state with a broken
  // bond, on every node of a small brick (corners, edges, faces: b_i ≠ 0 there), both influence
  // functions and every analysis; ν = 0.2 too, where γ = (3K − 5μ)/m < 0 in 3D.
  for (const Analysis& a : kAnalyses)
    for (const char* w : {"one", "gaussian"})
      for (const double nu : {0.3, 0.2}) {
        pd::Model m = pd::build_model(lps_case(a.dimension, a.name, {nu, w, 1.0}),
                                      pdtest::cubic_lattice(6, 5, a.dimension == 3 ? 4 : 1, kDx, a.dimension, 1e-3));
        const auto j = static_cast<std::size_t>(m.bonds.neighbour[3]);  // break bond 0–j (both copies), as brick() does
        m.bonds.broken[3] = 1;
        for (std::int64_t k = m.bonds.offsets[j]; k < m.bonds.offsets[j + 1]; ++k)
          if (m.bonds.neighbour[static_cast<std::size_t>(k)] == 0) m.bonds.broken[static_cast<std::size_t>(k)] = 1;
        const pd::State s = deformed(m);
        std::vector<double> blocks;
        ASSERT_TRUE(m.bond_model->jacobian_diagonal_blocks(m, s.u, blocks, false));
        ASSERT_EQ(blocks.size(), 9 * m.nodes.size());
        double worst = 0.0;
        for (std::size_t i = 0; i < m.nodes.size(); ++i) {
          const std::array<double, 9> fd = node_block_by_difference(m, s.u, i, 1e-9);
          double scale = 0.0, error = 0.0;
          for (int q = 0; q < 9; ++q) {
            scale = std::max(scale, std::fabs(fd[static_cast<std::size_t>(q)]));
            error = std::max(error, std::fabs(blocks[9 * i + static_cast<std::size_t>(q)] - fd[static_cast<std::size_t>(q)]));
          }
          ASSERT_LT(error, 1e-6 * scale) << a.name << " ω=" << w << " ν=" << nu << " node " << i;
          worst = std::max(worst, error / scale);
        }
        std::printf("[ lps      ] %s ω=%s ν=%.1f: diagonal blocks against the force's difference, worst %.2e relative\n",
                    a.name, w, nu, worst);
      }
}

TEST(Lps, DefiniteDiagonalBlocksArePositiveAndEqualTheFullOnesInTension) {
  for (const Analysis& a : kAnalyses) {
    // Compressed, ν = 0.2 (γ < 0 in 3D): the full blocks may be indefinite, the definite ones not.
    pd::Model m = lattice(a.dimension, a.name, {0.2, "one"}, 7);
    pd::State s(m.nodes.size());
    const pd::Vec3Array wiggle = pdtest::pseudo_random(s.size(), 9);
    for (std::size_t i = 0; i < s.size(); ++i)
      for (int d = 0; d < a.dimension; ++d) s.u[d][i] = -3e-3 * m.nodes.x[d][i] + 2e-6 * wiggle[d][i];
    std::vector<double> definite;
    ASSERT_TRUE(m.bond_model->jacobian_diagonal_blocks(m, s.u, definite, true));
    double scale = 0.0;
    for (double v : definite) scale = std::max(scale, std::fabs(v));
    for (std::size_t i = 0; i < m.nodes.size(); ++i)
      ASSERT_TRUE(minus_is_semi_definite(&definite[9 * i], scale)) << a.name << " node " << i;
    // Stretched, ν = 0.4 (γ > 0 in every analysis — plane stress: 2κ − 4μ > 0 needs ν > 1/3 — and
    // every bond in tension): nothing is left out.
    pd::Model t = lattice(a.dimension, a.name, {0.4, "one"}, 7);
    for (std::size_t i = 0; i < s.size(); ++i)
      for (int d = 0; d < a.dimension; ++d) s.u[d][i] = 2e-3 * t.nodes.x[d][i];
    std::vector<double> full, kept;
    t.bond_model->jacobian_diagonal_blocks(t, s.u, full, false);
    t.bond_model->jacobian_diagonal_blocks(t, s.u, kept, true);
    EXPECT_EQ(full, kept) << a.name;
  }
}
