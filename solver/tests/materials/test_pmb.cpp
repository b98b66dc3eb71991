// The PMB material as a room of its own: its registry entry and parameters, its constants, and
// its linearisation (Jacobian–vector product against a finite difference of its force, symmetry,
// rigid motions, agreement with the reference stiffness behind the exact step limit).
#include <gtest/gtest.h>

#include <cmath>

#include "core/stability.hpp"
#include "jacobian_check.hpp"
#include "lattice.hpp"
#include "materials/bond_model.hpp"
#include "materials/pmb/pmb.hpp"

namespace {

constexpr double kDx = 1e-3;

// A 6×5×4 brick, δ = 3.015dx, breakable; u = a smooth stretch plus a pseudo-random wiggle.
pd::Model brick(int dimension = 3) {
  const pd::Case c = dimension == 3 ? pdtest::lattice_case(3, "3d", kDx, 3.015 * kDx, 1e9, 1000.0, 1.0)
                                    : pdtest::lattice_case(2, "plane_stress", kDx, 3.015 * kDx, 1e9, 1000.0, 1.0, 1e-3);
  return pd::build_model(c, pdtest::cubic_lattice(6, 5, dimension == 3 ? 4 : 1, kDx, dimension, 1e-3));
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

pd::Vec3Array jacobian_product(const pd::ForceOperator& op, const pd::State& s, const pd::Vec3Array& x) {
  pd::Vec3Array y = pd::make_vec3(s.size());
  op.apply_jacobian(s, 0.0, x, y);
  return y;
}

}  // namespace

TEST(Pmb, IsRegisteredWithItsParameters) {
  const pd::MaterialDefinition& pmb = pd::material_registry().get("pmb");
  // E and G0, or c and s0 directly (one pair or the other: pmb.check), and LAMMPS's α.
  ASSERT_EQ(pmb.parameters.size(), 5u);
  const char* names[] = {"youngs_modulus", "fracture_energy", "micromodulus", "critical_stretch",
                         "critical_stretch_alpha"};
  for (std::size_t k = 0; k < 5; ++k) {
    EXPECT_EQ(pmb.parameters[k].name, names[k]);
    EXPECT_FALSE(pmb.parameters[k].required);
  }
  EXPECT_TRUE(pmb.parameters[4].lower_inclusive);  // α = 0 allowed
  ASSERT_NE(pmb.check, nullptr);
  try {
    pd::material_registry().get("lps2");
    FAIL() << "no error";
  } catch (const pd::Error& e) {
    EXPECT_EQ(std::string(e.what()), "unknown material model 'lps2'; known: lps, pmb");
  }
}

TEST(Pmb, ConstantsAreThoseOfValidationF1) {
  pd::BlockMaterial b;
  b.parameters["youngs_modulus"] = 1.0;
  b.parameters["fracture_energy"] = 1.0;
  // docs/theory.md T2: E = 1, δ = 2, G0 = 1 → s0 = 0.6454972243679028 (3D), c = 18K/(πδ⁴), K = 2E/3
  const pd::PairConstants k = pd::pmb_constants(b, "3d", 2.0, 0.0);
  EXPECT_NEAR(k.critical_stretch, 0.6454972243679028, 1e-15);
  EXPECT_DOUBLE_EQ(k.micromodulus, 18.0 * (2.0 / 3.0) / (3.14159265358979323846 * 16.0));
  b.parameters.erase("fracture_energy");
  EXPECT_TRUE(std::isinf(pd::pmb_constants(b, "plane_strain", 2.0, 1.0).critical_stretch));
}

TEST(Pmb, JacobianProductEqualsTheFiniteDifferenceOfTheForce) {
  for (int dimension : {2, 3}) {
    pd::Model m = brick(dimension);
    // Bond 3 of node 0 broken, both copies: it must be left out of both sides.
    const auto j = static_cast<std::size_t>(m.bonds.neighbour[3]);
    m.bonds.broken[3] = 1;
    for (std::int64_t k = m.bonds.offsets[j]; k < m.bonds.offsets[j + 1]; ++k)
      if (m.bonds.neighbour[static_cast<std::size_t>(k)] == 0) m.bonds.broken[static_cast<std::size_t>(k)] = 1;
    const pd::ForceOperator op(m);
    const pd::State s = deformed(m);
    const pd::Vec3Array x = pdtest::pseudo_random(s.size(), 3);
    const pd::Vec3Array jx = jacobian_product(op, s, x);
    const pd::Vec3Array fd = pdtest::force_difference(op, s, 0.0, x, 1e-8);
    EXPECT_LT(pdtest::distance(jx, fd), 1e-7 * pdtest::norm(jx)) << dimension << "D";
  }
}

TEST(Pmb, JacobianIsSymmetricAndZeroOnRigidMotion) {
  pd::Model m = brick();
  const pd::ForceOperator op(m);
  const pd::State s = deformed(m);
  const pd::Vec3Array x = pdtest::pseudo_random(s.size(), 1), y = pdtest::pseudo_random(s.size(), 2);
  const double xjy = pdtest::volume_dot(m.nodes.volume, x, jacobian_product(op, s, y));
  const double yjx = pdtest::volume_dot(m.nodes.volume, y, jacobian_product(op, s, x));
  EXPECT_NEAR(xjy, yjx, 1e-12 * std::fabs(xjy));
  const double scale = pdtest::norm(jacobian_product(op, s, x));
  // A rigid translation stretches no bond, at any state.
  pd::Vec3Array shift = pd::make_vec3(s.size());
  for (std::size_t i = 0; i < s.size(); ++i) shift[0][i] = 0.3, shift[1][i] = -0.2, shift[2][i] = 0.1;
  EXPECT_LT(pdtest::norm(jacobian_product(op, s, shift)), 1e-12 * scale);
  // A small rotation about z stretches no bond to first order at the reference configuration.
  const pd::State rest(s.size());
  pd::Vec3Array turn = pd::make_vec3(s.size());
  for (std::size_t i = 0; i < s.size(); ++i) turn[0][i] = -m.nodes.x[1][i], turn[1][i] = m.nodes.x[0][i];
  EXPECT_LT(pdtest::norm(jacobian_product(op, rest, turn)), 1e-12 * pdtest::norm(jacobian_product(op, rest, x)) * 1e3 * kDx);
}

TEST(Pmb, JacobianAtRestIsTheReferenceStiffnessOfTheExactStepLimit) {
  // core/stability's Lanczos applies M^{-1/2} K M^{-1/2}; at u = 0 the Jacobian is −K/V per node.
  pd::Model m = brick();
  const pd::ForceOperator op(m);
  const pd::State rest(m.nodes.size());
  const pd::Vec3Array x = pdtest::pseudo_random(rest.size(), 5);
  pd::Vec3Array scaled = pd::make_vec3(rest.size()), y = pd::make_vec3(rest.size());
  for (std::size_t d = 0; d < 3; ++d)
    for (std::size_t i = 0; i < rest.size(); ++i) scaled[d][i] = std::sqrt(m.density[i] * m.nodes.volume[i]) * x[d][i];
  pd::apply_symmetric_operator(m, {0.0, 0.0, 0.0}, scaled, y);
  const pd::Vec3Array jx = jacobian_product(op, rest, x);
  pd::Vec3Array expected = pd::make_vec3(rest.size());
  for (std::size_t d = 0; d < 3; ++d)
    for (std::size_t i = 0; i < rest.size(); ++i)
      expected[d][i] = -std::sqrt(m.density[i] * m.nodes.volume[i]) * y[d][i] / m.nodes.volume[i];
  EXPECT_LT(pdtest::distance(jx, expected), 1e-12 * pdtest::norm(jx));
}

TEST(Pmb, BondStiffnessIsTheTermOfEquation25) {
  pd::Model m = brick();
  const std::size_t i = 0;
  const auto j = static_cast<std::size_t>(m.bonds.neighbour[0]);
  const double length = pd::bond_length(m.nodes.x, i, j);
  EXPECT_EQ(m.bond_model->bond_stiffness(m, i, j, length), m.nodes.volume[j] * m.material.micromodulus_pair[0] / length);
}
