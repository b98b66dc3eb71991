// pd_mpi_halo: what a decomposed run exchanges (issue 15), measured on the `make bench` brick (side³
// simple cubic lattice, δ = 3.0002·dx, PMB). Run under mpiexec -np R; rank 0 prints one CSV row per
// rank: owned nodes, ghosts, ghosts per owned node, halo messages and bytes it sends per force
// evaluation, the bytes it sends per ordered sum (8 per owned node, to rank 0), and the wall time
// of a halo exchange and of a decomposed force evaluation (mean over --steps).
//
//   mpiexec -np R pd_mpi_halo --side N [--steps S]
#include <mpi.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "core/model.hpp"
#include "lattice.hpp"
#include "operator/force_operator.hpp"
#include "parallel/mpi_decomposed.hpp"

int main(int argc, char** argv) {
  int provided = 0;
  MPI_Init_thread(&argc, &argv, MPI_THREAD_FUNNELED, &provided);
  int side = 40, steps = 20;
  for (int k = 1; k + 1 < argc; k += 2) {
    const std::string a = argv[k];
    if (a == "--side") side = std::atoi(argv[k + 1]);
    else if (a == "--steps") steps = std::atoi(argv[k + 1]);
  }
  const double dx = 1e-3;
  const pd::Case c = pdtest::lattice_case(3, "3d", dx, 3.0002 * dx, 72e9, 2440.0, 4.0);
  const pd::Model global = pd::build_model(c, pdtest::cubic_lattice(side, side, side, dx, 3));
  pd::MpiDecomposed dec(MPI_COMM_WORLD, global);
  pd::ForceOperator op(dec.piece().model);
  op.set_decomposed(&dec);
  pd::State s(dec.piece().size());
  for (std::size_t l = 0; l < s.size(); ++l) s.u[0][l] = 1e-6 * static_cast<double>(dec.piece().global[l] % 7);

  using Clock = std::chrono::steady_clock;
  MPI_Barrier(MPI_COMM_WORLD);
  auto t0 = Clock::now();
  for (int k = 0; k < steps; ++k) dec.update_ghosts(s.u);
  const double exchange_s = std::chrono::duration<double>(Clock::now() - t0).count() / steps;
  MPI_Barrier(MPI_COMM_WORLD);
  t0 = Clock::now();
  for (int k = 0; k < steps; ++k) op.evaluate(s, 0.0);
  const double evaluate_s = std::chrono::duration<double>(Clock::now() - t0).count() / steps;
  MPI_Barrier(MPI_COMM_WORLD);
  t0 = Clock::now();
  for (int k = 0; k < steps; ++k) (void)op.strain_energy(s);
  const double sum_s = std::chrono::duration<double>(Clock::now() - t0).count() / steps;

  const pd::LocalPiece& p = dec.piece();
  const double row[] = {static_cast<double>(p.owned_local.size()), static_cast<double>(p.ghost_local.size()),
                        static_cast<double>(p.ghost_local.size()) / static_cast<double>(p.owned_local.size()),
                        static_cast<double>(dec.halo().messages_sent()), static_cast<double>(dec.halo().bytes_sent()),
                        8.0 * static_cast<double>(p.owned_local.size()), exchange_s, evaluate_s, sum_s};
  constexpr int kColumns = 9;
  std::vector<double> all(static_cast<std::size_t>(kColumns * dec.ranks()));
  MPI_Gather(row, kColumns, MPI_DOUBLE, all.data(), kColumns, MPI_DOUBLE, 0, MPI_COMM_WORLD);
  if (dec.rank() == 0) {
    std::printf("rank,nodes,owned,ghosts,ghosts_per_owned,halo_messages_sent,halo_bytes_sent,ordered_sum_bytes_sent,"
                "halo_exchange_s,force_evaluation_s,ordered_sum_s\n");
    for (int r = 0; r < dec.ranks(); ++r) {
      const double* v = &all[static_cast<std::size_t>(kColumns * r)];
      std::printf("%d,%zu,%.0f,%.0f,%.4f,%.0f,%.0f,%.0f,%.3e,%.3e,%.3e\n", r, global.nodes.size(), v[0], v[1], v[2], v[3],
                  v[4], v[5], v[6], v[7], v[8]);
    }
  }
  MPI_Finalize();
  return 0;
}
