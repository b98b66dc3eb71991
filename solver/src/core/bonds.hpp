// The bond list in CSR form, built once from the reference configuration with a cell list.
#pragma once
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

#include "core/nodes.hpp"

namespace pd {

// A bond exists for |ξ| ≤ δ·(1 + kHorizonTolerance). The tolerance keeps lattice bonds whose
// length equals δ in exact arithmetic (δ = 3dx) from being dropped by round-off in x_j − x_i,
// without admitting any other lattice distance.
constexpr double kHorizonTolerance = 1e-12;

// |ξ| = |x_j − x_i| of bond i→j, computed exactly as build_bonds computed it: x_j − x_i is the
// exact negative of x_i − x_j, so both copies of a bond see bitwise the same length.
inline double bond_length(const Vec3Array& x, std::size_t i, std::size_t j) {
  const double d0 = x[0][j] - x[0][i], d1 = x[1][j] - x[1][i], d2 = x[2][j] - x[2][i];
  return std::sqrt(d0 * d0 + d1 * d1 + d2 * d2);
}

// ν(|ξ|), the share of V_j inside the horizon (docs/theory.md T5): every rule we have is
// ν = clamp((outer − |ξ|)/dx, 0, 1) — LAMMPS's (δ − |ξ|)/dx + ½ and HHB's (δ − |ξ| + dx/2)/dx
// both have outer = δ + dx/2; full volumes have outer = +∞, so ν = 1. Two numbers instead of
// eight bytes per bond (core/partial_volume sets them).
struct VolumeWeight {
  double outer = HUGE_VAL;  // [m]
  double inv_dx = 1.0;      // [1/m]
  double operator()(double length) const { return std::min(1.0, std::max(0.0, (outer - length) * inv_dx)); }
};

// Every bond is stored from both ends (i→j in i's row and j→i in j's row), so a loop over nodes
// writes only its own node's force: no atomics, the same result for any thread count
// (LAMMPS PERI stores partners the same way).
// Five bytes per directed bond (docs/performance.md): bond data is streamed once per force
// evaluation, so what is cheaper to recompute than to load is not stored: |ξ| comes from the
// reference positions (bond_length, bitwise what the builder saw), ν from |ξ| (VolumeWeight).
struct BondList {
  std::vector<std::int64_t> offsets;    // row i is [offsets[i], offsets[i+1])
  std::vector<std::int32_t> neighbour;  // j, ascending within a row
  std::vector<std::uint8_t> broken;     // 1 once the bond has broken (never heals)
  VolumeWeight volume_weight;           // ν(|ξ|) of every bond; full volumes unless a rule set it
  // g_k, the surface-correction factor of directed bond k (core/surface_correction: Le & Bobaru
  // 2018), the same for both copies of a bond; empty without a correction (then g = 1, and no
  // kernel reads it: results are bitwise those of a build without it). 8 bytes per directed bond.
  std::vector<double> surface_factor;
  // The split surface correction's per-node factors of LPS's two moduli (core/surface_correction.hpp,
  // measured there; no case-file method sets them): surface_moduli[2i] multiplies node i's bulk
  // modulus, surface_moduli[2i + 1] its shear modulus. Empty otherwise (then LPS scales both by the
  // mean of its g, lps.hpp).
  std::vector<double> surface_moduli;

  bool corrected() const { return !surface_factor.empty(); }
  double factor(std::size_t k) const { return surface_factor.empty() ? 1.0 : surface_factor[k]; }

  std::size_t nodes() const { return offsets.empty() ? 0 : offsets.size() - 1; }
  std::size_t directed() const { return neighbour.size(); }  // each bond counted twice
};

// Cell list with bins of edge ≥ the cut-off: O(N) in the number of nodes, never O(N²).
// Throws pd::Error if two nodes coincide.
BondList build_bonds(const Vec3Array& x, double horizon);
// The rows of the nodes `rows` only (row r is node rows[r]'s, neighbours numbered globally, in
// the same ascending order build_bonds gives them): a rank of a decomposed run builds the rows it
// owns without the whole list (issue 15). Offsets have rows.size() + 1 entries.
BondList build_bond_rows(const Vec3Array& x, double horizon, const std::vector<std::int32_t>& rows);
// build_bonds's offsets alone (the partners counted, not stored): 8 bytes per node instead of
// ≈ 5 per directed bond. Throws what build_bonds throws.
std::vector<std::int64_t> count_bonds(const Vec3Array& x, double horizon);

}  // namespace pd
