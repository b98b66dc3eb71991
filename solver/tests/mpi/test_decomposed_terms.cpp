// The force terms and the LPS law decomposed over the ranks of this run (issue 15): body forces,
// indenters (their force on the body, a sum over the nodes inside, and the depth watch's step
// limit) and LPS's two sweeps with breaking. Velocity Verlet runs the same scene serially on the
// whole model (every rank alone) and decomposed — and the adaptive integrator on the same footing;
// after every step the gathered u and v, the
// energies, the external and damping work, the contact energy and the indenter forces equal the
// serial run's bit for bit, for 1, 2 and 3 ranks (ctest mpi_ranks_R) and 1 and 2 threads per rank.
#include <gtest/gtest.h>
#include <mpi.h>
#include <omp.h>

#include <cmath>
#include <cstring>
#include <functional>
#include <memory>
#include <string>

#include "bits.hpp"
#include "core/model.hpp"
#include "forces/indenter.hpp"
#include "integrators/adaptive.hpp"
#include "integrators/verlet.hpp"
#include "lattice.hpp"
#include "operator/force_operator.hpp"
#include "parallel/mpi_decomposed.hpp"

namespace {

constexpr double kDx = 1e-3;

using pdtest::same_bits;
using pdtest::differing;


pd::NodeSet set_where(const pd::Nodes& nodes, const std::string& name, const std::function<bool(std::size_t)>& in) {
  pd::NodeSet s{name, std::vector<std::uint8_t>(nodes.size(), 0)};
  for (std::size_t i = 0; i < nodes.size(); ++i) s.member[i] = in(i) ? 1 : 0;
  return s;
}

// A smooth velocity field with no symmetry, so that every sum has rounding to get wrong.
pd::Vec3Array wavy_velocity(const pd::Model& m, double amplitude) {
  pd::Vec3Array v = pd::make_vec3(m.nodes.size());
  for (std::size_t i = 0; i < m.nodes.size(); ++i) {
    const double x = m.nodes.x[0][i] / kDx, y = m.nodes.x[1][i] / kDx, z = m.nodes.x[2][i] / kDx;
    v[0][i] = amplitude * std::sin(0.7 * y + 0.2 * z * x);
    v[1][i] = amplitude * 0.6 * std::cos(0.5 * x - 0.3 * z);
    v[2][i] = amplitude * 0.3 * std::sin(0.9 * y * x + 0.1);
  }
  return v;
}

// What a step is compared by: every value every rank has, and the gathered fields on rank 0.
struct Outcome {
  std::int64_t steps_compared = 0;
  std::int64_t broken = 0;               // serial bonds broken over the run
  double external_work = 0.0;            // serial, at the end
  double contact_energy = 0.0;           // serial, at the end
  double indenter_energy = 0.0;          // serial, at the end
  std::vector<std::array<double, 3>> indenter_force;  // serial, at the end
  std::int64_t limit_nodes_seen = 0;     // steps at which the indenter step limit had a node
  std::int64_t iterations = 0, rejected = 0;  // serial, summed over the steps
};

using MakeIntegrator = std::function<std::unique_ptr<pd::Integrator>(pd::ForceOperator&)>;

std::unique_ptr<pd::Integrator> make_verlet(pd::ForceOperator& op) { return std::make_unique<pd::VelocityVerlet>(op); }

// `steps` steps of `global` from v0, serially (on this rank alone) and decomposed over the ranks of
// MPI_COMM_WORLD, compared bitwise after every step. An integrator that controls its step takes
// the next step it proposes (last_step().next_dt), as the time loop does.
Outcome run_both(const pd::Model& global_in, const pd::Vec3Array& v0, int steps, double dt_factor,
                 const MakeIntegrator& make = make_verlet, const pd::Case* configure = nullptr) {
  pd::Model global = global_in;
  const pd::Model initial = global_in;
  pd::ForceOperator serial_op(global);
  const std::unique_ptr<pd::Integrator> serial_integrator = make(serial_op);
  pd::Integrator& serial_verlet = *serial_integrator;
  pd::State serial(global.nodes.size());
  serial.v = v0;

  pd::MpiDecomposed dec(MPI_COMM_WORLD, initial);
  pd::ForceOperator op(dec.piece().model);
  op.set_decomposed(&dec);
  const std::unique_ptr<pd::Integrator> integrator = make(op);
  pd::Integrator& verlet = *integrator;
  pd::State local(dec.piece().size());
  local.v = pd::to_local(dec.piece(), v0);
  if (configure) {
    serial_verlet.configure(*configure);
    verlet.configure(*configure);
  }

  const double dt_stable = op.stable_time_step();
  EXPECT_TRUE(same_bits(dt_stable, serial_op.stable_time_step()));
  double t = 0.0, dt = dt_factor * dt_stable, ts = 0.0, dts = dt;
  serial_verlet.initialize(serial, ts);
  verlet.initialize(local, t);

  Outcome out;
  std::int64_t bad_steps = 0;
  for (int step = 1; step <= steps; ++step) {
    serial_verlet.step(serial, ts, dts);
    verlet.step(local, t, dt);
    const pd::StepReport& r = verlet.last_step();
    const pd::StepReport& rs = serial_verlet.last_step();
    out.broken += rs.broken_now;
    std::vector<double> values = {op.kinetic_energy(local), op.strain_energy(local), local.external_work,
                                  local.damping_work,       r.broken_energy_now,    pd::term_energy(local, "contact"), pd::term_energy(local, "indenters"), t, dt};
    std::vector<double> serial_values = {serial_op.kinetic_energy(serial), serial_op.strain_energy(serial),
                                         serial.external_work,             serial.damping_work,
                                         rs.broken_energy_now,             pd::term_energy(serial, "contact"), pd::term_energy(serial, "indenters"), ts, dts};
    bool same = r.broken_now == rs.broken_now && r.iterations == rs.iterations && r.rejected == rs.rejected &&
                local.indenter_force.size() == serial.indenter_force.size();
    out.iterations += rs.iterations;
    out.rejected += rs.rejected;
    if (rs.next_dt > 0.0) dts = rs.next_dt;
    if (r.next_dt > 0.0) dt = r.next_dt;
    for (std::size_t k = 0; same && k < serial.indenter_force.size(); ++k)
      for (std::size_t d = 0; d < 3; ++d) {
        values.push_back(local.indenter_force[k][d]);
        serial_values.push_back(serial.indenter_force[k][d]);
      }
    // The depth watch's step limit (run/loop.cpp), decomposed and serial.
    if (!global.indenters.empty()) {
      const pd::IndenterStepLimit a = pd::indenter_step_limit(dec.piece().model, t, local.u, 0.0, &dec);
      const pd::IndenterStepLimit b = pd::indenter_step_limit(global, ts, serial.u, 0.0);
      same = same && a.node == b.node && a.indenter == b.indenter;
      values.insert(values.end(), {a.dt, a.depth});
      serial_values.insert(serial_values.end(), {b.dt, b.depth});
      out.limit_nodes_seen += b.node >= 0;
    }
    for (std::size_t k = 0; k < values.size() && k < serial_values.size(); ++k)
      same = same && same_bits(values[k], serial_values[k]);
    same = same && values.size() == serial_values.size();
    const pd::Vec3Array u = dec.gather(local.u), v = dec.gather(local.v);
    if (dec.rank() == 0) same = same && differing(u, serial.u) == 0 && differing(v, serial.v) == 0;
    // Every rank decides alike (rank 0 alone saw the fields).
    int all_same = same ? 1 : 0, everywhere = 0;
    MPI_Allreduce(&all_same, &everywhere, 1, MPI_INT, MPI_MIN, MPI_COMM_WORLD);
    if (!everywhere) {
      ++bad_steps;
      ADD_FAILURE() << "step " << step << ": kinetic " << values[0] << " vs " << serial_values[0] << ", strain "
                    << values[1] << " vs " << serial_values[1] << ", external work " << values[2] << " vs "
                    << serial_values[2] << ", contact energy " << values[5] << " vs " << serial_values[5]
                    << ", broken " << r.broken_now << " vs " << rs.broken_now;
    } else {
      ++out.steps_compared;
    }
    if (bad_steps > 3) break;
  }
  out.external_work = serial.external_work;
  out.contact_energy = pd::term_energy(serial, "contact");
  out.indenter_energy = pd::term_energy(serial, "indenters");
  out.indenter_force = serial.indenter_force;
  return out;
}

class DecomposedTerms : public ::testing::TestWithParam<int> {};  // threads per rank

// Steps to run: all of them with one thread per rank; a fifth with two, enough to cross the ranks'
// threaded sweeps many times — 3 ranks × 2 threads on a 2-core machine wait on each other at every
// parallel region, and the full count took 80 s per test there.
int steps_for_threads(int steps, int threads) { return threads == 1 ? steps : steps / 5; }

// Gravity-like body forces on two overlapping sets, one in y and one in x with a ramp in time,
// a clamped face and damping: the external work is the body forces' (and the support's) power.
TEST_P(DecomposedTerms, BodyForcesGiveTheSerialRunBitwise) {
  omp_set_num_threads(GetParam());
  const int nx = 14, ny = 10, nz = 8;
  pd::Case c = pdtest::lattice_case(3, "3d", kDx, 3.015 * kDx, 70e9, 2700.0, -1.0);
  c.damping = 1e4;
  pd::Nodes nodes = pdtest::cubic_lattice(nx, ny, nz, kDx, 3);
  nodes.sets = {set_where(nodes, "all", [](std::size_t) { return true; }),
                set_where(nodes, "upper", [&](std::size_t i) { return nodes.x[1][i] > 4.5 * kDx; }),
                set_where(nodes, "left", [&](std::size_t i) { return nodes.x[0][i] < 1.5 * kDx; })};
  c.boundary_conditions.push_back({"left", "displacement", 0, {0.0}, {0.0}});
  c.boundary_conditions.push_back({"all", "body_force", 1, {0.0}, {-2.7e5}});
  c.boundary_conditions.push_back({"upper", "body_force", 0, {0.0, 1e-6}, {0.0, 3.1e7}});
  const pd::Model m = pd::build_model(c, nodes);
  ASSERT_EQ(m.conditions.body_forces.size(), 2u);
  const int steps = steps_for_threads(50, GetParam());
  const Outcome o = run_both(m, wavy_velocity(m, 0.5), steps, 0.8);
  EXPECT_EQ(o.steps_compared, steps);
  EXPECT_NE(o.external_work, 0.0);  // the body forces worked
}

// A plane indenter pushing a 2D plate from its left edge (every row has nodes inside, so the nodes
// inside span both of the force's 4096-node chunks) and a disk pressing its top: their
// forces on the body, the contact energy and the watch's step limit, step by step.
TEST_P(DecomposedTerms, IndentersAndTheirReactionsGiveTheSerialRunBitwise) {
  omp_set_num_threads(GetParam());
  const int n = 70;  // 4900 nodes: two chunks of the indenter sum
  pd::Case c = pdtest::lattice_case(2, "plane_stress", kDx, 3.015 * kDx, 1e9, 1000.0, 50.0, 1e-3);
  pd::IndenterSettings plane;
  plane.name = "wall";
  plane.shape = "plane";
  plane.normal = {1.0, 0.0, 0.0};  // out of the indenter, into the plate
  plane.centre = {0.3 * kDx, 0.0, 0.0};
  plane.velocity = {20.0, 0.0, 0.0};
  plane.stiffness = 1e15;
  pd::IndenterSettings disk;
  disk.name = "punch";
  disk.shape = "cylinder";
  disk.radius = 6 * kDx;
  disk.axis = {0.0, 0.0, 1.0};
  disk.centre = {40.3 * kDx, (n - 1) * kDx + 5.6 * kDx, 0.0};
  disk.velocity = {0.0, -15.0, 0.0};
  disk.stiffness = 2e15;
  c.indenters = {plane, disk};
  const pd::Model m = pd::build_model(c, pdtest::cubic_lattice(n, n, 1, kDx, 2, 1e-3));
  ASSERT_GT(m.nodes.size(), 4096u);
  const int steps = steps_for_threads(40, GetParam());
  const Outcome o = run_both(m, wavy_velocity(m, 0.2), steps, 0.7);
  EXPECT_EQ(o.steps_compared, steps);
  ASSERT_EQ(o.indenter_force.size(), 2u);
  EXPECT_GT(o.indenter_force[0][0], 0.0);  // the wall pushes +x
  EXPECT_LT(o.indenter_force[1][1], 0.0);  // the punch pushes −y
  EXPECT_GT(o.indenter_energy, 0.0);  // the indenters' potential has its own column (issue 16)
  EXPECT_EQ(o.contact_energy, 0.0);    // no contact pairs in this scene
  EXPECT_EQ(o.limit_nodes_seen, steps);
}

// LPS with breaking on a notched 3D lattice torn open by its initial velocities: the ghosts' P
// comes from their owners between the sweeps; m_i, a_i of the ghosts from the whole model.
TEST_P(DecomposedTerms, LpsWithBreakingGivesTheSerialRunBitwise) {
  omp_set_num_threads(GetParam());
  const int nx = 14, ny = 10, nz = 8;
  pd::Case c = pdtest::lattice_case(3, "3d", kDx, 3.015 * kDx, 70e9, 2700.0, 30.0);
  c.blocks[0].model = "lps";
  c.blocks[0].parameters["poisson_ratio"] = 0.22;
  c.blocks[0].choices["influence"] = "inverse_length";
  c.damping = 2e4;
  pd::Nodes nodes = pdtest::cubic_lattice(nx, ny, nz, kDx, 3);
  nodes.sets = {set_where(nodes, "left", [&](std::size_t i) { return nodes.x[0][i] < 1.5 * kDx; }),
                set_where(nodes, "right", [&](std::size_t i) { return nodes.x[0][i] > (nx - 2.5) * kDx; })};
  c.boundary_conditions.push_back({"left", "displacement", 0, {0.0}, {0.0}});
  c.boundary_conditions.push_back({"right", "velocity", 0, {0.0, 2e-6}, {0.0, 5.0}});
  pd::Model m = pd::build_model(c, nodes);
  ASSERT_EQ(m.bond_model->name(), "lps");
  // A notch: bonds across x = 6.5 dx with y < 4 dx start broken (families not whole: m'_i < m_i).
  for (std::size_t i = 0; i < m.nodes.size(); ++i)
    for (std::int64_t k = m.bonds.offsets[i]; k < m.bonds.offsets[i + 1]; ++k) {
      const auto j = static_cast<std::size_t>(m.bonds.neighbour[static_cast<std::size_t>(k)]);
      if ((m.nodes.x[0][i] - 6.5 * kDx) * (m.nodes.x[0][j] - 6.5 * kDx) < 0 && m.nodes.x[1][i] < 4 * kDx &&
          m.nodes.x[1][j] < 4 * kDx)
        m.bonds.broken[static_cast<std::size_t>(k)] = 1;
    }
  pd::Vec3Array v0 = wavy_velocity(m, 0.3);
  for (std::size_t i = 0; i < m.nodes.size(); ++i) v0[0][i] += m.nodes.x[0][i] > 6.5 * kDx ? 2.0 : -2.0;
  const int steps = steps_for_threads(50, GetParam());
  const Outcome o = run_both(m, v0, steps, 0.8);
  EXPECT_EQ(o.steps_compared, steps);
  EXPECT_GT(o.broken, 10);  // bonds broke, across ranks too on 2 and 3 of them
}

// The adaptive integrator (thesis §2.2) on a PMB lattice torn open and pulled: its eq. 2.6 norms are
// exact sums over the ranks, so every rank iterates, accepts and rejects as the serial run does.
TEST_P(DecomposedTerms, AdaptiveStepsGiveTheSerialRunBitwise) {
  omp_set_num_threads(GetParam());
  const int nx = 14, ny = 10, nz = 8;
  pd::Case c = pdtest::lattice_case(3, "3d", kDx, 3.015 * kDx, 70e9, 2700.0, 50.0);
  c.damping = 1e4;
  c.adaptive.dt_max = 2e-7;  // the default needs the exact limit of the whole model (run/prepare.cpp)
  c.adaptive.tol = 1e-4;
  pd::Nodes nodes = pdtest::cubic_lattice(nx, ny, nz, kDx, 3);
  nodes.sets = {set_where(nodes, "left", [&](std::size_t i) { return nodes.x[0][i] < 1.5 * kDx; }),
                set_where(nodes, "right", [&](std::size_t i) { return nodes.x[0][i] > (nx - 2.5) * kDx; })};
  c.boundary_conditions.push_back({"left", "displacement", 0, {0.0}, {0.0}});
  c.boundary_conditions.push_back({"right", "velocity", 0, {0.0, 2e-6}, {0.0, 8.0}});
  const pd::Model m = pd::build_model(c, nodes);
  pd::Vec3Array v0 = wavy_velocity(m, 0.3);
  for (std::size_t i = 0; i < m.nodes.size(); ++i) v0[0][i] += m.nodes.x[0][i] > 6.5 * kDx ? 3.0 : -3.0;
  const auto adaptive = [](pd::ForceOperator& op) -> std::unique_ptr<pd::Integrator> {
    return std::make_unique<pd::AdaptiveStep>(op);
  };
  const int steps = steps_for_threads(30, GetParam());
  const Outcome o = run_both(m, v0, steps, 1.5, adaptive, &c);
  EXPECT_EQ(o.steps_compared, steps);
  EXPECT_GT(o.iterations, steps);  // the fixed-point iteration ran (more than one iterate per step)
  EXPECT_GT(o.broken, 0);       // and bonds broke on accepted states
}

INSTANTIATE_TEST_SUITE_P(Threads, DecomposedTerms, ::testing::Values(1, 2));

}  // namespace
