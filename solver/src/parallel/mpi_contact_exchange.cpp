// The contact ghosts' communication of a decomposed run (issue 15; forces/contact_on_piece): the
// box exchange that finds them when the Verlet list is rebuilt, and the halo that keeps their
// displacements current in every force evaluation. Part of MpiDecomposed (parallel/mpi_decomposed.hpp).
#include <algorithm>
#include <cstdio>

#include "parallel/mpi_decomposed.hpp"

namespace pd {

namespace {

// A HaloExchange over the contact set, counting its traffic apart from the bonds' halo.
class MpiNodeHalo : public NodeHalo {
 public:
  MpiNodeHalo(MPI_Comm comm, const LocalPiece& set, const std::vector<std::int32_t>& owner,
              MpiDecomposed::ContactTraffic& traffic)
      : halo_(comm, set, owner), traffic_(traffic) {
    traffic_.ghosts = halo_.ghosts();
  }
  void exchange(Vec3Array& a) const override {
    const double start = MPI_Wtime();
    halo_.exchange(a);
    ++traffic_.halo_exchanges;
    traffic_.halo_messages += halo_.messages_sent();
    traffic_.halo_bytes += halo_.bytes_sent();
    traffic_.seconds += MPI_Wtime() - start;
  }

 private:
  HaloExchange halo_;
  MpiDecomposed::ContactTraffic& traffic_;
};

}  // namespace

void MpiDecomposed::exchange_in_boxes(const double lo[3], const double hi[3], const std::vector<std::int32_t>& global_node,
                                      const Vec3Array& position, const std::vector<double>& values, int width,
                                      std::vector<std::int32_t>& received_node, std::vector<double>& received_values) const {
  const double start = MPI_Wtime();
  const int ranks = this->ranks();
  const auto R = static_cast<std::size_t>(ranks);
  const double mine[6] = {lo[0], lo[1], lo[2], hi[0], hi[1], hi[2]};
  std::vector<double> boxes(6 * R);
  MPI_Allgather(mine, 6, MPI_DOUBLE, boxes.data(), 6, MPI_DOUBLE, comm_);
  // Per destination rank, in ascending rank order: the candidates inside its box, ascending.
  std::vector<int> send_count(R, 0), send_start(R + 1, 0);
  std::vector<std::int32_t> send_node;
  std::vector<double> send_values;
  const auto w = static_cast<std::size_t>(width);
  for (int r = 0; r < ranks; ++r) {
    const double* box = &boxes[6 * static_cast<std::size_t>(r)];
    if (r != rank_)
      for (std::size_t k = 0; k < global_node.size(); ++k) {
        bool inside = true;
        for (std::size_t d = 0; d < 3; ++d) inside = inside && position[d][k] >= box[d] && position[d][k] <= box[3 + d];
        if (!inside) continue;
        send_node.push_back(global_node[k]);
        send_values.insert(send_values.end(), values.begin() + static_cast<std::ptrdiff_t>(w * k),
                           values.begin() + static_cast<std::ptrdiff_t>(w * (k + 1)));
      }
    send_start[static_cast<std::size_t>(r) + 1] = static_cast<int>(send_node.size());
    send_count[static_cast<std::size_t>(r)] = send_start[static_cast<std::size_t>(r) + 1] - send_start[static_cast<std::size_t>(r)];
  }
  std::vector<int> recv_count(R, 0), recv_start(R + 1, 0);
  MPI_Alltoall(send_count.data(), 1, MPI_INT, recv_count.data(), 1, MPI_INT, comm_);
  for (std::size_t r = 0; r < R; ++r) recv_start[r + 1] = recv_start[r] + recv_count[r];
  std::vector<std::int32_t> nodes(static_cast<std::size_t>(recv_start[R]));
  MPI_Alltoallv(send_node.data(), send_count.data(), send_start.data(), MPI_INT32_T, nodes.data(), recv_count.data(),
                recv_start.data(), MPI_INT32_T, comm_);
  std::vector<int> send_value_count(R), send_value_start(R + 1), recv_value_count(R), recv_value_start(R + 1);
  for (std::size_t r = 0; r < R; ++r) send_value_count[r] = width * send_count[r], recv_value_count[r] = width * recv_count[r];
  for (std::size_t r = 0; r <= R; ++r) send_value_start[r] = width * send_start[r], recv_value_start[r] = width * recv_start[r];
  std::vector<double> gathered(w * nodes.size());
  MPI_Alltoallv(send_values.data(), send_value_count.data(), send_value_start.data(), MPI_DOUBLE, gathered.data(),
                recv_value_count.data(), recv_value_start.data(), MPI_DOUBLE, comm_);
  // Each sender's nodes ascend and a node has one owner: sorting the entries by node merges them.
  std::vector<std::size_t> order(nodes.size());
  for (std::size_t e = 0; e < order.size(); ++e) order[e] = e;
  std::sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return nodes[a] < nodes[b]; });
  received_node.clear();
  received_values.clear();
  for (std::size_t e : order) {
    received_node.push_back(nodes[e]);
    received_values.insert(received_values.end(), gathered.begin() + static_cast<std::ptrdiff_t>(w * e),
                           gathered.begin() + static_cast<std::ptrdiff_t>(w * (e + 1)));
  }
  ContactTraffic& t = *contact_traffic_;
  ++t.box_exchanges;
  t.box_bytes += static_cast<std::int64_t>(6 * 8 * (R - 1) + 4 * send_node.size() + 8 * send_values.size());
  t.seconds += MPI_Wtime() - start;
}

std::unique_ptr<NodeHalo> MpiDecomposed::make_node_halo(const std::vector<std::int32_t>& global,
                                                        const std::vector<std::int32_t>& ghost_local) const {
  LocalPiece set;  // what HaloExchange reads of a piece: the global numbers and which entries are ghosts
  set.rank = rank_;
  set.global = global;
  set.ghost_local = ghost_local;
  return std::make_unique<MpiNodeHalo>(comm_, set, decomposition_.owner, *contact_traffic_);
}

std::vector<std::string> MpiDecomposed::contact_traffic_report(std::int64_t steps) const {
  const ContactTraffic& t = *contact_traffic_;
  const double per = 1.0 / static_cast<double>(std::max<std::int64_t>(steps, 1));
  constexpr int kColumns = 7;
  const double row[kColumns] = {static_cast<double>(t.ghosts), static_cast<double>(t.box_exchanges) * per,
                                static_cast<double>(t.box_bytes) * per, static_cast<double>(t.halo_exchanges) * per,
                                static_cast<double>(t.halo_messages) * per, static_cast<double>(t.halo_bytes) * per,
                                t.seconds * per};
  return lines_on_rank_0(row, kColumns, [](int r, const double* v) {
    char line[512];
    std::snprintf(line, sizeof line,
                  "rank %d contact: %.0f contact ghosts not among the bond ghosts (last list); per step: %.3g box "
                  "exchanges sending %.4g bytes, %.3g contact halo exchanges, %.3g messages and %.4g bytes sent, "
                  "%.4g ms in communication",
                  r, v[0], v[1], v[2], v[3], v[4], v[5], 1e3 * v[6]);
    return std::string(line);
  });
}

}  // namespace pd
