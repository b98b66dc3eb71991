// Morton-order decomposition balanced by bond count (parallel/decomposition.hpp).
#include "parallel/decomposition.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <string>

#include "core/error.hpp"

namespace pd {

namespace {

__extension__ typedef unsigned __int128 Wide;  // GCC/Clang's 128-bit integer (__extension__: not ISO)

// The 21 low bits of v spread to every third bit (bit k → bit 3k).
std::uint64_t spread_bits(std::uint64_t v) {
  v &= 0x1fffff;
  v = (v | v << 32) & 0x1f00000000ffffULL;
  v = (v | v << 16) & 0x1f0000ff0000ffULL;
  v = (v | v << 8) & 0x100f00f00f00f00fULL;
  v = (v | v << 4) & 0x10c30c30c30c30c3ULL;
  v = (v | v << 2) & 0x1249249249249249ULL;
  return v;
}

}  // namespace

std::vector<std::uint64_t> morton_keys(const Vec3Array& x) {
  const std::size_t n = x[0].size();
  std::vector<std::uint64_t> keys(n, 0);
  if (n == 0) return keys;
  double lo[3], side = 0.0;
  for (int d = 0; d < 3; ++d) {
    const auto [mn, mx] = std::minmax_element(x[static_cast<std::size_t>(d)].begin(), x[static_cast<std::size_t>(d)].end());
    lo[d] = *mn;
    side = std::max(side, *mx - *mn);
  }
  const double cells = static_cast<double>((1u << 21) - 1);
  const double scale = side > 0.0 ? cells / side : 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    std::uint64_t key = 0;
    for (int d = 0; d < 3; ++d) {
      const double q = std::floor((x[static_cast<std::size_t>(d)][i] - lo[d]) * scale);
      key |= spread_bits(static_cast<std::uint64_t>(std::clamp(q, 0.0, cells))) << d;
    }
    keys[i] = key;
  }
  return keys;
}

Decomposition decompose(const Vec3Array& x, const BondList& bonds, int ranks, double horizon) {
  return decompose(x, bonds.offsets, ranks, horizon);
}

Decomposition decompose(const Vec3Array& x, const std::vector<std::int64_t>& offsets, int ranks, double horizon) {
  const auto n = static_cast<std::int64_t>(x[0].size());
  if (ranks < 1) throw Error("decomposition: " + std::to_string(ranks) + " ranks; at least 1 is needed");
  if (ranks > n)
    throw Error("decomposition: " + std::to_string(ranks) + " MPI ranks for " + std::to_string(n) +
                " nodes: every rank needs nodes of its own; run with at most " + std::to_string(n) +
                " ranks (RANKS=R with make, mpiexec -np R by hand)");
  Decomposition d;
  d.ranks = ranks;
  const std::vector<std::uint64_t> keys = morton_keys(x);
  d.order.resize(static_cast<std::size_t>(n));
  std::iota(d.order.begin(), d.order.end(), 0);
  // Ties (two nodes in one Morton cell) go by node number: the same order on every rank.
  std::sort(d.order.begin(), d.order.end(), [&](std::int64_t a, std::int64_t b) {
    const auto ka = keys[static_cast<std::size_t>(a)], kb = keys[static_cast<std::size_t>(b)];
    return ka != kb ? ka < kb : a < b;
  });
  const auto work_of = [&](std::int64_t i) {
    return 1 + offsets[static_cast<std::size_t>(i) + 1] - offsets[static_cast<std::size_t>(i)];
  };
  std::int64_t total = 0;
  for (std::int64_t i = 0; i < n; ++i) total += work_of(i);
  d.owner.assign(static_cast<std::size_t>(n), 0);
  d.piece_start.assign(static_cast<std::size_t>(ranks) + 1, n);
  d.piece_work.assign(static_cast<std::size_t>(ranks), 0);
  std::int64_t before = 0;
  int last = -1;
  for (std::int64_t p = 0; p < n; ++p) {
    const std::int64_t i = d.order[static_cast<std::size_t>(p)];
    // ⌊before·R/W⌋ in 128 bits: before·R may pass 2⁶³ for 10⁹ nodes × 10⁴ ranks.
    const int r = static_cast<int>(static_cast<Wide>(before) * static_cast<unsigned>(ranks) / static_cast<Wide>(total));
    while (last < r) d.piece_start[static_cast<std::size_t>(++last)] = p;
    d.owner[static_cast<std::size_t>(i)] = r;
    d.piece_work[static_cast<std::size_t>(r)] += work_of(i);
    before += work_of(i);
  }
  for (int r = 0; r < ranks; ++r)
    if (d.piece_start[static_cast<std::size_t>(r)] == d.piece_start[static_cast<std::size_t>(r) + 1])
      throw Error("decomposition: rank " + std::to_string(r) + " of " + std::to_string(ranks) +
                  " gets no node (one node holds more than 1/" + std::to_string(ranks) +
                  " of the bonds); run with fewer ranks (RANKS=R with make, mpiexec -np R by hand)");
  if (ranks > 1) {
    for (int r = 0; r < ranks; ++r) {
      double lo[3], hi[3];
      for (int c = 0; c < 3; ++c) lo[c] = HUGE_VAL, hi[c] = -HUGE_VAL;
      for (std::int64_t p = d.piece_start[static_cast<std::size_t>(r)]; p < d.piece_start[static_cast<std::size_t>(r) + 1]; ++p)
        for (int c = 0; c < 3; ++c) {
          const double v = x[static_cast<std::size_t>(c)][static_cast<std::size_t>(d.order[static_cast<std::size_t>(p)])];
          lo[c] = std::min(lo[c], v);
          hi[c] = std::max(hi[c], v);
        }
      const double side = std::max({hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]});
      if (side < horizon)
        throw Error("decomposition: rank " + std::to_string(r) + "'s piece is " + std::to_string(side) +
                    " m across, less than the horizon " + std::to_string(horizon) + " m (" + std::to_string(n) +
                    " nodes on " + std::to_string(ranks) + " ranks): its ghosts would outnumber its nodes; "
                    "run with fewer ranks (RANKS=R with make, mpiexec -np R by hand)");
    }
  }
  return d;
}

}  // namespace pd
