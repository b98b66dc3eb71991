// The decomposition of issue 15 without MPI: Morton order, pieces balanced by bond count, the
// errors for impossible decompositions, and each rank's piece — whose rows, run through the
// unchanged PMB kernel on local arrays, give the serial rows bit for bit (the heart of "results
// identical for any rank count"; tests/mpi/ checks the same with real messages under mpirun).
#include <gtest/gtest.h>

#include <cstring>
#include <set>

#include "core/cracks.hpp"
#include "core/error.hpp"
#include "lattice.hpp"
#include "materials/bond_model.hpp"
#include "materials/pmb/pmb.hpp"
#include "parallel/decomposition.hpp"
#include "parallel/local_model.hpp"
#include "pmb_s0.hpp"

namespace {

constexpr double kDx = 1e-3;

pd::Model lattice_model(int nx, int ny, int nz, double fracture_energy = -1.0) {
  const pd::Case c = pdtest::lattice_case(3, "3d", kDx, 3.015 * kDx, 70e9, 2700.0, fracture_energy);
  return pd::build_model(c, pdtest::cubic_lattice(nx, ny, nz, kDx, 3));
}

std::string error_of(const pd::Vec3Array& x, const pd::BondList& bonds, int ranks, double horizon) {
  try {
    pd::decompose(x, bonds, ranks, horizon);
  } catch (const pd::Error& e) {
    return e.what();
  }
  return "";
}

}  // namespace

TEST(Decomposition, MortonOrderOfACubeIsTheZCurve) {
  // The 8 corners of a cube in Morton order: x fastest, then y, then z — node_index order.
  const pd::Nodes nodes = pdtest::cubic_lattice(2, 2, 2, kDx, 3);
  const std::vector<std::uint64_t> keys = pd::morton_keys(nodes.x);
  for (std::size_t i = 1; i < keys.size(); ++i) EXPECT_LT(keys[i - 1], keys[i]) << i;
  // (1, 0, 0) is the largest 21-bit coordinate on x only: every third bit from bit 0.
  EXPECT_EQ(keys[1], 0x1249249249249249ULL);
  EXPECT_EQ(keys[2], keys[1] << 1);
  EXPECT_EQ(keys[4], keys[1] << 2);
}

TEST(Decomposition, ContiguousPiecesOfTheMortonOrderBalancedByBondCount) {
  const pd::Model m = lattice_model(16, 12, 10);
  std::int64_t total = 0, widest_row = 0;
  for (std::size_t i = 0; i < m.nodes.size(); ++i) {
    const std::int64_t row = 1 + m.bonds.offsets[i + 1] - m.bonds.offsets[i];
    total += row;
    widest_row = std::max(widest_row, row);
  }
  for (int ranks : {1, 2, 3, 7}) {
    const pd::Decomposition d = pd::decompose(m.nodes.x, m.bonds, ranks, m.horizon);
    ASSERT_EQ(d.piece_start.size(), static_cast<std::size_t>(ranks) + 1);
    EXPECT_EQ(d.piece_start.front(), 0);
    EXPECT_EQ(d.piece_start.back(), static_cast<std::int64_t>(m.nodes.size()));
    std::int64_t sum = 0;
    for (int r = 0; r < ranks; ++r) {
      // Each piece is a run of the curve, all of it owned by r.
      for (std::int64_t p = d.piece_start[static_cast<std::size_t>(r)]; p < d.piece_start[static_cast<std::size_t>(r) + 1]; ++p)
        EXPECT_EQ(d.owner[static_cast<std::size_t>(d.order[static_cast<std::size_t>(p)])], r);
      // Balanced: within one row's work of the even share (the cut is at a node).
      EXPECT_LE(std::abs(d.piece_work[static_cast<std::size_t>(r)] * ranks - total), widest_row * ranks) << ranks << " " << r;
      sum += d.piece_work[static_cast<std::size_t>(r)];
    }
    EXPECT_EQ(sum, total);
  }
}

