// The halo exchange overlapped with the bond sweep (parallel/row_split.hpp), on 1, 2 and 3 ranks
// (ctest mpi_ranks_R) with 1 and 2 threads per rank:
// - the split: every owned row is in exactly one of the interior and boundary lists, an interior
//   row has no ghost partner and a boundary row has one;
// - the order: when the law waits for u's ghosts, the ghosts still hold the NaN they were poisoned
//   with (nothing read or wrote them early), the law has waited once, the PMB interior rows already
//   hold their final force and the boundary rows none yet (LPS: no force yet — its first sweep
//   computes θ only); a boundary row swept before the wait would read NaN;
// - the bits: the overlapped force and W equal the serial sweep's and the decomposed blocking
//   sweep's (update_ghosts, then add_force) bit for bit, and so does the Krylov path's J·x;
// - the operator's other overlapped paths, watched at every wait (WatchedDecomposed): the breaking
//   passes of PMB (thesis rule), of LAMMPS's α rule (u and s0 in one exchange) and of LPS, each
//   through break_bonds on its own and break_bonds_and_evaluate, and J·x of PMB and LPS (LPS: x's
//   exchange, then P's with δP's). At each wait the ghosts still hold their poison, the interior
//   rows hold their final flags and force (or nothing yet, for a first sweep that computes θ only)
//   and the boundary rows are untouched; after it, flags, s0, f, W, the reports and J·x are the
//   serial ones bit for bit.
#include <gtest/gtest.h>
#include <mpi.h>
#include <omp.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <string>
#include <tuple>

#include "bits.hpp"
#include "core/model.hpp"
#include "lattice.hpp"
#include "materials/pmb/pmb.hpp"
#include "operator/force_operator.hpp"
#include "parallel/mpi_decomposed.hpp"
#include "pmb_s0.hpp"

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

// A Decomposed that forwards every call to an MpiDecomposed, and at each end of a halo exchange
// (the wait of an overlapped sweep) first records the exchange's width and calls at_wait with the
// arrays whose ghosts are about to arrive: what the tests below look at when the operator's law waits.
class WatchedDecomposed : public pd::Decomposed {
 public:
  explicit WatchedDecomposed(pd::MpiDecomposed& d) : d_(d) {}
  std::function<void(const pd::NodeColumns&)> at_wait;
  mutable std::vector<int> widths;  // of the exchanges ended, in order

  void begin_update_ghosts(const pd::NodeColumns& a) const override { d_.begin_update_ghosts(a); }
  void end_update_ghosts(const pd::NodeColumns& a) const override {
    widths.push_back(a.width());
    if (at_wait) at_wait(a);
    d_.end_update_ghosts(a);
  }
  const pd::RowSplit& row_split() const override { return d_.row_split(); }
  double exact_sum(const std::vector<double>& v, double start) const override { return d_.exact_sum(v, start); }
  void reduce(pd::ExactSum* s, int c, std::int64_t* i, int ic) const override { d_.reduce(s, c, i, ic); }
  std::int64_t total(std::int64_t v) const override { return d_.total(v); }
  double minimum(double v) const override { return d_.minimum(v); }
  int rank() const override { return d_.rank(); }
  int ranks() const override { return d_.ranks(); }
  const pd::LocalPiece& piece() const override { return d_.piece(); }
  pd::LocalPiece& piece() override { return d_.piece(); }
  std::vector<double> gather(const std::vector<double>& v) const override { return d_.gather(v); }
  std::vector<double> gather(const std::vector<double>& v, int width) const override { return d_.gather(v, width); }
  void broadcast(std::vector<double>& v) const override { d_.broadcast(v); }
  std::vector<std::int64_t> gather_to_all(const std::vector<std::int64_t>& v) const override { return d_.gather_to_all(v); }
  void gather_broken(const pd::BondList& l, pd::BondList& g) const override { d_.gather_broken(l, g); }
  std::vector<double> gather_bond_values(const pd::BondList& l, const std::vector<double>& v, int w,
                                         const pd::BondList& g) const override {
    return d_.gather_bond_values(l, v, w, g);
  }
  void gather_broken_lines(const pd::BondList& l, pd::BondList& g) const override { d_.gather_broken_lines(l, g); }
  std::vector<std::pair<std::int64_t, double>> gather_keyed(const std::vector<std::int64_t>& k,
                                                            const std::vector<double>& v) const override {
    return d_.gather_keyed(k, v);
  }
  std::vector<double> per_rank(double v) const override { return d_.per_rank(v); }
  std::string broadcast(const std::string& b) const override { return d_.broadcast(b); }
  void exchange_in_boxes(const double lo[3], const double hi[3], const std::vector<std::int32_t>& g, const pd::Vec3Array& x,
                         const std::vector<double>& v, int w, std::vector<std::int32_t>& rn,
                         std::vector<double>& rv) const override {
    d_.exchange_in_boxes(lo, hi, g, x, v, w, rn, rv);
  }
  std::unique_ptr<pd::NodeHalo> make_node_halo(const std::vector<std::int32_t>& g,
                                               const std::vector<std::int32_t>& l) const override {
    return d_.make_node_halo(g, l);
  }
  std::vector<std::string> contact_traffic_report(std::int64_t steps) const override { return d_.contact_traffic_report(steps); }
  Traffic traffic() const override { return d_.traffic(); }
  std::vector<std::string> traffic_report(std::int64_t steps) const override { return d_.traffic_report(steps); }

