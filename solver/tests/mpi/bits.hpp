// Test helper of the decomposed-run tests: "bitwise the serial run" as code — two doubles with the
// same bits, and the count of values of two fields whose bits differ — and the fields and notch
// the force tests load their lattices with.
#pragma once
#include <cmath>
#include <cstdint>
#include <cstring>

#include "core/model.hpp"
#include "core/nodes.hpp"

namespace pdtest {

inline bool same_bits(double a, double b) { return std::memcmp(&a, &b, sizeof a) == 0; }

inline std::int64_t differing(const pd::Vec3Array& a, const pd::Vec3Array& b) {
  std::int64_t bad = 0;
  for (std::size_t d = 0; d < 3; ++d)
    for (std::size_t i = 0; i < a[d].size(); ++i) bad += !same_bits(a[d][i], b[d][i]);
  return bad;
}

// A smooth displacement field with no symmetry, so that every row's sum has rounding to get wrong;
// amplitude relative to the lattice spacing dx.
inline pd::Vec3Array wavy(const pd::Model& m, double dx, double amplitude) {
  pd::Vec3Array u = pd::make_vec3(m.nodes.size());
  for (std::size_t i = 0; i < m.nodes.size(); ++i) {
    const double x = m.nodes.x[0][i] / dx, y = m.nodes.x[1][i] / dx, z = m.nodes.x[2][i] / dx;
    u[0][i] = amplitude * dx * std::sin(0.37 * x + 0.11 * y * z);
    u[1][i] = amplitude * dx * std::cos(0.23 * y - 0.05 * x * x);
    u[2][i] = amplitude * dx * std::sin(0.41 * z + 0.07 * x * y + 0.3);
  }
  return u;
}

// Pre-broken bonds: every bond crossing the plane x = 6.5 dx within y < 5 dx (a notch).
inline void notch(pd::Model& m, double dx) {
  for (std::size_t i = 0; i < m.nodes.size(); ++i)
    for (std::int64_t k = m.bonds.offsets[i]; k < m.bonds.offsets[i + 1]; ++k) {
      const auto j = static_cast<std::size_t>(m.bonds.neighbour[static_cast<std::size_t>(k)]);
      const double xi = m.nodes.x[0][i] / dx, xj = m.nodes.x[0][j] / dx;
      if ((xi - 6.5) * (xj - 6.5) < 0 && m.nodes.x[1][i] < 5 * dx && m.nodes.x[1][j] < 5 * dx)
        m.bonds.broken[static_cast<std::size_t>(k)] = 1;
    }
}

}  // namespace pdtest
