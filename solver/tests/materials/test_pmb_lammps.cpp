// LAMMPS-compatible PMB (docs/lammps.md; docs/theory.md T4): the per-node critical stretch
// s0_i = s00 − α·min_j s_ij on a chain computed by hand, the breaking order in which a bond over
// its critical stretch still carries its force in the step it breaks, c and s0 given directly, and
// the case reader's errors for a mix of the two parameter pairs.
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "core/error.hpp"
#include "core/model.hpp"
#include "io/case_reader.hpp"
#include "jacobian_check.hpp"
#include "lattice.hpp"
#include "materials/pmb/pmb.hpp"
#include "pmb_s0.hpp"

namespace {

constexpr double kDx = 1.0;        // a chain of unit spacing: stretches are the displacement steps
constexpr double kC = 1.0e3;       // c [N/m⁶]
constexpr double kS00 = 0.05;      // s00
constexpr double kAlpha = 0.25;    // α

// n nodes along x, δ = 1.5dx: only nearest neighbours are bonded. c and s0 given directly.
pd::Case chain_case(double alpha, const std::string& order) {
  pd::Case c = pdtest::lattice_case(3, "3d", kDx, 1.5 * kDx, 1.0, 1000.0, -1.0);
  c.blocks[0].parameters = {{"micromodulus", kC}, {"critical_stretch", kS00}};
  if (alpha > 0.0) c.blocks[0].parameters["critical_stretch_alpha"] = alpha;
  c.breaking_order = order;
  return c;
}

pd::Model chain(int n, double alpha, const std::string& order = "thesis") {
  return pd::build_model(chain_case(alpha, order), pdtest::cubic_lattice(n, 1, 1, kDx, 3));
}

pd::Vec3Array displacement_x(const std::vector<double>& ux) {
  pd::Vec3Array u = pd::make_vec3(ux.size());
  for (std::size_t i = 0; i < ux.size(); ++i) u[0][i] = ux[i];
  return u;
}

// Is the bond i→j broken (its copy in i's row)?
bool broken(const pd::Model& m, std::size_t i, std::size_t j) {
  for (std::int64_t k = m.bonds.offsets[i]; k < m.bonds.offsets[i + 1]; ++k)
    if (static_cast<std::size_t>(m.bonds.neighbour[static_cast<std::size_t>(k)]) == j)
      return m.bonds.broken[static_cast<std::size_t>(k)] != 0;
  ADD_FAILURE() << "no bond " << i << "→" << j;
  return false;
}

}  // namespace

TEST(PmbLammps, CriticalStretchPerNodeIsS00MinusAlphaTimesTheSmallestStretch) {
  pd::Model m = chain(4, kAlpha);
  // At rest every s0_i is s00 (LAMMPS's set-up pass at zero stretch).
  ASSERT_EQ(pdtest::s0_of(m).size(), 4u);
  for (double s0 : pdtest::s0_of(m)) EXPECT_EQ(s0, kS00);
  // Stretches 0.01 (0–1), 0.02 (1–2), −0.005 (2–3): compression raises s0 (LAMMPS peri/pmb).
  const pd::Vec3Array u = displacement_x({0.0, 0.01, 0.03, 0.025});
  pd::Vec3Array f = pd::make_vec3(4);
  m.bond_model->break_bonds_and_add_force(m, u, f, nullptr, false);
  const double s01 = ((1.0 + 0.01) - 0.0 - 1.0) / 1.0;  // the stretch of 0–1 as the kernel rounds it
  EXPECT_NEAR(pdtest::s0_of(m)[0], kS00 - kAlpha * 0.01, 1e-15);   // 0.0475
  EXPECT_NEAR(pdtest::s0_of(m)[1], kS00 - kAlpha * 0.01, 1e-15);   // min(0.01, 0.02)
  EXPECT_NEAR(pdtest::s0_of(m)[2], kS00 + kAlpha * 0.005, 1e-15);  // min(0.02, −0.005): 0.05125
  EXPECT_NEAR(pdtest::s0_of(m)[3], kS00 + kAlpha * 0.005, 1e-15);
  EXPECT_EQ(pdtest::s0_of(m)[0], kS00 - kAlpha * s01);  // exactly LAMMPS's s00 − α·s
  for (int k = 0; k < 6; ++k) EXPECT_EQ(m.bonds.broken[static_cast<std::size_t>(k)], 0);
}

