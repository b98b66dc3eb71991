// pd_mpi_halo: the speed of a decomposed run and what it exchanges (issue 15), on the `make bench`
// brick (side³ simple cubic lattice, dx = 1 mm, δ = 3.0002·dx, PMB; the top three layers move down
// at 0.1 m/s, as in pd_speed, so the loop measures the steady state with breaking tested every
// step). Run under mpiexec -np R with T threads per rank; one rank takes the serial path, as pdsolve
// does. Times `--steps` velocity-Verlet steps (after one untimed step), each followed by the kinetic
// and strain energy as pdsolve's loop computes them for its blow-up watch, and prints, from rank 0, one
// CSV row per rank: the loop's wall time (the slowest rank's) and directed bond updates per second
// of the whole brick; the rank's owned nodes, ghosts and ghosts per owned node; per step the halo
// messages and bytes it sent, the reductions (MPI_Allreduce: the breaking pass's count with its lost
// energy, the two energies) and their bytes, the wall time in communication (halo exchanges and
// every Allreduce, the waits for the slower rank included); its peak resident memory; and, of the
// communication time, the halo exchanges' (packing, MPI calls, waits, unpacking) and of that their
// waits (their second halves: what the sweep of the interior rows did not hide, parallel/row_split.hpp).
//
// --law lps: the LPS law (ν = 0.25; each rank cuts its piece from the whole model, as pdsolve does
// for LPS, whose m_i need whole rows); --alpha A: LAMMPS's breaking order and α rule (per-node s0,
// whose ghosts travel with u); --blocking: every owned row a boundary row, so that every sweep
// waits for its exchange first (the exchange without the overlap, in the same binary: a before/after);
// --kernel portable: PMB and LPS rows by the portable code even where the CPU has AVX2 (the same bits).
//
//   mpiexec -np R pd_mpi_halo --side N [--steps S] [--threads T] [--law pmb|lps] [--alpha A] [--blocking]
//   [--kernel auto|portable]
#include <mpi.h>
#include <omp.h>
#include <sys/resource.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <string>
#include <vector>

#include "core/avx2.hpp"
#include "core/model.hpp"
#include "core/stability.hpp"
#include "integrators/integrator.hpp"
#include "lattice.hpp"
#include "operator/force_operator.hpp"
#include "parallel/local_model.hpp"
#include "parallel/mpi_decomposed.hpp"

