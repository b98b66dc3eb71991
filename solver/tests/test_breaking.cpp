// Bond breaking: past s0 a bond breaks for good, from both ends, and carries no force afterwards;
// no-fail sets and unbreakable blocks keep their bonds; damage counts lost family volume.
#include <gtest/gtest.h>

#include <cmath>

#include "materials/pmb/pmb.hpp"
#include "integrators/integrator.hpp"
#include "lattice.hpp"

namespace {

// Two nodes one dx apart along x, one bond.
pd::Model pair_model(double fracture_energy) {
  const double dx = 1e-3;
  const pd::Case c = pdtest::lattice_case(3, "3d", dx, 1.5 * dx, 1e9, 1000.0, fracture_energy);
  return pd::build_model(c, pdtest::cubic_lattice(2, 1, 1, dx, 3));
}

pd::Vec3Array stretched(const pd::Model& m, double s) {
  pd::Vec3Array u = pd::make_vec3(2);
  u[0][1] = s * (m.nodes.x[0][1] - m.nodes.x[0][0]);
  return u;
}

double force_x_on_0(const pd::Model& m, const pd::Vec3Array& u) {
  pd::Vec3Array f = pd::make_vec3(2);
  pd::add_pmb_force(m, u, f);
  return f[0][0];
}

}  // namespace

TEST(Breaking, BondPastCriticalStretchBreaksAndCarriesNoForce) {
  pd::Model m = pair_model(10.0);
  const double s0 = m.material.block[0].critical_stretch;
  ASSERT_GT(s0, 0.0);
  ASSERT_EQ(m.bonds.directed(), 2u);

  // Just below s0: intact, and pulling (force on node 0 points to node 1, +x).
  pd::Vec3Array u = stretched(m, 0.99 * s0);
  EXPECT_EQ(pd::update_broken_bonds(m, u), 0);
  EXPECT_GT(force_x_on_0(m, u), 0.0);
  EXPECT_EQ(pd::bond_damage(m)[0], 0.0);

  // Past s0: breaks, both stored copies, counted once.
  u = stretched(m, 1.01 * s0);
  EXPECT_EQ(pd::update_broken_bonds(m, u), 1);
  EXPECT_EQ(m.bonds.broken[0], 1);
  EXPECT_EQ(m.bonds.broken[1], 1);
  EXPECT_EQ(pd::broken_bond_count(m), 1);
  EXPECT_EQ(force_x_on_0(m, u), 0.0);
  EXPECT_EQ(pd::strain_energy(m, u), 0.0);
  EXPECT_EQ(pd::bond_damage(m)[0], 1.0);

  // Permanently: back to the reference or compressed, still no force, and nothing new breaks.
  EXPECT_EQ(force_x_on_0(m, stretched(m, 0.0)), 0.0);
  EXPECT_EQ(force_x_on_0(m, stretched(m, -0.5 * s0)), 0.0);
  EXPECT_EQ(pd::update_broken_bonds(m, stretched(m, 2 * s0)), 0);
}

