// Gathers of per-node values to rank 0 in global node order (parallel/ordered_sum.hpp).
#include "parallel/ordered_sum.hpp"

#include <algorithm>
#include <climits>
#include <string>

#include "core/error.hpp"

namespace pd {

namespace {

// MPI-3's counts and displacements are int: a gather of more than INT_MAX entries to rank 0 would
// overflow them. Called with the same total on every rank, so every rank refuses alike (no hang).
void check_gather_size(std::int64_t total, const char* what) {
  if (total > INT_MAX)
    throw Error(std::to_string(total) + " " + what + " to gather on rank 0 (a checkpoint or a gathered frame): more "
                "than MPI's int counts allow (2^31 - 1); runs this large need output.parallel_frames: pieces and "
                "no checkpoint for now (issue 15)");
}

}  // namespace

OrderedSum::OrderedSum(MPI_Comm comm, const LocalPiece& piece)
    : comm_(comm), global_nodes_(piece.global_nodes), owned_local_(piece.owned_local) {
  int ranks = 1;
  MPI_Comm_rank(comm, &rank_);
  MPI_Comm_size(comm, &ranks);
  ranks_ = ranks;
  const int mine = static_cast<int>(owned_local_.size());
  if (rank_ == 0) counts_.resize(static_cast<std::size_t>(ranks)), starts_.assign(static_cast<std::size_t>(ranks) + 1, 0);
  MPI_Gather(&mine, 1, MPI_INT, counts_.data(), 1, MPI_INT, 0, comm);
  if (rank_ == 0)
    for (int r = 0; r < ranks; ++r) starts_[static_cast<std::size_t>(r) + 1] = starts_[static_cast<std::size_t>(r)] + counts_[static_cast<std::size_t>(r)];
  std::vector<std::int32_t> owned_global(owned_local_.size());
  for (std::size_t k = 0; k < owned_local_.size(); ++k) owned_global[k] = piece.global[static_cast<std::size_t>(owned_local_[k])];
  if (rank_ == 0) gathered_node_.resize(static_cast<std::size_t>(global_nodes_));
  MPI_Gatherv(owned_global.data(), mine, MPI_INT32_T, gathered_node_.data(), counts_.data(), starts_.data(),
              MPI_INT32_T, 0, comm);
  send_.resize(owned_local_.size());
  if (rank_ == 0) received_.resize(static_cast<std::size_t>(global_nodes_));
  // The whole model's directed bonds, the sum of the owned rows' (a ghost's row is empty): every rank
  // knows it without the whole rows' offsets, which only rank 0 keeps (run/prepare.hpp).
  std::int64_t owned_bonds = piece.model.bonds.directed();
  MPI_Allreduce(&owned_bonds, &directed_bonds_, 1, MPI_INT64_T, MPI_SUM, comm);
}

std::vector<double> OrderedSum::gather(const std::vector<double>& per_node) const {
  const double start = MPI_Wtime();
  for (std::size_t k = 0; k < owned_local_.size(); ++k) send_[k] = per_node[static_cast<std::size_t>(owned_local_[k])];
  MPI_Gatherv(send_.data(), static_cast<int>(send_.size()), MPI_DOUBLE, received_.data(), counts_.data(),
              starts_.data(), MPI_DOUBLE, 0, comm_);
  std::vector<double> out;
  if (rank_ == 0) {
    out.resize(received_.size());
    for (std::size_t k = 0; k < received_.size(); ++k) out[static_cast<std::size_t>(gathered_node_[k])] = received_[k];
  }
  ++calls_;
  bytes_ += static_cast<std::int64_t>(8 * send_.size());
  seconds_ += MPI_Wtime() - start;
  return out;
}

std::vector<double> OrderedSum::gather(const std::vector<double>& per_node, int width) const {
  const double start = MPI_Wtime();
  const auto w = static_cast<std::size_t>(width);
  std::vector<double> send(w * owned_local_.size());
  for (std::size_t k = 0; k < owned_local_.size(); ++k)
    for (std::size_t c = 0; c < w; ++c) send[w * k + c] = per_node[w * static_cast<std::size_t>(owned_local_[k]) + c];
  std::vector<int> counts, starts;
  std::vector<double> received;
  if (rank_ == 0) {
    for (int count : counts_) counts.push_back(width * count);
    for (int at : starts_) starts.push_back(width * at);
    received.resize(w * static_cast<std::size_t>(global_nodes_));
  }
  MPI_Gatherv(send.data(), static_cast<int>(send.size()), MPI_DOUBLE, received.data(), counts.data(), starts.data(),
              MPI_DOUBLE, 0, comm_);
  std::vector<double> out;
  if (rank_ == 0) {
    out.resize(received.size());
    for (std::size_t k = 0; k < gathered_node_.size(); ++k)
      for (std::size_t c = 0; c < w; ++c) out[w * static_cast<std::size_t>(gathered_node_[k]) + c] = received[w * k + c];
  }
  ++calls_;
  bytes_ += static_cast<std::int64_t>(8 * send.size());
  seconds_ += MPI_Wtime() - start;
  return out;
}

// The MPI type of a gathered row entry.
template <class T>
MPI_Datatype mpi_type_of();
template <>
MPI_Datatype mpi_type_of<std::uint8_t>() { return MPI_UINT8_T; }
template <>
MPI_Datatype mpi_type_of<double>() { return MPI_DOUBLE; }

template <class T>
void OrderedSum::gather_row_values(const BondList& local, const std::vector<T>& local_values, int width,
                                   const BondList& global, std::vector<T>& global_values, const char* what) const {
  check_gather_size(directed_bonds_ * width, what);  // the same on every rank
  const double start = MPI_Wtime();
  const auto w = static_cast<std::size_t>(width);
  std::vector<T> values;
  for (std::int32_t l : owned_local_)
    values.insert(values.end(), local_values.begin() + static_cast<std::ptrdiff_t>(w * static_cast<std::size_t>(local.offsets[static_cast<std::size_t>(l)])),
                  local_values.begin() + static_cast<std::ptrdiff_t>(w * static_cast<std::size_t>(local.offsets[static_cast<std::size_t>(l) + 1])));
  // Rank 0 knows every rank's owned rows (gathered_node_) and so how many values each sends.
  std::vector<int> counts, starts;
  if (rank_ == 0) {
    counts.assign(static_cast<std::size_t>(ranks_), 0);
    starts.assign(static_cast<std::size_t>(ranks_) + 1, 0);
    for (int r = 0; r < ranks_; ++r) {
      for (int k = starts_[static_cast<std::size_t>(r)]; k < starts_[static_cast<std::size_t>(r) + 1]; ++k) {
        const auto g = static_cast<std::size_t>(gathered_node_[static_cast<std::size_t>(k)]);
        counts[static_cast<std::size_t>(r)] += width * static_cast<int>(global.offsets[g + 1] - global.offsets[g]);
      }
      starts[static_cast<std::size_t>(r) + 1] = starts[static_cast<std::size_t>(r)] + counts[static_cast<std::size_t>(r)];
    }
  }
  std::vector<T> all(rank_ == 0 ? static_cast<std::size_t>(starts.back()) : 0);
  MPI_Gatherv(values.data(), static_cast<int>(values.size()), mpi_type_of<T>(), all.data(), counts.data(), starts.data(),
              mpi_type_of<T>(), 0, comm_);
  ++calls_;
  bytes_ += static_cast<std::int64_t>(values.size() * sizeof(T));
  seconds_ += MPI_Wtime() - start;
  if (rank_ != 0) return;
  global_values.resize(w * static_cast<std::size_t>(global.offsets.back()));
  std::size_t at = 0;
  for (std::int32_t g32 : gathered_node_) {
    const auto g = static_cast<std::size_t>(g32);
    for (std::size_t e = w * static_cast<std::size_t>(global.offsets[g]); e < w * static_cast<std::size_t>(global.offsets[g + 1]); ++e)
      global_values[e] = all[at++];
  }
}

void OrderedSum::gather_rows(const BondList& local, BondList& global) const {
  gather_row_values(local, local.broken, 1, global, global.broken, "directed bonds' broken flags");
}

std::vector<double> OrderedSum::gather_bond_values(const BondList& local, const std::vector<double>& per_bond, int width,
                                                   const BondList& global) const {
  std::vector<double> out;
  gather_row_values(local, per_bond, width, global, out, "values of directed bonds");
  return out;
}

void OrderedSum::gather_lines(const BondList& local, const std::vector<std::int32_t>& global, BondList& lines) const {
  std::vector<std::int32_t> ends;  // the owned rows' broken partners j > i, row after row
  std::vector<double> per_node(local.nodes(), 0.0);
  for (std::int32_t l : owned_local_) {
    const auto i = static_cast<std::size_t>(l);
    for (std::int64_t k = local.offsets[i]; k < local.offsets[i + 1]; ++k) {
      const std::int32_t j = global[static_cast<std::size_t>(local.neighbour[static_cast<std::size_t>(k)])];
      if (local.broken[static_cast<std::size_t>(k)] && j > global[i]) {
        ends.push_back(j);
        per_node[i] += 1.0;
      }
    }
  }
  std::int64_t total = static_cast<std::int64_t>(ends.size());
  MPI_Allreduce(MPI_IN_PLACE, &total, 1, MPI_INT64_T, MPI_SUM, comm_);
  check_gather_size(total, "broken bonds");
  const std::vector<double> count = gather(per_node);  // rank 0: per node, in global order (exact integers)
  const double start = MPI_Wtime();
  const int mine = static_cast<int>(ends.size());
  std::vector<int> counts(rank_ == 0 ? static_cast<std::size_t>(ranks_) : 0), starts(counts.size() + 1, 0);
  MPI_Gather(&mine, 1, MPI_INT, counts.data(), 1, MPI_INT, 0, comm_);
  for (std::size_t r = 0; r < counts.size(); ++r) starts[r + 1] = starts[r] + counts[r];
  std::vector<std::int32_t> all(rank_ == 0 ? static_cast<std::size_t>(starts.back()) : 0);
  MPI_Gatherv(ends.data(), mine, MPI_INT32_T, all.data(), counts.data(), starts.data(), MPI_INT32_T, 0, comm_);
  ++calls_;
  bytes_ += static_cast<std::int64_t>(sizeof(std::int32_t) * ends.size());
  seconds_ += MPI_Wtime() - start;
  lines = BondList{};
  if (rank_ != 0) return;
  const auto n = static_cast<std::size_t>(global_nodes_);
  lines.offsets.assign(n + 1, 0);
  for (std::size_t g = 0; g < n; ++g) lines.offsets[g + 1] = lines.offsets[g] + static_cast<std::int64_t>(count[g]);
  lines.neighbour.resize(all.size());
  lines.broken.assign(all.size(), 1);
  // The entries came rank after rank, each rank's rows in its owned order (gathered_node_).
  std::size_t at = 0;
  for (std::int32_t g32 : gathered_node_) {
    const auto g = static_cast<std::size_t>(g32);
    for (std::int64_t k = lines.offsets[g]; k < lines.offsets[g + 1]; ++k) lines.neighbour[static_cast<std::size_t>(k)] = all[at++];
  }
}

std::vector<std::pair<std::int64_t, double>> OrderedSum::gather_keyed(const std::vector<std::int64_t>& keys,
                                                                      const std::vector<double>& values) const {
  const double start = MPI_Wtime();
  const int mine = static_cast<int>(keys.size());
  std::vector<int> counts(rank_ == 0 ? static_cast<std::size_t>(ranks_) : 0), starts;
  MPI_Gather(&mine, 1, MPI_INT, counts.data(), 1, MPI_INT, 0, comm_);
  std::int64_t total = 0;
  if (rank_ == 0)
    for (int count : counts) starts.push_back(static_cast<int>(total)), total += count;
  std::vector<std::int64_t> all_keys(static_cast<std::size_t>(total));
  std::vector<double> all_values(static_cast<std::size_t>(total));
  MPI_Gatherv(keys.data(), mine, MPI_INT64_T, all_keys.data(), counts.data(), starts.data(), MPI_INT64_T, 0, comm_);
  MPI_Gatherv(values.data(), mine, MPI_DOUBLE, all_values.data(), counts.data(), starts.data(), MPI_DOUBLE, 0, comm_);
  std::vector<std::pair<std::int64_t, double>> out(static_cast<std::size_t>(total));
  for (std::size_t k = 0; k < out.size(); ++k) out[k] = {all_keys[k], all_values[k]};
  std::sort(out.begin(), out.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
  ++calls_;
  bytes_ += static_cast<std::int64_t>(16 * keys.size());
  seconds_ += MPI_Wtime() - start;
  return out;
}

}  // namespace pd