int main(int argc, char** argv) {
  int provided = 0;
  MPI_Init_thread(&argc, &argv, MPI_THREAD_FUNNELED, &provided);
  int side = 40, steps = 20, threads = 0, ranks = 1;
  std::string law = "pmb";
  double alpha = 0.0;
  bool blocking = false;
  MPI_Comm_size(MPI_COMM_WORLD, &ranks);
  for (int k = 1; k < argc; ++k) {
    const std::string a = argv[k];
    if (a == "--blocking") {
      blocking = true;
      continue;
    }
    if (k + 1 >= argc) break;
    if (a == "--side") side = std::atoi(argv[k + 1]);
    else if (a == "--steps") steps = std::atoi(argv[k + 1]);
    else if (a == "--threads") threads = std::atoi(argv[k + 1]);
    else if (a == "--law") law = argv[k + 1];
    else if (a == "--alpha") alpha = std::atof(argv[k + 1]);
    else if (a == "--kernel") {
      const std::string kernel = argv[k + 1];
      if (kernel != "auto" && kernel != "portable") {
        std::fprintf(stderr, "pd_mpi_halo: --kernel takes auto or portable, not %s\n", kernel.c_str());
        MPI_Finalize();
        return 2;
      }
      pd::set_avx2_rows(kernel == "auto");
    }
    ++k;
  }
  if (threads > 0) omp_set_num_threads(threads);
  threads = omp_get_max_threads();
  const double dx = 1e-3;
  pd::Case c = pdtest::lattice_case(3, "3d", dx, 3.0002 * dx, 72e9, 2440.0, 4.0);
  if (law == "lps") {
    c.blocks[0].model = "lps";
    c.blocks[0].parameters["poisson_ratio"] = 0.25;
  }
  if (alpha > 0.0) {
    c.breaking_order = "lammps";
    c.blocks[0].parameters["critical_stretch_alpha"] = alpha;
  }
  // One rank: the serial path (no decomposition), as pdsolve takes it. Several: each rank builds
  // only the rows of its own nodes, as pdsolve does for a pmb or lps case (run/prepare
  // whole_bonds_reason), and holds the whole cloud's node data.
  std::unique_ptr<pd::MpiDecomposed> dec;
  pd::Model global;
  double dt0 = 0.0;
  if (ranks > 1) {
    global = pd::build_model_without_bonds(c, pdtest::cubic_lattice(side, side, side, dx, 3));
    global.bonds.offsets = pd::count_bonds(global.nodes.x, pd::bond_search_cutoff(c));
    global.bond_model = pd::material_registry().get(law).make(global);
    dec = std::make_unique<pd::MpiDecomposed>(MPI_COMM_WORLD, global, pd::bond_search_cutoff(c), c.cracks, c.surface_correction);
    dt0 = 0.8 * dec->minimum(pd::stable_time_step(dec->piece().model));
  } else {
    global = pd::build_model(c, pdtest::cubic_lattice(side, side, side, dx, 3));
    dt0 = 0.8 * pd::stable_time_step(global);
  }
  if (dec && blocking) dec->split_rows_for_blocking();
  pd::Model& model = dec ? dec->piece().model : global;
  pd::ForceOperator op(model);
  if (dec) op.set_decomposed(dec.get());
  auto integrator = pd::integrator_registry().get("verlet")(op);

  pd::State whole(global.nodes.size());
  const double top = (side - 3) * dx - 0.5 * dx;
  for (std::size_t i = 0; i < global.nodes.size(); ++i)
    if (global.nodes.x[2][i] > top) whole.v[2][i] = -0.1;
  pd::State s(model.nodes.size());
  s.v = dec ? pd::to_local(dec->piece(), whole.v) : whole.v;
  double t = 0.0;
  integrator->initialize(s, t);
  double dt = dt0;
  integrator->step(s, t, dt);  // untimed: first touches of the arrays
  const pd::Decomposed::Traffic before = dec ? dec->traffic() : pd::Decomposed::Traffic{};

  using Clock = std::chrono::steady_clock;
  MPI_Barrier(MPI_COMM_WORLD);
  const auto t0 = Clock::now();
  double energy = 0.0;
  for (int k = 0; k < steps; ++k) {
    dt = dt0;
    integrator->step(s, t, dt);
    const pd::ForceOperator::KineticAndStrain e = op.kinetic_and_strain_energy(s);  // pdsolve's blow-up watch
    energy += e.kinetic + e.strain;
  }
  const double mine = std::chrono::duration<double>(Clock::now() - t0).count();
  double loop = mine;
  MPI_Allreduce(&mine, &loop, 1, MPI_DOUBLE, MPI_MAX, MPI_COMM_WORLD);
  if (!(energy >= 0.0)) std::fprintf(stderr, "pd_mpi_halo: the energy is %g, not finite and ≥ 0\n", energy);
  const pd::Decomposed::Traffic after = dec ? dec->traffic() : pd::Decomposed::Traffic{};

  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  const double per = 1.0 / steps;
  const double owned = dec ? static_cast<double>(dec->piece().owned_local.size()) : static_cast<double>(global.nodes.size());
  const double ghosts = dec ? static_cast<double>(dec->piece().ghost_local.size()) : 0.0;
  constexpr int kColumns = 11;
  const double row[kColumns] = {owned,
                                ghosts,
                                static_cast<double>(after.halo_messages - before.halo_messages) * per,
                                static_cast<double>(after.halo_bytes - before.halo_bytes) * per,
                                static_cast<double>(after.reductions - before.reductions) * per,
                                static_cast<double>(after.reduction_bytes - before.reduction_bytes) * per,
                                (after.halo_seconds - before.halo_seconds + after.reduction_seconds - before.reduction_seconds) * per,
                                mine,
                                static_cast<double>(usage.ru_maxrss) / 1024.0,
                                (after.halo_seconds - before.halo_seconds) * per,
                                (after.halo_wait_seconds - before.halo_wait_seconds) * per};
  int rank = 0;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  std::vector<double> all(static_cast<std::size_t>(kColumns * ranks));
  MPI_Gather(row, kColumns, MPI_DOUBLE, all.data(), kColumns, MPI_DOUBLE, 0, MPI_COMM_WORLD);
  if (rank == 0) {
    const double directed = static_cast<double>(global.bonds.offsets.back());  // held or only counted
    std::printf("rank,side,nodes,ranks,threads,steps,directed_bonds,loop_s,bond_updates_per_s,owned,ghosts,ghosts_per_owned,"
                "halo_messages_per_step,halo_bytes_per_step,reductions_per_step,reduction_bytes_per_step,"
                "communication_s_per_step,communication_share,peak_rss_mb,halo_s_per_step,halo_wait_s_per_step\n");
    for (int r = 0; r < ranks; ++r) {
      const double* v = &all[static_cast<std::size_t>(kColumns * r)];
      std::printf("%d,%d,%zu,%d,%d,%d,%.0f,%.4f,%.4e,%.0f,%.0f,%.4f,%.1f,%.0f,%.2f,%.0f,%.4e,%.4f,%.1f,%.4e,%.4e\n", r, side,
                  global.nodes.size(), ranks, threads, steps, directed, loop, directed * steps / loop, v[0], v[1], v[1] / v[0],
                  v[2], v[3], v[4], v[5], v[6], v[6] * steps / loop, v[8], v[9], v[10]);
    }
  }
  MPI_Finalize();
  return 0;
}