TEST(Decomposition, ImpossibleDecompositionsAreClearErrors) {
  const pd::Model m = lattice_model(10, 4, 4);  // 160 nodes
  EXPECT_NE(error_of(m.nodes.x, m.bonds, 161, m.horizon).find("161 MPI ranks for 160 nodes"), std::string::npos)
      << error_of(m.nodes.x, m.bonds, 161, m.horizon);
  EXPECT_NE(error_of(m.nodes.x, m.bonds, 161, m.horizon).find("at most 160 ranks"), std::string::npos);
  // 40 ranks on 160 nodes: pieces of about 4 nodes, a few dx across, inside a horizon of 3 dx.
  EXPECT_NE(error_of(m.nodes.x, m.bonds, 40, m.horizon).find("less than the horizon"), std::string::npos)
      << error_of(m.nodes.x, m.bonds, 40, m.horizon);
  EXPECT_EQ(error_of(m.nodes.x, m.bonds, 2, m.horizon), "");

  // One node holding most of the bonds: with 3 ranks the middle one gets nothing.
  pd::Vec3Array x = pd::make_vec3(3);
  x[0] = {0.0, 1.0, 2.0};
  pd::BondList heavy;
  heavy.offsets = {0, 1000, 1001, 1002};
  EXPECT_NE(error_of(x, heavy, 3, 0.1).find("rank 1 of 3 gets no node"), std::string::npos) << error_of(x, heavy, 3, 0.1);
}

TEST(LocalPiece, GhostsAreExactlyTheBondPartnersOfOwnedRowsAndRowsKeepTheirOrder) {
  pd::Model m = lattice_model(10, 9, 8);
  const int ranks = 3;
  const pd::Decomposition d = pd::decompose(m.nodes.x, m.bonds, ranks, m.horizon);
  std::int64_t owned_total = 0;
  for (int r = 0; r < ranks; ++r) {
    const pd::LocalPiece p = pd::make_local_piece(m, d.owner, r);
    std::set<std::int32_t> partners;
    for (std::size_t i = 0; i < m.nodes.size(); ++i)
      if (d.owner[i] == r)
        for (std::int64_t k = m.bonds.offsets[i]; k < m.bonds.offsets[i + 1]; ++k)
          if (d.owner[static_cast<std::size_t>(m.bonds.neighbour[static_cast<std::size_t>(k)])] != r)
            partners.insert(m.bonds.neighbour[static_cast<std::size_t>(k)]);
    std::set<std::int32_t> ghosts;
    for (std::int32_t l : p.ghost_local) ghosts.insert(p.global[static_cast<std::size_t>(l)]);
    EXPECT_EQ(ghosts, partners);
    EXPECT_FALSE(ghosts.empty());
    owned_total += static_cast<std::int64_t>(p.owned_local.size());
    for (std::size_t l = 1; l < p.size(); ++l) EXPECT_LT(p.global[l - 1], p.global[l]);
    for (std::size_t l = 0; l < p.size(); ++l) {
      const auto i = static_cast<std::size_t>(p.global[l]);
      const std::int64_t lk = p.model.bonds.offsets[l], len = p.model.bonds.offsets[l + 1] - lk;
      if (!p.owned[l]) {
        EXPECT_EQ(len, 0);  // a ghost's row is its owner's
        continue;
      }
      ASSERT_EQ(len, m.bonds.offsets[i + 1] - m.bonds.offsets[i]);
      for (std::int64_t q = 0; q < len; ++q)
        EXPECT_EQ(p.global[static_cast<std::size_t>(p.model.bonds.neighbour[static_cast<std::size_t>(lk + q)])],
                  m.bonds.neighbour[static_cast<std::size_t>(m.bonds.offsets[i] + q)]);
    }
  }
  EXPECT_EQ(owned_total, static_cast<std::int64_t>(m.nodes.size()));
}

