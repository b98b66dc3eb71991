// One row of the PMB kernel, portable: the terms of bond i→j that every pass computes alike, and
// the row's force density and strain energy summed in bond order. Internal to the PMB kernel
// (pmb_kernel.cpp and the AVX2 row, pmb_row_avx2.hpp, include it).
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>

#include "materials/pmb/pmb.hpp"

namespace pd {
namespace {

// What every pass needs of bond i→j: the reference length |ξ| (recomputed exactly as
// build_bonds computed it), the current bond vector e = y_j − y_i, its length y, and the stretch
// s = (y − |ξ|)/|ξ| (thesis eq. 1.9), zeroed near machine precision (thesis §2.2). Every pass
// computes it this one way, so both copies of a bond (y_j − y_i is the exact negative of y_i − y_j)
// and the force and breaking passes see bitwise the same stretch.
struct BondTerms {
  double e0, e1, e2, y, length, s, inv_y;  // inv_y = 1/y (1 for a bond crushed to a point, y = 0)
};

inline BondTerms bond_terms(const PmbArrays& a, const double xi[3], const double yi[3], std::int64_t j) {
  BondTerms b;
  const double d0 = a.x[0][j] - xi[0], d1 = a.x[1][j] - xi[1], d2 = a.x[2][j] - xi[2];
  b.length = std::sqrt(d0 * d0 + d1 * d1 + d2 * d2);  // core/bonds.hpp bond_length
  b.e0 = (a.x[0][j] + a.u[0][j]) - yi[0];
  b.e1 = (a.x[1][j] + a.u[1][j]) - yi[1];
  b.e2 = (a.x[2][j] + a.u[2][j]) - yi[2];
  b.y = std::sqrt(b.e0 * b.e0 + b.e1 * b.e1 + b.e2 * b.e2);
  const double s = (b.y - b.length) / b.length;
  b.s = std::fabs(s) > kStretchZero ? s : 0.0;
  // A bond crushed to a point (y = 0) has e = 0 and no direction: 1/y is replaced by 1, so its
  // force is 0, without a branch around the division.
  b.inv_y = 1.0 / (b.y > 0.0 ? b.y : 1.0);
  return b;
}

// A candidate for breaking: an intact bond stretched beyond s0 of its block pair. Bitwise &, so
// that the force loop stays free of branches; no-fail ends are left to break_row (a byte gather
// would keep the force loop from vectorising).
inline bool over_critical(bool intact, double s, double s0) { return intact & (s > s0); }

// Bonds per chunk of a row: the chunk's terms are computed by a loop the compiler vectorises
// (no reduction in it), then summed in bond order by a short scalar loop.
constexpr int kChunk = 64;

// One binary for every x86-64 machine, each running the widest code it can: GCC compiles the row
// three times, for baseline x86-64 (SSE2), x86-64-v2 (SSE4.2: 64-bit lane extracts, so the loop
// vectorises) and x86-64-v3 (AVX2, 4 lanes), and picks one at load time. All do the same IEEE
// operations in the same order (no FMA contraction, no reassociation), so results are bitwise the
// same on any CPU — unlike -march=native, whose binary may not run on the CI machine and whose FMAs
// would change the last bits (docs/performance.md).
#if defined(__GNUC__) && !defined(__clang__) && defined(__x86_64__)
#define PD_KERNEL_CLONES __attribute__((target_clones("default", "arch=x86-64-v2", "arch=x86-64-v3")))
#else
#define PD_KERNEL_CLONES
#endif

struct RowSums {
  double f0, f1, f2, w;    // Σ over the row of the force density components and of W_i's terms
  std::int64_t over = 0;   // bonds over their critical stretch (kBreaking only)
};

// Row i of the kernel from the current flags, its bonds from `begin` on, added to `sums` (the
// AVX2 row, pmb_row_avx2.hpp, leaves its last 0–3 bonds to this one); kBreaking also counts the
// bonds over their critical stretch, kOneBlock skips the gathers of the far end's block,
// kCorrected multiplies each bond's c by its surface-correction factor g_k
// (core/surface_correction), kUniform (PmbArrays::uniform: one block, no correction, full volumes,
// one V for every node) skips the gather of V_j and ν = 1: c ν V_j = ((intact·c)·V)·1 is
// intact·(c·V) bit for bit, intact being 0 or 1. Compile-time switches, so that the loop has no
// branch in it and vectorises in every variant (and without a correction it is the same code,
// bitwise, as before there was one).
template <bool kBreaking, bool kOneBlock, bool kCorrected = false, bool kUniform = false>
PD_KERNEL_CLONES RowSums pmb_row_part(const PmbArrays& a, std::int64_t i, const double* s0_pair, std::int64_t begin,
                                      RowSums sums) {
  const double* c_row = a.c_pair + a.block[i] * a.blocks;
  const double c_v = kUniform ? c_row[0] * a.volume[0] : 0.0;  // c·V of every bond (kUniform)
  const double* s0_row = kBreaking ? s0_pair + a.block[i] * a.blocks : nullptr;
  const double xi[3] = {a.x[0][i], a.x[1][i], a.x[2][i]};
  const double yi[3] = {xi[0] + a.u[0][i], xi[1] + a.u[1][i], xi[2] + a.u[2][i]};
  double sum0 = sums.f0, sum1 = sums.f1, sum2 = sums.f2, energy = sums.w;
  std::int64_t over = sums.over;
  const std::int64_t end = a.offsets[i + 1];
  for (std::int64_t k0 = begin; k0 < end; k0 += kChunk) {
    const int m = static_cast<int>(std::min<std::int64_t>(kChunk, end - k0));
    // The chunk's bytes and 32-bit indices, widened first: GCC sizes the vector loop by its
    // narrowest type, so one byte load in it would make it 32 bonds wide under AVX2 and spill
    // most of its registers; with only 64-bit types it is 4 bonds wide (docs/performance.md §2).
    std::int64_t j_q[kChunk], block_q[kChunk];
    double intact_q[kChunk], g_q[kChunk];
    for (int q = 0; q < m; ++q) {
      j_q[q] = a.neighbour[k0 + q];
      intact_q[q] = a.broken[k0 + q] == 0 ? 1.0 : 0.0;
      if constexpr (!kOneBlock) block_q[q] = a.block[j_q[q]];
      if constexpr (kCorrected) g_q[q] = a.factor[k0 + q];
    }
    // A bond's four terms side by side, so that the in-order sum below adds them as one vector
    // per bond; rows of 8 rather than 4, so that GCC stores them lane by lane instead of
    // transposing four vectors with shuffles (the port the gathers above already keep busy).
    alignas(64) double t[kChunk][8];
    for (int q = 0; q < m; ++q) {
      const std::int64_t j = j_q[q];
      const BondTerms b = bond_terms(a, xi, yi, j);
      const std::int64_t bj = kOneBlock ? 0 : block_q[q];
      const double intact = intact_q[q];
      if constexpr (kBreaking) over += over_critical(intact > 0.0, b.s, s0_row[bj]);
      // Broken bonds are multiplied by 0 rather than skipped: no branch, so the loop vectorises.
      double c_vj;
      if constexpr (kUniform) c_vj = intact * c_v;
      else c_vj = intact * c_row[bj] * a.volume[j] * a.volume_weight(b.length);
      if constexpr (kCorrected) c_vj *= g_q[q];
      const double scale = c_vj * b.s * b.inv_y;  // c s ν V_j / y
      t[q][0] = scale * b.e0;
      t[q][1] = scale * b.e1;
      t[q][2] = scale * b.e2;
      t[q][3] = 0.25 * c_vj * b.s * b.s * b.length;
    }
    for (int q = 0; q < m; ++q) {  // in bond order: the same sums for any thread count
      sum0 += t[q][0];
      sum1 += t[q][1];
      sum2 += t[q][2];
      energy += t[q][3];
    }
  }
  return RowSums{sum0, sum1, sum2, energy, over};
}

}  // namespace
}  // namespace pd
