// The bond list: the cell list finds exactly the brute-force family, both directed copies exist
// with bitwise-equal lengths, lattice bonds at exactly δ are kept, and eq. 2.5's time step.
#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <random>
#include <set>

#include "core/error.hpp"
#include "lattice.hpp"

TEST(Bonds, CellListMatchesBruteForceOnRandomCloud) {
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> uni(0.0, 1.0);
  const std::size_t n = 1500;
  pd::Vec3Array x = pd::make_vec3(n);
  for (std::size_t i = 0; i < n; ++i) {
    x[0][i] = uni(rng) * 2.0;
    x[1][i] = uni(rng);
    x[2][i] = uni(rng) * 0.5;
  }
  const double horizon = 0.13;
  const pd::BondList b = pd::build_bonds(x, horizon);
  ASSERT_EQ(b.nodes(), n);
  std::size_t expected_total = 0;
  for (std::size_t i = 0; i < n; ++i) {
    std::vector<std::int32_t> expected;
    for (std::size_t j = 0; j < n; ++j) {
      const double r = std::sqrt(std::pow(x[0][j] - x[0][i], 2) + std::pow(x[1][j] - x[1][i], 2) +
                                 std::pow(x[2][j] - x[2][i], 2));
      if (j != i && r <= horizon) expected.push_back(static_cast<std::int32_t>(j));
    }
    expected_total += expected.size();
    const std::vector<std::int32_t> got(b.neighbour.begin() + b.offsets[i], b.neighbour.begin() + b.offsets[i + 1]);
    ASSERT_EQ(got, expected) << "node " << i;
  }
  EXPECT_EQ(b.directed(), expected_total);
  EXPECT_GT(expected_total, 10 * n);  // the test exercises real families
}

TEST(Bonds, EachBondStoredFromBothEndsWithTheSameLength) {
  const pd::Nodes nodes = pdtest::cubic_lattice(8, 7, 7, 0.1, 3);
  const pd::BondList b = pd::build_bonds(nodes.x, 0.3 * (1 + 1e-13));
  std::map<std::pair<int, int>, double> length;
  for (std::size_t i = 0; i < b.nodes(); ++i)
    for (auto k = b.offsets[i]; k < b.offsets[i + 1]; ++k)
      length[{static_cast<int>(i), b.neighbour[static_cast<std::size_t>(k)]}] =
          pd::bond_length(nodes.x, i, static_cast<std::size_t>(b.neighbour[static_cast<std::size_t>(k)]));
  for (const auto& [key, r] : length) {
    auto it = length.find({key.second, key.first});
    ASSERT_NE(it, length.end());
    EXPECT_EQ(it->second, r);  // bitwise
  }
  // Bulk node: 122 partners at m = 3 (docs/theory.md C1).
  const std::size_t bulk = pdtest::node_index(3, 3, 3, 8, 7);
  EXPECT_EQ(b.offsets[bulk + 1] - b.offsets[bulk], 122);
}

TEST(Bonds, BondsOfLengthExactlyHorizonAreKept) {
  // δ = 3·dx computed in floating point; the (3,0,0) neighbours sit at |ξ| = δ up to round-off.
  const double dx = 0.1;
  const pd::Nodes nodes = pdtest::cubic_lattice(7, 7, 7, dx, 3);
  const pd::BondList b = pd::build_bonds(nodes.x, 3 * dx);
  const std::size_t bulk = pdtest::node_index(3, 3, 3, 7, 7);
  EXPECT_EQ(b.offsets[bulk + 1] - b.offsets[bulk], 122);
}

TEST(Bonds, CoincidentNodesAreRejected) {
  pd::Vec3Array x = pd::make_vec3(3);
  x[0] = {0.0, 1.0, 1.0};
  EXPECT_THROW(pd::build_bonds(x, 1.5), pd::Error);
}

TEST(Bonds, StableTimeStepIsThesisEq25) {
  // Two nodes one dx apart: Δt = √(2ρ / (V c / |ξ|)).
  pd::Nodes nodes = pdtest::cubic_lattice(2, 1, 1, 0.01, 3);
  const pd::Case c = pdtest::lattice_case(3, "3d", 0.01, 0.015, 1e9, 2000.0, -1.0);
  const pd::Model m = pd::build_model(c, nodes);
  const double cm = m.material.block[0].micromodulus;
  EXPECT_DOUBLE_EQ(pd::stable_time_step(m), std::sqrt(2.0 * 2000.0 / (1e-6 * cm / 0.01)));
  EXPECT_DOUBLE_EQ(cm, 12.0 * 1e9 / (3.14159265358979323846 * std::pow(0.015, 4)));  // docs/theory.md T2
}

TEST(Material, CriticalStretchMatchesPeridynamicsJl) {
  // docs/theory.md T2 unit test: E = 1, ν = 0.25, δ = 2, Gc = 1 → εc = 0.6454972243679028 (3D).
  pd::BlockMaterial b;
  b.parameters["youngs_modulus"] = 1.0;
  b.parameters["fracture_energy"] = 1.0;
  const pd::MaterialTable t = pd::make_material_table({b}, "3d", 2.0, 0.0);
  EXPECT_NEAR(t.block[0].critical_stretch, 0.6454972243679028, 1e-15);
}

TEST(Material, UnknownAnalysisListsTheRegistry) {
  try {
    pd::make_material_table({pd::BlockMaterial{}}, "plane", 1.0, 1.0);
    FAIL() << "no error";
  } catch (const pd::Error& e) {
    EXPECT_NE(std::string(e.what()).find("known: 3d, plane_strain, plane_stress"), std::string::npos) << e.what();
  }
}

// A node 1e150 m from the others (the largest coordinate the node file accepts): the cell grid
// grows its bins in double arithmetic instead of overflowing an integer count (issue 17, item 9:
// "internal error … max_size()"); the far node has no bond, the others keep theirs.
TEST(Bonds, AFarNodeDoesNotOverflowTheCellGrid) {
  const double dx = 1e-3;
  pd::Nodes nodes = pdtest::cubic_lattice(4, 4, 1, dx, 2, 1e-3);
  const pd::BondList near = pd::build_bonds(nodes.x, 1.5 * dx);
  for (std::size_t d = 0; d < 3; ++d) nodes.x[d].push_back(d == 0 ? 1e150 : 0.0);
  const pd::BondList b = pd::build_bonds(nodes.x, 1.5 * dx);
  ASSERT_EQ(b.nodes(), nodes.x[0].size());
  EXPECT_EQ(b.offsets[b.nodes()] - b.offsets[b.nodes() - 1], 0);  // the far node: no bond
  EXPECT_EQ(b.directed(), near.directed());
  EXPECT_EQ(std::vector<std::int32_t>(b.neighbour.begin(), b.neighbour.end()),
            std::vector<std::int32_t>(near.neighbour.begin(), near.neighbour.end()));
}
