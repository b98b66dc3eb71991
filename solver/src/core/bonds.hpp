// The bond list in CSR form, built once from the reference configuration with a cell list.
#pragma once
#include <cstdint>
#include <vector>

#include "core/nodes.hpp"

namespace pd {

// A bond exists for |ξ| ≤ δ·(1 + kHorizonTolerance). The tolerance keeps lattice bonds whose
// length equals δ in exact arithmetic (δ = 3dx) from being dropped by round-off in x_j − x_i,
// without admitting any other lattice distance.
constexpr double kHorizonTolerance = 1e-12;

// Every bond is stored from both ends (i→j in i's row and j→i in j's row), so a loop over nodes
// writes only its own node's force: no atomics, the same result for any thread count
// (LAMMPS PERI stores partners the same way).
struct BondList {
  std::vector<std::int64_t> offsets;    // row i is [offsets[i], offsets[i+1])
  std::vector<std::int32_t> neighbour;  // j, ascending within a row
  std::vector<double> length;           // |ξ| = |x_j − x_i| in the reference configuration
  std::vector<std::uint8_t> broken;     // 1 once the bond has broken (never heals)
  std::vector<double> volume_factor;    // ν: the share of V_j inside the horizon (validation.md F3); 1 by default

  std::size_t nodes() const { return offsets.empty() ? 0 : offsets.size() - 1; }
  std::size_t directed() const { return neighbour.size(); }  // each bond counted twice
};

// Cell list with bins of edge ≥ the cut-off: O(N) in the number of nodes, never O(N²).
// Throws pd::Error if two nodes coincide.
BondList build_bonds(const Vec3Array& x, double horizon);

}  // namespace pd
