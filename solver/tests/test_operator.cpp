// The operator between integrators and physics: it builds exactly the terms a scene needs and
// says so in the work plan; its force is the material's plus every term's; its linearised force
// (contact and indenters included) is the derivative of that force; prescribed motion is one
// implementation for every integrator.
#include <gtest/gtest.h>

#include <cmath>

#include "core/work_plan.hpp"
#include "forces/force_term.hpp"
#include "jacobian_check.hpp"
#include "lattice.hpp"
#include "materials/pmb/pmb.hpp"
#include "operator/force_operator.hpp"

namespace {

constexpr double kDx = 1e-3;

pd::Case plane_case() { return pdtest::lattice_case(2, "plane_stress", kDx, 3.015 * kDx, 1e9, 1000.0, -1.0, 1e-3); }

// Two 6×6 plates 5dx apart (no bonds between them), the second a block of its own.
pd::Model two_plates(pd::Case c) {
  pd::BlockMaterial b2 = c.blocks[0];
  b2.name = "second";
  b2.parameters["youngs_modulus"] = 2e9;
  c.blocks.push_back(b2);
  pd::Nodes a = pdtest::cubic_lattice(6, 6, 1, kDx, 2, 1e-3);
  pd::Nodes nodes = a;
  for (std::size_t i = 0; i < a.size(); ++i) {
    for (std::size_t d = 0; d < 3; ++d) nodes.x[d].push_back(a.x[d][i] + (d == 0 ? 10.0 * kDx : 0.0));
    nodes.volume.push_back(a.volume[i]);
    nodes.block.push_back(2);
  }
  return pd::build_model(c, std::move(nodes));
}

std::vector<std::string> plan(const pd::Model& m, const pd::Case& c) {
  pd::Model& mutable_model = const_cast<pd::Model&>(m);
  return pd::ForceOperator(mutable_model).work_plan(c);
}

bool has_line(const std::vector<std::string>& lines, const std::string& start) {
  for (const auto& l : lines)
    if (l.rfind(start, 0) == 0) return true;
  return false;
}

}  // namespace

TEST(ForceTerms, RegistryListsEveryTermInItsSummationOrder) {
  const auto& r = pd::force_term_registry();
  ASSERT_EQ(r.size(), 3u);
  EXPECT_EQ(r[0].name, "contact");
  EXPECT_EQ(r[1].name, "indenters");
  EXPECT_EQ(r[2].name, "body_force");
  for (std::size_t k = 1; k < r.size(); ++k) EXPECT_LT(r[k - 1].order, r[k].order);
}

TEST(Operator, WorkPlanNamesTheTermsTheSceneNeedsAndNoOthers) {
  pd::Case one = plane_case();
  const pd::Model single = pd::build_model(one, pdtest::cubic_lattice(5, 5, 1, kDx, 2, 1e-3));
  const auto lines = plan(single, one);
  EXPECT_TRUE(has_line(lines, "work: bond forces over"));
  EXPECT_TRUE(has_line(lines, "work: no contact search (one body and no self_contact)"));
  EXPECT_TRUE(has_line(lines, "work: no indenters"));
  EXPECT_TRUE(has_line(lines, "work: no breakage test (every block unbreakable)"));

  pd::Case two = plane_case();
  two.blocks[0].parameters["fracture_energy"] = 1.0;
  pd::IndenterSettings ball;
  ball.name = "ball";
  ball.shape = "sphere";
  ball.radius = 2 * kDx;
  ball.stiffness = 1e15;
  two.indenters.push_back(ball);
  const pd::Model pair = two_plates(two);
  const auto both = plan(pair, two);
  EXPECT_TRUE(has_line(both, "work: contact search (cell list + Verlet list) between blocks"));
  EXPECT_TRUE(has_line(both, "work: indenter 'ball' (sphere, R 0.002 m, K 1e+15 N/m⁵"));
  EXPECT_TRUE(has_line(both, "work: breakage test after every step"));
  EXPECT_FALSE(has_line(both, "work: no "));
  // The work summary adds the output schedule to the operator's plan.
  EXPECT_EQ(pd::work_summary(pd::ForceOperator(const_cast<pd::Model&>(pair)), two).back(),
            "work: frames only at output times, history row every 1 step(s)");
}

