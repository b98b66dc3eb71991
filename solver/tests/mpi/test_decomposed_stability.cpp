// The exact stability limit 2/ω_max (core/stability, Lanczos) on the ranks' pieces (issue 37,
// item 3): the largest eigenvalue, its iteration count and the step equal the serial Lanczos on the
// whole model bit for bit, for 1, 2 and 3 ranks (ctest mpi_ranks_R) — with 1 and 2 threads per rank
// on pieces cut from the whole model, and on pieces whose ranks built only their own rows — and so
// does the indenters' stable depth that run.log reports. Every rank computes the serial value
// itself on the whole model.
#include <gtest/gtest.h>
#include <mpi.h>
#include <omp.h>

#include <cmath>
#include <string>
#include <utility>

#include "bits.hpp"
#include "core/error.hpp"
#include "core/cracks.hpp"
#include "core/model.hpp"
#include "core/stability.hpp"
#include "forces/indenter.hpp"
#include "lattice.hpp"
#include "materials/bond_model.hpp"
#include "operator/force_operator.hpp"
#include "parallel/mpi_decomposed.hpp"

namespace {

constexpr double kDx = 1e-3;
constexpr int kNx = 12, kNy = 9, kNz = 8;  // 864 nodes: pieces of ~290 nodes on 3 ranks

using pdtest::same_bits;

// Two blocks (a stiff top: the pair micromoduli differ across it), a no-fail bottom, and a notch of
// broken bonds, which Lanczos leaves out: every kind of row the product has.
pd::Case brick_case() {
  return pdtest::lattice_case(3, "3d", kDx, 3.015 * kDx, 70e9, 2700.0, 30.0);
}

pd::Nodes brick_nodes(pd::Case& c) {
  pd::Nodes nodes = pdtest::cubic_lattice(kNx, kNy, kNz, kDx, 3);
  pdtest::add_stiff_top_and_no_fail_bottom(c, nodes, kDx, 200e9, 40.0);
  return nodes;
}

int rank_count() {
  int r = 1;
  MPI_Comm_size(MPI_COMM_WORLD, &r);
  return r;
}

class DecomposedStability : public ::testing::TestWithParam<int> {};  // threads per rank

TEST_P(DecomposedStability, LanczosOnThePiecesGivesTheSerialLimitBitwise) {
  omp_set_num_threads(GetParam());
  pd::Case c = brick_case();
  pd::Model global = pd::build_model(c, brick_nodes(c));
  ASSERT_EQ(global.material.blocks, 2);
  pdtest::notch(global, kDx);
  const pd::LanczosReport serial = pd::largest_eigenvalue(global);
  ASSERT_TRUE(serial.converged);
  ASSERT_GT(serial.iterations, 20);  // enough iterations for rounding to have somewhere to go wrong
  const double serial_dt = pd::exact_time_step(global);

  pd::MpiDecomposed dec(MPI_COMM_WORLD, global);
  if (rank_count() > 1) ASSERT_GT(dec.piece().ghost_local.size(), 0u);
  const pd::LanczosReport piece = pd::largest_eigenvalue(dec.piece().model, {0.0, 0.0, 0.0}, &dec);
  EXPECT_EQ(piece.iterations, serial.iterations);
  EXPECT_EQ(piece.converged, serial.converged);
  EXPECT_TRUE(same_bits(piece.lambda_max, serial.lambda_max)) << piece.lambda_max << " vs " << serial.lambda_max;
  // Through the operator, as the integrators ask for it (adaptive's default Δt_max, mixed).
  pd::ForceOperator op(dec.piece().model);
  op.set_decomposed(&dec);
  const double dt = op.exact_time_step();
  EXPECT_TRUE(same_bits(dt, serial_dt)) << dt << " vs " << serial_dt;
  // Not some other limit that happens to agree: below eq. 2.5's bound it is not.
  EXPECT_GT(dt, pd::stable_time_step(global));
}

// The ranks built only their own rows (what a run does when no feature needs the whole bond list):
// the same limit as the whole model's, bit for bit.
TEST(DecomposedStabilityRows, PiecesBuiltFromTheirOwnRowsGiveTheSerialLimitBitwise) {
  pd::Case c = brick_case();
  c.cracks.push_back(pd::CrackSegment{{6.5 * kDx, -1.0, 0.0}, {6.5 * kDx, 4.5 * kDx, 0.0}});  // cut on every rank
  const pd::Nodes nodes = brick_nodes(c);
  const double serial_dt = pd::exact_time_step(pd::build_model(c, nodes));

  pd::Model skeleton = pd::build_model_without_bonds(c, nodes);
  skeleton.bonds.offsets = pd::count_bonds(skeleton.nodes.x, pd::bond_search_cutoff(c));
  skeleton.bond_model = pd::material_registry().get("pmb").make(skeleton);
  pd::MpiDecomposed dec(MPI_COMM_WORLD, skeleton, pd::bond_search_cutoff(c), c.cracks, c.surface_correction);
  const double dt = pd::exact_time_step(dec.piece().model, &dec);
  EXPECT_TRUE(same_bits(dt, serial_dt)) << dt << " vs " << serial_dt;
}

// run.log's depth bound of an indenter (forces/indenter.hpp): the minimum over the owned rows and
// then over the ranks, the serial value — with and without the exact limit's ω_max².
TEST_P(DecomposedStability, IndenterStableDepthOnThePiecesIsTheSerialDepth) {
  omp_set_num_threads(GetParam());
  pd::Case c = brick_case();
  pd::IndenterSettings ball;
  ball.name = "ball";
  ball.shape = "sphere";
  ball.radius = 4 * kDx;
  ball.centre = {7 * kDx, 5 * kDx, 12 * kDx};
  ball.stiffness = 1e15;
  c.indenters = {ball};
  const pd::Model global = pd::build_model(c, brick_nodes(c));
  // Eq. 2.5's bound (a) alone at half its step; bound (b) at a step above eq. 2.5 with an ω_max²
  // below 4/dt² (as the exact limit's is for a step below it).
  const double stable = pd::stable_time_step(global), above = 1.05 * stable;
  pd::MpiDecomposed dec(MPI_COMM_WORLD, global);
  for (const auto& [dt, w2] : {std::pair{0.5 * stable, 0.0}, std::pair{above, 0.9 * 4.0 / (above * above)}}) {
    const double serial = pd::indenter_stable_depth(global, global.indenters[0], dt, w2);
    const double piece = pd::indenter_stable_depth(dec.piece().model, global.indenters[0], dt, w2, &dec);
    EXPECT_GT(serial, 0.0);
    EXPECT_TRUE(same_bits(piece, serial)) << piece << " vs " << serial << " (ω² " << w2 << ")";
  }
}

INSTANTIATE_TEST_SUITE_P(Threads, DecomposedStability, ::testing::Values(1, 2));

// LPS's product would read its partners' δθ, which do not travel: refused on every rank alike, by
// name, instead of a wrong limit.
TEST(DecomposedStabilityLaws, LpsOnPiecesIsRefusedOnEveryRank) {
  pd::Case c = pdtest::lattice_case(3, "3d", kDx, 3.015 * kDx, 70e9, 2700.0, 30.0);
  c.blocks[0].model = "lps";
  c.blocks[0].parameters["poisson_ratio"] = 0.3;
  const pd::Model global = pd::build_model(c, pdtest::cubic_lattice(8, 7, 6, kDx, 3));
  pd::MpiDecomposed dec(MPI_COMM_WORLD, global);
  try {
    pd::exact_time_step(dec.piece().model, &dec);
    FAIL() << "no error";
  } catch (const pd::Error& e) {
    EXPECT_NE(std::string(e.what()).find("pmb bonds only, not lps"), std::string::npos) << e.what();
  }
}

}  // namespace
