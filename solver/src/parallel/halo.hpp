// The halo exchange of a decomposed run (issue 15): every ghost's value from its owner, with
// non-blocking point-to-point messages (MPI_Irecv / MPI_Isend, one message per neighbouring rank
// and direction, then MPI_Waitall). Built once from the piece: each rank tells each owner which of
// its nodes it needs (MPI_Alltoall of counts, MPI_Alltoallv of global numbers), in ascending global
// order, so the owner packs and the receiver unpacks in one agreed order.
//
// An exchange runs whole (exchange) or in two halves (begin, end), so that a sweep of the rows
// that read no ghost runs while the messages travel (parallel/row_split.hpp). It carries one or
// several per-node arrays (parallel/node_columns.hpp) node by node in one message per neighbour.
// One exchange at a time: begin packs the owned values into one send buffer, end unpacks the one
// receive buffer.
#pragma once
#include <mpi.h>

#include <cstdint>
#include <vector>

#include "core/nodes.hpp"
#include "parallel/node_columns.hpp"
#include "parallel/local_model.hpp"

namespace pd {

class HaloExchange {
 public:
  // Collective over comm. owner: the rank of every global node (parallel/decomposition).
  HaloExchange(MPI_Comm comm, const LocalPiece& piece, const std::vector<std::int32_t>& owner);

  // The ghost entries of every array in a = their owners' entries (a.width() doubles per ghost, in
  // one message per neighbour). Collective over comm.
  void exchange(const NodeColumns& a) const;
  // exchange in two halves: begin posts the receives, packs a's owned entries and sends them
  // (MPI_Irecv, MPI_Isend) and returns; end (with the same arrays) waits for the messages
  // (MPI_Waitall) and writes a's ghost entries. Between them a's ghost entries are not yet their
  // owners' values, and no other exchange of this halo may begin. Collective over the neighbours.
  void begin(const NodeColumns& a) const;
  void end(const NodeColumns& a) const;

  // Per exchange, from this rank: messages sent and bytes sent (of payload) for a Vec3Array.
  std::int64_t messages_sent() const { return static_cast<std::int64_t>(send_rank_.size()); }
  std::int64_t bytes_sent() const { return static_cast<std::int64_t>(send_node_.size()) * 3 * 8; }
  std::int64_t ghosts() const { return static_cast<std::int64_t>(recv_node_.size()); }
  // Exchanges so far (of any arrays), their messages and payload bytes sent, and the wall time
  // spent in them (packing, MPI, unpacking; of a split exchange, in begin and end only: not the
  // sweep between them), and of that the time in end (the wait for messages the sweep did not
  // hide, and the unpacking).
  std::int64_t exchanges() const { return exchanges_; }
  std::int64_t messages() const { return messages_; }
  std::int64_t bytes() const { return bytes_; }
  double seconds() const { return seconds_; }
  double wait_seconds() const { return wait_seconds_; }

 private:
  MPI_Comm comm_;
  // Per neighbouring rank: the local nodes to send (recv) in message order, as CSR over the ranks.
  std::vector<int> send_rank_, recv_rank_;
  std::vector<std::int64_t> send_start_, recv_start_;
  std::vector<std::int32_t> send_node_, recv_node_;
  mutable std::vector<double> send_buffer_, recv_buffer_;
  mutable std::vector<MPI_Request> requests_;
  mutable std::int64_t exchanges_ = 0, messages_ = 0, bytes_ = 0;
  mutable double seconds_ = 0.0, wait_seconds_ = 0.0;
  mutable int in_flight_ = 0;  // 0: none; else the width of the exchange under way (begin → end)
  mutable std::size_t requests_posted_ = 0;
  void post(int width, int tag) const;  // the receives, then the sends of the packed buffer
};

}  // namespace pd
