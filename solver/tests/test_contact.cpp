// Contact and impact: two bodies bounce with momentum conserved to round-off and without
// interpenetration; the Verlet list with skin gives bitwise the forces of a fresh search at every
// step; an indenter's reaction follows K·h²; a single body builds no contact list; the partial-
// volume rules reproduce docs/theory.md C1's R_W factors.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>

#include "core/partial_volume.hpp"
#include "core/work_plan.hpp"
#include "forces/contact.hpp"
#include "forces/indenter.hpp"
#include "materials/pmb/pmb.hpp"
#include "integrators/integrator.hpp"
#include "io/case_reader.hpp"
#include "lattice.hpp"
#include "run/history_columns.hpp"
#include "forces/force_term.hpp"

namespace {

constexpr double kDx = 1e-3;

// Two 2D lattices of n × n nodes, block 1 at x ∈ [0, (n−1)dx], block 2 shifted by `shift` along x,
// the second with another material and 1.3× the node volume (unequal volumes test the pair symmetry).
pd::Model two_bodies(int n, double shift, pd::Case* out_case = nullptr) {
  pd::Case c = pdtest::lattice_case(2, "plane_stress", kDx, 3.015 * kDx, 1e9, 1000.0, -1.0, 1e-3);
  pd::BlockMaterial b2 = c.blocks[0];
  b2.name = "second";
  b2.parameters["youngs_modulus"] = 2e9;
  b2.density = 2000.0;
  c.blocks.push_back(b2);
  pd::Nodes a = pdtest::cubic_lattice(n, n, 1, kDx, 2, 1e-3);
  pd::Nodes nodes = a;
  for (std::size_t i = 0; i < a.size(); ++i) {
    for (std::size_t d = 0; d < 3; ++d) nodes.x[d].push_back(a.x[d][i] + (d == 0 ? shift : 0.0));
    nodes.volume.push_back(1.3 * a.volume[i]);
    nodes.block.push_back(2);
  }
  if (out_case) *out_case = c;
  return pd::build_model(c, std::move(nodes));
}

double momentum_x(const pd::Model& m, const pd::State& s, double* scale) {
  double p = 0.0, q = 0.0;
  for (std::size_t i = 0; i < s.size(); ++i) {
    const double mass = m.density[i] * m.nodes.volume[i];
    p += mass * s.v[0][i];
    q += mass * std::fabs(s.v[0][i]);
  }
  if (scale) *scale = q;
  return p;
}

}  // namespace

TEST(Contact, TwoBodiesBounceConservingMomentumWithoutInterpenetration) {
  const int n = 6;
  pd::Model m = two_bodies(n, (n - 1) * kDx + 5 * kDx);  // a gap of 5dx > δ: no bonds between them
  ASSERT_TRUE(m.contact.pairs);                           // auto: two blocks
  pd::State s(m.nodes.size());
  for (std::size_t i = 0; i < s.size(); ++i) s.v[0][i] = m.block_index[i] == 0 ? 50.0 : -50.0;
  double scale = 0.0;
  const double p0 = momentum_x(m, s, &scale);
  pd::ForceOperator op_integrator(m);
  auto integrator = pd::integrator_registry().get("verlet")(op_integrator);
  double t = 0.0;
  integrator->initialize(s, t);
  const double dt = 0.8 * pd::stable_time_step(m);
  double closest = 1e9, worst_momentum = 0.0;
  for (int k = 0; k < 1500; ++k) {
    double h = dt;
    integrator->step(s, t, h);
    double right_of_1 = -1e9, left_of_2 = 1e9;
    for (std::size_t i = 0; i < s.size(); ++i) {
      const double y = m.nodes.x[0][i] + s.u[0][i];
      if (m.block_index[i] == 0) right_of_1 = std::max(right_of_1, y);
      else left_of_2 = std::min(left_of_2, y);
    }
    closest = std::min(closest, left_of_2 - right_of_1);
    worst_momentum = std::max(worst_momentum, std::fabs(momentum_x(m, s, nullptr) - p0));
  }
  EXPECT_LE(worst_momentum, 1e-13 * scale);  // equal and opposite pair forces: round-off only
  EXPECT_GT(closest, 0.5 * kDx);              // repelled before the contact distance 1.35dx closed
  EXPECT_LT(closest, 1.35 * kDx);             // they did touch
  // They bounced: block 1 now moves left, block 2 right.
  double v1 = 0.0, v2 = 0.0;
  for (std::size_t i = 0; i < s.size(); ++i) (m.block_index[i] == 0 ? v1 : v2) += s.v[0][i];
  EXPECT_LT(v1, 0.0);
  EXPECT_GT(v2, 0.0);
  EXPECT_GT(m.contact_list.rebuilds(), 1);
}

