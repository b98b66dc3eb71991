// Declared state (core/state_arrays.hpp, issue 37 item 2): a material with history declares its
// arrays once, and the checkpoint, the halo, mixed's rollback and the frame writer carry them
// without naming them. The material here exists only in this file — PMB whose bonds remember their
// largest stretch (a history per bond, as a plastic stretch would be) and whose nodes remember the
// largest stretch of their row (per node: exchanged with the ghosts and written to frames) — and no
// other file was edited for it: the target of the issue, a stateful material is its folder, its
// test file and its schema entry. (The law is in peak_stretch_pmb.hpp beside this file, so that the
// decomposed tests, tests/mpi/, run it on several ranks too.)
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <memory>
#include <string>

#include "core/error.hpp"
#include "core/model.hpp"
#include "files.hpp"
#include "io/checkpoint.hpp"
#include "io/output.hpp"
#include "io/read_file.hpp"
#include "lattice.hpp"
#include "materials/pmb/pmb.hpp"
#include "operator/force_operator.hpp"
#include "parallel/decomposition.hpp"
#include "parallel/local_model.hpp"
#include "parallel/node_columns.hpp"
#include "peak_stretch_pmb.hpp"
#include "run/state_checkpoint.hpp"

namespace {

namespace fs = std::filesystem;
using pdtest::kBondPeak;
using pdtest::kNodePeak;
using pdtest::PeakStretchPmb;

constexpr double kDx = 1e-3;

// A 12 × 6 plate of glass-like PMB, with the law above and its state at rest.
pd::Model plate() {
  pd::Case c = pdtest::lattice_case(2, "plane_stress", kDx, 3.015 * kDx, 70e9, 2500.0, 1000.0, 1e-3);
  pd::Model m = pd::build_model(c, pdtest::cubic_lattice(12, 6, 1, kDx, 2, 1e-3));
  m.bond_model = std::make_shared<PeakStretchPmb>();
  pd::declare_state(m);
  return m;
}

// A pull along x growing with x, `amount` of stretch at the right edge, and a wobble across.
pd::Vec3Array pulled(const pd::Model& m, double amount) {
  pd::Vec3Array u = pd::make_vec3(m.nodes.size());
  for (std::size_t i = 0; i < m.nodes.size(); ++i) {
    u[0][i] = amount * m.nodes.x[0][i] * (1.0 + 0.3 * std::sin(7.0 * static_cast<double>(i)));
    u[1][i] = 0.2 * amount * m.nodes.x[1][i] * std::cos(5.0 * static_cast<double>(i));
  }
  return u;
}

const std::vector<double>& values(const pd::Model& m, const char* name) { return m.state_arrays.find(name)->values; }

bool same_bits(const std::vector<double>& a, const std::vector<double>& b) {
  return a.size() == b.size() && (a.empty() || std::memcmp(a.data(), b.data(), a.size() * sizeof(double)) == 0);
}

// One breaking pass of the operator at `u`, as a time step makes it.
void breaking_pass(pd::Model& m, const pd::Vec3Array& u) {
  pd::ForceOperator op(m);
  pd::State s(m.nodes.size());
  s.u = u;
  op.break_bonds_and_evaluate(s, 0.0);
}

}  // namespace

TEST(DeclaredState, TheModelHoldsWhatTheLawDeclaredSizedPerNodeAndPerBond) {
  pd::Model m = plate();
  ASSERT_EQ(m.state_arrays.all().size(), 2u);
  EXPECT_EQ(values(m, kBondPeak).size(), m.bonds.directed());
  EXPECT_EQ(values(m, kNodePeak).size(), m.nodes.size());
  breaking_pass(m, pulled(m, 2e-3));
  EXPECT_GT(*std::max_element(values(m, kNodePeak).begin(), values(m, kNodePeak).end()), 1e-3);
  EXPECT_GT(*std::max_element(values(m, kBondPeak).begin(), values(m, kBondPeak).end()), 1e-3);
  EXPECT_FALSE(pd::node_critical_stretch(m));  // α = 0: PMB's own history is not declared
}

