// Gathers of per-node values of a decomposed run to rank 0, in global node order (issue 15): the
// frames, history's whole-model columns and checkpoints read them there. Each costs
// 8 bytes per owned node (per value) to rank 0. The per-step sums over nodes do not gather: they are
// exact sums over each rank's own nodes, added across ranks with one MPI_Allreduce
// (core/exact_sum.hpp, MpiDecomposed::exact_sum).
#pragma once
#include <mpi.h>

#include <cstdint>
#include <utility>
#include <vector>

#include "parallel/local_model.hpp"

namespace pd {

class OrderedSum {
 public:
  // Collective over comm: rank 0 learns every rank's owned global numbers once.
  OrderedSum(MPI_Comm comm, const LocalPiece& piece);

  // The owned entries of every rank, in global node order, on rank 0 (empty elsewhere). Collective.
  std::vector<double> gather(const std::vector<double>& per_node) const;
  // The same for `width` values per node (local node l's at width·l …): on rank 0, node g's at
  // width·g …. One MPI_Gatherv. Collective.
  std::vector<double> gather(const std::vector<double>& per_node, int width) const;
  // The broken flags of the owned rows of `local` (the piece's bond list) into the same rows of
  // `global` (the whole model's), on rank 0. Collective.
  void gather_rows(const BondList& local, BondList& global) const;
  // `width` values per directed bond of the owned rows of `local` (per_bond, over local's rows) in
  // the whole model's bond order (rows of `global`), on rank 0 (empty elsewhere). Collective.
  std::vector<double> gather_bond_values(const BondList& local, const std::vector<double>& per_bond, int width,
                                         const BondList& global) const;
  // The broken bonds j > i of the owned rows of `local` (global: the piece's global numbers), as
  // rows of the whole model on rank 0 (Decomposed::gather_broken_lines). Collective.
  void gather_lines(const BondList& local, const std::vector<std::int32_t>& global, BondList& lines) const;
  // Every rank's (key, value) entries on rank 0 sorted by key, keys unique (Decomposed::gather_keyed).
  // Two MPI_Gatherv after one MPI_Gather of the counts. Collective.
  std::vector<std::pair<std::int64_t, double>> gather_keyed(const std::vector<std::int64_t>& keys,
                                                            const std::vector<double>& values) const;
  // Gathers so far, the bytes this rank sent in them, and their wall time.
  std::int64_t calls() const { return calls_; }
  std::int64_t bytes_sent() const { return bytes_; }
  double seconds() const { return seconds_; }

 private:
  // gather_rows and gather_bond_values: the owned rows' values into global_values over global's rows.
  template <class T>
  void gather_row_values(const BondList& local, const std::vector<T>& local_values, int width, const BondList& global,
                         std::vector<T>& global_values, const char* what) const;
  MPI_Comm comm_;
  int rank_ = 0;
  std::int64_t global_nodes_ = 0;
  std::int64_t directed_bonds_ = 0;  // of the whole model: the owned rows' summed over the ranks
  std::vector<std::int32_t> owned_local_;
  int ranks_ = 1;
  std::vector<int> counts_, starts_;        // rank 0: per rank, its owned count and offset
  std::vector<std::int32_t> gathered_node_; // rank 0: the global number of each gathered entry
  mutable std::vector<double> send_, received_;
  mutable std::int64_t calls_ = 0, bytes_ = 0;
  mutable double seconds_ = 0.0;
};

}  // namespace pd
