// Why a rank's rows are split in two: the halo exchange overlapped with the bond sweep (issue 15).
//
// A decomposed force evaluation needs its ghosts' values (u; LAMMPS's s0 with u; LPS's P_j between
// its two sweeps; x, then P_j and δP_j, for a J·x) from their owners. An owned row whose bond partners are all owned reads no ghost, so it can be swept
// while those values are still on their way:
//
//   begin the exchange (MPI_Irecv / MPI_Isend, parallel/halo)
//   sweep the interior rows   (every partner owned: no ghost read)
//   wait for the exchange     (the ghosts now hold their owners' values)
//   sweep the boundary rows   (at least one partner is a ghost)
//
// Each row is still summed alone, in bond order, from the same values, and no row of a sweep reads
// another row's result of that sweep, so the result is bitwise the blocking exchange's (and the
// serial run's): only the order in which the rows are visited changes. On a brick cut into slabs
// the interior rows are most of a piece (its volume), the boundary rows a layer δ thick at each cut
// (its surface), so most of the sweep hides the messages.
//
// The split depends only on the rows' neighbour lists — broken bonds count too: a broken bond still
// reads its partner's u (its term is multiplied by 0, and a stale or NaN u would spoil that) — and
// those never change during a run (a piece's rows are made once, parallel/local_model), so it is
// made once per piece (parallel/mpi_decomposed). Pure bookkeeping, no MPI.
#pragma once
#include <cstdint>
#include <functional>
#include <type_traits>
#include <vector>

namespace pd {

struct LocalPiece;

struct RowSplit {
  std::vector<std::int32_t> interior;  // owned rows whose bond partners are all owned, ascending
  std::vector<std::int32_t> boundary;  // owned rows with at least one ghost partner, ascending
};

// The split of the piece's owned rows (above): every owned row in exactly one of the two lists.
RowSplit split_rows(const LocalPiece& piece);

// The rows a sweep visits: every row 0 … nodes − 1 (the default: the serial sweep, unchanged), or
// row[0 … count) (of: a list, perhaps empty — a piece without ghosts has no boundary rows).
struct RowSubset {
  bool every = true;
  const std::int32_t* row = nullptr;
  std::int64_t count = 0;
  static RowSubset of(const std::vector<std::int32_t>& rows) {
    return RowSubset{false, rows.data(), static_cast<std::int64_t>(rows.size())};
  }
  std::int64_t size(std::int64_t nodes) const { return every ? nodes : count; }
  std::int64_t at(std::int64_t r) const { return every ? r : row[r]; }
};

// Arrays' ghost values still on their way (Decomposed::send_ghosts): what a law's overlapped sweep
// (materials/bond_model.hpp) gets. It sweeps rows.interior, calls wait(), which returns once every
// ghost entry holds its owner's value, then sweeps rows.boundary (sweep_overlapped below). wait() ends
// the exchange once; later calls do nothing, so the operator calls it again after the law, for a
// law that did not need to.
class GhostsInFlight {
 public:
  GhostsInFlight(const RowSplit& split, std::function<void()> end) : rows(split), end_(std::move(end)) {}
  GhostsInFlight(const GhostsInFlight&) = delete;
  GhostsInFlight& operator=(const GhostsInFlight&) = delete;
  const RowSplit& rows;
  void wait() const {
    if (waited_) return;
    waited_ = true;
    end_();
  }
  bool waited() const { return waited_; }

 private:
  std::function<void()> end_;
  mutable bool waited_ = false;
};

// The overlapped sweep in one place, for every law and every sweep that reads ghost values
// (parallel/row_split.hpp above): sweep(interior rows) while the ghosts travel, ghosts.wait(), then
// sweep(boundary rows). sweep takes a RowSubset; what it returns (a count of broken bonds) is added
// over the two halves, or it returns nothing.
template <class Sweep>
auto sweep_overlapped(const GhostsInFlight& ghosts, Sweep&& sweep) {
  using Result = decltype(sweep(RowSubset{}));
  if constexpr (std::is_void_v<Result>) {
    sweep(RowSubset::of(ghosts.rows.interior));
    ghosts.wait();
    sweep(RowSubset::of(ghosts.rows.boundary));
  } else {
    Result result = sweep(RowSubset::of(ghosts.rows.interior));
    ghosts.wait();
    result += sweep(RowSubset::of(ghosts.rows.boundary));
    return result;
  }
}

}  // namespace pd
