// Sums and gathers over the nodes of a decomposed run whose result does not depend on the rank
// count (issue 15). A floating-point sum's bits depend on its order, and the serial solver sums
// per-node terms one by one in node order; so the owned nodes' terms are gathered to rank 0
// (MPI_Gatherv), put in global node order, summed one by one exactly as the serial loop does, and
// the result broadcast (MPI_Bcast): the serial sum's bits, on every rank, for any rank count.
// Its cost is 8 bytes per node to rank 0 per sum; an exact (integer-accumulator) sum would cost
// 8 bytes per rank, but would change the serial results' last bits — left for when that matters.
#pragma once
#include <mpi.h>

#include <cstdint>
#include <vector>

#include "parallel/local_model.hpp"

namespace pd {

class OrderedSum {
 public:
  // Collective over comm: rank 0 learns every rank's owned global numbers once.
  OrderedSum(MPI_Comm comm, const LocalPiece& piece);

  // start + Σ per_node[l] over owned l, added in global node order, on every rank. Collective.
  double sum(const std::vector<double>& per_node, double start = 0.0) const;
  // The owned entries of every rank, in global node order, on rank 0 (empty elsewhere). Collective.
  std::vector<double> gather(const std::vector<double>& per_node) const;
  // The same for `width` values per node (local node l's at width·l …): on rank 0, node g's at
  // width·g …. One MPI_Gatherv. Collective.
  std::vector<double> gather(const std::vector<double>& per_node, int width) const;
  // The broken flags of the owned rows of `local` (the piece's bond list) into the same rows of
  // `global` (the whole model's), on rank 0. Collective.
  void gather_rows(const BondList& local, BondList& global) const;
  // The broken bonds j > i of the owned rows of `local` (global: the piece's global numbers), as
  // rows of the whole model on rank 0 (Decomposed::gather_broken_lines). Collective.
  void gather_lines(const BondList& local, const std::vector<std::int32_t>& global, BondList& lines) const;
  // Gathers so far (sums included), the bytes this rank sent in them, and their wall time.
  std::int64_t calls() const { return calls_; }
  std::int64_t bytes_sent() const { return bytes_; }
  double seconds() const { return seconds_; }

 private:
  MPI_Comm comm_;
  int rank_ = 0;
  std::int64_t global_nodes_ = 0;
  std::vector<std::int32_t> owned_local_;
  int ranks_ = 1;
  std::vector<int> counts_, starts_;        // rank 0: per rank, its owned count and offset
  std::vector<std::int32_t> gathered_node_; // rank 0: the global number of each gathered entry
  mutable std::vector<double> send_, received_;
  mutable std::int64_t calls_ = 0, bytes_ = 0;
  mutable double seconds_ = 0.0;
};

}  // namespace pd
