// Builds a cell list over a point cloud (see cell_grid.hpp).
#include "core/cell_grid.hpp"

namespace pd {

CellGrid make_cell_grid(const double* const x[3], std::size_t n, double cutoff) {
  CellGrid grid;
  double hi[3] = {0, 0, 0};
  for (int d = 0; d < 3; ++d) {
    grid.lo[d] = n ? *std::min_element(x[d], x[d] + n) : 0.0;
    hi[d] = n ? *std::max_element(x[d], x[d] + n) : 0.0;
  }
  // Bins of edge ≥ cut-off, so every partner lies in the 27 bins around a node.
  grid.edge = cutoff;
  const double max_bins = 2.0 * static_cast<double>(n) + 1000.0;
  // The counts in double first: a node far from the others (a 1e300 coordinate) must make the bins
  // larger, not overflow the integer count (issue 17, item 9). An extent beyond what a double can
  // hold is refused by the node-file reader, so `total` is finite here.
  for (;;) {
    double total = 1.0;
    double count[3];
    for (int d = 0; d < 3; ++d) {
      count[d] = std::floor((hi[d] - grid.lo[d]) / grid.edge) + 1.0;
      total *= count[d];
    }
    if (total <= max_bins) {
      for (int d = 0; d < 3; ++d) grid.count[d] = static_cast<std::int64_t>(count[d]);
      break;
    }
    grid.edge *= 1.5;  // the factor the bond lists of existing runs were built with
  }
  const std::int64_t bins = grid.count[0] * grid.count[1] * grid.count[2];
  std::vector<std::int64_t> node_bin(n);
  grid.start.assign(static_cast<std::size_t>(bins) + 1, 0);
  for (std::size_t i = 0; i < n; ++i) {
    node_bin[i] = grid.bin(grid.coordinate(0, x[0][i]), grid.coordinate(1, x[1][i]), grid.coordinate(2, x[2][i]));
    ++grid.start[static_cast<std::size_t>(node_bin[i]) + 1];
  }
  for (std::int64_t b = 0; b < bins; ++b) grid.start[static_cast<std::size_t>(b) + 1] += grid.start[static_cast<std::size_t>(b)];
  grid.order.resize(n);
  std::vector<std::int64_t> fill(grid.start.begin(), grid.start.end() - 1);
  for (std::size_t i = 0; i < n; ++i)
    grid.order[static_cast<std::size_t>(fill[static_cast<std::size_t>(node_bin[i])]++)] = static_cast<std::int32_t>(i);
  return grid;
}

}  // namespace pd
