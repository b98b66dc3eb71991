// A decomposed run on MPI's ranks (parallel/mpi_decomposed.hpp).
#include "parallel/mpi_decomposed.hpp"

#include <sys/resource.h>

#include <algorithm>
#include <cstdio>
#include <functional>
#include <string>

#include "core/cracks.hpp"
#include "core/surface_correction.hpp"

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
  row_split_ = split_rows(piece_);
  sum_ = std::make_unique<OrderedSum>(comm, piece_);
  // The law's per-node constants of the ghosts from their owners (LPS's m_j: a ghost's row is empty).
  piece_.model.bond_model->set_decomposed(this);
  // The Morton order served the cut only (8 bytes a node of the whole cloud); the owners stay (the
  // contact ghosts' halo asks them).
  std::vector<std::int64_t>().swap(decomposition_.order);
}

MpiDecomposed::MpiDecomposed(MPI_Comm comm, const Model& skeleton, double cutoff, const std::vector<CrackSegment>& cracks,
                             const std::string& surface_correction)
    : comm_(comm), decomposition_(decompose(skeleton.nodes.x, skeleton.bonds.offsets, size_of(comm), skeleton.horizon)) {
  MPI_Comm_rank(comm, &rank_);
  // The Morton order served the cut only (8 bytes a node of the whole cloud): freed before the rows
  // are built, where a rank's memory peaks. The owners stay (the halos ask them).
  std::vector<std::int64_t>().swap(decomposition_.order);
  std::vector<std::int32_t> rows;  // the owned nodes, ascending
  for (std::size_t i = 0; i < decomposition_.owner.size(); ++i)
    if (decomposition_.owner[i] == rank_) rows.push_back(static_cast<std::int32_t>(i));
  {
    // The owned rows only: ≈ 1/R of the whole list, renumbered in place into the piece.
    BondList owned = build_bond_rows(skeleton.nodes.x, cutoff, rows);
    cut_crossing_bonds(cracks, skeleton.nodes.x, owned, &rows);  // pre-cracks (notches) start broken
    piece_ = make_local_piece(skeleton, decomposition_.owner, rank_, std::move(owned));
  }
  halo_ = std::make_unique<HaloExchange>(comm, piece_, decomposition_.owner);
  row_split_ = split_rows(piece_);
  sum_ = std::make_unique<OrderedSum>(comm, piece_);
  // The surface correction on the owned rows, the ghosts' per-node factors from their owners
  // (core/surface_correction.hpp), and the law made again with them, as build_model does.
  Model& m = piece_.model;
  apply_surface_correction(surface_correction, m, this);
  if (m.bonds.corrected()) m.bond_model = material_registry().get(m.bond_model->name()).make(m);
  // The law's per-node constants of the ghosts from their owners (LPS's m_j: a ghost's row is empty).
  m.bond_model->set_decomposed(this);
  // The law's history at rest (core/state_arrays.hpp): the owned rows give the owned nodes' and
  // bonds' values (the serial values: the same rows), and the ghosts take their owners' for the
  // arrays that travel with them (a ghost's row is empty here).
  if (!piece_.model.state_arrays.empty()) {
    piece_.model.bond_model->initialise_state(piece_.model);
    NodeColumns ghosts;
    add_halo_state(ghosts, piece_.model.state_arrays);
    if (ghosts.width() > 0) halo_->exchange(ghosts);
  }
}

double MpiDecomposed::exact_sum(const std::vector<double>& per_node, double start) const {
  ExactSum sum;
  for (std::int32_t l : piece_.owned_local) sum.add(per_node[static_cast<std::size_t>(l)]);
  reduce(&sum, 1);
  sum.add(start);  // once, after the ranks' sums: start is the same on every rank
  return sum.value();
}

