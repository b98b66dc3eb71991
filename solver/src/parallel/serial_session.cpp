// parallel/session.hpp for a build without MPI: one rank.
#include <cstdio>
#include <cstdlib>

#include "parallel/decomposed.hpp"
#include "parallel/session.hpp"

namespace pd {

void start_ranks(int*, char***) {
  // Started by mpirun on several ranks, each copy would run the whole case alone and all would
  // write the same files: refuse instead. (OpenMPI's and MPICH's launchers say the rank count so.)
  for (const char* name : {"OMPI_COMM_WORLD_SIZE", "PMI_SIZE"}) {
    const char* value = std::getenv(name);
    if (value && std::atoi(value) > 1) {
      if (const char* rank = std::getenv("OMPI_COMM_WORLD_RANK"); !rank || std::atoi(rank) == 0)
        std::fprintf(stderr,
                     "pdsolve: error: started on %s MPI ranks, but this pdsolve was built without MPI (PD_MPI off): "
                     "install libopenmpi-dev and rebuild (make solver), or run it without mpirun\n",
                     value);
      std::exit(1);
    }
  }
}
void stop_ranks() {}
RankInfo world_ranks() { return RankInfo{}; }
void abort_ranks(int code) { std::exit(code); }
bool built_with_mpi() { return false; }
std::unique_ptr<Decomposed> decompose_over_ranks(const Model&) { return nullptr; }
std::unique_ptr<Decomposed> decompose_rows_over_ranks(const Model&, double, const std::vector<CrackSegment>&, const std::string&) {
  return nullptr;
}

}  // namespace pd
