// Reaction forces of a decomposed run (core/reactions.hpp, issue 37 item 3): each rank sends only the
// terms of its owned support nodes to rank 0 (Decomposed::gather_keyed), which adds them in the
// serial order, so history.csv's reaction columns are the serial run's bits without gathering the
// whole state. For 1, 2 and 3 ranks (ctest mpi_ranks_R).
#include <gtest/gtest.h>
#include <mpi.h>

#include <cmath>

#include "bits.hpp"
#include "core/model.hpp"
#include "core/reactions.hpp"
#include "lattice.hpp"
#include "parallel/mpi_decomposed.hpp"

namespace {

constexpr double kDx = 1e-3;

}  // namespace

TEST(DecomposedReactions, RankZeroAddsThePiecesTermsToTheSerialBits) {
  const int nx = 14, ny = 9, nz = 8;
  pd::Case c = pdtest::lattice_case(3, "3d", kDx, 3.015 * kDx, 70e9, 2700.0, 3.8);
  // Both grips held in x, y and z, the right one pulled with a velocity table (its slope: a ≠ 0).
  c.boundary_conditions.push_back({"left", "displacement", 0, {0.0}, {0.0}});
  c.boundary_conditions.push_back({"left", "displacement", 1, {0.0}, {0.0}});
  c.boundary_conditions.push_back({"right", "velocity", 0, {0.0, 2e-6}, {0.0, 5.0}});
  c.boundary_conditions.push_back({"right", "displacement", 2, {0.0}, {0.0}});
  const pd::Model global = pd::build_model(c, pdtest::bar_with_grips(nx, ny, nz, kDx));
  pd::MpiDecomposed dec(MPI_COMM_WORLD, global);
  const pd::LocalPiece& p = dec.piece();

  // A force density with every bit pattern different: sums in another order would round otherwise.
  pd::State serial(global.nodes.size()), local(p.size());
  for (int d = 0; d < 3; ++d)
    for (std::size_t i = 0; i < global.nodes.size(); ++i)
      serial.f[static_cast<std::size_t>(d)][i] = std::sin(1.7 * static_cast<double>(i) + d) * 1.3e12 + 0.1 * d;
  for (int d = 0; d < 3; ++d)
    for (std::size_t l = 0; l < p.size(); ++l)
      local.f[static_cast<std::size_t>(d)][l] = serial.f[static_cast<std::size_t>(d)][static_cast<std::size_t>(p.global[l])];

  const double t = 1e-6;  // on the velocity table's ramp: a = 2.5e6 m/s² on the right grip
  std::int64_t terms_here = 0;
  for (const char* set : {"left", "right"}) {
    const pd::ReactionTerms terms = pd::reaction_terms(p.model, local, set, t, p.global, p.global_nodes);
    terms_here += static_cast<std::int64_t>(terms.key.size());
    const auto sorted = dec.gather_keyed(terms.key, terms.value);
    if (dec.rank() != 0) {
      EXPECT_TRUE(sorted.empty());
      continue;
    }
    const std::array<double, 3> pieces = pd::sum_reaction_terms(p.model, sorted, p.global_nodes);
    const std::array<double, 3> whole = pd::reaction_force(global, serial, set, t);
    for (int d = 0; d < 3; ++d) EXPECT_TRUE(pdtest::same_bits(pieces[static_cast<std::size_t>(d)], whole[static_cast<std::size_t>(d)])) << set << " " << d;
    // Each prescribed component has a non-zero reaction; the free one (z on the left) none.
    EXPECT_NE(whole[0], 0.0);
    EXPECT_EQ(whole[2] == 0.0, std::string(set) == "left");
  }
  // Every support node's term came from exactly one rank: 2 conditions × 2 grips' nodes (2 layers each).
  EXPECT_EQ(dec.total(terms_here), 2 * 2 * (2 * ny * nz));
  // And on several ranks both grips are not on one rank: the gather joined the pieces.
  if (dec.ranks() > 1) EXPECT_LT(terms_here, 2 * 2 * (2 * ny * nz));
}