void MpiDecomposed::reduce(ExactSum* sums, int count, std::int64_t* integers, int integer_count) const {
  const double start = MPI_Wtime();
  const auto limbs = static_cast<std::size_t>(ExactSum::kLimbs);
  const std::size_t exact = limbs * static_cast<std::size_t>(count);
  limbs_.resize(exact + static_cast<std::size_t>(integer_count));
  for (int k = 0; k < count; ++k) {
    sums[k].normalise();  // digits in [0, 2^32): the ranks' limbs add without overflow (core/exact_sum.hpp)
    std::copy(sums[k].limbs(), sums[k].limbs() + limbs, limbs_.begin() + static_cast<std::ptrdiff_t>(limbs * static_cast<std::size_t>(k)));
  }
  if (integer_count > 0) std::copy(integers, integers + integer_count, limbs_.begin() + static_cast<std::ptrdiff_t>(exact));
  MPI_Allreduce(MPI_IN_PLACE, limbs_.data(), static_cast<int>(limbs_.size()), MPI_INT64_T, MPI_SUM, comm_);
  for (int k = 0; k < count; ++k) {
    std::copy(limbs_.begin() + static_cast<std::ptrdiff_t>(limbs * static_cast<std::size_t>(k)),
              limbs_.begin() + static_cast<std::ptrdiff_t>(limbs * static_cast<std::size_t>(k + 1)), sums[k].limbs());
    sums[k].normalise();
  }
  if (integer_count > 0) std::copy(limbs_.begin() + static_cast<std::ptrdiff_t>(exact), limbs_.end(), integers);
  ++reductions_;
  reduction_bytes_ += static_cast<std::int64_t>(8 * limbs_.size());
  reduction_seconds_ += MPI_Wtime() - start;
}

std::int64_t MpiDecomposed::total(std::int64_t local) const {
  std::int64_t sum = local;
  reduce(nullptr, 0, &sum, 1);
  return sum;
}

double MpiDecomposed::minimum(double local) const {
  const double start = MPI_Wtime();
  double least = local;
  MPI_Allreduce(&local, &least, 1, MPI_DOUBLE, MPI_MIN, comm_);
  ++reductions_;
  reduction_bytes_ += 8;
  reduction_seconds_ += MPI_Wtime() - start;
  return least;
}

std::string MpiDecomposed::broadcast(const std::string& bytes) const {
  // The length first (64 bits: a checkpoint may pass 2 GB), then the bytes in chunks MPI's int counts hold.
  std::uint64_t size = rank_ == 0 ? bytes.size() : 0;
  MPI_Bcast(&size, 1, MPI_UINT64_T, 0, comm_);
  std::string out = rank_ == 0 ? bytes : std::string(size, '\0');
  constexpr std::uint64_t kChunk = 1u << 30;
  for (std::uint64_t at = 0; at < size; at += kChunk)
    MPI_Bcast(out.data() + at, static_cast<int>(std::min(kChunk, size - at)), MPI_CHAR, 0, comm_);
  return out;
}

Decomposed::Traffic MpiDecomposed::traffic() const {
  Traffic t;
  t.halo_exchanges = halo_->exchanges();
  t.halo_messages = halo_->messages();
  t.halo_bytes = halo_->bytes();
  t.halo_seconds = halo_->seconds();
  t.halo_wait_seconds = halo_->wait_seconds();
  t.reductions = reductions_;
  t.reduction_bytes = reduction_bytes_;
  t.gathers = sum_->calls();
  t.gather_bytes = sum_->bytes_sent();
  t.reduction_seconds = reduction_seconds_ + sum_->seconds();
  return t;
}

std::vector<std::string> MpiDecomposed::lines_on_rank_0(const double* row, int columns,
                                                        const std::function<std::string(int, const double*)>& line) const {
  std::vector<double> all(rank_ == 0 ? static_cast<std::size_t>(columns * ranks()) : 0);
  MPI_Gather(row, columns, MPI_DOUBLE, all.data(), columns, MPI_DOUBLE, 0, comm_);
  std::vector<std::string> lines;
  for (int r = 0; r < ranks() && rank_ == 0; ++r) lines.push_back(line(r, &all[static_cast<std::size_t>(columns * r)]));
  return lines;
}