// The energy a bond takes with it (history.csv broken_bond_energy, docs/theory.md C4): the PMB bond
// energy w = ½ c s² |ξ| ν V_i V_j at the critical stretch s0 at which it broke, from the closed forms
// of docs/theory.md T2 (3D: c = 12E/(πδ⁴), s0 = √(5G0/(9Kδ)), K = E/(3(1 − 2·¼))), whatever stretch
// past s0 the step that broke it reached. Before issue 16 it was taken at that stretch: 2.25 × here.
TEST(Breaking, ABrokenBondTakesItsEnergyAtTheCriticalStretch) {
  const double dx = 1e-3, delta = 1.5 * dx, E = 1e9, G0 = 10.0;
  const double K = E / (3.0 * (1.0 - 2.0 * 0.25)), c = 12.0 * E / (M_PI * std::pow(delta, 4));
  const double s0 = std::sqrt(5.0 * G0 / (9.0 * K * delta));
  for (const bool with_force : {false, true}) {
    pd::Model m = pair_model(G0);
    ASSERT_NEAR(m.material.block[0].critical_stretch, s0, 1e-12 * s0);
    ASSERT_DOUBLE_EQ(m.nodes.volume[0], dx * dx * dx);
    ASSERT_DOUBLE_EQ(m.nodes.volume[1], dx * dx * dx);
    const double nu = m.bonds.volume_weight(dx);
    const double closed_form = 0.5 * c * s0 * s0 * dx * nu * std::pow(dx, 6);
    const pd::Vec3Array u = stretched(m, 1.5 * s0);  // the step overshot s0 by half
    pd::BreakReport r;
    if (with_force) {  // the path of every integrator: breaking and the force in one sweep
      pd::Vec3Array f = pd::make_vec3(2);
      r = m.bond_model->break_bonds_and_add_force(m, u, f, nullptr, true);
    } else {
      r = m.bond_model->break_bonds(m, u, true);
    }
    EXPECT_EQ(r.broken, 1);
    EXPECT_NEAR(r.energy, closed_form, 1e-12 * closed_form) << (with_force ? "with force" : "breaking only");
    EXPECT_GT(closed_form, 0.0);
  }
}

TEST(Breaking, UnbreakableBlockAndNoFailSetsKeepTheirBonds) {
  pd::Model unbreakable = pair_model(-1.0);  // fracture_energy null
  EXPECT_TRUE(std::isinf(unbreakable.material.block[0].critical_stretch));
  EXPECT_EQ(pd::update_broken_bonds(unbreakable, stretched(unbreakable, 0.5)), 0);

  pd::Model m = pair_model(10.0);
  m.no_fail[1] = 1;
  EXPECT_EQ(pd::update_broken_bonds(m, stretched(m, 10 * m.material.block[0].critical_stretch)), 0);
  EXPECT_NE(force_x_on_0(m, stretched(m, 0.1)), 0.0);
}

TEST(Breaking, InterfaceBondTakesTheWeakerBlockAndNeverBreaksNextToUnbreakable) {
  pd::BlockMaterial a, b, c;
  a.parameters["youngs_modulus"] = b.parameters["youngs_modulus"] = c.parameters["youngs_modulus"] = 1e9;
  a.parameters["fracture_energy"] = 10.0;
  b.parameters["fracture_energy"] = 1.0;
  c.parameters["youngs_modulus"] = 3e9;  // unbreakable
  const pd::MaterialTable t = pd::make_material_table({a, b, c}, "3d", 1e-3, 0.0);
  EXPECT_EQ(t.critical_pair[0 * 3 + 1], t.block[1].critical_stretch);
  EXPECT_EQ(t.critical_pair[1 * 3 + 0], t.block[1].critical_stretch);
  EXPECT_TRUE(std::isinf(t.critical_pair[0 * 3 + 2]));
  EXPECT_DOUBLE_EQ(t.micromodulus_pair[0 * 3 + 2], 0.5 * (t.block[0].micromodulus + t.block[2].micromodulus));
}

TEST(Breaking, PulledApartInATimeLoopTheBondBreaksAndTheNodesFlyFree) {
  pd::Model m = pair_model(1e-3);
  pd::State s(2);
  s.v[0][1] = 50.0;  // node 1 leaves at 50 m/s
  s.v[0][0] = -50.0;
  pd::ForceOperator op_integrator(m);
  auto integrator = pd::integrator_registry().get("verlet")(op_integrator);
  double t = 0.0;
  integrator->initialize(s, t);
  const double dt = 0.5 * pd::stable_time_step(m);
  std::int64_t broken = 0;
  for (int k = 0; k < 2000 && broken == 0; ++k) {
    double h = dt;
    integrator->step(s, t, h);
    broken += integrator->last_step().broken_now;
  }
  ASSERT_EQ(broken, 1);
  const double v1 = s.v[0][1];
  for (int k = 0; k < 10; ++k) {
    double h = dt;
    integrator->step(s, t, h);
  }
  EXPECT_EQ(s.v[0][1], v1);  // no force: the velocity no longer changes
  EXPECT_EQ(s.f[0][1], 0.0);
}