TEST(DeclaredState, AWrongDeclarationIsRefusedNamingTheArray) {
  const auto message = [](std::vector<pd::StateDeclaration> d) -> std::string {
    try {
      pd::StateArrays(d, 4, 8);
    } catch (const pd::Error& e) {
      return e.what();
    }
    return "(no error)";
  };
  pd::StateDeclaration bond{"plastic_stretch", pd::StateExtent::per_bond};
  bond.halo = true;
  EXPECT_NE(message({bond}).find("declared state 'plastic_stretch': a per-bond array cannot be exchanged with ghosts"),
            std::string::npos);
  bond.halo = false;
  bond.frames = true;
  EXPECT_NE(message({bond}).find("cannot be written to frames"), std::string::npos);
  pd::StateDeclaration node{"peak", pd::StateExtent::per_node};
  EXPECT_NE(message({node, node}).find("declared state 'peak': declared twice"), std::string::npos);
}

// A checkpoint takes every array with `checkpoint` (checkpointed_state; a run's pieces by the same
// declarations, checkpoint_sections_of), the file carries them by name, and read_checkpoint gives
// them back (fits_checkpointed_state, restore_checkpointed_state): the restored model's next
// pass is the uninterrupted one's, bit for bit.
TEST(DeclaredState, IsCheckpointedAndRestoredBitwise) {
  pd::Model run = plate();
  breaking_pass(run, pulled(run, 2e-3));
  pd::Checkpoint k;
  k.nodes = run.nodes.size();
  k.directed_bonds = run.bonds.directed();
  k.integrator = "verlet";
  k.state = pd::State(run.nodes.size());
  k.broken_flags = run.bonds.broken;
  for (std::size_t i = 0; i < k.nodes; ++i) k.row_length.push_back(static_cast<std::int32_t>(run.bonds.offsets[i + 1] - run.bonds.offsets[i]));
  k.state_arrays = pd::checkpointed_state(run);
  const fs::path file = pdtest::temp_dir("declared_state") / "checkpoint.bin";
  pd::write_checkpoint(file, k);
  const pd::Checkpoint read = pd::read_checkpoint(file);

  pd::Model restarted = plate();
  ASSERT_TRUE(pd::fits_checkpointed_state(read.state_arrays, restarted, k.nodes, k.directed_bonds));
  restarted.bonds.broken = read.broken_flags;
  pd::restore_checkpointed_state(read.state_arrays, restarted);
  for (const char* name : {kBondPeak, kNodePeak}) EXPECT_TRUE(same_bits(values(restarted, name), values(run, name))) << name;
  const pd::Vec3Array further = pulled(run, 3e-3);
  breaking_pass(run, further);
  breaking_pass(restarted, further);
  EXPECT_EQ(restarted.bonds.broken, run.bonds.broken);
  for (const char* name : {kBondPeak, kNodePeak}) EXPECT_TRUE(same_bits(values(restarted, name), values(run, name))) << name;

  // A checkpoint of a law with other history does not fit (start.cpp then says it does not fit this model).
  pd::Model plain = pd::build_model(pdtest::lattice_case(2, "plane_stress", kDx, 3.015 * kDx, 70e9, 2500.0, 1000.0, 1e-3),
                                    pdtest::cubic_lattice(12, 6, 1, kDx, 2, 1e-3));
  EXPECT_FALSE(pd::fits_checkpointed_state(read.state_arrays, plain, k.nodes, k.directed_bonds));
  EXPECT_FALSE(pd::fits_checkpointed_state(read.state_arrays, restarted, k.nodes + 1, k.directed_bonds));
  fs::remove_all(file.parent_path());
}

// Mixed puts back what a quasi-static try changed when it abandons the try (integrators/mixed.cpp:
// save_rollback before the try, restore_rollback after it failed), every array with `rollback`.
TEST(DeclaredState, IsRolledBackWhenATryIsAbandoned) {
  pd::Model m = plate();
  breaking_pass(m, pulled(m, 1e-3));
  const pd::StateArrays before = m.state_arrays;
  const std::vector<std::vector<double>> saved = m.state_arrays.save_rollback();
  breaking_pass(m, pulled(m, 4e-3));  // the abandoned try: it changes both arrays
  EXPECT_FALSE(same_bits(values(m, kNodePeak), before.find(kNodePeak)->values));
  EXPECT_FALSE(same_bits(values(m, kBondPeak), before.find(kBondPeak)->values));
  m.state_arrays.restore_rollback(saved);
  for (const char* name : {kBondPeak, kNodePeak})
    EXPECT_TRUE(same_bits(values(m, name), before.find(name)->values)) << name;
}