std::vector<std::string> MpiDecomposed::traffic_report(std::int64_t steps) const {
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);  // ru_maxrss: this process's (this rank's) peak resident set, in KiB on Linux
  const Traffic t = traffic();
  const double per = 1.0 / static_cast<double>(std::max<std::int64_t>(steps, 1));
  constexpr int kColumns = 12;
  const double row[kColumns] = {static_cast<double>(piece_.owned_local.size()), static_cast<double>(piece_.ghost_local.size()),
                                static_cast<double>(t.halo_exchanges) * per, static_cast<double>(t.halo_messages) * per,
                                static_cast<double>(t.halo_bytes) * per, static_cast<double>(t.reductions) * per,
                                static_cast<double>(t.reduction_bytes) * per, static_cast<double>(t.gathers) * per,
                                static_cast<double>(t.gather_bytes) * per, t.halo_seconds * per, t.reduction_seconds * per,
                                static_cast<double>(usage.ru_maxrss) / 1024.0};
  return lines_on_rank_0(row, kColumns, [](int r, const double* v) {
    char line[640];
    std::snprintf(line, sizeof line,
                  "rank %d: %.0f owned nodes, %.0f ghosts (%.3f per owned node); per step: %.2g halo exchanges, "
                  "%.3g messages and %.4g bytes sent, %.3g exact sums (MPI_Allreduce of %.4g bytes), %.3g gathers "
                  "sending %.4g bytes to rank 0, %.4g ms in communication (halo %.4g ms, sums and gathers %.4g ms); "
                  "peak memory %.1f MB",
                  r, v[0], v[1], v[1] / std::max(v[0], 1.0), v[2], v[3], v[4], v[5], v[6], v[7], v[8],
                  1e3 * (v[9] + v[10]), 1e3 * v[9], 1e3 * v[10], v[11]);
    return std::string(line);
  });
}

void MpiDecomposed::broadcast(std::vector<double>& values) const {
  MPI_Bcast(values.data(), static_cast<int>(values.size()), MPI_DOUBLE, 0, comm_);
}

std::vector<std::int64_t> MpiDecomposed::gather_to_all(const std::vector<std::int64_t>& values) const {
  const double start = MPI_Wtime();
  int mine = static_cast<int>(values.size());
  std::vector<int> counts(static_cast<std::size_t>(ranks())), at(counts.size() + 1, 0);
  MPI_Allgather(&mine, 1, MPI_INT, counts.data(), 1, MPI_INT, comm_);
  for (std::size_t r = 0; r < counts.size(); ++r) at[r + 1] = at[r] + counts[r];
  std::vector<std::int64_t> all(static_cast<std::size_t>(at.back()));
  MPI_Allgatherv(values.data(), mine, MPI_INT64_T, all.data(), counts.data(), at.data(), MPI_INT64_T, comm_);
  ++reductions_;
  reduction_bytes_ += 8 * static_cast<std::int64_t>(all.size());
  reduction_seconds_ += MPI_Wtime() - start;
  return all;
}

std::vector<double> MpiDecomposed::per_rank(double value) const {
  std::vector<double> all(rank_ == 0 ? static_cast<std::size_t>(ranks()) : 0);
  MPI_Gather(&value, 1, MPI_DOUBLE, all.data(), 1, MPI_DOUBLE, 0, comm_);
  return all;
}

void MpiDecomposed::gather_broken_lines(const BondList& local, BondList& lines) const {
  sum_->gather_lines(local, piece_.global, lines);
}

std::unique_ptr<Decomposed> decompose_rows_over_ranks(const Model& skeleton, double cutoff,
                                                      const std::vector<CrackSegment>& cracks,
                                                      const std::string& surface_correction) {
  int initialized = 0, ranks = 1;
  MPI_Initialized(&initialized);
  if (initialized) MPI_Comm_size(MPI_COMM_WORLD, &ranks);
  if (ranks == 1) return nullptr;
  return std::make_unique<MpiDecomposed>(MPI_COMM_WORLD, skeleton, cutoff, cracks, surface_correction);
}

std::unique_ptr<Decomposed> decompose_over_ranks(const Model& global) {
  int initialized = 0, ranks = 1;
  MPI_Initialized(&initialized);
  if (initialized) MPI_Comm_size(MPI_COMM_WORLD, &ranks);
  if (ranks == 1) return nullptr;
  return std::make_unique<MpiDecomposed>(MPI_COMM_WORLD, global);
}

}  // namespace pd