TEST(Contact, NeighbourListGivesTheForcesOfAFreshSearchAtEveryStep) {
  // A breakable single body with self-contact under random velocities: nodes move, bonds break,
  // fragments touch; the list is rebuilt only now and then.
  pd::Case c = pdtest::lattice_case(2, "plane_stress", kDx, 3.015 * kDx, 1e9, 1000.0, 0.01, 1e-3);
  c.contact.self_contact = true;
  c.contact.skin = 0.3 * kDx;
  pd::Model m = pd::build_model(c, pdtest::cubic_lattice(12, 12, 1, kDx, 2, 1e-3));
  ASSERT_TRUE(m.contact.pairs);
  pd::State s(m.nodes.size());
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> uni(-1.0, 1.0);
  for (std::size_t d = 0; d < 2; ++d)
    for (double& v : s.v[d]) v = 40.0 * uni(rng);
  pd::ForceOperator op_integrator(m);
  auto integrator = pd::integrator_registry().get("verlet")(op_integrator);
  double t = 0.0;
  integrator->initialize(s, t);
  const double dt = 0.5 * pd::stable_time_step(m);
  const int steps = 300;
  std::int64_t active_pairs_seen = 0;
  for (int k = 0; k < steps; ++k) {
    double h = dt;
    integrator->step(s, t, h);
    pd::Vec3Array f_list = pd::make_vec3(s.size()), f_fresh = pd::make_vec3(s.size());
    const double e_list = pd::ShortRangeForce(m).AddMult(s.u, f_list);
    const pd::ContactPairs fresh = pd::NeighbourList::search(m.nodes.x, s.u, m.block_index, m.contact);
    const double e_fresh = pd::ShortRangeForce(m).AddMult(fresh, s.u, f_fresh);
    for (std::size_t d = 0; d < 3; ++d) ASSERT_EQ(f_list[d], f_fresh[d]) << "step " << k << " component " << d;
    ASSERT_EQ(e_list, e_fresh) << "step " << k;
    for (double f : f_fresh[0]) active_pairs_seen += f != 0.0;
  }
  EXPECT_GT(active_pairs_seen, 0);                // contact forces were present
  EXPECT_GT(m.contact_list.rebuilds(), 2);        // the skin rule did trigger rebuilds ...
  EXPECT_LT(m.contact_list.rebuilds(), steps / 3);  // ... but far fewer than one per step
}

TEST(Contact, SingleBodyBuildsNoContactList) {
  const pd::Case c = pdtest::lattice_case(2, "plane_stress", kDx, 3.015 * kDx, 1e9, 1000.0, -1.0, 1e-3);
  pd::Model m = pd::build_model(c, pdtest::cubic_lattice(8, 8, 1, kDx, 2, 1e-3));
  EXPECT_FALSE(m.contact.pairs);
  pd::State s(m.nodes.size());
  s.v[0][0] = 5.0;
  pd::ForceOperator op_integrator(m);
  auto integrator = pd::integrator_registry().get("verlet")(op_integrator);
  double t = 0.0;
  integrator->initialize(s, t);
  for (int k = 0; k < 10; ++k) {
    double h = 1e-8;
    integrator->step(s, t, h);
  }
  EXPECT_EQ(m.contact_list.rebuilds(), 0);
  EXPECT_EQ(m.contact_list.pairs().directed(), 0u);
  EXPECT_EQ(pd::term_energy(s, "contact"), 0.0);
  // contact: off wins over two blocks; self_contact turns the search on for one body.
  pd::Case two;
  pd::Model off_model = two_bodies(4, 10 * kDx, &two);
  two.contact.enabled = "off";
  EXPECT_FALSE(pd::plan_contact(two, off_model.block_index, 1.0).pairs);
  pd::Case self = c;
  self.contact.self_contact = true;
  EXPECT_TRUE(pd::build_model(self, pdtest::cubic_lattice(4, 4, 1, kDx, 2, 1e-3)).contact.pairs);
}