TEST(LocalPiece, OwnedRowsOfTheKernelOnAPieceAreTheSerialRowsBitwise) {
  pd::Model m = lattice_model(10, 9, 8, 0.5);
  pd::Vec3Array u = pd::make_vec3(m.nodes.size());
  const double s0 = m.material.block[0].critical_stretch;
  for (std::size_t i = 0; i < m.nodes.size(); ++i) {
    u[0][i] = (m.nodes.x[0][i] > 4.5 * kDx ? 2.0 * s0 * kDx : 0.0) + 1e-3 * kDx * std::sin(1e3 * m.nodes.x[1][i]);
    u[1][i] = 1e-3 * kDx * std::cos(0.7e3 * m.nodes.x[2][i] + 1e3 * m.nodes.x[0][i]);
  }
  pd::Model serial = m;
  pd::Vec3Array f = pd::make_vec3(m.nodes.size());
  std::vector<double> w(m.nodes.size());
  const std::int64_t broken = pd::break_bonds_and_add_pmb_force(serial, u, f, w.data());
  ASSERT_GT(broken, 0);
  const pd::Decomposition d = pd::decompose(m.nodes.x, m.bonds, 3, m.horizon);
  std::int64_t broken_sum = 0;
  for (int r = 0; r < 3; ++r) {
    pd::LocalPiece p = pd::make_local_piece(m, d.owner, r);
    pd::Vec3Array fl = pd::make_vec3(p.size());
    std::vector<double> wl(p.size());
    broken_sum += pd::break_bonds_and_add_pmb_force(p.model, pd::to_local(p, u), fl, wl.data());
    for (std::int32_t l : p.owned_local) {
      const auto i = static_cast<std::size_t>(p.global[static_cast<std::size_t>(l)]);
      for (int c = 0; c < 3; ++c)
        EXPECT_EQ(std::memcmp(&fl[static_cast<std::size_t>(c)][static_cast<std::size_t>(l)], &f[static_cast<std::size_t>(c)][i], 8), 0);
      EXPECT_EQ(std::memcmp(&wl[static_cast<std::size_t>(l)], &w[i], 8), 0);
    }
  }
  EXPECT_EQ(broken_sum, broken);  // each broken bond counted once, on the rank of its lower end
}

// What a bond's breaking and force read besides positions travels into the piece: the LAMMPS order,
// the per-node s0 of the α rule (ghosts too: the halo refreshes them later) and the surface-
// correction factors of the owned rows (issue 15; before, the pieces ran the thesis order and the
// decomposed run refused the other two).
TEST(LocalPiece, CarriesTheBreakingOrderThePerNodeCriticalStretchAndTheSurfaceFactors) {
  pd::Model m = lattice_model(10, 9, 8, 0.5);
  m.break_after_force = true;
  for (double& alpha : m.material.alpha_pair) alpha = 0.25;  // the α rule: PMB declares s0_i
  pd::declare_state(m);
  std::vector<double>& s0 = *pd::node_critical_stretch(m);
  for (std::size_t i = 0; i < m.nodes.size(); ++i) s0[i] = 1e-3 * (1.0 + 1e-3 * static_cast<double>(i));
  m.bonds.surface_factor.resize(m.bonds.directed());
  for (std::size_t k = 0; k < m.bonds.directed(); ++k) m.bonds.surface_factor[k] = 1.0 + 1e-5 * static_cast<double>(k);
  const pd::Decomposition d = pd::decompose(m.nodes.x, m.bonds, 3, m.horizon);
  for (int r = 0; r < 3; ++r) {
    const pd::LocalPiece p = pd::make_local_piece(m, d.owner, r);
    EXPECT_TRUE(p.model.break_after_force);
    ASSERT_EQ(pdtest::s0_of(p.model).size(), p.size());
    ASSERT_EQ(p.model.bonds.surface_factor.size(), p.model.bonds.directed());
    for (std::size_t l = 0; l < p.size(); ++l) {
      const auto i = static_cast<std::size_t>(p.global[l]);
      EXPECT_EQ(pdtest::s0_of(p.model)[l], s0[i]);
      for (std::int64_t q = 0; q < p.model.bonds.offsets[l + 1] - p.model.bonds.offsets[l]; ++q)
        EXPECT_EQ(p.model.bonds.surface_factor[static_cast<std::size_t>(p.model.bonds.offsets[l] + q)],
                  m.bonds.surface_factor[static_cast<std::size_t>(m.bonds.offsets[i] + q)]);
    }
  }
  m.break_after_force = false;
  for (double& alpha : m.material.alpha_pair) alpha = 0.0;  // no α: no s0_i declared
  pd::declare_state(m);
  m.bonds.surface_factor.clear();
  const pd::LocalPiece plain = pd::make_local_piece(m, d.owner, 1);
  EXPECT_FALSE(plain.model.break_after_force);
  EXPECT_TRUE(pdtest::s0_of(plain.model).empty());
  EXPECT_FALSE(plain.model.bonds.corrected());
}

