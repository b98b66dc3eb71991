// A decomposed run on MPI's ranks (issue 15): the decomposition, this rank's piece, its halo
// exchange, the exact sums and the gathers, behind the Decomposed interface the operator calls.
#pragma once
#include <mpi.h>

#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "core/model.hpp"
#include "parallel/decomposed.hpp"
#include "parallel/decomposition.hpp"
#include "parallel/halo.hpp"
#include "parallel/local_model.hpp"
#include "parallel/ordered_sum.hpp"
#include "parallel/row_split.hpp"

namespace pd {

class MpiDecomposed : public Decomposed {
 public:
  // Collective over comm: every rank decomposes the (whole) model the same way and builds its own
  // piece, halo and sums. Throws pd::Error on every rank alike for a decomposition that cannot
  // work (parallel/decomposition.hpp), so no rank waits for another.
  MpiDecomposed(MPI_Comm comm, const Model& global);
  // The same without the whole bond list: `skeleton` has the per-node data and, in bonds.offsets,
  // every node's row length (build_model_without_bonds, count_bonds); this rank builds the rows of
  // its owned nodes (cut-off `cutoff`, pre-cracks `cracks`) and nothing else, then the surface
  // correction's factors of `surface_correction` (core/surface_correction.hpp) on those rows. The
  // same piece, bit for bit.
  MpiDecomposed(MPI_Comm comm, const Model& skeleton, double cutoff, const std::vector<CrackSegment>& cracks,
                const std::string& surface_correction);

  int rank() const override { return rank_; }
  int ranks() const override { return decomposition_.ranks; }
  const Decomposition& decomposition() const { return decomposition_; }
  LocalPiece& piece() override { return piece_; }
  const LocalPiece& piece() const override { return piece_; }
  const HaloExchange& halo() const { return *halo_; }

  void begin_update_ghosts(const NodeColumns& a) const override { halo_->begin(a); }
  void end_update_ghosts(const NodeColumns& a) const override { halo_->end(a); }
  const RowSplit& row_split() const override { return row_split_; }
  // Every owned row a boundary row: each overlapped sweep then waits for its exchange before any row
  // (the blocking exchange), the same bits. For a before/after of the overlap in one binary
  // (pd_mpi_halo --blocking); a run never calls it.
  void split_rows_for_blocking() {
    row_split_.boundary = piece_.owned_local;
    row_split_.interior.clear();
  }
  double exact_sum(const std::vector<double>& per_node, double start = 0.0) const override;
  void reduce(ExactSum* sums, int count, std::int64_t* integers = nullptr, int integer_count = 0) const override;
  std::int64_t total(std::int64_t local) const override;
  double minimum(double local) const override;

  using Decomposed::gather;
  std::vector<double> gather(const std::vector<double>& per_node) const override { return sum_->gather(per_node); }
  std::vector<double> gather(const std::vector<double>& per_node, int width) const override {
    return sum_->gather(per_node, width);
  }
  void broadcast(std::vector<double>& values) const override;
  std::vector<std::int64_t> gather_to_all(const std::vector<std::int64_t>& values) const override;
  void gather_broken(const BondList& local, BondList& global) const override { sum_->gather_rows(local, global); }
  std::vector<double> gather_bond_values(const BondList& local, const std::vector<double>& per_bond, int width,
                                         const BondList& global) const override {
    return sum_->gather_bond_values(local, per_bond, width, global);
  }
  std::vector<std::pair<std::int64_t, double>> gather_keyed(const std::vector<std::int64_t>& keys,
                                                            const std::vector<double>& values) const override {
    return sum_->gather_keyed(keys, values);
  }
  std::string broadcast(const std::string& bytes_on_rank_0) const override;
  std::vector<double> per_rank(double value) const override;
  void gather_broken_lines(const BondList& local, BondList& lines) const override;
  Traffic traffic() const override;
  std::vector<std::string> traffic_report(std::int64_t steps) const override;

  // Contact ghosts (parallel/mpi_contact_exchange.cpp).
  void exchange_in_boxes(const double lo[3], const double hi[3], const std::vector<std::int32_t>& global_node,
                         const Vec3Array& position, const std::vector<double>& values, int width,
                         std::vector<std::int32_t>& received_node, std::vector<double>& received_values) const override;
  std::unique_ptr<NodeHalo> make_node_halo(const std::vector<std::int32_t>& global,
                                           const std::vector<std::int32_t>& ghost_local) const override;
  std::vector<std::string> contact_traffic_report(std::int64_t steps) const override;
  // What the contact ghosts cost this rank so far: sent by this rank.
  struct ContactTraffic {
    std::int64_t box_exchanges = 0, box_bytes = 0;               // boxes (Allgather) and candidates (Alltoallv)
    std::int64_t halo_exchanges = 0, halo_messages = 0, halo_bytes = 0;
    std::int64_t ghosts = 0;                                     // in the last halo made
    double seconds = 0.0;
  };
  const ContactTraffic& contact_traffic() const { return *contact_traffic_; }

 private:
  // run.log's per-rank lines: every rank's `columns` values gathered on rank 0 and written there by
  // line(rank, its values), rank after rank (empty elsewhere). Collective.
  std::vector<std::string> lines_on_rank_0(const double* row, int columns,
                                           const std::function<std::string(int, const double*)>& line) const;
  MPI_Comm comm_;
  int rank_ = 0;
  Decomposition decomposition_;
  LocalPiece piece_;
  std::unique_ptr<HaloExchange> halo_;
  RowSplit row_split_;  // of piece_'s owned rows (parallel/row_split.hpp)
  std::unique_ptr<OrderedSum> sum_;  // the gathers to rank 0
  mutable std::vector<std::int64_t> limbs_;  // reduce's buffer
  mutable std::int64_t reductions_ = 0, reduction_bytes_ = 0;
  mutable double reduction_seconds_ = 0.0;
  std::unique_ptr<ContactTraffic> contact_traffic_ = std::make_unique<ContactTraffic>();  // shared with the halos made
};

}  // namespace pd