// The frame writer writes every per-node array with `frames` as a point field of its name, after
// the fields output.fields chooses; a per-bond array is not a frame field.
TEST(DeclaredState, IsWrittenToFramesPerNode) {
  pd::Model m = plate();
  breaking_pass(m, pulled(m, 2e-3));
  pd::State s(m.nodes.size());
  pd::FrameFormat format;
  format.float32 = false;
  const pd::VtuGrid g = pd::frame_grid(m, s, 0.0, 0, format);
  const auto field = [&](const std::string& name) -> const pd::VtuArray* {
    for (const pd::VtuArray& a : g.point_data)
      if (a.name == name) return &a;
    return nullptr;
  };
  ASSERT_TRUE(field(kNodePeak));
  EXPECT_EQ(g.point_data.back().name, kNodePeak);
  std::vector<double> written(m.nodes.size());
  ASSERT_EQ(field(kNodePeak)->bytes.size(), written.size() * sizeof(double));
  std::memcpy(written.data(), field(kNodePeak)->bytes.data(), field(kNodePeak)->bytes.size());
  EXPECT_TRUE(same_bits(written, values(m, kNodePeak)));
  EXPECT_FALSE(field(kBondPeak));
}

// A decomposed run: the per-node array with `halo` travels with u in the breaking pass's exchange
// (operator/force_operator.cpp breaking_ghost_values is u + add_halo_state), the per-bond one does
// not (a ghost has no row); each piece starts from the whole model's arrays — its local nodes', its
// owned rows'.
TEST(DeclaredState, TravelsWithTheGhostsAndIntoThePieces) {
  pd::Model m = plate();
  breaking_pass(m, pulled(m, 2e-3));
  pd::Vec3Array u = pd::make_vec3(m.nodes.size());
  pd::NodeColumns columns(u);
  pd::add_halo_state(columns, m.state_arrays);
  ASSERT_EQ(columns.width(), 4);
  EXPECT_EQ(columns[3], m.state_arrays.find(kNodePeak)->values.data());

  const pd::Decomposition d = pd::decompose(m.nodes.x, m.bonds, 3, m.horizon);
  for (int r = 0; r < 3; ++r) {
    pd::LocalPiece piece = pd::make_local_piece(m, d.owner, r);
    const std::vector<double>& node = values(piece.model, kNodePeak);
    const std::vector<double>& bond = values(piece.model, kBondPeak);
    ASSERT_EQ(node.size(), piece.size());
    ASSERT_EQ(bond.size(), piece.model.bonds.directed());
    std::int64_t differ = 0;
    for (std::size_t l = 0; l < piece.size(); ++l) {
      const auto i = static_cast<std::size_t>(piece.global[l]);
      differ += node[l] != values(m, kNodePeak)[i];
      const std::int64_t length = piece.model.bonds.offsets[l + 1] - piece.model.bonds.offsets[l];
      for (std::int64_t q = 0; q < length; ++q)
        differ += bond[static_cast<std::size_t>(piece.model.bonds.offsets[l] + q)] !=
                  values(m, kBondPeak)[static_cast<std::size_t>(m.bonds.offsets[i] + q)];
    }
    EXPECT_EQ(differ, 0) << "rank " << r;
  }
}