TEST(Indenter, ReactionOfAPlaneIsKTimesDepthSquaredOnTheTopRow) {
  const int n = 10;
  pd::Case c = pdtest::lattice_case(2, "plane_stress", kDx, 3.015 * kDx, 1e9, 1000.0, -1.0, 1e-3);
  pd::IndenterSettings plane;
  plane.name = "punch";
  plane.shape = "plane";
  plane.normal = {0.0, -1.0, 0.0};  // out of the indenter, down into the block
  plane.stiffness = 1e15;
  const double top = (n - 1) * kDx;
  plane.centre = {0.0, top, 0.0};
  plane.velocity = {0.0, -1.0, 0.0};  // 1 m/s down: depth h = t·1 m/s
  c.indenters.push_back(plane);
  pd::Model m = pd::build_model(c, pdtest::cubic_lattice(n, n, 1, kDx, 2, 1e-3));
  const double row_volume = n * kDx * kDx * 1e-3;
  pd::State s(m.nodes.size());
  for (double h : {0.1 * kDx, 0.2 * kDx, 0.7 * kDx}) {  // rigid nodes (u = 0): the law exactly
    pd::ForceOperator(m).evaluate(s, h / 1.0);
    ASSERT_EQ(s.indenter_force.size(), 1u);
    EXPECT_NEAR(-s.indenter_force[0][1], plane.stiffness * h * h * row_volume, 1e-12 * plane.stiffness * h * h * row_volume);
    EXPECT_EQ(s.indenter_force[0][0], 0.0);
    // history.csv's indenter_energy (issue 16): the indenter's own, Σ V K h³/3, with contact off.
    EXPECT_FALSE(m.contact.pairs);
    EXPECT_NEAR(pd::term_energy(s, "indenters"), plane.stiffness * h * h * h / 3.0 * row_volume, 1e-12 * pd::term_energy(s, "indenters"));
    EXPECT_EQ(pd::term_energy(s, "contact"), 0.0);
    pd::HistoryRow row;
    pd::HistoryColumns(m, c).fill(row, pd::HistoryInputs{s, h / 1.0, 0.0});
    const auto& names = pd::fixed_history_columns();
    const auto column = [&](const char* name) {
      return row.extra[static_cast<std::size_t>(std::find(names.begin(), names.end(), name) - names.begin())];
    };
    EXPECT_EQ(column("indenter_energy"), pd::term_energy(s, "indenters"));
    EXPECT_EQ(column("contact_energy"), 0.0);
  }
  // A slow push on a block clamped at its bottom rows: the block is far stiffer than the indenter
  // spring, so the reaction follows K·A·h² with h = v·t, and the energy balance holds.
  pd::Case push = c;
  pd::BoundaryCondition clamp;
  clamp.set = "bottom";
  clamp.kind = "displacement";
  clamp.times = {0.0};
  clamp.values = {0.0};
  for (int comp : {0, 1}) {
    clamp.component = comp;
    push.boundary_conditions.push_back(clamp);
  }
  push.node_sets = {"bottom"};
  pd::Nodes nodes = pdtest::cubic_lattice(n, n, 1, kDx, 2, 1e-3);
  pd::NodeSet bottom{"bottom", std::vector<std::uint8_t>(nodes.size(), 0)};
  for (std::size_t i = 0; i < nodes.size(); ++i) bottom.member[i] = nodes.x[1][i] < 2.5 * kDx;
  nodes.sets.push_back(bottom);
  pd::Model pm = pd::build_model(push, std::move(nodes));
  pd::State ps(pm.nodes.size());
  pd::ForceOperator op_integrator(pm);
  auto integrator = pd::integrator_registry().get("verlet")(op_integrator);
  double t = 0.0;
  integrator->initialize(ps, t);
  const double dt = 0.8 * pd::stable_time_step(pm);
  double previous = 0.0, e0 = 0.0;
  int checked = 0;
  while (t < 0.5 * kDx / 1.0) {
    double h = dt;
    integrator->step(ps, t, h);
    const double depth = t * 1.0, reaction = -ps.indenter_force[0][1];
    if (depth > 0.1 * kDx) {
      EXPECT_NEAR(reaction / (plane.stiffness * row_volume * depth * depth), 1.0, 0.02) << "t " << t;
      EXPECT_GT(reaction, previous);  // grows with depth
      ++checked;
    }
    previous = reaction;
    double ke = 0.0;
    for (std::size_t i = 0; i < ps.size(); ++i)
      ke += 0.5 * pm.density[i] * pm.nodes.volume[i] * (ps.v[0][i] * ps.v[0][i] + ps.v[1][i] * ps.v[1][i]);
    const double strain = pd::strain_energy(pm, ps.u);
    const double balance = ke + strain + pd::term_energy(ps, "contact") + pd::term_energy(ps, "indenters") - ps.external_work;
    e0 = std::max(e0, ps.external_work);
    // Energy in = work of the moving indenter (trapezoidal in time, so loose while F ∝ t² is tiny).
    if (depth > 0.1 * kDx) EXPECT_NEAR(balance, 0.0, 0.01 * e0) << "t " << t;
  }
  EXPECT_GT(e0, 0.0);
  EXPECT_GT(checked, 100);
}