TEST(PmbLammps, ABondBreaksOverTheSmallerCriticalStretchOfItsEndsFromThePreviousPass) {
  // First pass as above: s0_0 = s0_1 = 0.0475, s0_2 = s0_3 = 0.05125. Then stretch 0–1 to 0.048 and
  // 2–3 to 0.051: 0–1 is over min(s0_0, s0_1) = 0.0475 and breaks although it is under s00 = 0.05;
  // 2–3 is over s00 but under min(s0_2, s0_3) = 0.05125 and holds; 1–2 at 0.02 holds.
  pd::Model m = chain(4, kAlpha);
  pd::Vec3Array f = pd::make_vec3(4);
  m.bond_model->break_bonds(m, displacement_x({0.0, 0.01, 0.03, 0.025}), false);
  const pd::BreakReport r =
      m.bond_model->break_bonds_and_add_force(m, displacement_x({0.0, 0.048, 0.068, 0.119}), f, nullptr, false);
  EXPECT_EQ(r.broken, 1);
  EXPECT_TRUE(broken(m, 0, 1));
  EXPECT_TRUE(broken(m, 1, 0));
  EXPECT_FALSE(broken(m, 1, 2));
  EXPECT_FALSE(broken(m, 2, 3));
  EXPECT_FALSE(broken(m, 3, 2));
  // Without α (s0 fixed at s00) the same state breaks 2–3 and keeps 0–1.
  pd::Model fixed = chain(4, 0.0);
  EXPECT_TRUE(pdtest::s0_of(fixed).empty());
  fixed.bond_model->break_bonds_and_add_force(fixed, displacement_x({0.0, 0.048, 0.068, 0.119}), f, nullptr, false);
  EXPECT_FALSE(broken(fixed, 0, 1));
  EXPECT_TRUE(broken(fixed, 2, 3));
}

TEST(PmbLammps, InTheLammpsOrderABondOverItsCriticalStretchCarriesItsForceInTheStepItBreaks) {
  // Two nodes, stretch 0.06 > s00 = 0.05. f_0 = c·s·V_1 along +x (ν = 1: full volumes).
  const pd::Vec3Array u = displacement_x({0.0, 0.06});
  const double s = ((1.0 + 0.06) - 0.0 - 1.0) / 1.0;
  for (const std::string order : {"lammps", "thesis"}) {
    pd::Model m = chain(2, 0.0, order);
    EXPECT_EQ(m.break_after_force, order == "lammps");
    pd::Vec3Array f = pd::make_vec3(2);
    double w[2] = {-1.0, -1.0};
    const pd::BreakReport r = m.bond_model->break_bonds_and_add_force(m, u, f, w, true);
    EXPECT_EQ(r.broken, 1) << order;
    EXPECT_TRUE(broken(m, 0, 1) && broken(m, 1, 0)) << order;  // broken after the pass either way
    // The energy it held when it broke: ½ c s0² |ξ| V_0 V_1 at the critical stretch s00 it crossed,
    // not at its stretch s = 0.06 after the pass (issue 16).
    EXPECT_DOUBLE_EQ(r.energy, 0.5 * kC * kS00 * kS00 * 1.0);
    if (order == "lammps") {
      // f[d][i]: component d of node i
      EXPECT_DOUBLE_EQ(f[0][0], kC * s * 1.0);  // c s V_1 e/|e|, e = +x
      EXPECT_EQ(f[1][0], 0.0);
      EXPECT_EQ(f[2][0], 0.0);
      EXPECT_DOUBLE_EQ(f[0][1], -kC * s * 1.0);
      EXPECT_DOUBLE_EQ(w[0], 0.25 * kC * s * s * 1.0);  // W_i of the bond that carried force
    } else {
      EXPECT_EQ(f[0][0], 0.0);  // thesis §2.2: broken before the force
      EXPECT_EQ(f[0][1], 0.0);
      EXPECT_EQ(w[0], 0.0);
    }
    // The next pass: the bond is gone in both orders.
    pd::Vec3Array g = pd::make_vec3(2);
    m.bond_model->break_bonds_and_add_force(m, u, g, nullptr, false);
    EXPECT_EQ(g[0][0], 0.0) << order;
  }
}

