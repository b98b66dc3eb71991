// A cell list over a point cloud (bins of edge ≥ a cut-off): the O(N) proximity search shared by
// the bond builder (reference positions) and the contact Verlet list (current positions).
#pragma once
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

namespace pd {

struct CellGrid {
  double lo[3] = {0, 0, 0};
  double edge = 0.0;
  std::int64_t count[3] = {1, 1, 1};
  std::vector<std::int64_t> start;  // bin b holds order[start[b] .. start[b+1])
  std::vector<std::int32_t> order;  // node indices sorted by bin, in node order within a bin

  std::int64_t coordinate(int d, double value) const {
    auto c = static_cast<std::int64_t>(std::floor((value - lo[d]) / edge));
    return std::clamp<std::int64_t>(c, 0, count[d] - 1);
  }
  std::int64_t bin(std::int64_t cx, std::int64_t cy, std::int64_t cz) const {
    return (cz * count[1] + cy) * count[0] + cx;
  }

  // Calls visit(j) for every node j ≠ i in the 27 bins around point p (9 in a flat 2D cloud, whose
  // grid has one bin across z): a superset of the nodes within the cut-off of p.
  template <class Visit>
  void for_each_near(const double p[3], std::size_t i, Visit&& visit) const {
    const std::int64_t c[3] = {coordinate(0, p[0]), coordinate(1, p[1]), coordinate(2, p[2])};
    for (std::int64_t cz = std::max<std::int64_t>(c[2] - 1, 0); cz <= std::min(c[2] + 1, count[2] - 1); ++cz)
      for (std::int64_t cy = std::max<std::int64_t>(c[1] - 1, 0); cy <= std::min(c[1] + 1, count[1] - 1); ++cy)
        for (std::int64_t cx = std::max<std::int64_t>(c[0] - 1, 0); cx <= std::min(c[0] + 1, count[0] - 1); ++cx) {
          const auto b = static_cast<std::size_t>(bin(cx, cy, cz));
          for (std::int64_t k = start[b]; k < start[b + 1]; ++k) {
            const auto j = static_cast<std::size_t>(order[static_cast<std::size_t>(k)]);
            if (j != i) visit(j);
          }
        }
  }
};

// Bins the n points (x[0][i], x[1][i], x[2][i]) with bins of edge ≥ cutoff; a sparse cloud in a
// large box gets larger bins so that the bin array stays O(N). Serial and in node order, so the
// grid (and every search over it) is the same for any thread count.
CellGrid make_cell_grid(const double* const x[3], std::size_t n, double cutoff);

}  // namespace pd
