// parallel/session.hpp for a build without MPI: one rank.
#include <cstdlib>

#include "parallel/decomposed.hpp"
#include "parallel/session.hpp"

namespace pd {

void start_ranks(int*, char***) {}
void stop_ranks() {}
RankInfo world_ranks() { return RankInfo{}; }
void abort_ranks(int code) { std::exit(code); }
bool built_with_mpi() { return false; }
std::unique_ptr<Decomposed> decompose_over_ranks(const Model&) { return nullptr; }

}  // namespace pd
