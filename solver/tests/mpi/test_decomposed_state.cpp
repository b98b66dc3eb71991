// Declared state on a decomposed run (core/state_arrays.hpp, issue 37 item 2), for 1, 2 and 3 ranks
// (ctest mpi_ranks_R): a law with history that only the tests know (tests/materials/
// peak_stretch_pmb.hpp: a per-bond and a per-node array) runs on every piece; its per-node array
// travels with u in the breaking pass's exchange (the ghosts hold their owners' values from the
// previous pass), and gathered on rank 0 as a checkpoint gathers it (parallel/gather_state) both
// arrays are the serial run's, bit for bit.
#include <gtest/gtest.h>
#include <mpi.h>

#include <algorithm>
#include <cstring>

#include "bits.hpp"
#include "core/model.hpp"
#include "lattice.hpp"
#include "materials/peak_stretch_pmb.hpp"
#include "operator/force_operator.hpp"
#include "parallel/gather_state.hpp"
#include "parallel/mpi_decomposed.hpp"

namespace {

constexpr double kDx = 1e-3;

pd::Model peak_model() {
  const pd::Case c = pdtest::lattice_case(3, "3d", kDx, 3.015 * kDx, 70e9, 2700.0, 3.8);
  pd::Model m = pd::build_model(c, pdtest::cubic_lattice(12, 9, 8, kDx, 3));
  m.bond_model = std::make_shared<pdtest::PeakStretchPmb>();
  pd::declare_state(m);
  return m;
}

const std::vector<double>& values(const pd::Model& m, const char* name) { return m.state_arrays.find(name)->values; }

std::int64_t differ(const std::vector<double>& a, const std::vector<double>& b) {
  if (a.size() != b.size()) return static_cast<std::int64_t>(std::max(a.size(), b.size()));
  std::int64_t n = 0;
  for (std::size_t k = 0; k < a.size(); ++k) n += !pdtest::same_bits(a[k], b[k]);
  return n;
}

}  // namespace

TEST(DecomposedState, TheHaloCarriesTheDeclaredNodeArrayAndTheGatherGivesTheSerialArrays) {
  pd::Model global = peak_model();
  pd::MpiDecomposed dec(MPI_COMM_WORLD, global);  // before the serial passes change the global model
  const pd::LocalPiece& p = dec.piece();
  pd::Model& piece = dec.piece().model;
  ASSERT_EQ(values(piece, pdtest::kNodePeak).size(), p.size());
  ASSERT_EQ(values(piece, pdtest::kBondPeak).size(), piece.bonds.directed());
  pd::ForceOperator op(piece);
  op.set_decomposed(&dec);
  pd::ForceOperator serial_op(global);
  pd::State local(p.size()), serial(global.nodes.size());

  // Pass 1, then pass 2 at a larger stretch (some bonds break in each: s0 ≈ 4.4e-5 here).
  const pd::Vec3Array u1 = pdtest::wavy(global, kDx, 5e-5), u2 = pdtest::wavy(global, kDx, 8e-5);
  local.u = pd::to_local(p, u1);
  serial.u = u1;
  op.break_bonds_and_evaluate(local, 0.0);
  serial_op.break_bonds_and_evaluate(serial, 0.0);
  const std::vector<double> node_after_1 = values(global, pdtest::kNodePeak);
  ASSERT_GT(*std::max_element(node_after_1.begin(), node_after_1.end()), 0.0);
  local.u = pd::to_local(p, u2);
  serial.u = u2;
  op.break_bonds_and_evaluate(local, 0.0);
  serial_op.break_bonds_and_evaluate(serial, 0.0);

  // Owned nodes: pass 2's serial values; ghosts: their owners' after pass 1, which came with u.
  std::int64_t owned_wrong = 0, ghost_wrong = 0;
  for (std::size_t l = 0; l < p.size(); ++l) {
    const auto g = static_cast<std::size_t>(p.global[l]);
    const double mine = values(piece, pdtest::kNodePeak)[l];
    if (p.owned[l]) owned_wrong += !pdtest::same_bits(mine, values(global, pdtest::kNodePeak)[g]);
    else ghost_wrong += !pdtest::same_bits(mine, node_after_1[g]);
  }
  EXPECT_EQ(dec.total(owned_wrong), 0);
  EXPECT_EQ(dec.total(ghost_wrong), 0);
  if (dec.ranks() > 1) EXPECT_GT(dec.total(static_cast<std::int64_t>(p.ghost_local.size())), 0);

  // Gathered as a checkpoint gathers them, on rank 0: the serial arrays.
  pd::Model whole = peak_model();
  pd::gather_state(dec, whole, [](const pd::StateDeclaration& d) { return d.checkpoint; });
  if (dec.rank() == 0) {
    EXPECT_EQ(differ(values(whole, pdtest::kNodePeak), values(global, pdtest::kNodePeak)), 0);
    EXPECT_EQ(differ(values(whole, pdtest::kBondPeak), values(global, pdtest::kBondPeak)), 0);
  }
}
