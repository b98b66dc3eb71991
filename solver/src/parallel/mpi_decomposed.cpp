// A decomposed run on MPI's ranks (parallel/mpi_decomposed.hpp).
#include "parallel/mpi_decomposed.hpp"

#include <algorithm>

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

void MpiDecomposed::gather_entries(const std::vector<std::int32_t>& global_node, const std::vector<double>& values,
                                   int width, std::vector<std::int32_t>& all_nodes, std::vector<double>& all_values) const {
  const int ranks = this->ranks();
  const int mine = static_cast<int>(global_node.size());
  std::vector<int> counts(static_cast<std::size_t>(ranks), 0), starts(static_cast<std::size_t>(ranks) + 1, 0);
  MPI_Gather(&mine, 1, MPI_INT, counts.data(), 1, MPI_INT, 0, comm_);
  for (int r = 0; r < ranks; ++r) starts[static_cast<std::size_t>(r) + 1] = starts[static_cast<std::size_t>(r)] + counts[static_cast<std::size_t>(r)];
  std::vector<std::int32_t> nodes(rank_ == 0 ? static_cast<std::size_t>(starts.back()) : 0);
  MPI_Gatherv(global_node.data(), mine, MPI_INT32_T, nodes.data(), counts.data(), starts.data(), MPI_INT32_T, 0, comm_);
  std::vector<int> value_counts(counts.size()), value_starts(starts.size());
  for (std::size_t r = 0; r < counts.size(); ++r) value_counts[r] = width * counts[r];
  for (std::size_t r = 0; r < starts.size(); ++r) value_starts[r] = width * starts[r];
  std::vector<double> gathered(rank_ == 0 ? static_cast<std::size_t>(value_starts.back()) : 0);
  MPI_Gatherv(values.data(), width * mine, MPI_DOUBLE, gathered.data(), value_counts.data(), value_starts.data(),
              MPI_DOUBLE, 0, comm_);
  all_nodes.clear();
  all_values.clear();
  if (rank_ != 0) return;
  // Each rank's entries ascend; sorting the entry numbers by node merges them (nodes are distinct).
  std::vector<std::size_t> order(nodes.size());
  for (std::size_t e = 0; e < order.size(); ++e) order[e] = e;
  std::sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return nodes[a] < nodes[b]; });
  const auto w = static_cast<std::size_t>(width);
  for (std::size_t e : order) {
    all_nodes.push_back(nodes[e]);
    all_values.insert(all_values.end(), gathered.begin() + static_cast<std::ptrdiff_t>(w * e),
                      gathered.begin() + static_cast<std::ptrdiff_t>(w * (e + 1)));
  }
}

void MpiDecomposed::broadcast(std::vector<double>& values) const {
  MPI_Bcast(values.data(), static_cast<int>(values.size()), MPI_DOUBLE, 0, comm_);
}

std::unique_ptr<Decomposed> decompose_over_ranks(const Model& global) {
  int initialized = 0, ranks = 1;
  MPI_Initialized(&initialized);
  if (initialized) MPI_Comm_size(MPI_COMM_WORLD, &ranks);
  if (ranks == 1) return nullptr;
  return std::make_unique<MpiDecomposed>(MPI_COMM_WORLD, global);
}

}  // namespace pd
