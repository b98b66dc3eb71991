// One row of the PMB kernel written with AVX2 intrinsics: bitwise the portable row (pmb_row.hpp),
// 11–16 % less CPU time per step on the Intel guest of docs/performance.md §3. Internal to the PMB
// kernel (pmb_kernel.cpp includes it and picks this row when the CPU has AVX2).
//
// Why by hand: GCC's vectorised portable row stores each bond's four terms lane by lane into a
// buffer and sums them in bond order in a second loop, so every bond costs four stores and a
// reload. Here the four terms of 4 bonds stay in registers: a 4×4 transpose turns (f0, f1, f2, W)
// per component into one vector per bond, added to the row's sums in bond order. Every bond does
// the same IEEE operations in the same order as bond_terms and pmb_row_part (no FMA: the target is
// "avx2", not "fma"), so the sums and flags are bit for bit those of the portable row; the test
// Kernel.Avx2RowIsBitwiseThePortableRow compares the two over every variant. (Where an input is
// already NaN or infinite, a NaN sum may come out with the other sign: the two rows pass NaN
// operands through in another order. A run stops at the first non-finite u or v anyway:
// run/loop.cpp.)
#pragma once

#include "core/avx2.hpp"
#include "materials/pmb/pmb_row.hpp"

#ifdef PD_HAVE_AVX2_ROWS
namespace pd {
namespace {

using avx2::gather4;
using avx2::squared_norm;

// The same switches and result as pmb_row_part over the whole of row i.
template <bool kBreaking, bool kOneBlock, bool kCorrected = false, bool kUniform = false>
PD_AVX2 RowSums pmb_row_avx2(const PmbArrays& a, std::int64_t i, const double* s0_pair) {
  const double* c_row = a.c_pair + a.block[i] * a.blocks;
  const double* s0_row = kBreaking ? s0_pair + a.block[i] * a.blocks : nullptr;
  const double xi[3] = {a.x[0][i], a.x[1][i], a.x[2][i]};
  const double yi[3] = {xi[0] + a.u[0][i], xi[1] + a.u[1][i], xi[2] + a.u[2][i]};
  const __m256d xi0 = _mm256_set1_pd(xi[0]), xi1 = _mm256_set1_pd(xi[1]), xi2 = _mm256_set1_pd(xi[2]);
  const __m256d yi0 = _mm256_set1_pd(yi[0]), yi1 = _mm256_set1_pd(yi[1]), yi2 = _mm256_set1_pd(yi[2]);
  const __m256d zero = _mm256_setzero_pd(), one = _mm256_set1_pd(1.0), quarter = _mm256_set1_pd(0.25);
  const __m256d stretch_zero = _mm256_set1_pd(kStretchZero);
  const __m256d abs_mask = _mm256_castsi256_pd(_mm256_set1_epi64x(0x7fffffffffffffffLL));
  // c·V of every bond (kUniform), c of the one block (kOneBlock), the one block's s0.
  const __m256d c_v = _mm256_set1_pd(kUniform ? c_row[0] * a.volume[0] : 0.0);
  const __m256d c_one = _mm256_set1_pd(kOneBlock ? c_row[0] : 0.0);
  const __m256d s0_one = _mm256_set1_pd(kBreaking && kOneBlock ? s0_row[0] : 0.0);
  const __m256d nu_outer = _mm256_set1_pd(a.volume_weight.outer), nu_inv_dx = _mm256_set1_pd(a.volume_weight.inv_dx);
  __m256d sums = zero;  // (Σf0, Σf1, Σf2, ΣW) of the row so far, in bond order
  std::int64_t over = 0;
  const std::int64_t end = a.offsets[i + 1];
  std::int64_t k = a.offsets[i];
  for (; k + 4 <= end; k += 4) {
    const std::int64_t j[4] = {a.neighbour[k], a.neighbour[k + 1], a.neighbour[k + 2], a.neighbour[k + 3]};
    const __m256d intact_mask = avx2::intact_mask4(a.broken + k);
    const __m256d intact = _mm256_and_pd(intact_mask, one);  // 1.0 or 0.0, the portable row's intact_q
    // bond_terms, operation by operation.
    const __m256d xj0 = gather4(a.x[0], j), xj1 = gather4(a.x[1], j), xj2 = gather4(a.x[2], j);
    const __m256d length =
        _mm256_sqrt_pd(squared_norm(_mm256_sub_pd(xj0, xi0), _mm256_sub_pd(xj1, xi1), _mm256_sub_pd(xj2, xi2)));
    const __m256d e0 = _mm256_sub_pd(_mm256_add_pd(xj0, gather4(a.u[0], j)), yi0);
    const __m256d e1 = _mm256_sub_pd(_mm256_add_pd(xj1, gather4(a.u[1], j)), yi1);
    const __m256d e2 = _mm256_sub_pd(_mm256_add_pd(xj2, gather4(a.u[2], j)), yi2);
    const __m256d y = _mm256_sqrt_pd(squared_norm(e0, e1, e2));
    const __m256d raw_s = _mm256_div_pd(_mm256_sub_pd(y, length), length);
    // |s| > kStretchZero ? s : 0 (a NaN compares false and gives +0, as the ternary does).
    const __m256d s = _mm256_and_pd(_mm256_cmp_pd(_mm256_and_pd(raw_s, abs_mask), stretch_zero, _CMP_GT_OQ), raw_s);
    const __m256d inv_y = _mm256_div_pd(one, _mm256_blendv_pd(one, y, _mm256_cmp_pd(y, zero, _CMP_GT_OQ)));
    // c ν V_j of each bond, in the portable row's order ((intact·c)·V_j)·ν, then ·g.
    __m256d c_vj;
    std::int64_t bj[4] = {0, 0, 0, 0};
    if constexpr (!kOneBlock)
      for (int q = 0; q < 4; ++q) bj[q] = a.block[j[q]];
    if constexpr (kUniform) {
      c_vj = _mm256_mul_pd(intact, c_v);
    } else {
      const __m256d c = kOneBlock ? c_one : gather4(c_row, bj);
      // VolumeWeight: min(1, max(0, (outer − |ξ|)/dx)); maxpd/minpd return their second operand
      // on a NaN or a tie, as std::max(0.0, v) and std::min(1.0, v) do.
      const __m256d nu =
          _mm256_min_pd(_mm256_max_pd(_mm256_mul_pd(_mm256_sub_pd(nu_outer, length), nu_inv_dx), zero), one);
      c_vj = _mm256_mul_pd(_mm256_mul_pd(_mm256_mul_pd(intact, c), gather4(a.volume, j)), nu);
    }
    if constexpr (kCorrected) c_vj = _mm256_mul_pd(c_vj, _mm256_loadu_pd(a.factor + k));
    if constexpr (kBreaking) {  // over_critical: intact & (s > s0)
      const __m256d s0 = kOneBlock ? s0_one : gather4(s0_row, bj);
      over += __builtin_popcount(_mm256_movemask_pd(_mm256_and_pd(intact_mask, _mm256_cmp_pd(s, s0, _CMP_GT_OQ))));
    }
    const __m256d scale = _mm256_mul_pd(_mm256_mul_pd(c_vj, s), inv_y);  // c s ν V_j / y
    const __m256d t0 = _mm256_mul_pd(scale, e0), t1 = _mm256_mul_pd(scale, e1), t2 = _mm256_mul_pd(scale, e2);
    const __m256d t3 = _mm256_mul_pd(_mm256_mul_pd(_mm256_mul_pd(_mm256_mul_pd(quarter, c_vj), s), s), length);
    sums = avx2::add_in_bond_order(sums, t0, t1, t2, t3);  // bonds k … k+3, in order
  }
  alignas(32) double out[4];
  _mm256_store_pd(out, sums);
  // The last 0–3 bonds: the portable row goes on from these sums, in the same order.
  return pmb_row_part<kBreaking, kOneBlock, kCorrected, kUniform>(a, i, s0_pair, k,
                                                                   RowSums{out[0], out[1], out[2], out[3], over});
}

}  // namespace
}  // namespace pd

#endif
