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

Vec3Array MpiDecomposed::gather(const Vec3Array& a) const {
  Vec3Array out;
  for (int d = 0; d < 3; ++d) out[static_cast<std::size_t>(d)] = sum_->gather(a[static_cast<std::size_t>(d)]);
  return out;
}

}  // namespace pd