TEST(Operator, ForceIsTheMaterialsPlusEveryTerm) {
  pd::Case c = plane_case();
  pd::BoundaryCondition gravity{"all", "body_force", 1, {0.0}, {-9.81 * 1000.0}};
  c.boundary_conditions.push_back(gravity);
  pd::Nodes nodes = pdtest::cubic_lattice(5, 5, 1, kDx, 2, 1e-3);
  nodes.sets.push_back({"all", std::vector<std::uint8_t>(nodes.size(), 1)});
  pd::Model m = pd::build_model(c, std::move(nodes));
  const pd::ForceOperator op(m);
  pd::State s(m.nodes.size());
  s.u = pdtest::pseudo_random(s.size(), 9);
  for (auto& comp : s.u)
    for (double& v : comp) v *= 1e-6;
  op.evaluate(s, 0.0);
  pd::Vec3Array bonds = pd::make_vec3(s.size());
  pd::add_pmb_force(m, s.u, bonds);
  for (std::size_t i = 0; i < s.size(); ++i) {
    EXPECT_EQ(s.f[0][i], bonds[0][i]);
    EXPECT_EQ(s.f[1][i], bonds[1][i] + -9.81 * 1000.0);
  }
  // Its power: Σ V b·v.
  for (std::size_t i = 0; i < s.size(); ++i) s.v[1][i] = 2.0;
  EXPECT_DOUBLE_EQ(op.external_power(s, 0.0), -9.81 * 1000.0 * 2.0 * 25.0 * kDx * kDx * 1e-3);
}

TEST(Operator, ContactJacobianIsTheDerivativeOfTheContactForce) {
  pd::Case c = plane_case();
  pd::Model m = two_plates(c);
  const pd::ForceOperator op(m);
  pd::State s(m.nodes.size());
  // The second plate moved 4.2dx towards the first: its left column is 0.8dx from the first's
  // right column, inside the contact distance 1.35dx; a wiggle so that pairs are not aligned.
  const pd::Vec3Array wiggle = pdtest::pseudo_random(s.size(), 4);
  for (std::size_t i = 0; i < s.size(); ++i) {
    if (m.block_index[i] == 1) s.u[0][i] = -4.2 * kDx;
    s.u[0][i] += 2e-5 * wiggle[0][i];
    s.u[1][i] += 2e-5 * wiggle[1][i];
  }
  op.evaluate(s, 0.0);  // builds the contact list at s.u
  ASSERT_GT(pd::term_energy(s, "contact"), 0.0);
  const pd::Vec3Array x = pdtest::pseudo_random(s.size(), 6);
  pd::Vec3Array jx = pd::make_vec3(s.size());
  op.apply_jacobian(s, 0.0, x, jx);
  const pd::Vec3Array fd = pdtest::force_difference(op, s, 0.0, x, 1e-9);
  EXPECT_LT(pdtest::distance(jx, fd), 1e-7 * pdtest::norm(jx));
  // ... and it is a real part of the total: without it the product is off by far more.
  pd::Vec3Array bonds_only = pd::make_vec3(s.size());
  m.bond_model->add_jacobian_product(m, s.u, x, bonds_only);
  EXPECT_GT(pdtest::distance(bonds_only, fd), 1e-3 * pdtest::norm(jx));
}