TEST(Indenter, CylinderPushesANodeRadiallyOut) {
  pd::Case c = pdtest::lattice_case(2, "plane_stress", kDx, 3.015 * kDx, 1e9, 1000.0, -1.0, 1e-3);
  pd::IndenterSettings disk;
  disk.name = "d";
  disk.shape = "cylinder";
  disk.radius = 2.0 * kDx;
  disk.axis = {0.0, 0.0, 1.0};
  disk.stiffness = 1e15;
  disk.centre = {0.0, 0.0, 0.0};  // node (0,0) at the centre gets no force; (1,0) is 1dx deep, ...
  c.indenters.push_back(disk);
  pd::Model m = pd::build_model(c, pdtest::cubic_lattice(3, 3, 1, kDx, 2, 1e-3));
  pd::State s(m.nodes.size());
  pd::ForceOperator(m).evaluate(s, 0.0);
  pd::Vec3Array bonds_only = pd::make_vec3(s.size());
  pd::add_pmb_force(m, s.u, bonds_only);
  const std::size_t right = pdtest::node_index(1, 0, 0, 3, 3), diagonal = pdtest::node_index(1, 1, 0, 3, 3);
  EXPECT_DOUBLE_EQ(s.f[0][right] - bonds_only[0][right], 1e15 * kDx * kDx);  // K·(R − r)², r = dx
  EXPECT_DOUBLE_EQ(s.f[1][right] - bonds_only[1][right], 0.0);
  const double h = 2.0 * kDx - std::sqrt(2.0) * kDx;
  EXPECT_NEAR(s.f[0][diagonal] - bonds_only[0][diagonal], 1e15 * h * h / std::sqrt(2.0), 1e-9 * 1e15 * h * h);
  EXPECT_EQ(s.f[0][pdtest::node_index(2, 0, 0, 3, 3)], bonds_only[0][pdtest::node_index(2, 0, 0, 3, 3)]);  // r = R
}

TEST(PartialVolume, RulesReproduceTheC1FactorsAtMEquals3) {
  // docs/theory.md C1(b): W = 4.5K·s̄²·R_W at a bulk node under isotropic stretch, with
  // R_W = Σ V_j ν_j |ξ_j|/(πδ⁴) = 1.120850 (full volumes) and 0.900206 (LAMMPS ν) for δ = 3dx.
  const int n = 9;
  const double E = 1e9, K = E / 1.5;  // 3D PMB: Poisson ratio 1/4
  const double stretch = 1e-3;
  for (const auto& [rule, expected] : {std::pair<std::string, double>{"none", 1.120850}, {"lammps", 0.900206}}) {
    pd::Case c = pdtest::lattice_case(3, "3d", kDx, 3.0 * kDx, E, 1000.0, -1.0);
    c.partial_volume = rule;
    const pd::Model m = pd::build_model(c, pdtest::cubic_lattice(n, n, n, kDx, 3));
    pd::Vec3Array u = pd::make_vec3(m.nodes.size());
    for (std::size_t d = 0; d < 3; ++d)
      for (std::size_t i = 0; i < m.nodes.size(); ++i) u[d][i] = stretch * m.nodes.x[d][i];
    const std::vector<double> w = pd::strain_energy_density(m, u);
    const double wc = w[pdtest::node_index(4, 4, 4, n, n)];
    EXPECT_NEAR(wc / (4.5 * K * stretch * stretch), expected, 2e-6) << rule;
  }
  // HHB: the family reaches to δ + dx/2 with weight (δ − |ξ| + dx/2)/dx on the outer shell.
  const pd::PartialVolumeRule& hhb = pd::partial_volume_registry().get("hhb");
  EXPECT_DOUBLE_EQ(pd::bond_cutoff(hhb, 3.0 * kDx, kDx), 3.5 * kDx);
  EXPECT_DOUBLE_EQ(hhb.factor(2.0 * kDx, 3.0 * kDx, kDx), 1.0);
  EXPECT_NEAR(hhb.factor(3.0 * kDx, 3.0 * kDx, kDx), 0.5, 1e-12);
  EXPECT_NEAR(hhb.factor(std::sqrt(12.0) * kDx, 3.0 * kDx, kDx), 3.5 - std::sqrt(12.0), 1e-12);
  pd::Case c = pdtest::lattice_case(3, "3d", kDx, 3.0 * kDx, E, 1000.0, -1.0);
  c.partial_volume = "hhb";
  const pd::Model m = pd::build_model(c, pdtest::cubic_lattice(n, n, n, kDx, 3));
  const std::size_t centre = pdtest::node_index(4, 4, 4, n, n);
  EXPECT_EQ(m.bonds.offsets[centre + 1] - m.bonds.offsets[centre], 122 + 8 + 24 + 24);  // |ξ|² = 10, 11, 12 join
  EXPECT_THROW(pd::partial_volume_registry().get("exact"), pd::Error);
}