 private:
  pd::MpiDecomposed& d_;
};

// The lattice with a law and a breaking rule: "pmb" (the thesis rule), "lammps" (LAMMPS's order and
// α = 0.25: per-node s0) or "lps".
pd::Model breaking_model(const std::string& kind) {
  pd::Case c = pdtest::lattice_case(3, "3d", kDx, 3.015 * kDx, 70e9, 2700.0, 0.5);
  if (kind == "lps") {
    c.blocks[0].model = "lps";
    c.blocks[0].parameters["poisson_ratio"] = 0.22;
  }
  if (kind == "lammps") {
    c.breaking_order = "lammps";
    c.blocks[0].parameters["critical_stretch_alpha"] = 0.25;
  }
  pd::Model m = pd::build_model(c, pdtest::cubic_lattice(kNx, kNy, kNz, kDx, 3));
  pdtest::notch(m, kDx);
  return m;
}

// Row l's broken flags on the piece.
std::vector<std::uint8_t> row_flags(const pd::Model& m, std::size_t l) {
  return {m.bonds.broken.begin() + m.bonds.offsets[l], m.bonds.broken.begin() + m.bonds.offsets[l + 1]};
}

// The ghosts' poison: NaN in u (a row that read one early would have a NaN force), −1 in LAMMPS's
// s0 (not NaN: min(s0_i, NaN) is s0_i, so a NaN would hide an early read; −1 breaks every bond).
constexpr double kS0Poison = -1.0;
void poison_ghost_s0(const pd::LocalPiece& p, pd::Model& m) {
  for (std::int32_t l : p.ghost_local)
    if (std::vector<double>* s0 = pd::node_critical_stretch(m)) (*s0)[static_cast<std::size_t>(l)] = kS0Poison;
}

class OverlapBreaking : public ::testing::TestWithParam<std::tuple<std::string, int>> {};  // kind, threads per rank