TEST(Operator, IndenterJacobianIsTheDerivativeOfTheIndenterForce) {
  for (const char* shape : {"sphere", "cylinder", "plane"}) {
    pd::Case c = pdtest::lattice_case(3, "3d", kDx, 3.015 * kDx, 1e9, 1000.0, -1.0);
    pd::IndenterSettings ind;
    ind.name = shape;
    ind.shape = shape;
    ind.radius = 3.3 * kDx;
    ind.stiffness = 1e17;
    ind.centre = {2.5 * kDx, 2.2 * kDx, 6.1 * kDx};  // above the top face z = 4dx, 1.2dx deep at most
    ind.axis = {1.0, 0.0, 0.0};
    ind.normal = {0.0, 0.0, -1.0};
    if (std::string(shape) == "plane") ind.centre = {0.0, 0.0, 3.3 * kDx};
    c.indenters.push_back(ind);
    pd::Model m = pd::build_model(c, pdtest::cubic_lattice(6, 5, 5, kDx, 3));
    const pd::ForceOperator op(m);
    pd::State s(m.nodes.size());
    const pd::Vec3Array wiggle = pdtest::pseudo_random(s.size(), 8);
    for (std::size_t d = 0; d < 3; ++d)
      for (std::size_t i = 0; i < s.size(); ++i) s.u[d][i] = 3e-5 * wiggle[d][i];
    op.evaluate(s, 0.0);
    ASSERT_GT(pd::term_energy(s, "indenters"), 0.0) << shape;
    ASSERT_EQ(pd::term_energy(s, "contact"), 0.0) << shape;  // one body, no contact: the indenter's energy is its own
    const pd::Vec3Array x = pdtest::pseudo_random(s.size(), 2);
    pd::Vec3Array jx = pd::make_vec3(s.size()), bonds_only = pd::make_vec3(s.size());
    op.apply_jacobian(s, 0.0, x, jx);
    m.bond_model->add_jacobian_product(m, s.u, x, bonds_only);
    const pd::Vec3Array fd = pdtest::force_difference(op, s, 0.0, x, 1e-10);
    EXPECT_LT(pdtest::distance(jx, fd), 1e-6 * pdtest::distance(jx, bonds_only)) << shape;
    EXPECT_GT(pdtest::distance(jx, bonds_only), 1e-3 * pdtest::norm(jx)) << shape;
  }
}

TEST(Operator, PrescribedMotionGivesTheMeanOrTheEndVelocity) {
  pd::Case c = plane_case();
  c.boundary_conditions = {{"left", "displacement", 0, {0.0, 1.0}, {0.0, 2.0}},  // u = 2t
                           {"right", "velocity", 1, {0.0, 1.0}, {0.0, 4.0}}};    // v = 4t
  pd::Nodes nodes = pdtest::cubic_lattice(5, 5, 1, kDx, 2, 1e-3);
  pd::NodeSet left{"left", std::vector<std::uint8_t>(nodes.size(), 0)}, right{"right", left.member};
  left.member[0] = 1;
  right.member[4] = 1;
  nodes.sets = {left, right};
  pd::Model m = pd::build_model(c, std::move(nodes));
  const pd::ForceOperator op(m);
  pd::State s(m.nodes.size());
  op.impose_prescribed_motion(s, 0.5);
  EXPECT_EQ(s.u[0][0], 1.0);
  EXPECT_EQ(s.v[0][0], 2.0);
  EXPECT_EQ(s.v[1][4], 2.0);
  EXPECT_TRUE(op.fixed()[0][0] && op.fixed()[1][4] && !op.fixed()[1][0]);
  pd::Vec3Array u = s.u, v = s.v;
  op.advance_prescribed_motion(s.u, u, v, 0.5, 0.75, 0.25, false);
  EXPECT_EQ(u[0][0], 1.5);
  EXPECT_EQ(v[0][0], 2.0);
  EXPECT_DOUBLE_EQ(u[1][4], s.u[1][4] + 0.25 * 2.5);  // ∫ 4t dt from 0.5 to 0.75
  EXPECT_DOUBLE_EQ(v[1][4], 2.5);                      // the mean velocity over the step
  op.advance_prescribed_motion(s.u, u, v, 0.5, 0.75, 0.25, true);
  EXPECT_EQ(v[1][4], 3.0);  // the end velocity
  op.impose_prescribed_velocity(v, 1.0);
  EXPECT_EQ(v[1][4], 4.0);
}
