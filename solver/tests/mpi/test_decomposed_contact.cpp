// Contact on the ranks of this run (issue 15; forces/contact_on_piece): two 2D bodies fly into each
// other, the first breakable, with self-contact so that its fragments push on each other too.
// After every Verlet step the gathered u and v, the contact energy, the kinetic energy and the
// list's build count equal the serial run's bit for bit, for 1, 2 and 3 ranks (ctest mpi_ranks_R)
// and 1 and 2 threads per rank; the owned rows of the last list add up to the serial list.
// The linearised contact force of the Newton solves (quasi_static, implicit, mixed): with the square
// pressed into the plate, the decomposed J·δu and diagonal blocks equal the serial ones bit for bit.
#include <gtest/gtest.h>
#include <mpi.h>
#include <omp.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "bits.hpp"
#include "core/model.hpp"
#include "forces/contact.hpp"
#include "integrators/verlet.hpp"
#include "lattice.hpp"
#include "operator/force_operator.hpp"
#include "parallel/local_model.hpp"
#include "parallel/mpi_decomposed.hpp"

namespace {

constexpr double kDx = 1e-3;

// A 14 × 10 plate (block 1, breakable) and a 6 × 6 stiffer, heavier square (block 2) 4.5 dx above
// its middle (a gap wider than δ: no bonds between them).
pd::Model plate_and_square() {
  pd::Case c = pdtest::lattice_case(2, "plane_stress", kDx, 3.015 * kDx, 1e9, 1000.0, 2.0, 1e-3);
  pd::BlockMaterial b2 = c.blocks[0];
  b2.name = "second";
  b2.parameters["youngs_modulus"] = 4e9;
  b2.density = 4000.0;
  c.blocks.push_back(b2);
  c.contact.self_contact = true;
  pd::Nodes nodes = pdtest::cubic_lattice(14, 10, 1, kDx, 2, 1e-3);
  const pd::Nodes square = pdtest::cubic_lattice(6, 6, 1, kDx, 2, 1e-3);
  for (std::size_t i = 0; i < square.size(); ++i) {
    nodes.x[0].push_back(square.x[0][i] + 4 * kDx);
    nodes.x[1].push_back(square.x[1][i] + 13.5 * kDx);
    nodes.x[2].push_back(0.0);
    nodes.volume.push_back(square.volume[i]);
    nodes.block.push_back(2);
  }
  return pd::build_model(c, std::move(nodes));
}

// The square falls at 300 m/s onto the plate; a wavy part so that no two rows are alike.
pd::Vec3Array velocities(const pd::Model& m) {
  pd::Vec3Array v = pd::make_vec3(m.nodes.size());
  for (std::size_t i = 0; i < m.nodes.size(); ++i) {
    const double x = m.nodes.x[0][i] / kDx, y = m.nodes.x[1][i] / kDx;
    v[0][i] = 0.5 * std::sin(0.7 * y + 0.3 * x);
    v[1][i] = (m.block_index[i] == 1 ? -300.0 : 0.0) + 0.4 * std::cos(0.5 * x - 0.2 * y);
  }
  return v;
}

using pdtest::differing;
using pdtest::same_bits;

}  // namespace

class DecomposedContact : public ::testing::TestWithParam<int> {};  // threads per rank

