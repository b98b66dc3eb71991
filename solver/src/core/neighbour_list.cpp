// Builds and refreshes the contact Verlet list (see neighbour_list.hpp).
#include "core/neighbour_list.hpp"

#include <omp.h>

#include <chrono>
#include <cmath>
#include <string>

#include "core/cell_grid.hpp"
#include "core/error.hpp"

namespace pd {

ContactPairs NeighbourList::search(const Vec3Array& x, const Vec3Array& u, const std::vector<std::int32_t>& block,
                                const ContactParameters& p) {
  ContactPairs out;
  Scratch scratch;
  search(x, u, block, p, out, scratch);
  return out;
}

void NeighbourList::search(const Vec3Array& x, const Vec3Array& u, const std::vector<std::int32_t>& block,
                        const ContactParameters& p, ContactPairs& out, Scratch& scratch, const std::uint8_t* rows) {
  const std::size_t n = x[0].size();
  out.offsets.assign(n + 1, 0);
  out.neighbour.clear();
  out.distance.clear();
  if (n == 0) return;
  Vec3Array& y = scratch.y;
  for (std::size_t d = 0; d < 3; ++d) {
    y[d].resize(n);
    for (std::size_t i = 0; i < n; ++i) y[d][i] = x[d][i] + u[d][i];
  }
  const double reach = p.distance + p.skin;
  const double* const yp[3] = {y[0].data(), y[1].data(), y[2].data()};
  // Bins of edge ≥ contact distance + skin: every candidate lies in the neighbouring bins.
  const CellGrid grid = make_cell_grid(yp, n, reach);
  const double reach2 = reach * reach;
  const double bonded2 = p.bond_cutoff * p.bond_cutoff;

  // The candidates j of row i within contact distance + skin of node i now.
  auto for_each = [&](std::size_t i, auto&& visit) {
    const double pi[3] = {y[0][i], y[1][i], y[2][i]};
    grid.for_each_near(pi, i, [&](std::size_t j) {
      if (!p.self_contact && block[i] == block[j]) return;
      const double e0 = y[0][j] - pi[0], e1 = y[1][j] - pi[1], e2 = y[2][j] - pi[2];
      if (e0 * e0 + e1 * e1 + e2 * e2 > reach2) return;
      visit(static_cast<std::int32_t>(j));
    });
  };
  // d_ij of a pair from the reference length x_j − x_i: bitwise the same from both ends, so d_ij = d_ji.
  auto pair_distance = [&](std::size_t i, std::size_t j) {
    const double x0 = x[0][j] - x[0][i], x1 = x[1][j] - x[1][i], x2 = x[2][j] - x[2][i];
    const double xi2 = x0 * x0 + x1 * x1 + x2 * x2;
    return contact_distance(std::sqrt(xi2), xi2 <= bonded2, p.distance);
  };
  // One pass over the cells: each thread finds the rows of its contiguous share of the nodes
  // (schedule static: one block per thread) into its own buffer of j's, row after row, each row
  // sorted so that the list (and every sum over it) does not depend on the bin layout or the
  // thread count; then the offsets are summed and each thread writes its rows into place.
  auto& found = scratch.found;
  found.resize(static_cast<std::size_t>(omp_get_max_threads()));
#pragma omp parallel
  {
    std::vector<std::int32_t>& mine = found[static_cast<std::size_t>(omp_get_thread_num())];
    mine.clear();
    std::int64_t first = 0, last = -1;  // this thread's rows [first, last]
#pragma omp for schedule(static)
    for (std::int64_t i = 0; i < static_cast<std::int64_t>(n); ++i) {
      if (last < first) first = i;
      last = i;
      const std::size_t row_start = mine.size();
      if (!rows || rows[i]) for_each(static_cast<std::size_t>(i), [&](std::int32_t j) { mine.push_back(j); });
      std::sort(mine.begin() + static_cast<std::ptrdiff_t>(row_start), mine.end());
      out.offsets[static_cast<std::size_t>(i) + 1] = static_cast<std::int64_t>(mine.size() - row_start);
    }
#pragma omp single
    {
      for (std::size_t i = 0; i < n; ++i) out.offsets[i + 1] += out.offsets[i];
      out.neighbour.resize(static_cast<std::size_t>(out.offsets[n]));
      out.distance.resize(out.neighbour.size());
    }  // the barrier after single: the offsets and arrays are ready for every thread
    std::size_t from = 0;
    for (std::int64_t i = first; i <= last; ++i)
      for (auto k = static_cast<std::size_t>(out.offsets[static_cast<std::size_t>(i)]);
           k < static_cast<std::size_t>(out.offsets[static_cast<std::size_t>(i) + 1]); ++k) {
        const std::int32_t j = mine[from++];
        out.neighbour[k] = j;
        out.distance[k] = pair_distance(static_cast<std::size_t>(i), static_cast<std::size_t>(j));
      }
  }
}

bool NeighbourList::update(const Vec3Array& x, const Vec3Array& u, const std::vector<std::int32_t>& block,
                        const ContactParameters& p) {
  const auto n = static_cast<std::int64_t>(x[0].size());
  bool stale = rebuilds_ == 0 || static_cast<std::int64_t>(u_build_[0].size()) != n;
  if (!stale) {
    const int moved = moved_since_build(u, p);
    // A non-finite state cannot be binned; the time loop stops on it after this step anyway.
    if (moved == 2) return false;
    stale = moved != 0;
  }
  if (!stale) return false;
  const auto start = std::chrono::steady_clock::now();
  search(x, u, block, p, pairs_, scratch_);
  u_build_ = u;
  ++rebuilds_;
  seconds_ += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return true;
}

int NeighbourList::moved_since_build(const Vec3Array& u, const ContactParameters& p) const {
  // The Verlet-skin criterion: rebuild once any node has moved more than skin/2 (max is exact,
  // so the decision does not depend on the thread count, nor on the rank count: forces/contact_on_piece).
  const auto n = static_cast<std::int64_t>(u[0].size());
  const double limit2 = 0.25 * p.skin * p.skin;
  int moved = 0;  // 1: moved too far; 2: non-finite
#pragma omp parallel for schedule(static) reduction(max : moved)
  for (std::int64_t i = 0; i < n; ++i) {
    const auto s = static_cast<std::size_t>(i);
    const double d0 = u[0][s] - u_build_[0][s], d1 = u[1][s] - u_build_[1][s], d2 = u[2][s] - u_build_[2][s];
    const double r2 = d0 * d0 + d1 * d1 + d2 * d2;
    if (!std::isfinite(r2)) moved = 2;
    else if (r2 > limit2) moved = std::max(moved, 1);
  }
  return moved;
}

void NeighbourList::record_build(ContactPairs& pairs, const Vec3Array& u_build, double seconds, bool counted) {
  std::swap(pairs_, pairs);
  u_build_ = u_build;
  rebuilds_ += counted ? 1 : 0;
  seconds_ += seconds;
}

void NeighbourList::restore_record(const Vec3Array& u_build, std::int64_t rebuilds, double seconds) {
  pairs_ = ContactPairs{};
  u_build_ = u_build;
  rebuilds_ = rebuilds;
  seconds_ = seconds;
}

void NeighbourList::restore(const Vec3Array& x, const Vec3Array& u_build, const std::vector<std::int32_t>& block,
                         const ContactParameters& p, std::int64_t rebuilds, double seconds) {
  pairs_ = rebuilds > 0 ? search(x, u_build, block, p) : ContactPairs{};
  u_build_ = u_build;
  rebuilds_ = rebuilds;
  seconds_ = seconds;
}

}  // namespace pd