// A checkpoint in pieces (io/checkpoint.hpp, run/state_checkpoint.hpp): written by 2 pieces, each
// its owned nodes and rows, it restores into 3 pieces and into the whole model (one rank) with
// every array bitwise what the uninterrupted model holds there — the state, the law's declared
// per-node and per-bond history, the broken flags — and read_checkpoint assembles the whole model.
// Pure bookkeeping (no MPI): the pieces are cut with make_local_piece as a decomposed run cuts them.
TEST(DeclaredState, CheckpointInPiecesRestoresIntoAnyPieceCountBitwise) {
  pd::Model m = plate();
  breaking_pass(m, pulled(m, 2e-3));
  const std::size_t n = m.nodes.size();
  pd::State whole(n);
  for (std::size_t i = 0; i < n; ++i)
    for (std::size_t d = 0; d < 3; ++d) {
      whole.u[d][i] = 1e-6 * static_cast<double>(i) + 0.1 * static_cast<double>(d) + 1.0 / 3.0;
      whole.v[d][i] = -std::sqrt(static_cast<double>(i + d));
      whole.f[d][i] = std::exp(0.001 * static_cast<double>(i)) * static_cast<double>(d + 1);
      whole.w[i] = std::cos(static_cast<double>(i));
    }
  auto local_state = [&](const pd::LocalPiece& piece) {
    pd::State s(piece.size());
    s.u = pd::to_local(piece, whole.u), s.v = pd::to_local(piece, whole.v), s.f = pd::to_local(piece, whole.f);
    s.w = pd::to_local(piece, whole.w);
    return s;
  };
  const fs::path index = pdtest::temp_dir("checkpoint_pieces") / "checkpoint.bin";
  pd::Checkpoint k;
  k.nodes = n, k.directed_bonds = m.bonds.directed(), k.integrator = "verlet", k.frame_times = {0.0};
  k.sections = pd::checkpoint_sections_of(m, 0, false);
  const pd::Decomposition two = pd::decompose(m.nodes.x, m.bonds, 2, m.horizon);
  for (int r = 0; r < 2; ++r) {
    const pd::LocalPiece piece = pd::make_local_piece(m, two.owner, r);
    k.pieces.push_back(pd::write_checkpoint_piece(index, pd::checkpoint_piece_file(7, r),
                                                  pd::checkpoint_piece_of(piece.model, &piece, local_state(piece), {}, nullptr)));
    EXPECT_LT(k.pieces.back().nodes, n);
  }
  pd::write_checkpoint_index(index, k);
  const pd::Checkpoint read = pd::parse_checkpoint(pd::read_whole_file(index, "the checkpoint"), index.string());
  ASSERT_EQ(read.pieces.size(), 2u);

  const pd::Decomposition three = pd::decompose(m.nodes.x, m.bonds, 3, m.horizon);
  for (int r = 0; r < 3; ++r) {
    const pd::LocalPiece expected = pd::make_local_piece(m, three.owner, r);
    pd::LocalPiece fresh = pd::make_local_piece(plate(), three.owner, r);
    pd::State got(fresh.size());
    pd::restore_from_pieces(index, read, fresh.model, &fresh, got, {}, nullptr, nullptr);
    const pd::State want = local_state(expected);
    for (std::size_t d = 0; d < 3; ++d) {
      EXPECT_TRUE(same_bits(got.u[d], want.u[d]) && same_bits(got.v[d], want.v[d]) && same_bits(got.f[d], want.f[d])) << r;
    }
    EXPECT_TRUE(same_bits(got.w, want.w)) << r;
    for (const char* name : {kNodePeak, kBondPeak}) EXPECT_TRUE(same_bits(values(fresh.model, name), values(expected.model, name))) << name;
    EXPECT_EQ(fresh.model.bonds.broken, expected.model.bonds.broken) << r;
  }
  pd::Model serial = plate();
  pd::State got(n);
  pd::restore_from_pieces(index, read, serial, nullptr, got, {}, nullptr, nullptr);
  for (std::size_t d = 0; d < 3; ++d) EXPECT_TRUE(same_bits(got.u[d], whole.u[d]) && same_bits(got.f[d], whole.f[d]));
  for (const char* name : {kNodePeak, kBondPeak}) EXPECT_TRUE(same_bits(values(serial, name), values(m, name))) << name;
  EXPECT_EQ(serial.bonds.broken, m.bonds.broken);
  EXPECT_GT(std::count(m.bonds.broken.begin(), m.bonds.broken.end(), 1), 0);  // the pass broke bonds
  const pd::Checkpoint assembled = pd::read_checkpoint(index);
  EXPECT_TRUE(same_bits(assembled.state.v[2], whole.v[2]));
  EXPECT_EQ(assembled.broken_flags, m.bonds.broken);

  // A model of another law's history does not fit: its rows differ from the pieces' rows.
  pd::Model other = pd::build_model(pdtest::lattice_case(2, "plane_stress", kDx, 3.015 * kDx, 70e9, 2500.0, 1000.0, 1e-3),
                                    pdtest::cubic_lattice(12, 6, 1, kDx, 2, 1e-3));
  EXPECT_NE(pd::checkpoint_sections_of(other, 0, false), read.sections);
  fs::remove_all(index.parent_path());
}