// A rank that builds only its own rows (issue 15: memory per rank falls with the rank count) gets
// the piece it would cut from the whole model, bit for bit: the same counts, owners, ghosts, rows,
// pre-cracked flags and LAMMPS s0 of its owned nodes — with the whole list never built.
TEST(LocalPiece, BuiltFromItsOwnRowsIsThePieceOfTheWholeModel) {
  pd::Case c = pdtest::lattice_case(3, "3d", kDx, 3.015 * kDx, 70e9, 2700.0, 0.5);
  c.partial_volume = "hhb";  // a widened family: the cut-off is the rule's, not δ
  c.cracks.push_back(pd::CrackSegment{{4.5 * kDx, -1.0, 0.0}, {4.5 * kDx, 3.5 * kDx, 0.0}});
  const pd::Model whole = pd::build_model(c, pdtest::cubic_lattice(12, 9, 8, kDx, 3));
  pd::Model skeleton = pd::build_model_without_bonds(c, pdtest::cubic_lattice(12, 9, 8, kDx, 3));
  EXPECT_TRUE(skeleton.bonds.neighbour.empty());
  skeleton.bonds.offsets = pd::count_bonds(skeleton.nodes.x, pd::bond_search_cutoff(c));
  ASSERT_EQ(skeleton.bonds.offsets, whole.bonds.offsets);
  skeleton.bond_model = pd::material_registry().get("pmb").make(skeleton);
  std::int64_t broken_in_whole = 0;
  for (std::uint8_t b : whole.bonds.broken) broken_in_whole += b;
  ASSERT_GT(broken_in_whole, 0);  // the crack cut some bonds
  const std::vector<double> s0 = pd::initial_node_critical_stretch(whole.material, whole.block_index, whole.bonds);
  const pd::Decomposition d = pd::decompose(whole.nodes.x, whole.bonds, 3, whole.horizon);
  ASSERT_EQ(pd::decompose(skeleton.nodes.x, skeleton.bonds.offsets, 3, skeleton.horizon).owner, d.owner);
  std::int64_t broken_in_pieces = 0, held = 0;
  for (int r = 0; r < 3; ++r) {
    std::vector<std::int32_t> rows;
    for (std::size_t i = 0; i < d.owner.size(); ++i)
      if (d.owner[i] == r) rows.push_back(static_cast<std::int32_t>(i));
    pd::BondList owned = pd::build_bond_rows(skeleton.nodes.x, pd::bond_search_cutoff(c), rows);
    pd::cut_crossing_bonds(c.cracks, skeleton.nodes.x, owned, &rows);
    const pd::LocalPiece own = pd::make_local_piece(skeleton, d.owner, r, owned);
    const pd::LocalPiece cut = pd::make_local_piece(whole, d.owner, r);
    EXPECT_EQ(own.global, cut.global);
    EXPECT_EQ(own.owned, cut.owned);
    EXPECT_EQ(own.model.bonds.offsets, cut.model.bonds.offsets);
    EXPECT_EQ(own.model.bonds.neighbour, cut.model.bonds.neighbour);
    EXPECT_EQ(own.model.bonds.broken, cut.model.bonds.broken);
    EXPECT_EQ(own.model.bonds.volume_weight.outer, whole.bonds.volume_weight.outer);
    EXPECT_LT(own.model.bonds.directed(), whole.bonds.directed());
    held += static_cast<std::int64_t>(own.model.bonds.directed());
    for (std::uint8_t b : own.model.bonds.broken) broken_in_pieces += b;
    const std::vector<double> own_s0 = pd::initial_node_critical_stretch(own.model.material, own.model.block_index, own.model.bonds);
    for (std::int32_t l : own.owned_local)
      EXPECT_EQ(own_s0[static_cast<std::size_t>(l)], s0[static_cast<std::size_t>(own.global[static_cast<std::size_t>(l)])]);
  }
  EXPECT_EQ(held, static_cast<std::int64_t>(whole.bonds.directed()));  // every row on exactly one rank
  EXPECT_EQ(broken_in_pieces, broken_in_whole);
  pd::BondList wrong = pd::build_bond_rows(skeleton.nodes.x, pd::bond_search_cutoff(c), {0, 1});
  EXPECT_THROW(pd::make_local_piece(skeleton, d.owner, 0, wrong), pd::Error);
}