TEST_P(DecomposedContact, EveryStepEqualsTheSerialStepBitwise) {
  omp_set_num_threads(GetParam());
  pd::Model global = plate_and_square();
  ASSERT_TRUE(global.contact.pairs);
  const pd::Model initial = global;
  const pd::Vec3Array v0 = velocities(global);

  pd::ForceOperator serial_op(global);
  pd::VelocityVerlet serial_verlet(serial_op);
  pd::State serial(global.nodes.size());
  serial.v = v0;

  pd::MpiDecomposed dec(MPI_COMM_WORLD, initial);
  pd::ForceOperator op(dec.piece().model);
  op.set_decomposed(&dec);
  pd::VelocityVerlet verlet(op);
  pd::State local(dec.piece().size());
  local.v = pd::to_local(dec.piece(), v0);

  double t = 0.0, ts = 0.0, dt = 0.8 * serial_op.stable_time_step(), dts = dt;
  serial_verlet.initialize(serial, ts);
  verlet.initialize(local, t);
  const pd::NeighbourList& serial_list = global.contact_list;
  const pd::NeighbourList& list = dec.piece().model.contact_list;

  const int steps = GetParam() == 1 ? 400 : 100;
  std::int64_t bad_steps = 0;
  double most_contact_energy = 0.0;
  for (int step = 1; step <= steps; ++step) {
    serial_verlet.step(serial, ts, dts);
    verlet.step(local, t, dt);
    most_contact_energy = std::max(most_contact_energy, pd::term_energy(serial, "contact"));
    bool same = same_bits(pd::term_energy(local, "contact"), pd::term_energy(serial, "contact")) &&
                same_bits(op.kinetic_energy(local), serial_op.kinetic_energy(serial)) &&
                list.rebuilds() == serial_list.rebuilds() && verlet.last_step().broken_now == serial_verlet.last_step().broken_now;
    const pd::Vec3Array u = dec.gather(local.u), v = dec.gather(local.v);
    if (dec.rank() == 0) same = same && differing(u, serial.u) == 0 && differing(v, serial.v) == 0;
    int all_same = same ? 1 : 0;
    MPI_Allreduce(MPI_IN_PLACE, &all_same, 1, MPI_INT, MPI_MIN, MPI_COMM_WORLD);
    if (!all_same) {
      ++bad_steps;
      ADD_FAILURE() << "step " << step << ": contact energy " << pd::term_energy(local, "contact") << " vs " << pd::term_energy(serial, "contact")
                    << ", builds " << list.rebuilds() << " vs " << serial_list.rebuilds();
    }
    if (bad_steps > 3) break;
  }
  // The pieces' owned rows are the serial list's rows.
  EXPECT_EQ(dec.total(static_cast<std::int64_t>(list.pairs().directed())),
            static_cast<std::int64_t>(serial_list.pairs().directed()));
  // The scene did what it is meant to test: the bodies touched, the list was rebuilt several
  // times, and with 1 thread (the whole run) the plate broke.
  EXPECT_GT(most_contact_energy, 0.0);
  EXPECT_GT(serial_list.rebuilds(), 5);
  if (GetParam() == 1) {
    std::int64_t broken = 0;
    for (std::uint8_t b : global.bonds.broken) broken += b;
    EXPECT_GT(broken, 10);
  }
  // The contact ghosts were exchanged: a box exchange per build, a halo per force evaluation.
  EXPECT_EQ(dec.contact_traffic().box_exchanges, serial_list.rebuilds());
  EXPECT_EQ(dec.contact_traffic().halo_exchanges, steps + 1);
  // On several ranks some pairs crossed them: the square and the plate share no bond, so a pair
  // between nodes of two ranks needs a contact ghost that the bonds' halo does not bring.
  if (dec.ranks() > 1) EXPECT_GT(dec.total(dec.contact_traffic().halo_bytes), 0);
}


namespace {

// The 3×3 diagonal block of every node (zero where a node has no free dof), 9 values per node, from
// stiffness_diagonal_blocks' groups over `dofs`.
std::vector<double> per_node_blocks(const pd::ForceOperator& op, const pd::State& s, const pd::FreeDofs& dofs) {
  std::vector<std::int64_t> first;
  std::vector<double> blocks, out(9 * s.size(), 0.0);
  EXPECT_TRUE(op.stiffness_diagonal_blocks(s, 0.0, dofs, first, blocks));
  for (std::size_t g = 0; g + 1 < first.size(); ++g) {
    const auto i = static_cast<std::size_t>(dofs.node[static_cast<std::size_t>(first[g])]);
    std::copy(&blocks[9 * g], &blocks[9 * g] + 9, &out[9 * i]);
  }
  return out;
}

}  // namespace

