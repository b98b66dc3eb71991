// The halo exchange of a decomposed run (issue 15): every ghost's value from its owner, with
// non-blocking point-to-point messages (MPI_Irecv / MPI_Isend, one message per neighbouring rank
// and direction, then MPI_Waitall). Built once from the piece: each rank tells each owner which of
// its nodes it needs (MPI_Alltoall of counts, MPI_Alltoallv of global numbers), in ascending global
// order, so the owner packs and the receiver unpacks in one agreed order.
#pragma once
#include <mpi.h>

#include <cstdint>
#include <vector>

#include "core/nodes.hpp"
#include "parallel/local_model.hpp"

namespace pd {

class HaloExchange {
 public:
  // Collective over comm. owner: the rank of every global node (parallel/decomposition).
  HaloExchange(MPI_Comm comm, const LocalPiece& piece, const std::vector<std::int32_t>& owner);

  // a's ghost entries = their owners' entries (3 doubles per ghost). Collective over comm.
  void exchange(Vec3Array& a) const;
  // a's ghost entries = their owners' entries, for a scalar per node (1 double per ghost). Collective.
  void exchange(std::vector<double>& a) const;

  // Per exchange, from this rank: messages sent and bytes sent (of payload).
  std::int64_t messages_sent() const { return static_cast<std::int64_t>(send_rank_.size()); }
  std::int64_t bytes_sent() const { return static_cast<std::int64_t>(send_node_.size()) * 3 * 8; }
  std::int64_t ghosts() const { return static_cast<std::int64_t>(recv_node_.size()); }
  // Exchanges so far and the wall time spent in them (packing, MPI, unpacking).
  std::int64_t exchanges() const { return exchanges_; }
  double seconds() const { return seconds_; }

 private:
  MPI_Comm comm_;
  // Per neighbouring rank: the local nodes to send (recv) in message order, as CSR over the ranks.
  std::vector<int> send_rank_, recv_rank_;
  std::vector<std::int64_t> send_start_, recv_start_;
  std::vector<std::int32_t> send_node_, recv_node_;
  mutable std::vector<double> send_buffer_, recv_buffer_;
  mutable std::vector<MPI_Request> requests_;
  mutable std::int64_t exchanges_ = 0;
  mutable double seconds_ = 0.0;
};

}  // namespace pd
