// What a decomposed run computes on its pieces without the whole bond list (issue 37 item 3), for
// 1, 2 and 3 ranks (ctest mpi_ranks_R): LPS's per-node constants and the surface correction's
// factors, summed over each rank's owned rows with the ghosts' taken from their owners, are the
// serial bits at every local node and bond; mixed's load-path check, each rank's components of the
// bond graph joined across the ranks, gives the serial verdict for cuts across the rank boundaries.
#include <gtest/gtest.h>
#include <mpi.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <tuple>

#include "bits.hpp"
#include "core/model.hpp"
#include "integrators/load_path.hpp"
#include "lattice.hpp"
#include "materials/lps/lps.hpp"
#include "operator/force_operator.hpp"
#include "parallel/mpi_decomposed.hpp"

namespace {

constexpr double kDx = 1e-3;

// A brick of `law` with surface correction `method`; its pieces made as pdsolve makes them when no
// rank holds the whole list (run/prepare.cpp): the rows of each rank's own nodes only.
pd::Case brick_case(const std::string& law, const std::string& method) {
  pd::Case c = pdtest::lattice_case(3, "3d", kDx, 3.015 * kDx, 70e9, 2700.0, 3.8);
  c.blocks[0].model = law;
  if (law == "lps") c.blocks[0].parameters["poisson_ratio"] = 0.27;
  c.surface_correction = method;
  return c;
}

std::unique_ptr<pd::MpiDecomposed> pieces_from_rows(const pd::Case& c, const pd::Nodes& nodes) {
  pd::Model skeleton = pd::build_model_without_bonds(c, nodes);
  skeleton.bonds.offsets = pd::count_bonds(skeleton.nodes.x, pd::bond_search_cutoff(c));
  skeleton.bond_model = pd::material_registry().get(c.blocks[0].model).make(skeleton);
  return std::make_unique<pd::MpiDecomposed>(MPI_COMM_WORLD, skeleton, pd::bond_search_cutoff(c), c.cracks,
                                             c.surface_correction);
}

// Owned rows' bond values of the piece that differ in bits from the whole model's same rows.
std::int64_t rows_differing(const pd::LocalPiece& p, const pd::BondList& whole, const std::vector<double>& w,
                            const std::vector<double>& l) {
  std::int64_t differ = 0;
  for (std::int32_t local : p.owned_local) {
    const auto g = static_cast<std::size_t>(p.global[static_cast<std::size_t>(local)]);
    const auto begin = p.model.bonds.offsets[static_cast<std::size_t>(local)];
    if (p.model.bonds.offsets[static_cast<std::size_t>(local) + 1] - begin != whole.offsets[g + 1] - whole.offsets[g]) return -1;
    for (std::int64_t k = 0; k < whole.offsets[g + 1] - whole.offsets[g]; ++k)
      differ += !pdtest::same_bits(l[static_cast<std::size_t>(begin + k)], w[static_cast<std::size_t>(whole.offsets[g] + k)]);
  }
  return differ;
}

}  // namespace

class PiecesConstants : public ::testing::TestWithParam<std::tuple<std::string, std::string>> {};