TEST(PmbLammps, WhileNothingBreaksTheLammpsOrderIsBitwiseTheThesisOrder) {
  // A 6×5×4 brick under a smooth stretch and a wiggle, s00 above every stretch: same bits.
  pd::Case c = pdtest::lattice_case(3, "3d", 1e-3, 3.015e-3, 1e9, 1000.0, 1.0);
  c.blocks[0].parameters = {{"micromodulus", 1e20}, {"critical_stretch", 0.5}};
  pd::Model thesis = pd::build_model(c, pdtest::cubic_lattice(6, 5, 4, 1e-3, 3));
  c.breaking_order = "lammps";
  pd::Model lammps = pd::build_model(c, pdtest::cubic_lattice(6, 5, 4, 1e-3, 3));
  const std::size_t n = thesis.nodes.size();
  const pd::Vec3Array wiggle = pdtest::pseudo_random(n, 3);
  pd::Vec3Array u = pd::make_vec3(n);
  for (std::size_t i = 0; i < n; ++i)
    for (std::size_t d = 0; d < 3; ++d) u[d][i] = 1e-3 * thesis.nodes.x[d][i] + 1e-7 * wiggle[d][i];
  pd::Vec3Array f1 = pd::make_vec3(n), f2 = pd::make_vec3(n);
  std::vector<double> w1(n), w2(n);
  thesis.bond_model->break_bonds_and_add_force(thesis, u, f1, w1.data(), true);
  lammps.bond_model->break_bonds_and_add_force(lammps, u, f2, w2.data(), true);
  for (std::size_t d = 0; d < 3; ++d) EXPECT_EQ(f1[d], f2[d]);
  EXPECT_EQ(w1, w2);
}

TEST(PmbLammps, MicromodulusAndCriticalStretchGivenDirectlyAreTheYoungsModulusRoute) {
  // E and G0 → (c, s0) by docs/theory.md T2; the same c and s0 given directly give the same table,
  // the same forces and the same broken bonds.
  pd::Case by_e = pdtest::lattice_case(3, "3d", 1e-3, 3.015e-3, 7.2e10, 2440.0, 4.0);
  pd::Model a = pd::build_model(by_e, pdtest::cubic_lattice(6, 5, 4, 1e-3, 3));
  pd::Case by_c = by_e;
  by_c.blocks[0].parameters = {{"micromodulus", a.material.block[0].micromodulus},
                               {"critical_stretch", a.material.block[0].critical_stretch}};
  pd::Model b = pd::build_model(by_c, pdtest::cubic_lattice(6, 5, 4, 1e-3, 3));
  EXPECT_EQ(a.material.micromodulus_pair, b.material.micromodulus_pair);
  EXPECT_EQ(a.material.critical_pair, b.material.critical_pair);
  EXPECT_GT(a.material.block[0].critical_stretch, 1e-4);  // a finite s0 from G0 = 4 J/m²
  const std::size_t n = a.nodes.size();
  pd::Vec3Array u = pd::make_vec3(n);
  for (std::size_t i = 0; i < n; ++i) u[0][i] = 2.0 * a.material.block[0].critical_stretch * a.nodes.x[0][i] *
                                                (a.nodes.x[0][i] > 2.5e-3 ? 1.0 : 0.0);
  pd::Vec3Array fa = pd::make_vec3(n), fb = pd::make_vec3(n);
  const pd::BreakReport ra = a.bond_model->break_bonds_and_add_force(a, u, fa, nullptr, true);
  const pd::BreakReport rb = b.bond_model->break_bonds_and_add_force(b, u, fb, nullptr, true);
  EXPECT_GT(ra.broken, 0);
  EXPECT_EQ(ra.broken, rb.broken);
  EXPECT_EQ(a.bonds.broken, b.bonds.broken);
  for (std::size_t d = 0; d < 3; ++d) EXPECT_EQ(fa[d], fb[d]);
}

