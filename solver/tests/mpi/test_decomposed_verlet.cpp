// Velocity Verlet on the ranks of this run (issue 15): 60 steps of a notched 3D lattice torn open
// by its initial velocities, one face clamped, the other pulled by a velocity table, with damping —
// bonds break across ranks. After every step the gathered u and v, the bonds broken in the step and
// the energy they held, the kinetic and strain energy and the external and damping work equal the
// serial integrator's bit for bit, for 1, 2 and 3 ranks (ctest mpi_ranks_R).
#include <gtest/gtest.h>
#include <mpi.h>

#include <cmath>
#include <cstring>

#include "bits.hpp"
#include "core/model.hpp"
#include "integrators/verlet.hpp"
#include "lattice.hpp"
#include "operator/force_operator.hpp"
#include "parallel/mpi_decomposed.hpp"

namespace {

constexpr double kDx = 1e-3;

pd::Model torn_lattice() {
  const int nx = 14, ny = 10, nz = 8;
  pd::Case c = pdtest::lattice_case(3, "3d", kDx, 3.015 * kDx, 70e9, 2700.0, 50.0);
  c.damping = 2e4;
  pd::Nodes nodes = pdtest::cubic_lattice(nx, ny, nz, kDx, 3);
  pd::NodeSet left{"left", std::vector<std::uint8_t>(nodes.size(), 0)};
  pd::NodeSet right{"right", std::vector<std::uint8_t>(nodes.size(), 0)};
  for (std::size_t i = 0; i < nodes.size(); ++i) {
    left.member[i] = nodes.x[0][i] < 1.5 * kDx;
    right.member[i] = nodes.x[0][i] > (nx - 2.5) * kDx;
  }
  nodes.sets = {left, right};
  c.boundary_conditions.push_back({"left", "displacement", 0, {0.0}, {0.0}});
  c.boundary_conditions.push_back({"right", "velocity", 0, {0.0, 2e-6}, {0.0, 5.0}});
  pd::Model m = pd::build_model(c, nodes);
  // A notch: the bonds across x = 6.5 dx with y < 4 dx start broken.
  for (std::size_t i = 0; i < m.nodes.size(); ++i)
    for (std::int64_t k = m.bonds.offsets[i]; k < m.bonds.offsets[i + 1]; ++k) {
      const auto j = static_cast<std::size_t>(m.bonds.neighbour[static_cast<std::size_t>(k)]);
      if ((m.nodes.x[0][i] - 6.5 * kDx) * (m.nodes.x[0][j] - 6.5 * kDx) < 0 && m.nodes.x[1][i] < 4 * kDx &&
          m.nodes.x[1][j] < 4 * kDx)
        m.bonds.broken[static_cast<std::size_t>(k)] = 1;
    }
  return m;
}

// Opening velocities: ±2 m/s across the notch plane, with a wavy part so no two rows are alike.
pd::Vec3Array opening(const pd::Model& m) {
  pd::Vec3Array v = pd::make_vec3(m.nodes.size());
  for (std::size_t i = 0; i < m.nodes.size(); ++i) {
    const double x = m.nodes.x[0][i] / kDx, y = m.nodes.x[1][i] / kDx, z = m.nodes.x[2][i] / kDx;
    v[0][i] = (x > 6.5 ? 2.0 : -2.0) + 0.3 * std::sin(0.7 * y + 0.2 * z * x);
    v[1][i] = 0.2 * std::cos(0.5 * x - 0.3 * z);
    v[2][i] = 0.1 * std::sin(0.9 * y * x);
  }
  return v;
}

using pdtest::same_bits;
using pdtest::differing;


}  // namespace

TEST(DecomposedVerlet, EveryStepEqualsTheSerialStepBitwise) {
  pd::Model global = torn_lattice();
  const pd::Model initial = global;  // before any bond of the run breaks
  const pd::Vec3Array v0 = opening(global);

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

  // The stable step: a min over the ranks, the serial value exactly.
  const double dt_stable = op.stable_time_step();
  EXPECT_TRUE(same_bits(dt_stable, serial_op.stable_time_step()));
  double t = 0.0, dt = 0.8 * dt_stable, ts = 0.0, dts = dt;
  serial_verlet.initialize(serial, ts);
  verlet.initialize(local, t);

  std::int64_t broken = 0, bad_steps = 0;
  for (int step = 1; step <= 60; ++step) {
    serial_verlet.step(serial, ts, dts);
    verlet.step(local, t, dt);
    const pd::StepReport& r = verlet.last_step();
    const pd::StepReport& rs = serial_verlet.last_step();
    broken += rs.broken_now;
    const double values[] = {op.kinetic_energy(local), op.strain_energy(local), local.external_work,
                             local.damping_work, r.broken_energy_now, t};
    const double serial_values[] = {serial_op.kinetic_energy(serial), serial_op.strain_energy(serial),
                                    serial.external_work, serial.damping_work, rs.broken_energy_now, ts};
    bool same = r.broken_now == rs.broken_now;
    for (int k = 0; k < 6; ++k) same = same && same_bits(values[k], serial_values[k]);
    const pd::Vec3Array u = dec.gather(local.u), v = dec.gather(local.v);
    if (dec.rank() == 0) same = same && differing(u, serial.u) == 0 && differing(v, serial.v) == 0;
    if (!same) {
      ++bad_steps;
      ADD_FAILURE() << "step " << step << ": kinetic " << values[0] << " vs " << serial_values[0] << ", strain "
                    << values[1] << " vs " << serial_values[1] << ", external work " << values[2] << " vs "
                    << serial_values[2] << ", damping work " << values[3] << " vs " << serial_values[3]
                    << ", broken " << r.broken_now << " vs " << rs.broken_now;
    }
    if (bad_steps > 3) break;
  }
  // The run did what it is meant to test: bonds broke, and work was done at the supports.
  EXPECT_GT(broken, 10);
  EXPECT_NE(serial.external_work, 0.0);
  EXPECT_GT(serial.damping_work, 0.0);
}
