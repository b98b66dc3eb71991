// parallel/session.hpp with MPI.
#include <mpi.h>

#include <cstdlib>

#include "parallel/session.hpp"

namespace pd {

namespace {

// Started by an MPI launcher? OpenMPI's mpirun sets OMPI_COMM_WORLD_SIZE, a PMIx launcher (OpenMPI 4+,
// Slurm's srun --mpi=pmix) PMIX_RANK, MPICH's Hydra and Slurm's PMI-2 PMI_SIZE.
bool launched_by_mpi() {
  return std::getenv("OMPI_COMM_WORLD_SIZE") || std::getenv("PMIX_RANK") || std::getenv("PMI_SIZE");
}

}  // namespace

void start_ranks(int* argc, char*** argv) {
  // Without a launcher the run is one rank and needs no MPI at all: OpenMPI's "singleton" start
  // would fork a daemon and cost ~0.8 s per pdsolve (measured: pdsolve --version 0.76 s with it),
  // which the test suite pays hundreds of times. MPI stays uninitialised and world_ranks() says 1.
  if (!launched_by_mpi()) return;
  int provided = 0;
  MPI_Init_thread(argc, argv, MPI_THREAD_FUNNELED, &provided);
}

void stop_ranks() {
  int initialized = 0, finalized = 0;
  MPI_Initialized(&initialized);
  MPI_Finalized(&finalized);
  if (initialized && !finalized) MPI_Finalize();
}

RankInfo world_ranks() {
  int initialized = 0;
  MPI_Initialized(&initialized);
  RankInfo r;
  if (initialized) {
    MPI_Comm_rank(MPI_COMM_WORLD, &r.rank);
    MPI_Comm_size(MPI_COMM_WORLD, &r.size);
  }
  return r;
}

void abort_ranks(int code) {
  int initialized = 0;
  MPI_Initialized(&initialized);
  if (initialized && world_ranks().size > 1) MPI_Abort(MPI_COMM_WORLD, code);
  std::exit(code);
}

bool built_with_mpi() { return true; }

}  // namespace pd
