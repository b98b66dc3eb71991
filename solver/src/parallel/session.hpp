// The ranks of this process's run (issue 15). Built with PD_MPI: MPI's world (MPI_Init_thread with
// MPI_THREAD_FUNNELED — OpenMP threads inside a rank, MPI called by the main thread only). Built
// without: one rank. A binary built with MPI and started without mpirun is one rank too.
#pragma once

namespace pd {

struct RankInfo {
  int rank = 0;
  int size = 1;
};

// Once, first thing in main; stop_ranks() before returning (both no-ops without MPI).
void start_ranks(int* argc, char*** argv);
void stop_ranks();
RankInfo world_ranks();
// Ends every rank of the run with `code` (MPI_Abort): what a rank does on an error the others cannot
// know of, so that they do not wait for it for ever. Without MPI: std::exit(code).
[[noreturn]] void abort_ranks(int code);
bool built_with_mpi();

}  // namespace pd
