// The halo exchange overlapped with the bond sweep (parallel/row_split.hpp), on 1, 2 and 3 ranks
// (ctest mpi_ranks_R) with 1 and 2 threads per rank:
// - the split: every owned row is in exactly one of the interior and boundary lists, an interior
//   row has no ghost partner and a boundary row has one;
// - the order: when the law waits for u's ghosts, the ghosts still hold the NaN they were poisoned
//   with (nothing read or wrote them early), the law has waited once, the PMB interior rows already
//   hold their final force and the boundary rows none yet (LPS: no force yet — its first sweep
//   computes θ only); a boundary row swept before the wait would read NaN;
// - the bits: the overlapped force and W equal the serial sweep's and the decomposed blocking
//   sweep's (update_ghosts, then add_force) bit for bit, and so does the Krylov path's J·x.
#include <gtest/gtest.h>
#include <mpi.h>
#include <omp.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <tuple>

#include "bits.hpp"
#include "core/model.hpp"
#include "lattice.hpp"
#include "operator/force_operator.hpp"
#include "parallel/mpi_decomposed.hpp"

namespace {

constexpr double kDx = 1e-3;
constexpr int kNx = 14, kNy = 11, kNz = 9;  // 1386 nodes: pieces of ~460 nodes on 3 ranks

using pdtest::same_bits;

int rank_count() {
  int r = 1;
  MPI_Comm_size(MPI_COMM_WORLD, &r);
  return r;
}

pd::Model lattice_model(const std::string& law) {
  pd::Case c = pdtest::lattice_case(3, "3d", kDx, 3.015 * kDx, 70e9, 2700.0, 0.5);
  if (law == "lps") {
    c.blocks[0].model = "lps";
    c.blocks[0].parameters["poisson_ratio"] = 0.22;
  }
  pd::Model m = pd::build_model(c, pdtest::cubic_lattice(kNx, kNy, kNz, kDx, 3));
  // A notch (bonds across x = 6.5 dx with y < 5 dx start broken): a broken bond to a ghost still
  // makes its row a boundary row.
  pdtest::notch(m, kDx);
  return m;
}

// A smooth field with no symmetry, small enough that no bond is near breaking.
pd::Vec3Array wavy(const pd::Model& m, double amplitude) { return pdtest::wavy(m, kDx, amplitude); }

// This rank's u from the global field, the ghosts poisoned (NaN): only the exchange makes them right.
pd::Vec3Array poisoned_local(const pd::LocalPiece& p, const pd::Vec3Array& u_global) {
  pd::Vec3Array u = pd::to_local(p, u_global);
  for (std::int32_t l : p.ghost_local)
    for (auto& c : u) c[static_cast<std::size_t>(l)] = std::nan("");
  return u;
}

TEST(RowSplit, EveryOwnedRowIsInteriorOrBoundaryOnceAndInteriorRowsReadNoGhost) {
  const pd::Model global = lattice_model("pmb");
  pd::MpiDecomposed dec(MPI_COMM_WORLD, global);
  const pd::LocalPiece& p = dec.piece();
  const pd::RowSplit& split = dec.row_split();
  const auto ascending = [](const std::vector<std::int32_t>& v) {
    return std::adjacent_find(v.begin(), v.end(), [](std::int32_t a, std::int32_t b) { return a >= b; }) == v.end();
  };
  ASSERT_TRUE(ascending(split.interior));
  ASSERT_TRUE(ascending(split.boundary));
  // Two strictly ascending lists that merge into the strictly ascending owned list: disjoint, and
  // their union is the owned rows.
  std::vector<std::int32_t> both;
  std::merge(split.interior.begin(), split.interior.end(), split.boundary.begin(), split.boundary.end(),
             std::back_inserter(both));
  EXPECT_EQ(both, p.owned_local);
  const pd::BondList& b = p.model.bonds;
  const auto ghost_partners = [&](std::int32_t i) {
    std::int64_t n = 0;
    for (std::int64_t k = b.offsets[static_cast<std::size_t>(i)]; k < b.offsets[static_cast<std::size_t>(i) + 1]; ++k)
      n += p.owned[static_cast<std::size_t>(b.neighbour[static_cast<std::size_t>(k)])] == 0;
    return n;
  };
  for (std::int32_t i : split.interior) EXPECT_EQ(ghost_partners(i), 0) << "interior row " << i;
  for (std::int32_t i : split.boundary) EXPECT_GT(ghost_partners(i), 0) << "boundary row " << i;
  if (rank_count() == 1) {
    EXPECT_TRUE(split.boundary.empty());  // no ghosts: nothing to wait for
  } else {
    // A real overlap: rows to sweep while the messages travel, and rows that need them.
    EXPECT_GT(split.interior.size(), 0u);
    EXPECT_GT(split.boundary.size(), 0u);
    EXPECT_GT(p.ghost_local.size(), 0u);
  }
}

class Overlap : public ::testing::TestWithParam<std::tuple<std::string, int>> {};  // law, threads per rank

TEST_P(Overlap, InteriorRowsBeforeTheGhostsArriveBoundaryRowsAfterWithTheBlockingBits) {
  const std::string law = std::get<0>(GetParam());
  omp_set_num_threads(std::get<1>(GetParam()));
  pd::Model global = lattice_model(law);
  ASSERT_EQ(global.bond_model->name(), law);
  const pd::Vec3Array u = wavy(global, 0.01);

  pd::ForceOperator serial_op(global);
  pd::State serial(global.nodes.size());
  serial.u = u;
  serial_op.evaluate(serial, 0.0);

  pd::MpiDecomposed dec(MPI_COMM_WORLD, global);
  pd::Model& model = dec.piece().model;
  pd::ForceOperator op(model);
  op.set_decomposed(&dec);  // the law's too: LPS exchanges its P through it
  const pd::LocalPiece& p = dec.piece();
  const pd::RowSplit& split = dec.row_split();
  const std::size_t n = p.size();

  // The overlapped sweep, with the wait instrumented.
  pd::Vec3Array ul = poisoned_local(p, u), f = pd::make_vec3(n);
  std::vector<double> w(n, 0.0);
  int waits = 0;
  bool ghosts_untouched_at_wait = true;
  pd::Vec3Array f_at_wait;
  dec.begin_update_ghosts(ul);
  const pd::GhostsInFlight u_ghosts(split, [&] {
    ++waits;
    for (std::int32_t l : p.ghost_local)
      for (const auto& c : ul) ghosts_untouched_at_wait = ghosts_untouched_at_wait && std::isnan(c[static_cast<std::size_t>(l)]);
    f_at_wait = f;
    dec.end_update_ghosts(ul);
  });
  model.bond_model->add_force_overlapped(model, ul, f, w.data(), u_ghosts);
  EXPECT_EQ(waits, 1);
  EXPECT_TRUE(ghosts_untouched_at_wait);
  ASSERT_EQ(f_at_wait[0].size(), n);

  // The blocking sweep on the same piece: every ghost first, then every row.
  pd::Vec3Array ub = poisoned_local(p, u), fb = pd::make_vec3(n);
  std::vector<double> wb(n, 0.0);
  dec.update_ghosts(ub);
  model.bond_model->add_force(model, ub, fb, wb.data());

  std::int64_t differ_serial = 0, differ_blocking = 0, early = 0, late = 0;
  for (std::int32_t l : p.owned_local) {
    const auto li = static_cast<std::size_t>(l);
    const auto g = static_cast<std::size_t>(p.global[li]);
    for (std::size_t d = 0; d < 3; ++d) {
      differ_serial += !same_bits(f[d][li], serial.f[d][g]);
      differ_blocking += !same_bits(f[d][li], fb[d][li]);
    }
    differ_serial += !same_bits(w[li], serial.w[g]);
    differ_blocking += !same_bits(w[li], wb[li]);
  }
  for (std::int32_t l : split.interior)  // PMB: done before the wait; LPS: its force sweep comes after
    for (std::size_t d = 0; d < 3; ++d)
      early += law == "pmb" ? !same_bits(f_at_wait[d][static_cast<std::size_t>(l)], f[d][static_cast<std::size_t>(l)])
                            : f_at_wait[d][static_cast<std::size_t>(l)] != 0.0;
  for (std::int32_t l : split.boundary)  // nothing before the wait
    for (std::size_t d = 0; d < 3; ++d) late += f_at_wait[d][static_cast<std::size_t>(l)] != 0.0;
  EXPECT_EQ(differ_serial, 0);
  EXPECT_EQ(differ_blocking, 0);
  EXPECT_EQ(early, 0);
  EXPECT_EQ(late, 0);
  // The field loads every row: an interior row's force is not 0 by accident.
  std::int64_t zero_interior = 0;
  for (std::int32_t l : split.interior) zero_interior += f[0][static_cast<std::size_t>(l)] == 0.0;
  EXPECT_EQ(zero_interior, 0);

  // The operator's path (evaluate: begin, the law's overlapped sweep, wait) gives the same bits.
  pd::State s(n);
  s.u = poisoned_local(p, u);
  op.evaluate(s, 0.0);
  EXPECT_EQ(pdtest::differing(s.f, f), 0);

  // The matrix-free J·x of the Krylov solves (apply_jacobian: x's exchange overlapped with the
  // interior rows for PMB, LPS waits first): the serial product's bits on every owned row.
  const pd::Vec3Array x = wavy(global, 0.003);
  pd::Vec3Array y_serial = pd::make_vec3(global.nodes.size()), y = pd::make_vec3(n);
  serial_op.apply_jacobian(serial, 0.0, x, y_serial);
  op.apply_jacobian(s, 0.0, poisoned_local(p, x), y);
  std::int64_t differ_jacobian = 0, zero_jacobian = 0;
  for (std::int32_t l : p.owned_local) {
    const auto li = static_cast<std::size_t>(l);
    for (std::size_t d = 0; d < 3; ++d) differ_jacobian += !same_bits(y[d][li], y_serial[d][static_cast<std::size_t>(p.global[li])]);
    zero_jacobian += y[0][li] == 0.0;
  }
  EXPECT_EQ(differ_jacobian, 0);
  EXPECT_LT(zero_jacobian, static_cast<std::int64_t>(p.owned_local.size()) / 10);  // a product that is not 0
}

INSTANTIATE_TEST_SUITE_P(LawsAndThreads, Overlap,
                         ::testing::Combine(::testing::Values(std::string("pmb"), std::string("lps")), ::testing::Values(1, 2)));

}  // namespace
