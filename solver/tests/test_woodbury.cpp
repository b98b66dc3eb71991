// Broken bonds taken out of a factorised tangent (linalg/woodbury.hpp,
// integrators/bonds_out_of_factor.hpp): the corrected solve is the solve with the tangent assembled
// without those bonds, round by round; and what cannot be so taken out is refused.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "integrators/bonds_out_of_factor.hpp"
#include "lattice.hpp"
#include "linalg/cholesky.hpp"
#include "linalg/woodbury.hpp"
#include "operator/force_operator.hpp"

namespace {

constexpr double kDx = 1e-3;
constexpr int kSide = 16;

pd::Model plate_model(int dimension) {
  if (dimension == 2)
    return pdtest::held_at_left(pdtest::lattice_case(2, "plane_stress", kDx, 3.015 * kDx, 1e9, 1000.0, -1.0),
                                pdtest::cubic_lattice(kSide, kSide, 1, kDx, 2), kDx);
  return pdtest::held_at_left(pdtest::lattice_case(3, "3d", kDx, 3.015 * kDx, 1e9, 1000.0, -1.0),
                              pdtest::cubic_lattice(kSide, kSide - 2, 5, kDx, 3), kDx);
}

struct Plate {
  // A 2D lattice of 16 × 16 nodes (or a 3D slab of 16 × 14 × 5), δ = 3.015 dx, its first
  // two columns held; stretched along x and sheared, so that every bond has both an axial and a
  // transverse stiffness (s/y ≠ 0).
  int dimension;
  pd::Model m;
  pd::ForceOperator op{m};
  pd::State s{m.nodes.size()};
  pd::FreeDofs dofs;
  explicit Plate(int dim = 2) : dimension(dim), m(plate_model(dim)) {
    for (std::size_t i = 0; i < s.size(); ++i) {
      s.u[0][i] = 1e-3 * m.nodes.x[0][i] + 2e-4 * m.nodes.x[1][i];
      s.u[1][i] = -3e-4 * m.nodes.x[1][i];
      if (dim == 3) s.u[2][i] = 1e-4 * m.nodes.x[0][i] - 2e-4 * m.nodes.x[2][i];
    }
    op.impose_prescribed_motion(s, 0.0);
    // A node held in y alone (a roller): its bonds keep their x (and z) columns only at that end.
    m.conditions.fixed[1][node(8, 2)] = 1;
    dofs = pd::FreeDofs::of(m.nodes.size(), dim, op.fixed());
  }
  bool factorize(pd::SparseCholesky& factor) const { return factor.factorize(op.assemble_stiffness(s, 0.0, dofs)); }
  // Breaks the bond of row i to j, both halves (or only i's with one_side).
  void break_bond(std::size_t i, std::size_t j, bool one_side = false) {
    for (int side = 0; side < (one_side ? 1 : 2); ++side) {
      const std::size_t a = side == 0 ? i : j, b = side == 0 ? j : i;
      for (auto k = m.bonds.offsets[a]; k < m.bonds.offsets[a + 1]; ++k)
        if (static_cast<std::size_t>(m.bonds.neighbour[static_cast<std::size_t>(k)]) == b) m.bonds.broken[static_cast<std::size_t>(k)] = 1;
    }
  }
  std::size_t node(int x, int y) const { return pdtest::node_index(x, y, dimension == 3 ? 2 : 0, kSide, dimension == 3 ? kSide - 2 : kSide); }
};

std::vector<double> load(std::size_t n) {
  std::vector<double> b(n);
  for (std::size_t q = 0; q < n; ++q) b[q] = std::sin(0.37 * static_cast<double>(q) + 0.1) + 0.25;
  return b;
}

// max |a − b| / max |b|
double relative_difference(const std::vector<double>& a, const std::vector<double>& b) {
  double diff = 0.0, scale = 0.0;
  for (std::size_t q = 0; q < b.size(); ++q) diff = std::max(diff, std::fabs(a[q] - b[q])), scale = std::max(scale, std::fabs(b[q]));
  return diff / scale;
}

}  // namespace

