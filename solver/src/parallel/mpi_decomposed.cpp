// A decomposed run on MPI's ranks (parallel/mpi_decomposed.hpp).
#include "parallel/mpi_decomposed.hpp"

namespace pd {

namespace {

int size_of(MPI_Comm comm) {
  int ranks = 1;
  MPI_Comm_size(comm, &ranks);
  return ranks;
}

}  // namespace

MpiDecomposed::MpiDecomposed(MPI_Comm comm, const Model& global)
    : comm_(comm), decomposition_(decompose(global.nodes.x, global.bonds, size_of(comm), global.horizon)) {
  MPI_Comm_rank(comm, &rank_);
  piece_ = make_local_piece(global, decomposition_.owner, rank_);
  halo_ = std::make_unique<HaloExchange>(comm, piece_, decomposition_.owner);
  sum_ = std::make_unique<OrderedSum>(comm, piece_);
}

std::int64_t MpiDecomposed::total(std::int64_t local) const {
  std::int64_t sum = 0;
  MPI_Allreduce(&local, &sum, 1, MPI_INT64_T, MPI_SUM, comm_);
  return sum;
}

double MpiDecomposed::minimum(double local) const {
  double least = local;
  MPI_Allreduce(&local, &least, 1, MPI_DOUBLE, MPI_MIN, comm_);
  return least;
}

std::unique_ptr<Decomposed> decompose_over_ranks(const Model& global) {
  int initialized = 0, ranks = 1;
  MPI_Initialized(&initialized);
  if (initialized) MPI_Comm_size(MPI_COMM_WORLD, &ranks);
  if (ranks == 1) return nullptr;
  return std::make_unique<MpiDecomposed>(MPI_COMM_WORLD, global);
}

}  // namespace pd