TEST(Contact, CaseReaderRechecksContactAndIndenterKeys) {
  const std::string head = R"({"format_version": 1, "nodes_file": "n.vtu", "dimension": 2, "analysis": "plane_stress",
    "thickness": 0.001, "grid_spacing": 0.001, "horizon": 0.003,
    "blocks": [{"id": 1, "name": "a", "density": 1000, "youngs_modulus": 1e9}],
    "time": {"end": 1e-3}, "output": {"every_steps": 1})";
  const pd::Case ok = pd::parse_case(head + R"(, "partial_volume": "lammps",
    "contact": {"enabled": "on", "self_contact": true, "skin": 0.0004, "stiffness_factor": 10},
    "indenters": [{"name": "p", "shape": "plane", "centre": [0, 0, 0], "normal": [0, -2, 0], "stiffness": 1e15},
                  {"name": "c", "shape": "cylinder", "radius": 0.002, "centre": [0, 0, 0], "stiffness": 1e14}]})",
                                      "c.json");
  EXPECT_EQ(ok.partial_volume, "lammps");
  EXPECT_EQ(ok.contact.enabled, "on");
  EXPECT_TRUE(ok.contact.self_contact);
  EXPECT_EQ(ok.contact.skin, 0.0004);
  ASSERT_EQ(ok.indenters.size(), 2u);
  EXPECT_EQ(ok.indenters[0].normal[1], -1.0);  // normalised
  EXPECT_EQ(ok.indenters[1].axis[2], 1.0);     // default axis z
  const auto error_of = [&](const std::string& tail) {
    try {
      pd::parse_case(head + tail, "c.json");
    } catch (const pd::Error& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_NE(error_of(R"(, "partial_volume": "exact"})").find("partial_volume: unknown partial_volume rule 'exact'; known: hhb, lammps, none"), std::string::npos);
  EXPECT_NE(error_of(R"(, "contact": {"enabled": "maybe"}})").find("contact.enabled: unknown value 'maybe'"), std::string::npos);
  EXPECT_NE(error_of(R"(, "contact": {"skin": -1}})").find("contact.skin: must be > 0"), std::string::npos);
  EXPECT_NE(error_of(R"(, "indenters": [{"name": "p", "shape": "cone", "centre": [0,0,0], "stiffness": 1}]})")
                .find("indenters[0].shape: unknown indenter shape 'cone'; known: cylinder, plane, sphere"),
            std::string::npos);
  EXPECT_NE(error_of(R"(, "indenters": [{"name": "p", "shape": "plane", "centre": [0,0,0], "normal": [0,0,0], "stiffness": 1}]})")
                .find("indenters[0].normal: must be a non-zero vector"),
            std::string::npos);
  EXPECT_NE(error_of(R"(, "indenters": [{"name": "p", "shape": "sphere", "centre": [0,0,0], "stiffness": 1}]})")
                .find("indenters[0].radius: required key is missing"),
            std::string::npos);
}

TEST(Indenter, StepLimitIsEquation25WithTheOneEndedIndenterSpring) {
  // One node inside a small disk. Bound (a): √(2ρ/(Σ_j c V_j/|ξ| + K·h)) at that node, the sum
  // written out here bond by bond; the indenter's spring 2K·h has one moving end, so it enters
  // eq. 2.5's sum (which counts each two-ended bond spring once) as K·h. indenter_stable_depth is
  // the depth where (a) equals dt at the stiffest node (an interior one, as the centre of a 9 × 9
  // plate is). Bound (b), with ω_max known: 2/√(ω_max² + 2K·h/ρ).
  const int n = 9;
  pd::Case c = pdtest::lattice_case(2, "plane_stress", kDx, 3.015 * kDx, 1e9, 1000.0, -1.0, 1e-3);
  pd::IndenterSettings disk;
  disk.name = "d";
  disk.shape = "cylinder";
  disk.radius = 0.3 * kDx;
  disk.axis = {0.0, 0.0, 1.0};
  disk.stiffness = 1e19;
  c.indenters.push_back(disk);
  pd::Model m = pd::build_model(c, pdtest::cubic_lattice(n, n, 1, kDx, 2, 1e-3));
  const std::size_t centre = pdtest::node_index(4, 4, 0, n, n);
  const pd::Vec3Array u = pd::make_vec3(m.nodes.size());
  // Nobody inside: no limit.
  m.indenters[0].centre = {-5 * kDx, -5 * kDx, 0.0};
  EXPECT_EQ(pd::indenter_step_limit(m, 0.0, u).node, -1);
  EXPECT_TRUE(std::isinf(pd::indenter_step_limit(m, 0.0, u).dt));

  double sum = 0.0;  // thesis eq. 2.5's sum at the centre node, full volumes
  const double micromodulus = m.material.micromodulus_pair[0];
  for (std::int64_t k = m.bonds.offsets[centre]; k < m.bonds.offsets[centre + 1]; ++k) {
    const auto j = static_cast<std::size_t>(m.bonds.neighbour[static_cast<std::size_t>(k)]);
    const double dxj = m.nodes.x[0][j] - m.nodes.x[0][centre], dyj = m.nodes.x[1][j] - m.nodes.x[1][centre];
    sum += micromodulus * m.nodes.volume[j] / std::sqrt(dxj * dxj + dyj * dyj);
  }
  const double rho = m.density[centre];
  EXPECT_NEAR(pd::stable_time_step(m), std::sqrt(2.0 * rho / sum), 1e-12 * pd::stable_time_step(m));

  for (const double offset : {0.05 * kDx, 0.2 * kDx}) {  // h = R − offset
    m.indenters[0].centre = {m.nodes.x[0][centre] + offset, m.nodes.x[1][centre], 0.0};
    const pd::IndenterStepLimit limit = pd::indenter_step_limit(m, 0.0, u);
    const double h = disk.radius - offset;
    EXPECT_EQ(limit.node, static_cast<std::int64_t>(centre));
    EXPECT_EQ(limit.indenter, 0u);
    EXPECT_NEAR(limit.depth, h, 1e-12 * kDx);
    EXPECT_NEAR(limit.dt, std::sqrt(2.0 * rho / (sum + disk.stiffness * h)), 1e-12 * limit.dt);
    // (b) wins when the exact ω_max is well below eq. 2.5's bound (here: its square root of 2/3).
    const double omega2 = (2.0 / 3.0) * 2.0 * sum / rho;
    const double weyl = 2.0 / std::sqrt(omega2 + 2.0 * disk.stiffness * h / rho);
    EXPECT_NEAR(pd::indenter_step_limit(m, 0.0, u, omega2).dt, std::max(weyl, limit.dt), 1e-12 * weyl);
  }
  // At the depth indenter_stable_depth gives for a step dt, the centre node's bound (a) is dt.
  const double dt = 0.8 * pd::stable_time_step(m);
  const double depth = pd::indenter_stable_depth(m, m.indenters[0], dt);
  EXPECT_NEAR(depth, (2.0 * rho / (dt * dt) - sum) / disk.stiffness, 1e-9 * depth);
  m.indenters[0].centre = {m.nodes.x[0][centre] + (0.3 * kDx - depth), m.nodes.x[1][centre], 0.0};
  EXPECT_NEAR(pd::indenter_step_limit(m, 0.0, u).dt, dt, 1e-9 * dt);
  // A single bondless node: bound (a) is exactly velocity Verlet's 2/ω with ω² = 2K·h/ρ.
  pd::Case lone = c;
  pd::Nodes one = pdtest::cubic_lattice(1, 1, 1, kDx, 2, 1e-3);
  pd::Model single = pd::build_model(lone, std::move(one));
  single.indenters[0].centre = {0.1 * kDx, 0.0, 0.0};  // h = 0.2 dx
  const double h1 = 0.2 * kDx, omega = std::sqrt(2.0 * disk.stiffness * h1 / single.density[0]);
  EXPECT_NEAR(pd::indenter_step_limit(single, 0.0, pd::make_vec3(1)).dt, 2.0 / omega, 1e-12 / omega);
}