TEST_P(DecomposedContact, JacobianProductAndDiagonalBlocksEqualTheSerialOnesBitwise) {
  omp_set_num_threads(GetParam());
  pd::Model global = plate_and_square();
  const pd::Model initial = global;
  // The square moved 3.6 dx down: 0.9 dx from the plate, inside the contact distance 1.35 dx, and a
  // wavy part on every node so that no two rows are alike; δu wavy too.
  pd::Vec3Array u = pd::make_vec3(global.nodes.size()), du = pd::make_vec3(global.nodes.size());
  for (std::size_t i = 0; i < global.nodes.size(); ++i) {
    const double x = global.nodes.x[0][i] / kDx, y = global.nodes.x[1][i] / kDx;
    u[0][i] = 0.02 * kDx * std::sin(0.7 * y + 0.3 * x);
    u[1][i] = (global.block_index[i] == 1 ? -3.6 * kDx : 0.0) + 0.02 * kDx * std::cos(0.5 * x - 0.2 * y);
    du[0][i] = std::cos(0.9 * x + 0.4 * y);
    du[1][i] = std::sin(0.3 * x - 0.8 * y) + 0.5;
  }
  pd::ForceOperator serial_op(global);
  pd::State serial(global.nodes.size());
  serial.u = u;
  serial_op.evaluate(serial, 0.0);  // builds the contact list, as a Newton iteration's residual does
  ASSERT_GT(pd::term_energy(serial, "contact"), 0.0);
  pd::Vec3Array serial_y = pd::make_vec3(serial.size());
  serial_op.apply_jacobian(serial, 0.0, du, serial_y);
  // The contact part is there: the product without it differs.
  pd::Vec3Array contact_only = pd::make_vec3(serial.size());
  pd::ShortRangeForce(global).AddJacobianProduct(serial.u, du, contact_only);
  std::int64_t contact_rows = 0;
  for (std::size_t i = 0; i < serial.size(); ++i) contact_rows += contact_only[1][i] != 0.0;
  EXPECT_GT(contact_rows, 10);
  const pd::FreeDofs serial_dofs = serial_op.free_dofs(3);
  const std::vector<double> serial_blocks = per_node_blocks(serial_op, serial, serial_dofs);

  pd::MpiDecomposed dec(MPI_COMM_WORLD, initial);
  pd::ForceOperator op(dec.piece().model);
  op.set_decomposed(&dec);
  pd::State local(dec.piece().size());
  local.u = pd::to_local(dec.piece(), u);
  op.evaluate(local, 0.0);
  EXPECT_TRUE(pdtest::same_bits(pd::term_energy(local, "contact"), pd::term_energy(serial, "contact")));
  // δu's ghosts from their owners inside apply_jacobian: the owned entries are all it may read.
  pd::Vec3Array local_du = pd::to_local(dec.piece(), du);
  for (std::int32_t g : dec.piece().ghost_local)
    for (auto& component : local_du) component[static_cast<std::size_t>(g)] = -7.0;
  const std::int64_t exchanges_before = dec.contact_traffic().halo_exchanges;
  pd::Vec3Array y = pd::make_vec3(local.size());
  op.apply_jacobian(local, 0.0, local_du, y);
  EXPECT_EQ(dec.contact_traffic().halo_exchanges, exchanges_before + 2);  // u and δu of the contact ghosts
  const pd::Vec3Array gathered = dec.gather(y);
  const std::vector<double> blocks = dec.gather(per_node_blocks(op, local, op.free_dofs(3)), 9);
  if (dec.rank() == 0) {
    EXPECT_EQ(differing(gathered, serial_y), 0);
    std::int64_t bad = 0;
    for (std::size_t k = 0; k < blocks.size(); ++k) bad += !same_bits(blocks[k], serial_blocks[k]);
    EXPECT_EQ(bad, 0);
    EXPECT_EQ(blocks.size(), serial_blocks.size());
  }
  // On several ranks pairs crossed them (the square and the plate share no bond).
  if (dec.ranks() > 1) EXPECT_GT(dec.total(dec.contact_traffic().halo_bytes), 0);
}

INSTANTIATE_TEST_SUITE_P(Threads, DecomposedContact, ::testing::Values(1, 2));