TEST_P(PiecesConstants, AreTheSerialBitsAtOwnedNodesAndGhosts) {
  const auto& [law, method] = GetParam();
  const pd::Case c = brick_case(law, method);
  const pd::Nodes nodes = pdtest::cubic_lattice(11, 9, 8, kDx, 3);
  pd::Model whole = pd::build_model(c, nodes);
  const auto dec = pieces_from_rows(c, nodes);
  const pd::LocalPiece& p = dec->piece();
  if (dec->ranks() > 1) ASSERT_GT(dec->total(static_cast<std::int64_t>(p.ghost_local.size())), 0);
  // The surface factors of the owned rows (each end's factors: the ghosts' came from their owners).
  EXPECT_EQ(whole.bonds.corrected(), method != "none");
  EXPECT_EQ(p.model.bonds.corrected(), method != "none");
  if (method != "none") {
    EXPECT_EQ(dec->total(rows_differing(p, whole.bonds, whole.bonds.surface_factor, p.model.bonds.surface_factor)), 0);
    // Not all 1: the brick's faces are corrected.
    EXPECT_NE(*std::min_element(whole.bonds.surface_factor.begin(), whole.bonds.surface_factor.end()),
              *std::max_element(whole.bonds.surface_factor.begin(), whole.bonds.surface_factor.end()));
  }
  // LPS's weighted volume at every local node, ghosts too (their rows are empty on the piece).
  if (law == "lps") {
    const auto& m_whole = dynamic_cast<const pd::LpsModel&>(*whole.bond_model).weighted_volume();
    const auto& m_piece = dynamic_cast<const pd::LpsModel&>(*p.model.bond_model).weighted_volume();
    ASSERT_EQ(m_piece.size(), p.size());
    std::int64_t differ = 0;
    for (std::size_t l = 0; l < p.size(); ++l)
      differ += !pdtest::same_bits(m_piece[l], m_whole[static_cast<std::size_t>(p.global[l])]);
    EXPECT_EQ(dec->total(differ), 0);
  }
  // Every node's term of eq. 2.5 reads both ends' constants: the least step is the serial one.
  EXPECT_TRUE(pdtest::same_bits(dec->minimum(pd::stable_time_step(p.model)), pd::stable_time_step(whole)));
  // And the force at a wavy displacement, owned nodes (each reads its ghosts' m, a, P, g).
  pd::ForceOperator op(dec->piece().model), serial(whole);
  op.set_decomposed(dec.get());
  pd::State local(p.size()), all(whole.nodes.size());
  all.u = pdtest::wavy(whole, kDx, 2e-5);
  local.u = pd::to_local(p, all.u);
  op.evaluate(local, 0.0);
  serial.evaluate(all, 0.0);
  std::int64_t differ = 0;
  for (std::int32_t l : p.owned_local)
    for (std::size_t d = 0; d < 3; ++d)
      differ += !pdtest::same_bits(local.f[d][static_cast<std::size_t>(l)], all.f[d][static_cast<std::size_t>(p.global[static_cast<std::size_t>(l)])]);
  EXPECT_EQ(dec->total(differ), 0);
}

INSTANTIATE_TEST_SUITE_P(LawsAndCorrections, PiecesConstants,
                         ::testing::Combine(::testing::Values(std::string("lps"), std::string("pmb")),
                                            ::testing::Values(std::string("none"), std::string("energy"),
                                                              std::string("volume"))));

namespace {

constexpr int kNx = 18, kNy = 4, kNz = 4;

// The bar of test_mixed.cpp, longer: its left grip clamped, its right one pulled (two groups).
pd::Model bar() {
  pd::Case c = pdtest::lattice_case(3, "3d", kDx, 3.015 * kDx, 1e9, 1000.0, 3.6);
  pdtest::clamp_left_pull_right(c, 1e-5, 1e-3, true);
  return pd::build_model(c, pdtest::bar_with_grips(kNx, kNy, kNz, kDx));
}

// Breaks the directed bonds across the plane x = cut (only those from the left end when
// `one_copy`: the reverse copies stay intact, and the edge with them), but `keep` edges.
void cut(pd::Model& m, double at, bool one_copy, int keep) {
  const auto& x = m.nodes.x[0];
  for (std::size_t i = 0; i < m.bonds.nodes(); ++i)
    for (std::int64_t k = m.bonds.offsets[i]; k < m.bonds.offsets[i + 1]; ++k) {
      const auto j = static_cast<std::size_t>(m.bonds.neighbour[static_cast<std::size_t>(k)]);
      if (std::min(x[i], x[j]) < at && std::max(x[i], x[j]) > at && (!one_copy || x[i] < x[j]) && keep-- <= 0)
        m.bonds.broken[static_cast<std::size_t>(k)] = 1;
    }
}

// Every bond of node i broken (both copies): a free fragment of one node.
void loosen(pd::Model& m, std::size_t i) {
  for (std::int64_t k = m.bonds.offsets[i]; k < m.bonds.offsets[i + 1]; ++k) {
    m.bonds.broken[static_cast<std::size_t>(k)] = 1;
    const auto j = static_cast<std::size_t>(m.bonds.neighbour[static_cast<std::size_t>(k)]);
    for (std::int64_t q = m.bonds.offsets[j]; q < m.bonds.offsets[j + 1]; ++q)
      if (static_cast<std::size_t>(m.bonds.neighbour[static_cast<std::size_t>(q)]) == i) m.bonds.broken[static_cast<std::size_t>(q)] = 1;
  }
}

}  // namespace