TEST_P(OverlapBreaking, EachPassSweepsInteriorRowsBeforeItsOneWaitAndBoundaryRowsAfterWithTheSerialBits) {
  const std::string kind = std::get<0>(GetParam());
  omp_set_num_threads(std::get<1>(GetParam()));
  pd::Model global = breaking_model(kind);
  ASSERT_EQ(pd::uses_lammps_rules(global), kind == "lammps");
  pd::MpiDecomposed dec(MPI_COMM_WORLD, global);  // before the serial passes break the global model's bonds
  WatchedDecomposed watched(dec);
  pd::Model& model = dec.piece().model;
  pd::ForceOperator op(model);
  op.set_decomposed(&watched);
  const pd::LocalPiece& p = dec.piece();
  const pd::RowSplit& split = dec.row_split();
  const std::size_t n = p.size();
  const bool per_node_s0 = kind == "lammps";
  ASSERT_EQ(pdtest::s0_of(model).empty(), !per_node_s0);

  // Two passes over stretches around s0 (≈ 4.4e-5 here: the wavy field's stretches reach about its
  // amplitude), so that some bonds break in each, in interior and boundary rows alike: break_bonds
  // on its own (the implicit integrators' call), then break_bonds_and_evaluate, whose α rule reads
  // the s0 the first pass left.
  const pd::Vec3Array u1 = wavy(global, 5e-5), u2 = wavy(global, 8e-5);
  pd::ForceOperator serial_op(global);
  pd::State serial(global.nodes.size());
  serial.u = u1;
  const pd::BreakReport serial1 = serial_op.break_bonds(serial);
  const std::vector<std::uint8_t> serial_flags1 = global.bonds.broken;
  const std::vector<double> serial_s01 = pdtest::s0_of(global);
  serial.u = u2;
  const pd::BreakReport serial2 = serial_op.break_bonds_and_evaluate(serial, 0.0);
  ASSERT_GT(serial1.broken, 0);
  ASSERT_GT(serial2.broken, 0);

  // What a pass must show at its (first) wait: the ghosts still poisoned; interior rows' flags
  // already final and boundary rows' as before the pass (checked after it, from these copies).
  const auto expect_poisoned_ghosts = [&](const pd::NodeColumns& a) {
    std::int64_t touched = 0;
    for (std::int32_t l : p.ghost_local) {
      for (int c = 0; c < 3; ++c) touched += !std::isnan(a[c][l]);
      if (a.width() == 4) touched += a[3][l] != kS0Poison;
    }
    EXPECT_EQ(touched, 0);
  };
  std::vector<std::uint8_t> flags_before, flags_at_wait;
  int u_waits = 0;
  // Counts of the rows whose flags changed in the pass, and of those whose state at the wait was
  // wrong: interior rows not yet final, boundary rows already changed.
  const auto check_flags = [&](std::int64_t& interior_broke, std::int64_t& boundary_broke) {
    std::int64_t interior_late = 0, boundary_early = 0;
    interior_broke = boundary_broke = 0;
    const auto slice = [&](const std::vector<std::uint8_t>& all, std::int32_t l) {
      return std::vector<std::uint8_t>(all.begin() + model.bonds.offsets[static_cast<std::size_t>(l)],
                                       all.begin() + model.bonds.offsets[static_cast<std::size_t>(l) + 1]);
    };
    for (std::int32_t l : split.interior) {
      interior_broke += slice(flags_before, l) != row_flags(model, static_cast<std::size_t>(l));
      interior_late += slice(flags_at_wait, l) != row_flags(model, static_cast<std::size_t>(l));
    }
    for (std::int32_t l : split.boundary) {
      boundary_broke += slice(flags_before, l) != row_flags(model, static_cast<std::size_t>(l));
      boundary_early += slice(flags_at_wait, l) != slice(flags_before, l);
    }
    EXPECT_EQ(interior_late, 0);
    EXPECT_EQ(boundary_early, 0);
  };
  // The owned rows' flags and s0 against the serial ones (the piece's rows hold the global rows'
  // bonds in the same order).
  const auto expect_serial_flags_and_s0 = [&](const std::vector<std::uint8_t>& flags, const std::vector<double>& s0) {
    std::int64_t differ = 0;
    for (std::int32_t l : p.owned_local) {
      const auto li = static_cast<std::size_t>(l);
      const auto g = static_cast<std::size_t>(p.global[li]);
      const std::vector<std::uint8_t> mine = row_flags(model, li);
      ASSERT_EQ(static_cast<std::int64_t>(mine.size()), global.bonds.offsets[g + 1] - global.bonds.offsets[g]);
      for (std::size_t q = 0; q < mine.size(); ++q) differ += mine[q] != flags[static_cast<std::size_t>(global.bonds.offsets[g]) + q];
      if (per_node_s0) differ += !same_bits(pdtest::s0_of(model)[li], s0[g]);
    }
    EXPECT_EQ(differ, 0);
  };

  // Pass 1: break_bonds on its own.
  pd::State s(n);
  s.u = poisoned_local(p, u1);
  poison_ghost_s0(p, model);
  flags_before = model.bonds.broken;
  watched.widths.clear();
  watched.at_wait = [&](const pd::NodeColumns& a) {
    if (a.width() < 3) return;  // LPS's P: its second sweep's exchange
    ++u_waits;
    expect_poisoned_ghosts(a);
    flags_at_wait = model.bonds.broken;
  };
  const pd::BreakReport report1 = op.break_bonds(s);
  EXPECT_EQ(u_waits, 1);
  // One exchange for u (with s0 under the α rule: one message, not two); LPS's P after it.
  const std::vector<int> widths = kind == "lps" ? std::vector<int>{3, 1} : std::vector<int>{per_node_s0 ? 4 : 3};
  EXPECT_EQ(watched.widths, widths);
  std::int64_t interior_broke = 0, boundary_broke = 0;
  check_flags(interior_broke, boundary_broke);
  EXPECT_GT(dec.total(interior_broke), 0);
  if (dec.ranks() > 1) EXPECT_GT(dec.total(boundary_broke), 0);
  expect_serial_flags_and_s0(serial_flags1, serial_s01);
  EXPECT_EQ(report1.broken, serial1.broken);
  EXPECT_TRUE(same_bits(report1.energy, serial1.energy));

  // Pass 2: break_bonds_and_evaluate, with the force at the wait too.
  s.u = poisoned_local(p, u2);
  poison_ghost_s0(p, model);
  flags_before = model.bonds.broken;
  for (auto& c : s.f) std::fill(c.begin(), c.end(), 0.0);
  pd::Vec3Array f_at_u_wait, f_at_p_wait;
  u_waits = 0;
  watched.widths.clear();
  watched.at_wait = [&](const pd::NodeColumns& a) {
    if (a.width() < 3) {
      f_at_p_wait = s.f;
      return;
    }
    ++u_waits;
    expect_poisoned_ghosts(a);
    flags_at_wait = model.bonds.broken;
    f_at_u_wait = s.f;
  };
  const pd::BreakReport report2 = op.break_bonds_and_evaluate(s, 0.0);
  EXPECT_EQ(u_waits, 1);
  EXPECT_EQ(watched.widths, widths);
  check_flags(interior_broke, boundary_broke);
  EXPECT_GT(dec.total(interior_broke), 0);
  if (dec.ranks() > 1) EXPECT_GT(dec.total(boundary_broke), 0);
  expect_serial_flags_and_s0(global.bonds.broken, pdtest::s0_of(global));
  EXPECT_EQ(report2.broken, serial2.broken);
  EXPECT_TRUE(same_bits(report2.energy, serial2.energy));
  // The force at the wait that precedes the force sweep (PMB: u's; LPS: P's, its first sweep gives
  // θ only): interior rows final, boundary rows nothing yet. Then f and W the serial ones.
  const pd::Vec3Array& f_at_wait = kind == "lps" ? f_at_p_wait : f_at_u_wait;
  ASSERT_EQ(f_at_wait[0].size(), n);
  std::int64_t early = 0, late = 0, differ = 0;
  for (std::int32_t l : split.interior)
    for (std::size_t d = 0; d < 3; ++d) early += !same_bits(f_at_wait[d][static_cast<std::size_t>(l)], s.f[d][static_cast<std::size_t>(l)]);
  for (std::int32_t l : split.boundary)
    for (std::size_t d = 0; d < 3; ++d) late += f_at_wait[d][static_cast<std::size_t>(l)] != 0.0;
  if (kind == "lps")  // no force at u's wait: its first sweep computes θ only
    for (std::int32_t l : p.owned_local)
      for (std::size_t d = 0; d < 3; ++d) late += f_at_u_wait[d][static_cast<std::size_t>(l)] != 0.0;
  for (std::int32_t l : p.owned_local) {
    const auto li = static_cast<std::size_t>(l);
    const auto g = static_cast<std::size_t>(p.global[li]);
    for (std::size_t d = 0; d < 3; ++d) differ += !same_bits(s.f[d][li], serial.f[d][g]);
    differ += !same_bits(s.w[li], serial.w[g]);
  }
  EXPECT_EQ(early, 0);
  EXPECT_EQ(late, 0);
  EXPECT_EQ(differ, 0);
}

