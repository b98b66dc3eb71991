// Ghost exchange with non-blocking MPI messages (parallel/halo.hpp).
#include "parallel/halo.hpp"

#include <algorithm>
#include <stdexcept>

namespace pd {

HaloExchange::HaloExchange(MPI_Comm comm, const LocalPiece& piece, const std::vector<std::int32_t>& owner)
    : comm_(comm) {
  int ranks = 1;
  MPI_Comm_size(comm, &ranks);
  // What this rank receives: its ghosts grouped by owner, ascending global number within a group
  // (ghost_local is ascending in local and so in global number).
  std::vector<int> want_count(static_cast<std::size_t>(ranks), 0);
  for (std::int32_t l : piece.ghost_local) ++want_count[static_cast<std::size_t>(owner[static_cast<std::size_t>(piece.global[static_cast<std::size_t>(l)])])];
  std::vector<int> want_start(static_cast<std::size_t>(ranks) + 1, 0);
  for (int r = 0; r < ranks; ++r) want_start[static_cast<std::size_t>(r) + 1] = want_start[static_cast<std::size_t>(r)] + want_count[static_cast<std::size_t>(r)];
  std::vector<std::int32_t> want_global(piece.ghost_local.size());
  std::vector<std::int32_t> want_local(piece.ghost_local.size());
  {
    std::vector<int> at(want_start.begin(), want_start.end() - 1);
    for (std::int32_t l : piece.ghost_local) {
      const std::int32_t g = piece.global[static_cast<std::size_t>(l)];
      const int r = owner[static_cast<std::size_t>(g)];
      want_global[static_cast<std::size_t>(at[static_cast<std::size_t>(r)])] = g;
      want_local[static_cast<std::size_t>(at[static_cast<std::size_t>(r)]++)] = l;
    }
  }
  // What this rank sends: the owners learn who needs which of their nodes.
  std::vector<int> give_count(static_cast<std::size_t>(ranks), 0);
  MPI_Alltoall(want_count.data(), 1, MPI_INT, give_count.data(), 1, MPI_INT, comm);
  std::vector<int> give_start(static_cast<std::size_t>(ranks) + 1, 0);
  for (int r = 0; r < ranks; ++r) give_start[static_cast<std::size_t>(r) + 1] = give_start[static_cast<std::size_t>(r)] + give_count[static_cast<std::size_t>(r)];
  std::vector<std::int32_t> give_global(static_cast<std::size_t>(give_start.back()));
  MPI_Alltoallv(want_global.data(), want_count.data(), want_start.data(), MPI_INT32_T, give_global.data(),
                give_count.data(), give_start.data(), MPI_INT32_T, comm);

  send_start_.push_back(0);
  recv_start_.push_back(0);
  for (int r = 0; r < ranks; ++r) {
    if (give_count[static_cast<std::size_t>(r)] > 0) {
      send_rank_.push_back(r);
      for (int k = give_start[static_cast<std::size_t>(r)]; k < give_start[static_cast<std::size_t>(r) + 1]; ++k) {
        // global → local: piece.global is ascending
        const std::int32_t g = give_global[static_cast<std::size_t>(k)];
        const auto it = std::lower_bound(piece.global.begin(), piece.global.end(), g);
        send_node_.push_back(static_cast<std::int32_t>(it - piece.global.begin()));
      }
      send_start_.push_back(static_cast<std::int64_t>(send_node_.size()));
    }
    if (want_count[static_cast<std::size_t>(r)] > 0) {
      recv_rank_.push_back(r);
      for (int k = want_start[static_cast<std::size_t>(r)]; k < want_start[static_cast<std::size_t>(r) + 1]; ++k)
        recv_node_.push_back(want_local[static_cast<std::size_t>(k)]);
      recv_start_.push_back(static_cast<std::int64_t>(recv_node_.size()));
    }
  }
  send_buffer_.resize(3 * send_node_.size());
  recv_buffer_.resize(3 * recv_node_.size());
  requests_.resize(send_rank_.size() + recv_rank_.size());
}

// Tags: one per width, though one exchange at a time runs anyway (begin refuses a second).
namespace {
constexpr int kTagBase = 15;  // issue 15
}  // namespace

void HaloExchange::post(int width, int tag) const {
  std::size_t q = 0;
  for (std::size_t m = 0; m < recv_rank_.size(); ++m) {
    const std::int64_t begin = recv_start_[m], count = recv_start_[m + 1] - begin;
    MPI_Irecv(recv_buffer_.data() + width * begin, static_cast<int>(width * count), MPI_DOUBLE, recv_rank_[m], tag, comm_,
              &requests_[q++]);
  }
  for (std::size_t m = 0; m < send_rank_.size(); ++m) {
    const std::int64_t begin = send_start_[m], count = send_start_[m + 1] - begin;
    MPI_Isend(send_buffer_.data() + width * begin, static_cast<int>(width * count), MPI_DOUBLE, send_rank_[m], tag, comm_,
              &requests_[q++]);
  }
  requests_posted_ = q;
}

void HaloExchange::begin(const NodeColumns& a) const {
  if (in_flight_) throw std::logic_error("HaloExchange::begin: an exchange is already under way");
  const double start = MPI_Wtime();
  const auto width = static_cast<std::size_t>(a.width());
  if (send_buffer_.size() < width * send_node_.size()) send_buffer_.resize(width * send_node_.size());
  if (recv_buffer_.size() < width * recv_node_.size()) recv_buffer_.resize(width * recv_node_.size());
  // Node by node, every array's entry together: one message per neighbour.
  for (std::size_t k = 0; k < send_node_.size(); ++k)
    for (std::size_t c = 0; c < width; ++c) send_buffer_[width * k + c] = a[static_cast<int>(c)][send_node_[k]];
  post(a.width(), kTagBase + a.width());
  in_flight_ = a.width();
  messages_ += static_cast<std::int64_t>(send_rank_.size());
  bytes_ += static_cast<std::int64_t>(width * send_node_.size() * sizeof(double));
  seconds_ += MPI_Wtime() - start;
}

void HaloExchange::end(const NodeColumns& a) const {
  if (in_flight_ != a.width()) throw std::logic_error("HaloExchange::end: no exchange of these arrays under way");
  const double start = MPI_Wtime();
  const auto width = static_cast<std::size_t>(a.width());
  MPI_Waitall(static_cast<int>(requests_posted_), requests_.data(), MPI_STATUSES_IGNORE);
  for (std::size_t k = 0; k < recv_node_.size(); ++k)
    for (std::size_t c = 0; c < width; ++c) a[static_cast<int>(c)][recv_node_[k]] = recv_buffer_[width * k + c];
  in_flight_ = 0;
  ++exchanges_;
  const double spent = MPI_Wtime() - start;
  seconds_ += spent;
  wait_seconds_ += spent;
}

void HaloExchange::exchange(const NodeColumns& a) const {
  begin(a);
  end(a);
}

}  // namespace pd
