// Builds the CSR bond list from reference positions with a cell list (bins of edge ≥ the cut-off).
#include "core/bonds.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "core/cell_grid.hpp"
#include "core/error.hpp"

namespace pd {

namespace {

// Calls visit(j) for every partner j of node i (unordered).
template <class Visit>
void for_each_partner(const Vec3Array& x, const CellGrid& grid, double cutoff2, std::size_t i,
                      Visit&& visit) {
  const double xi = x[0][i], yi = x[1][i], zi = x[2][i];
  const double p[3] = {xi, yi, zi};
  grid.for_each_near(p, i, [&](std::size_t j) {
    // ξ = x_j − x_i; computed the same way from both ends, so |ξ| is bitwise symmetric.
    const double d0 = x[0][j] - xi, d1 = x[1][j] - yi, d2 = x[2][j] - zi;
    const double r2 = d0 * d0 + d1 * d1 + d2 * d2;
    if (r2 > cutoff2) return;
    if (r2 == 0.0)
      throw Error("nodes " + std::to_string(i) + " and " + std::to_string(j) + " have the same reference position");
    visit(static_cast<std::int32_t>(j));
  });
}

}  // namespace

namespace {

void check_search(std::size_t n, double horizon) {
  if (n > static_cast<std::size_t>(std::numeric_limits<std::int32_t>::max()))
    throw Error("too many nodes for 32-bit neighbour indices: " + std::to_string(n));
  if (!(horizon > 0.0) || !std::isfinite(horizon)) throw Error("horizon must be a finite number > 0");
}

// The partner counts of the given rows (rows[r] a node, or every node when rows is null): offsets
// of their CSR rows. Throws pd::Error for coinciding nodes (the first met).
std::vector<std::int64_t> count_rows(const Vec3Array& x, const CellGrid& grid, double cutoff2,
                                     const std::vector<std::int32_t>* rows) {
  const std::size_t count_of_rows = rows ? rows->size() : x[0].size();
  std::vector<std::int64_t> offsets(count_of_rows + 1, 0);
  std::string error;
#pragma omp parallel for schedule(dynamic, 256)
  for (std::int64_t r = 0; r < static_cast<std::int64_t>(count_of_rows); ++r) {
    try {
      const auto i = rows ? static_cast<std::size_t>((*rows)[static_cast<std::size_t>(r)]) : static_cast<std::size_t>(r);
      std::int64_t count = 0;
      for_each_partner(x, grid, cutoff2, i, [&](std::int32_t) { ++count; });
      offsets[static_cast<std::size_t>(r) + 1] = count;
    } catch (const Error& e) {
#pragma omp critical(pd_bond_error)
      if (error.empty()) error = e.what();
    }
  }
  if (!error.empty()) throw Error(error);
  for (std::size_t r = 0; r < count_of_rows; ++r) offsets[r + 1] += offsets[r];
  return offsets;
}

// Two passes (count, then fill) so that each row is written by one thread only.
BondList build_rows(const Vec3Array& x, double horizon, const std::vector<std::int32_t>* rows) {
  const std::size_t n = x[0].size();
  check_search(n, horizon);
  BondList bonds;
  bonds.offsets.assign((rows ? rows->size() : n) + 1, 0);
  if (n == 0) return bonds;
  const double cutoff = horizon * (1.0 + kHorizonTolerance);
  const double* const xp[3] = {x[0].data(), x[1].data(), x[2].data()};
  const CellGrid grid = make_cell_grid(xp, n, cutoff);
  const double cutoff2 = cutoff * cutoff;
  bonds.offsets = count_rows(x, grid, cutoff2, rows);
  const std::size_t count_of_rows = bonds.offsets.size() - 1;
  const auto total = static_cast<std::size_t>(bonds.offsets.back());
  bonds.neighbour.resize(total);
  bonds.broken.assign(total, 0);

#pragma omp parallel for schedule(dynamic, 256)
  for (std::int64_t r = 0; r < static_cast<std::int64_t>(count_of_rows); ++r) {
    const auto i = rows ? static_cast<std::size_t>((*rows)[static_cast<std::size_t>(r)]) : static_cast<std::size_t>(r);
    std::int32_t* row = bonds.neighbour.data() + bonds.offsets[static_cast<std::size_t>(r)];
    std::int32_t* end = row;
    for_each_partner(x, grid, cutoff2, i, [&](std::int32_t j) { *end++ = j; });
    std::sort(row, end);  // ascending j: deterministic order, better locality
  }
  return bonds;
}

}  // namespace

BondList build_bonds(const Vec3Array& x, double horizon) { return build_rows(x, horizon, nullptr); }

BondList build_bond_rows(const Vec3Array& x, double horizon, const std::vector<std::int32_t>& rows) {
  return build_rows(x, horizon, &rows);
}

std::vector<std::int64_t> count_bonds(const Vec3Array& x, double horizon) {
  const std::size_t n = x[0].size();
  check_search(n, horizon);
  if (n == 0) return {0};
  const double cutoff = horizon * (1.0 + kHorizonTolerance);
  const double* const xp[3] = {x[0].data(), x[1].data(), x[2].data()};
  const CellGrid grid = make_cell_grid(xp, n, cutoff);
  return count_rows(x, grid, cutoff * cutoff, nullptr);
}

}  // namespace pd