TEST(PiecesLoadPath, TheVerdictsAreTheSerialOnesForCutsAcrossTheRankBoundaries) {
  const pd::Model uncut = bar();
  pd::MpiDecomposed dec(MPI_COMM_WORLD, uncut);
  pd::LocalPiece& p = dec.piece();
  const pd::LoadPath serial(uncut), pieces(p.model, &dec);
  ASSERT_EQ(pieces.groups(), serial.groups());
  ASSERT_EQ(pieces.groups(), 2);
  ASSERT_TRUE(pieces.linked_uncut());
  const pd::LoadPath kept_serial(uncut), kept(p.model, &dec);  // asked after every change: the local check
  std::int64_t crossing_cuts = 0, separated = 0, cases = 0;
  for (int half = 5; half < 2 * kNx - 5; ++half)
    for (int variant = 0; variant < 4; ++variant) {
      pd::Model whole = uncut;
      const double at = 0.5 * half * kDx;
      cut(whole, at, variant == 1, variant == 2 ? 1 : 0);  // variant 2: one edge left across
      if (variant == 3) {  // and a loose node on each side of the cut, beside it
        for (std::size_t i = 0; i < whole.nodes.size(); ++i)
          if (std::fabs(whole.nodes.x[0][i] - (at - 2.5 * kDx)) < 0.6 * kDx && whole.nodes.x[1][i] == kDx && whole.nodes.x[2][i] == kDx)
            loosen(whole, i);
          else if (std::fabs(whole.nodes.x[0][i] - (at + 2.5 * kDx)) < 0.6 * kDx && whole.nodes.x[1][i] == 2 * kDx &&
                   whole.nodes.x[2][i] == 2 * kDx)
            loosen(whole, i);
      }
      pd::rows_to_local(p, whole.bonds, p.model.bonds);
      // Whether the cut broke bonds between nodes of two ranks (some cut must, on several ranks).
      std::int64_t crossing = 0;
      for (std::int32_t l : p.owned_local)
        for (std::int64_t k = p.model.bonds.offsets[static_cast<std::size_t>(l)]; k < p.model.bonds.offsets[static_cast<std::size_t>(l) + 1]; ++k)
          crossing += p.model.bonds.broken[static_cast<std::size_t>(k)] && !p.owned[static_cast<std::size_t>(p.model.bonds.neighbour[static_cast<std::size_t>(k)])];
      crossing_cuts += dec.total(crossing) > 0;
      const bool expected = serial.separated(whole.bonds);
      separated += expected;
      ++cases;
      EXPECT_EQ(pd::LoadPath(p.model, &dec).separated(p.model.bonds), expected) << "cut at " << at << ", variant " << variant;
      EXPECT_EQ(kept.separated(p.model.bonds), expected) << "cut at " << at << ", variant " << variant;
      EXPECT_EQ(kept_serial.separated(whole.bonds), expected);
      const std::vector<std::int32_t> held = serial.held_by_one_group(whole.bonds), mine = pieces.held_by_one_group(p.model.bonds);
      ASSERT_EQ(mine.size(), p.size());
      std::int64_t wrong = 0;
      for (std::size_t l = 0; l < p.size(); ++l) wrong += mine[l] != held[static_cast<std::size_t>(p.global[l])];
      EXPECT_EQ(dec.total(wrong), 0) << "cut at " << at << ", variant " << variant;
    }
  // Both verdicts occur, and on several ranks cuts ran across a rank boundary.
  EXPECT_GT(separated, 0);
  EXPECT_LT(separated, cases);
  if (dec.ranks() > 1) EXPECT_GT(crossing_cuts, 0);
}
