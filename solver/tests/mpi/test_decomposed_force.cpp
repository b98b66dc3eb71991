// The PMB force sweep, breaking and energies decomposed over the ranks of this run (issue 15): the
// gathered force, the strain and kinetic energy, the break count and the energy lost with the
// broken bonds equal the serial operator's bit for bit, for 1, 2 and 3 ranks (ctest mpi_ranks_R),
// with 1 and 2 threads per rank. Every rank computes the serial result itself on the whole model.
#include <gtest/gtest.h>
#include <mpi.h>
#include <omp.h>

#include <cmath>
#include <cstring>

#include "bits.hpp"
#include "core/model.hpp"
#include "lattice.hpp"
#include "materials/pmb/pmb.hpp"
#include "operator/force_operator.hpp"
#include "parallel/mpi_decomposed.hpp"

namespace {

constexpr double kDx = 1e-3;
constexpr int kNx = 14, kNy = 11, kNz = 9;  // 1386 nodes: pieces of ~460 nodes on 3 ranks

pd::Model lattice_model(double fracture_energy) {
  const pd::Case c = pdtest::lattice_case(3, "3d", kDx, 3.015 * kDx, 70e9, 2700.0, fracture_energy);
  return pd::build_model(c, pdtest::cubic_lattice(kNx, kNy, kNz, kDx, 3));
}

pd::Vec3Array wavy(const pd::Model& m, double amplitude) { return pdtest::wavy(m, kDx, amplitude); }
void notch(pd::Model& m) { pdtest::notch(m, kDx); }

using pdtest::same_bits;

int rank_count() {
  int r = 1;
  MPI_Comm_size(MPI_COMM_WORLD, &r);
  return r;
}

// The local state of this rank's piece from a global field, ghosts poisoned (NaN) so that only the
// halo exchange can make them right.
pd::State local_state(const pd::MpiDecomposed& dec, const pd::Vec3Array& u_global, const pd::Vec3Array& v_global) {
  const pd::LocalPiece& p = dec.piece();
  pd::State s(p.size());
  s.u = pd::to_local(p, u_global);
  s.v = pd::to_local(p, v_global);
  for (std::int32_t l : p.ghost_local)
    for (auto& c : s.u) c[static_cast<std::size_t>(l)] = std::nan("");
  return s;
}

// Gathered force on rank 0 equals the serial force bitwise; returns the number of differing values.
std::int64_t differing_forces(const pd::MpiDecomposed& dec, const pd::State& local, const pd::State& serial) {
  const pd::Vec3Array f = dec.gather(local.f);
  std::int64_t bad = 0;
  if (dec.rank() == 0)
    for (int d = 0; d < 3; ++d)
      for (std::size_t i = 0; i < serial.size(); ++i) bad += !same_bits(f[static_cast<std::size_t>(d)][i], serial.f[static_cast<std::size_t>(d)][i]);
  return bad;
}

class Decomposed : public ::testing::TestWithParam<int> {};  // threads per rank

TEST_P(Decomposed, ForceAndEnergiesEqualTheSerialSweepBitwise) {
  omp_set_num_threads(GetParam());
  pd::Model global = lattice_model(-1.0);  // unbreakable
  notch(global);
  const pd::Vec3Array u = wavy(global, 0.01), v = wavy(global, 3.0);

  pd::ForceOperator serial_op(global);
  pd::State serial(global.nodes.size());
  serial.u = u;
  serial.v = v;
  serial_op.evaluate(serial, 0.0);

  pd::MpiDecomposed dec(MPI_COMM_WORLD, global);
  pd::ForceOperator op(dec.piece().model);
  op.set_decomposed(&dec);
  pd::State local = local_state(dec, u, v);
  op.evaluate(local, 0.0);

  // A real decomposition: with more than one rank every piece has ghosts and owns only its share.
  if (rank_count() > 1) {
    EXPECT_GT(dec.piece().ghost_local.size(), 0u);
    EXPECT_LT(dec.piece().owned_local.size(), global.nodes.size());
  }
  for (std::int32_t l : dec.piece().ghost_local)
    EXPECT_TRUE(same_bits(local.u[0][static_cast<std::size_t>(l)], u[0][static_cast<std::size_t>(dec.piece().global[static_cast<std::size_t>(l)])]));
  EXPECT_EQ(differing_forces(dec, local, serial), 0);
  const double strain = op.strain_energy(local), kinetic = op.kinetic_energy(local);
  EXPECT_GT(strain, 0.0);
  EXPECT_TRUE(same_bits(strain, serial_op.strain_energy(serial))) << strain << " vs " << serial_op.strain_energy(serial);
  EXPECT_TRUE(same_bits(kinetic, serial_op.kinetic_energy(serial))) << kinetic << " vs " << serial_op.kinetic_energy(serial);
  // Both at once (the run loop's call: one reduction instead of two), the same bits on every rank
  // and serially.
  const std::int64_t reductions = dec.traffic().reductions;
  const pd::ForceOperator::KineticAndStrain both = op.kinetic_and_strain_energy(local);
  EXPECT_EQ(dec.traffic().reductions, reductions + 1);
  EXPECT_TRUE(same_bits(both.kinetic, kinetic) && same_bits(both.strain, strain));
  const pd::ForceOperator::KineticAndStrain serial_both = serial_op.kinetic_and_strain_energy(serial);
  EXPECT_TRUE(same_bits(serial_both.kinetic, kinetic) && same_bits(serial_both.strain, strain));
}

TEST_P(Decomposed, BondsCrossingRanksBreakOnBothEndsInTheSameStepAsSerially) {
  omp_set_num_threads(GetParam());
  pd::Model global = lattice_model(0.5);  // breakable: s0 small enough for the field below
  notch(global);
  const double s0 = global.material.block[0].critical_stretch;
  // Opening of the notch plane: u_x jumps by a few s0·δ across x = 6.5 dx (plus the wavy field), so
  // some bonds across it break and others, shorter in x, do not.
  pd::Vec3Array u = wavy(global, 0.2 * s0);
  for (std::size_t i = 0; i < global.nodes.size(); ++i)
    if (global.nodes.x[0][i] > 6.5 * kDx) u[0][i] += 2.0 * s0 * kDx;
  const pd::Vec3Array v = pd::make_vec3(global.nodes.size());

  pd::ForceOperator serial_op(global);
  pd::State serial(global.nodes.size());
  serial.u = u;
  const pd::BreakReport serial_report = serial_op.break_bonds_and_evaluate(serial, 0.0);
  ASSERT_GT(serial_report.broken, 0);
  ASSERT_LT(serial_report.broken, static_cast<std::int64_t>(global.bonds.directed() / 2));

  pd::Model before_breaking = lattice_model(0.5);
  notch(before_breaking);
  pd::MpiDecomposed dec(MPI_COMM_WORLD, before_breaking);
  pd::ForceOperator op(dec.piece().model);
  op.set_decomposed(&dec);
  pd::State local = local_state(dec, u, v);
  const pd::BreakReport report = op.break_bonds_and_evaluate(local, 0.0);

  EXPECT_EQ(report.broken, serial_report.broken);
  EXPECT_TRUE(same_bits(report.energy, serial_report.energy)) << report.energy << " vs " << serial_report.energy;
  EXPECT_EQ(differing_forces(dec, local, serial), 0);
  EXPECT_TRUE(same_bits(op.strain_energy(local), serial_op.strain_energy(serial)));
  // Every owned row's flags are the serial row's: a bond to a ghost broke here exactly when it broke
  // in the serial sweep, where both copies break together, so it broke on the other rank too.
  const pd::LocalPiece& p = dec.piece();
  std::int64_t differing_flags = 0, crossing_broken = 0;
  for (std::int32_t l : p.owned_local) {
    const auto i = static_cast<std::size_t>(p.global[static_cast<std::size_t>(l)]);
    const std::int64_t lk = p.model.bonds.offsets[static_cast<std::size_t>(l)], gk = global.bonds.offsets[i];
    for (std::int64_t q = 0; q < global.bonds.offsets[i + 1] - gk; ++q) {
      const std::uint8_t flag = p.model.bonds.broken[static_cast<std::size_t>(lk + q)];
      differing_flags += flag != global.bonds.broken[static_cast<std::size_t>(gk + q)];
      crossing_broken += flag && !p.owned[static_cast<std::size_t>(p.model.bonds.neighbour[static_cast<std::size_t>(lk + q)])];
    }
  }
  EXPECT_EQ(differing_flags, 0);
  // Some broken bonds cross ranks (else the test would not test it): summed over the ranks.
  if (rank_count() > 1) EXPECT_GT(dec.total(crossing_broken), 0);

  // The next step on the broken state: still the serial bits.
  const pd::Vec3Array u2 = wavy(global, 0.3 * s0);
  serial.u = u2;
  serial_op.evaluate(serial, 0.0);
  local.u = pd::to_local(p, u2);
  op.evaluate(local, 0.0);
  EXPECT_EQ(differing_forces(dec, local, serial), 0);
  EXPECT_TRUE(same_bits(op.strain_energy(local), serial_op.strain_energy(serial)));
}

TEST_P(Decomposed, StretchRatioIsTheSerialOneOnAnyNumberOfRanks) {
  // The reduction of the quasi-static cut (materials/bond_model.hpp StretchRatio): the largest
  // stretch ratio, a maximum over the ranks, and the count of bonds over s0, each counted on one
  // rank, equal the serial ones bit for bit; the count is what the breaking pass then breaks.
  omp_set_num_threads(GetParam());
  pd::Model global = lattice_model(0.5);
  notch(global);
  const double s0 = global.material.block[0].critical_stretch;
  pd::Vec3Array u = wavy(global, 0.2 * s0);
  for (std::size_t i = 0; i < global.nodes.size(); ++i)
    if (global.nodes.x[0][i] > 6.5 * kDx) u[0][i] += 2.0 * s0 * kDx;
  pd::ForceOperator serial_op(global);
  pd::State serial(global.nodes.size());
  serial.u = u;
  const pd::StretchRatio expected = serial_op.stretch_ratio(serial);
  ASSERT_GT(expected.over, 0);
  ASSERT_GT(expected.largest, 1.0);

  pd::Model piece_of = lattice_model(0.5);
  notch(piece_of);
  pd::MpiDecomposed dec(MPI_COMM_WORLD, piece_of);
  pd::ForceOperator op(dec.piece().model);
  op.set_decomposed(&dec);
  pd::State local = local_state(dec, u, pd::make_vec3(global.nodes.size()));  // ghosts NaN: the exchange fills them
  const pd::StretchRatio got = op.stretch_ratio(local);
  EXPECT_TRUE(same_bits(got.largest, expected.largest)) << got.largest << " vs " << expected.largest;
  EXPECT_EQ(got.over, expected.over);
  // Each rank's own rows see only part of the bonds over s0 (the reduction is needed).
  const pd::StretchRatio mine = dec.piece().model.bond_model->stretch_ratio(dec.piece().model, local.u);
  if (rank_count() > 1) EXPECT_LT(mine.over, expected.over);
  EXPECT_EQ(op.break_bonds(local).broken, expected.over);
}

INSTANTIATE_TEST_SUITE_P(Threads, Decomposed, ::testing::Values(1, 2));

TEST(Halo, MessagesGoOnlyToRanksThatShareBonds) {
  const pd::Model global = lattice_model(-1.0);
  pd::MpiDecomposed dec(MPI_COMM_WORLD, global);
  const int ranks = rank_count();
  // Everything received is a ghost; everything sent, summed over the ranks, is everything received.
  const std::int64_t sent = dec.total(dec.halo().bytes_sent()), ghosts = dec.total(dec.halo().ghosts());
  EXPECT_EQ(dec.halo().ghosts(), static_cast<std::int64_t>(dec.piece().ghost_local.size()));
  EXPECT_EQ(sent, ghosts * 24);
  EXPECT_LE(dec.halo().messages_sent(), ranks - 1);
  if (ranks == 1) EXPECT_EQ(sent, 0);
  EXPECT_EQ(dec.total(static_cast<std::int64_t>(dec.piece().owned_local.size())), static_cast<std::int64_t>(global.nodes.size()));
}

}  // namespace