INSTANTIATE_TEST_SUITE_P(RulesAndThreads, OverlapBreaking,
                         ::testing::Combine(::testing::Values(std::string("pmb"), std::string("lammps"), std::string("lps")),
                                            ::testing::Values(1, 2)));

class OverlapKrylov : public ::testing::TestWithParam<std::tuple<std::string, int>> {};  // law, threads per rank

// The matrix-free J·x of the Krylov solves (apply_jacobian), watched: at x's wait the ghosts' x are
// still NaN and the boundary rows' y untouched (PMB: interior rows' y final; LPS: no y yet, its
// first sweep computes δP only); LPS then waits once more, for P and δP together (one exchange of
// 2 values per ghost), with the interior rows' y final and the boundary rows' still 0. y is the
// serial product bit for bit.
TEST_P(OverlapKrylov, InteriorRowsBeforeEachWaitBoundaryRowsAfterWithTheSerialBits) {
  const std::string law = std::get<0>(GetParam());
  omp_set_num_threads(std::get<1>(GetParam()));
  pd::Model global = lattice_model(law);
  const pd::Vec3Array u = wavy(global, 0.01), x = wavy(global, 0.003);
  pd::ForceOperator serial_op(global);
  pd::State serial(global.nodes.size());
  serial.u = u;
  serial_op.evaluate(serial, 0.0);
  pd::Vec3Array y_serial = pd::make_vec3(global.nodes.size());
  serial_op.apply_jacobian(serial, 0.0, x, y_serial);

  pd::MpiDecomposed dec(MPI_COMM_WORLD, global);
  WatchedDecomposed watched(dec);
  pd::Model& model = dec.piece().model;
  pd::ForceOperator op(model);
  op.set_decomposed(&watched);
  const pd::LocalPiece& p = dec.piece();
  const pd::RowSplit& split = dec.row_split();
  const std::size_t n = p.size();
  pd::State s(n);
  s.u = poisoned_local(p, u);
  op.evaluate(s, 0.0);  // s.u's ghosts current, as apply_jacobian requires

  pd::Vec3Array y = pd::make_vec3(n), y_at_x_wait, y_at_p_wait;
  std::int64_t touched = 0;
  watched.widths.clear();
  watched.at_wait = [&](const pd::NodeColumns& a) {
    if (a.width() == 3) {
      for (std::int32_t l : p.ghost_local)
        for (int c = 0; c < 3; ++c) touched += !std::isnan(a[c][l]);
      y_at_x_wait = y;
    } else {
      y_at_p_wait = y;
    }
  };
  op.apply_jacobian(s, 0.0, poisoned_local(p, x), y);
  EXPECT_EQ(touched, 0);
  EXPECT_EQ(watched.widths, law == "lps" ? std::vector<int>({3, 2}) : std::vector<int>({3}));
  const pd::Vec3Array& y_at_wait = law == "lps" ? y_at_p_wait : y_at_x_wait;
  ASSERT_EQ(y_at_wait[0].size(), n);
  std::int64_t early = 0, late = 0, differ = 0, zero = 0;
  for (std::int32_t l : split.interior)
    for (std::size_t d = 0; d < 3; ++d) early += !same_bits(y_at_wait[d][static_cast<std::size_t>(l)], y[d][static_cast<std::size_t>(l)]);
  for (std::int32_t l : split.boundary)
    for (std::size_t d = 0; d < 3; ++d) late += y_at_wait[d][static_cast<std::size_t>(l)] != 0.0;
  if (law == "lps")
    for (std::int32_t l : p.owned_local)
      for (std::size_t d = 0; d < 3; ++d) late += y_at_x_wait[d][static_cast<std::size_t>(l)] != 0.0;
  for (std::int32_t l : p.owned_local) {
    const auto li = static_cast<std::size_t>(l);
    for (std::size_t d = 0; d < 3; ++d) differ += !same_bits(y[d][li], y_serial[d][static_cast<std::size_t>(p.global[li])]);
    zero += y[0][li] == 0.0;
  }
  EXPECT_EQ(early, 0);
  EXPECT_EQ(late, 0);
  EXPECT_EQ(differ, 0);
  EXPECT_LT(zero, static_cast<std::int64_t>(p.owned_local.size()) / 10);  // a product that is not 0
}

INSTANTIATE_TEST_SUITE_P(LawsAndThreads, OverlapKrylov,
                         ::testing::Combine(::testing::Values(std::string("pmb"), std::string("lps")), ::testing::Values(1, 2)));

}  // namespace
