// Builds the CSR bond list from reference positions with a cell list (bins of edge ≥ the cut-off).
#include "core/bonds.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "core/error.hpp"

namespace pd {

namespace {

struct CellGrid {
  double lo[3];
  double edge;
  std::int64_t count[3];
  std::vector<std::int64_t> start;  // bin b holds order[start[b] .. start[b+1])
  std::vector<std::int32_t> order;  // node indices sorted by bin

  std::int64_t coordinate(int d, double value) const {
    auto c = static_cast<std::int64_t>(std::floor((value - lo[d]) / edge));
    return std::clamp<std::int64_t>(c, 0, count[d] - 1);
  }
  std::int64_t bin(std::int64_t cx, std::int64_t cy, std::int64_t cz) const {
    return (cz * count[1] + cy) * count[0] + cx;
  }
};

CellGrid make_grid(const Vec3Array& x, double cutoff) {
  const std::size_t n = x[0].size();
  CellGrid grid;
  double hi[3];
  for (int d = 0; d < 3; ++d) {
    grid.lo[d] = *std::min_element(x[d].begin(), x[d].end());
    hi[d] = *std::max_element(x[d].begin(), x[d].end());
  }
  // Bins of edge ≥ cut-off, so every partner lies in the 27 bins around a node; a sparse cloud in
  // a large box gets larger bins so the bin array stays O(N).
  grid.edge = cutoff;
  const double max_bins = 2.0 * static_cast<double>(n) + 1000.0;
  for (;;) {
    double total = 1.0;
    for (int d = 0; d < 3; ++d) {
      grid.count[d] = static_cast<std::int64_t>(std::floor((hi[d] - grid.lo[d]) / grid.edge)) + 1;
      total *= static_cast<double>(grid.count[d]);
    }
    if (total <= max_bins) break;
    grid.edge *= 1.5;
  }
  const std::int64_t bins = grid.count[0] * grid.count[1] * grid.count[2];
  std::vector<std::int64_t> node_bin(n);
  grid.start.assign(static_cast<std::size_t>(bins) + 1, 0);
  for (std::size_t i = 0; i < n; ++i) {
    node_bin[i] = grid.bin(grid.coordinate(0, x[0][i]), grid.coordinate(1, x[1][i]),
                           grid.coordinate(2, x[2][i]));
    ++grid.start[static_cast<std::size_t>(node_bin[i]) + 1];
  }
  for (std::int64_t b = 0; b < bins; ++b) grid.start[b + 1] += grid.start[b];
  grid.order.resize(n);
  std::vector<std::int64_t> fill(grid.start.begin(), grid.start.end() - 1);
  for (std::size_t i = 0; i < n; ++i)  // serial and in node order: deterministic
    grid.order[static_cast<std::size_t>(fill[static_cast<std::size_t>(node_bin[i])]++)] =
        static_cast<std::int32_t>(i);
  return grid;
}

// Calls visit(j, |ξ|) for every partner j of node i (unordered).
template <class Visit>
void for_each_partner(const Vec3Array& x, const CellGrid& grid, double cutoff2, std::size_t i,
                      Visit&& visit) {
  const double xi = x[0][i], yi = x[1][i], zi = x[2][i];
  const std::int64_t c[3] = {grid.coordinate(0, xi), grid.coordinate(1, yi), grid.coordinate(2, zi)};
  for (std::int64_t cz = std::max<std::int64_t>(c[2] - 1, 0); cz <= std::min(c[2] + 1, grid.count[2] - 1); ++cz)
    for (std::int64_t cy = std::max<std::int64_t>(c[1] - 1, 0); cy <= std::min(c[1] + 1, grid.count[1] - 1); ++cy)
      for (std::int64_t cx = std::max<std::int64_t>(c[0] - 1, 0); cx <= std::min(c[0] + 1, grid.count[0] - 1); ++cx) {
        const auto b = static_cast<std::size_t>(grid.bin(cx, cy, cz));
        for (std::int64_t k = grid.start[b]; k < grid.start[b + 1]; ++k) {
          const auto j = static_cast<std::size_t>(grid.order[static_cast<std::size_t>(k)]);
          if (j == i) continue;
          // ξ = x_j − x_i; computed the same way from both ends, so |ξ| is bitwise symmetric.
          const double d0 = x[0][j] - xi, d1 = x[1][j] - yi, d2 = x[2][j] - zi;
          const double r2 = d0 * d0 + d1 * d1 + d2 * d2;
          if (r2 > cutoff2) continue;
          if (r2 == 0.0)
            throw Error("nodes " + std::to_string(i) + " and " + std::to_string(j) +
                        " have the same reference position");
          visit(static_cast<std::int32_t>(j), std::sqrt(r2));
        }
      }
}

}  // namespace

BondList build_bonds(const Vec3Array& x, double horizon) {
  const std::size_t n = x[0].size();
  if (n > static_cast<std::size_t>(std::numeric_limits<std::int32_t>::max()))
    throw Error("too many nodes for 32-bit neighbour indices: " + std::to_string(n));
  if (!(horizon > 0.0) || !std::isfinite(horizon)) throw Error("horizon must be a finite number > 0");
  BondList bonds;
  bonds.offsets.assign(n + 1, 0);
  if (n == 0) return bonds;
  const double cutoff = horizon * (1.0 + kHorizonTolerance);
  const CellGrid grid = make_grid(x, cutoff);
  const double cutoff2 = cutoff * cutoff;

  // Two passes (count, then fill) so that each node's row is written by one thread only.
  std::string error;
#pragma omp parallel for schedule(dynamic, 256)
  for (std::int64_t i = 0; i < static_cast<std::int64_t>(n); ++i) {
    try {
      std::int64_t count = 0;
      for_each_partner(x, grid, cutoff2, static_cast<std::size_t>(i), [&](std::int32_t, double) { ++count; });
      bonds.offsets[static_cast<std::size_t>(i) + 1] = count;
    } catch (const Error& e) {
#pragma omp critical(pd_bond_error)
      if (error.empty()) error = e.what();
    }
  }
  if (!error.empty()) throw Error(error);
  for (std::size_t i = 0; i < n; ++i) bonds.offsets[i + 1] += bonds.offsets[i];
  const auto total = static_cast<std::size_t>(bonds.offsets[n]);
  bonds.neighbour.resize(total);
  bonds.length.resize(total);
  bonds.broken.assign(total, 0);

#pragma omp parallel for schedule(dynamic, 256)
  for (std::int64_t i = 0; i < static_cast<std::int64_t>(n); ++i) {
    std::vector<std::pair<std::int32_t, double>> row;
    for_each_partner(x, grid, cutoff2, static_cast<std::size_t>(i),
                     [&](std::int32_t j, double r) { row.emplace_back(j, r); });
    std::sort(row.begin(), row.end());  // ascending j: deterministic order, better locality
    auto k = static_cast<std::size_t>(bonds.offsets[static_cast<std::size_t>(i)]);
    for (const auto& [j, r] : row) {
      bonds.neighbour[k] = j;
      bonds.length[k] = r;
      ++k;
    }
  }
  return bonds;
}

}  // namespace pd