namespace {

void rounds_solve_as_the_tangent_without_them(int dimension) {
  Plate p(dimension);
  pd::SparseCholesky factor;
  ASSERT_TRUE(p.factorize(factor));
  const std::vector<double> b = load(p.dofs.size());
  pd::Woodbury out;
  // Round 1: three bonds at the middle, along x, y and a diagonal; one to a held node.
  std::vector<std::uint8_t> before = p.m.bonds.broken;
  const std::size_t c = p.node(8, 8);
  p.break_bond(c, p.node(9, 8));
  p.break_bond(c, p.node(8, 10));
  p.break_bond(c, p.node(10, 9));
  p.break_bond(p.node(1, 5), p.node(3, 5));  // node (1, 5) is held: its end has no dofs
  p.break_bond(p.node(8, 2), p.node(9, 2));  // node (8, 2) is held in y only
  const std::vector<std::uint8_t> after = p.m.bonds.broken;
  EXPECT_EQ(pd::add_broken_bonds(p.m, before, p.s.u, false, p.dofs, out), 5);
  EXPECT_EQ(out.columns(), 5 * dimension);  // every component is a dof at one end at least
  EXPECT_EQ(p.m.bonds.broken, after);  // the flags as they were found
  ASSERT_TRUE(out.update(factor, p.dofs.size()));
  std::vector<double> corrected, direct;
  factor.solve(b, corrected);
  out.apply(corrected);
  pd::SparseCholesky fresh;
  ASSERT_TRUE(p.factorize(fresh));  // now without the four bonds
  fresh.solve(b, direct);
  EXPECT_LT(relative_difference(corrected, direct), 1e-10) << dimension << "D";
  // Without the correction the solve is another one: the check above is not vacuous.
  std::vector<double> plain;
  factor.solve(b, plain);
  EXPECT_GT(relative_difference(plain, direct), 1e-4);
  // Round 2: two more, added to the first four.
  before = p.m.bonds.broken;
  p.break_bond(p.node(12, 3), p.node(13, 3));
  p.break_bond(p.node(12, 3), p.node(12, 4));
  EXPECT_EQ(pd::add_broken_bonds(p.m, before, p.s.u, false, p.dofs, out), 2);
  EXPECT_EQ(out.columns(), 7 * dimension);
  ASSERT_TRUE(out.update(factor, p.dofs.size()));
  factor.solve(b, corrected);
  out.apply(corrected);
  ASSERT_TRUE(p.factorize(fresh));
  fresh.solve(b, direct);
  EXPECT_LT(relative_difference(corrected, direct), 1e-10) << dimension << "D";
}

}  // namespace

TEST(Woodbury, BondsTakenOutRoundByRoundSolveAsTheTangentWithoutThemIn2d) { rounds_solve_as_the_tangent_without_them(2); }

TEST(Woodbury, BondsTakenOutRoundByRoundSolveAsTheTangentWithoutThemIn3d) { rounds_solve_as_the_tangent_without_them(3); }

TEST(Woodbury, ABondBrokenOnOneSideOrANodeLeftHangingIsRefused) {
  Plate p;
  pd::SparseCholesky factor;
  ASSERT_TRUE(p.factorize(factor));
  // One half only: U C Uᵀ would not be the change.
  pd::Woodbury out;
  std::vector<std::uint8_t> before = p.m.bonds.broken;
  p.break_bond(p.node(8, 8), p.node(9, 8), true);
  EXPECT_EQ(pd::add_broken_bonds(p.m, before, p.s.u, false, p.dofs, out), -1);
  EXPECT_EQ(out.columns(), 0);
  // Every bond of a free node: the tangent without them is singular (the node hangs by nothing),
  // and S says so.
  before = p.m.bonds.broken;
  const std::size_t c = p.node(12, 12);
  for (auto k = p.m.bonds.offsets[c]; k < p.m.bonds.offsets[c + 1]; ++k)
    p.break_bond(c, static_cast<std::size_t>(p.m.bonds.neighbour[static_cast<std::size_t>(k)]));
  const std::int64_t bonds = p.m.bonds.offsets[c + 1] - p.m.bonds.offsets[c];
  pd::Woodbury hanging;
  EXPECT_EQ(pd::add_broken_bonds(p.m, before, p.s.u, false, p.dofs, hanging), bonds);
  EXPECT_FALSE(hanging.update(factor, p.dofs.size()));
}