namespace {

const char* const kChainCase = R"({
  "format_version": 1, "case": "t", "title": "x", "source": "t.yaml", "nodes_file": "nodes.vtu",
  "output_dir": ".", "dimension": 3, "analysis": "3d", "grid_spacing": 0.001, "horizon": 0.0030002,
  "blocks": [{"id": 1, "name": "brick", "model": "pmb", "density": 2440.0, "micromodulus": 3.4e21,
              "critical_stretch": 0.001, "critical_stretch_alpha": 0.25}],
  "breaking_order": "lammps",
  "time": {"end": 0.01}, "output": {"every_steps": 10}
})";

std::string case_error(const std::string& from, const std::string& to) {
  std::string text = kChainCase;
  const auto at = text.find(from);
  EXPECT_NE(at, std::string::npos) << from;
  if (at == std::string::npos) return "";
  text.replace(at, from.size(), to);
  try {
    pd::parse_case(text, "out/x/case.json");
  } catch (const pd::Error& e) {
    return e.what();
  }
  return "no error";
}

}  // namespace

TEST(PmbLammps, TheCaseReaderTakesOnePairOrTheOtherAndAlphaAtLeastZero) {
  const pd::Case ok = pd::parse_case(kChainCase, "out/x/case.json");
  EXPECT_EQ(ok.breaking_order, "lammps");
  EXPECT_EQ(ok.blocks[0].parameter("critical_stretch_alpha"), 0.25);
  EXPECT_EQ(pd::parse_case(std::string(kChainCase).replace(std::string(kChainCase).find("\"critical_stretch_alpha\": 0.25"),
                                                           30, "\"critical_stretch_alpha\": 0.0"),
                           "out/x/case.json")
                .blocks[0]
                .parameter("critical_stretch_alpha"),
            0.0);  // α = 0 is allowed: s0 stays fixed
  const std::string pairs = "give youngs_modulus (and fracture_energy) or micromodulus (and critical_stretch), not a mix";
  EXPECT_EQ(case_error("\"micromodulus\": 3.4e21,", "\"micromodulus\": 3.4e21, \"youngs_modulus\": 7e10,"),
            "out/x/case.json: blocks[0].micromodulus: is given beside youngs_modulus: " + pairs);
  EXPECT_EQ(case_error("\"micromodulus\": 3.4e21,", ""), "out/x/case.json: blocks[0].youngs_modulus: is missing: " + pairs);
  EXPECT_EQ(case_error("\"micromodulus\": 3.4e21,", "\"youngs_modulus\": 7e10,"),
            "out/x/case.json: blocks[0].critical_stretch: is given with youngs_modulus: " + pairs +
                " (fracture_energy gives s0 from E)");
  EXPECT_EQ(case_error("\"critical_stretch\": 0.001,", "\"fracture_energy\": 4,"),
            "out/x/case.json: blocks[0].fracture_energy: is given with micromodulus: " + pairs +
                " (critical_stretch is s0 itself)");
  EXPECT_EQ(case_error("\"critical_stretch\": 0.001,", ""),
            "out/x/case.json: blocks[0].critical_stretch_alpha: needs a breakable material: give fracture_energy or "
            "critical_stretch");
  EXPECT_EQ(case_error("\"critical_stretch_alpha\": 0.25", "\"critical_stretch_alpha\": -0.1"),
            "out/x/case.json: blocks[0].critical_stretch_alpha: must be at least 0.0, got -0.1");
  EXPECT_EQ(case_error("\"breaking_order\": \"lammps\"", "\"breaking_order\": \"lamps\""),
            "out/x/case.json: breaking_order: unknown order 'lamps'; known: thesis, lammps");
}