namespace {

// The exact sums across ranks (core/exact_sum.hpp, MpiDecomposed::exact_sum and reduce): terms of
// both signs over 200 binades, whose naive sum depends on the order, give the serial exact sum's
// bits on every rank for any rank count; ghosts' entries (poisoned) are left out.
TEST(ExactSumOverRanks, EqualsTheSerialExactSumBitwise) {
  const pd::Model global = lattice_model(-1.0);
  pd::MpiDecomposed dec(MPI_COMM_WORLD, global);
  const std::size_t n = global.nodes.size();
  std::vector<double> terms(n);
  for (std::size_t i = 0; i < n; ++i)
    terms[i] = std::ldexp(std::sin(0.7 * static_cast<double>(i) + 0.2), static_cast<int>((37 * i) % 200) - 100);
  const pd::LocalPiece& p = dec.piece();
  std::vector<double> local(p.size());
  for (std::size_t l = 0; l < p.size(); ++l) local[l] = terms[static_cast<std::size_t>(p.global[l])];
  for (std::int32_t l : p.ghost_local) local[static_cast<std::size_t>(l)] = std::nan("");
  const double serial = pd::exact_sum(terms, 0.25);
  EXPECT_TRUE(same_bits(dec.exact_sum(local, 0.25), serial));
  // Several accumulators in one reduction: each term and its square.
  pd::ExactSum sums[2];
  for (std::int32_t l : p.owned_local) {
    sums[0].add(local[static_cast<std::size_t>(l)]);
    sums[1].add(local[static_cast<std::size_t>(l)] * local[static_cast<std::size_t>(l)]);
  }
  dec.reduce(sums, 2);
  pd::ExactSum squares;
  for (double t : terms) squares.add(t * t);
  EXPECT_TRUE(same_bits(sums[0].value(), pd::exact_sum(terms)));
  EXPECT_TRUE(same_bits(sums[1].value(), squares.value()));
  EXPECT_EQ(dec.traffic().reduction_bytes, 3 * 8 * pd::ExactSum::kLimbs);  // 1 + 2 accumulators, whatever n is
}

// Integers ride in the same MPI_Allreduce as the exact sums (the breaking pass's count with its
// lost energy): each summed over the ranks, exactly, and the sums as without them.
TEST(ExactSumOverRanks, IntegersSumInTheSameReduction) {
  const pd::Model global = lattice_model(-1.0);
  pd::MpiDecomposed dec(MPI_COMM_WORLD, global);
  const pd::LocalPiece& p = dec.piece();
  pd::ExactSum volume;
  for (std::int32_t l : p.owned_local) volume.add(p.model.nodes.volume[static_cast<std::size_t>(l)]);
  std::int64_t integers[2] = {static_cast<std::int64_t>(p.owned_local.size()), dec.rank() + 1};
  const pd::Decomposed::Traffic before = dec.traffic();
  dec.reduce(&volume, 1, integers, 2);
  const int r = rank_count();
  EXPECT_EQ(integers[0], static_cast<std::int64_t>(global.nodes.size()));
  EXPECT_EQ(integers[1], static_cast<std::int64_t>(r) * (r + 1) / 2);
  EXPECT_TRUE(same_bits(volume.value(), pd::exact_sum(global.nodes.volume)));
  EXPECT_EQ(dec.traffic().reductions, before.reductions + 1);
  EXPECT_EQ(dec.traffic().reduction_bytes - before.reduction_bytes, 8 * (pd::ExactSum::kLimbs + 2));
  // total() is such a reduction too, and counted.
  EXPECT_EQ(dec.total(1), r);
  EXPECT_EQ(dec.traffic().reductions, before.reductions + 2);
}

}  // namespace
