// Bonds crossing the pre-crack segments of the case start broken (core/cracks.hpp).
#include "core/cracks.hpp"

namespace pd {

namespace {

// Twice the signed area of the triangle o, a, b: > 0 when b lies to the left of o→a.
double orientation(const double o[2], const double a[2], const double b[2]) {
  return (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0]);
}

}  // namespace

bool segments_cross(const double p[2], const double q[2], const double a[2], const double b[2]) {
  // Proper crossing: p and q strictly on opposite sides of line ab, and a and b strictly on
  // opposite sides of line pq (the standard orientation test).
  const double ab_p = orientation(a, b, p), ab_q = orientation(a, b, q);
  const double pq_a = orientation(p, q, a), pq_b = orientation(p, q, b);
  return ((ab_p > 0.0 && ab_q < 0.0) || (ab_p < 0.0 && ab_q > 0.0)) &&
         ((pq_a > 0.0 && pq_b < 0.0) || (pq_a < 0.0 && pq_b > 0.0));
}

std::int64_t cut_crossing_bonds(const std::vector<CrackSegment>& cracks, const Vec3Array& x, BondList& bonds,
                                const std::vector<std::int32_t>* rows) {
  if (cracks.empty()) return 0;
  const auto n = static_cast<std::int64_t>(bonds.nodes());
  std::int64_t cut = 0;  // integer sum: exact in any order
#pragma omp parallel for schedule(static) reduction(+ : cut)
  for (std::int64_t r = 0; r < n; ++r) {
    const auto row = static_cast<std::size_t>(r);
    const auto ii = rows ? static_cast<std::size_t>((*rows)[row]) : row;
    const double p[2] = {x[0][ii], x[1][ii]};
    for (std::int64_t k = bonds.offsets[row]; k < bonds.offsets[row + 1]; ++k) {
      const auto j = static_cast<std::size_t>(bonds.neighbour[static_cast<std::size_t>(k)]);
      const double q[2] = {x[0][j], x[1][j]};
      for (const auto& crack : cracks) {
        const double a[2] = {crack.from[0], crack.from[1]}, b[2] = {crack.to[0], crack.to[1]};
        // Both copies of a bond must break together (materials/pmb/pmb.hpp relies on it, and so does
        // momentum). The test is symmetric in p, q in exact arithmetic only: orientation(p, q, a)
        // and orientation(q, p, a) round differently, so a crack end nearly in line with a bond
        // could split the copies. Test every bond with its lower-index end first.
        const bool crosses = ii < j ? segments_cross(p, q, a, b) : segments_cross(q, p, a, b);
        if (crosses) {
          bonds.broken[static_cast<std::size_t>(k)] = 1;
          if (ii < j) ++cut;
          break;
        }
      }
    }
  }
  return cut;
}

}  // namespace pd
