// The fast rows of the LPS kernel's two sweeps, portable: sweep 1's Σ ω|ξ| ext V_j and m'_i,
// sweep 2's force density and W_i, each summed in bond order. Internal to the LPS kernel
// (lps_kernel.cpp and the AVX2 rows, lps_row_avx2.hpp, include it). Each row can start at a given
// bond from given sums: the AVX2 rows leave the last 0–3 bonds of a row to these.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>

#include "materials/lps/lps_kernel.hpp"

namespace pd {
namespace {

// Bonds per chunk of a row: the chunk's terms are computed by loops the compiler vectorises (no
// reduction in them), then summed in bond order by a short scalar loop, so the sums are those of
// a plain loop over the row in order (and the slow exact paths of lps_kernel.hpp give bitwise the same).
constexpr int kChunk = 64;

// One binary for every x86-64 machine, each running its widest code with the same IEEE operations
// (no FMA contraction: solver/CMakeLists.txt), as PMB's kernel (docs/performance.md).
#if defined(__GNUC__) && !defined(__clang__) && defined(__x86_64__)
#define PD_LPS_CLONES __attribute__((target_clones("default", "arch=x86-64-v2", "arch=x86-64-v3")))
#else
#define PD_LPS_CLONES
#endif

// Sweep 1's sums of a row so far: Σ ω|ξ| ext V_j, m'_i = Σ ω|ξ|² V_j (intact bonds), and with
// kBreaking the intact bonds over s0.
struct DilatationSums {
  double theta = 0.0, m = 0.0;
  std::int64_t over = 0;
};

// Sweep 1, row i from the current flags, its bonds from `begin` on, added to `sums`: Σ ω|ξ| ext V_j
// and m'_i; kBreaking also counts the intact bonds over s0 (candidates: no-fail ends are left to
// dilatation_row); kOneBlock skips the gather of the far end's block (one s0 for every bond).
template <Influence kKind, bool kBreaking, bool kOneBlock>
PD_LPS_CLONES DilatationSums dilatation_row_part(const LpsKernel& k, std::int64_t i, const double* s0_row,
                                                 const std::int32_t* block, std::int64_t begin, DilatationSums sums) {
  const double xi0 = k.x[0][i], xi1 = k.x[1][i], xi2 = k.x[2][i];
  const double yi0 = xi0 + k.u[0][i], yi1 = xi1 + k.u[1][i], yi2 = xi2 + k.u[2][i];
  double st = sums.theta, sm = sums.m;
  std::int64_t ov = sums.over;
  const std::int64_t end = k.offsets[i + 1];
  for (std::int64_t base = begin; base < end; base += kChunk) {
    const int m = static_cast<int>(std::min<std::int64_t>(kChunk, end - base));
    std::int64_t jq[kChunk];
    double intact[kChunk], s0q[kChunk], ta[kChunk], tb[kChunk], gq[kChunk];
    for (int q = 0; q < m; ++q) {
      jq[q] = k.neighbour[base + q];
      intact[q] = k.broken[base + q] ? 0.0 : 1.0;
      gq[q] = k.factor ? k.factor[base + q] : 1.0;  // ×1 is exact: without a correction, the same bits
      if constexpr (kBreaking) s0q[q] = kOneBlock ? s0_row[0] : s0_row[block[jq[q]]];
    }
    for (int q = 0; q < m; ++q) {
      const std::int64_t j = jq[q];
      const double d0 = k.x[0][j] - xi0, d1 = k.x[1][j] - xi1, d2 = k.x[2][j] - xi2;
      const double length = std::sqrt(d0 * d0 + d1 * d1 + d2 * d2);
      const double e0 = (k.x[0][j] + k.u[0][j]) - yi0, e1 = (k.x[1][j] + k.u[1][j]) - yi1,
                   e2 = (k.x[2][j] + k.u[2][j]) - yi2;
      const double y = std::sqrt(e0 * e0 + e1 * e1 + e2 * e2);
      const double raw = y - length;
      const double ext = std::fabs(raw) > kLpsStretchZero * length ? raw : 0.0;
      const double omega = influence_of<kKind>(length, k.horizon);
      const double vj = k.volume[j] * k.volume_weight(length) * gq[q];
      ta[q] = intact[q] * (omega * length * ext * vj);
      tb[q] = intact[q] * (omega * length * length * vj);
      if constexpr (kBreaking) ov += (intact[q] > 0.0) & (raw > s0q[q] * length);  // Bond::over
    }
    for (int q = 0; q < m; ++q) {
      st += ta[q];
      sm += tb[q];
    }
  }
  return DilatationSums{st, sm, ov};
}

// Sweep 2's sums of a row so far: the force density and Σ ω (e^d)² V_j.
struct ForceSums {
  double f0 = 0.0, f1 = 0.0, f2 = 0.0, dev = 0.0;
};
// Sweep 2's result for a row: the force density and W_i (lps.hpp).
struct ForceRow {
  double f0, f1, f2, w;
};

// Sweep 2, row i, its bonds from `begin` on, added to `sums`: the force density and W_i (lps.hpp),
// from θ and P of both ends.
template <Influence kKind>
PD_LPS_CLONES ForceRow force_row_part(const LpsKernel& k, std::int64_t i, const double* theta, const double* p,
                                      std::int64_t begin, ForceSums sums) {
  const double xi0 = k.x[0][i], xi1 = k.x[1][i], xi2 = k.x[2][i];
  const double yi0 = xi0 + k.u[0][i], yi1 = xi1 + k.u[1][i], yi2 = xi2 + k.u[2][i];
  const double pi = p[i], ai = k.a[i], th = theta[i], d = k.d;
  double f0 = sums.f0, f1 = sums.f1, f2 = sums.f2, dev = sums.dev;
  const std::int64_t end = k.offsets[i + 1];
  for (std::int64_t base = begin; base < end; base += kChunk) {
    const int m = static_cast<int>(std::min<std::int64_t>(kChunk, end - base));
    std::int64_t jq[kChunk];
    double intact[kChunk], pq[kChunk], aq[kChunk], t0[kChunk], t1[kChunk], t2[kChunk], tw[kChunk], gq[kChunk];
    for (int q = 0; q < m; ++q) {
      jq[q] = k.neighbour[base + q];
      gq[q] = k.factor ? k.factor[base + q] : 1.0;  // ×1 is exact: without a correction, the same bits
      intact[q] = k.broken[base + q] ? 0.0 : 1.0;
      pq[q] = p[jq[q]];
      aq[q] = k.a[jq[q]];
    }
    for (int q = 0; q < m; ++q) {
      const std::int64_t j = jq[q];
      const double d0 = k.x[0][j] - xi0, d1 = k.x[1][j] - xi1, d2 = k.x[2][j] - xi2;
      const double length = std::sqrt(d0 * d0 + d1 * d1 + d2 * d2);
      const double e0 = (k.x[0][j] + k.u[0][j]) - yi0, e1 = (k.x[1][j] + k.u[1][j]) - yi1,
                   e2 = (k.x[2][j] + k.u[2][j]) - yi2;
      const double y = std::sqrt(e0 * e0 + e1 * e1 + e2 * e2);
      const double raw = y - length;
      const double ext = std::fabs(raw) > kLpsStretchZero * length ? raw : 0.0;
      const double inv_y = 1.0 / (y > 0.0 ? y : 1.0);
      const double omega = influence_of<kKind>(length, k.horizon);
      const double vj = k.volume[j] * k.volume_weight(length) * gq[q];
      const double tt = omega * (length * (pi + pq[q]) + (ai + aq[q]) * ext);
      const double scale = intact[q] * (tt * vj * inv_y);
      t0[q] = scale * e0;
      t1[q] = scale * e1;
      t2[q] = scale * e2;
      const double ed = ext - th * length / d;
      tw[q] = intact[q] * (omega * ed * ed * vj);
    }
    for (int q = 0; q < m; ++q) {  // in bond order: the same sums for any thread count
      f0 += t0[q];
      f1 += t1[q];
      f2 += t2[q];
      dev += tw[q];
    }
  }
  return ForceRow{f0, f1, f2, 0.5 * k.kappa[i] * th * th + 0.5 * ai * dev};
}

}  // namespace
}  // namespace pd
