// The fast rows of the LPS kernel's two sweeps written with AVX2 intrinsics: bitwise the portable
// rows (lps_row.hpp). Internal to the LPS kernel (lps_kernel.cpp includes it and picks these rows
// when avx2_rows() is on: core/avx2.hpp).
//
// Why by hand, as PMB's row (materials/pmb/pmb_row_avx2.hpp, docs/performance.md §2): GCC's
// vectorised portable rows store each bond's terms lane by lane into per-chunk arrays and sum them
// in bond order in a second loop. Here the terms of 4 bonds stay in registers and are added to the
// row's sums in bond order directly: sweep 1's two sums (Σ ω|ξ| ext V_j, m'_i) as one 128-bit
// vector per bond (two unpacks), sweep 2's four (f0, f1, f2, the deviatoric sum) as one 256-bit
// vector per bond (a 4×4 transpose). Every bond does the same IEEE operations as the portable row in
// the same order (no FMA: the target is "avx2", not "fma", and lps_kernel.cpp is compiled with
// -ffp-contract=off), and the last 0–3 bonds of a row go to the portable row, which continues from
// these sums; the test Lps.Avx2RowsAreBitwiseThePortableRows compares the two. (Where an input is
// already NaN or infinite, a NaN result may come out with another sign or payload: x86 passes on
// the first of two NaN operands, and GCC may order the operands of a commutative operation in the
// portable row either way. A run stops at the first non-finite u or v anyway: run/loop.cpp.)
#pragma once

#include "core/avx2.hpp"
#include "materials/lps/lps_row.hpp"

#ifdef PD_HAVE_AVX2_ROWS
namespace pd {
namespace {

using avx2::gather4;

// What both rows compute of bonds k … k+3 alike (the portable rows' first lines): |ξ|, e = y_j − y_i,
// y, raw = y − |ξ|, ext = raw but 0 where |raw| ≤ kLpsStretchZero·|ξ| (a NaN compares false and
// gives +0, as the ternary does), and the flags: intact_mask all ones on intact bonds, intact 1.0 or 0.0.
struct LpsBonds4 {
  __m256d length, e0, e1, e2, y, raw, ext, intact_mask, intact;
};

struct LpsRowFrame {  // what every bond of row i shares
  __m256d xi0, xi1, xi2, yi0, yi1, yi2;
};

PD_AVX2 inline LpsRowFrame lps_row_frame(const LpsKernel& k, std::int64_t i) {
  const double xi0 = k.x[0][i], xi1 = k.x[1][i], xi2 = k.x[2][i];
  const double yi0 = xi0 + k.u[0][i], yi1 = xi1 + k.u[1][i], yi2 = xi2 + k.u[2][i];
  return LpsRowFrame{_mm256_set1_pd(xi0), _mm256_set1_pd(xi1), _mm256_set1_pd(xi2),
                     _mm256_set1_pd(yi0), _mm256_set1_pd(yi1), _mm256_set1_pd(yi2)};
}

PD_AVX2 inline LpsBonds4 lps_bonds4(const LpsKernel& k, const LpsRowFrame& r, std::int64_t q, const std::int64_t j[4]) {
  const __m256d one = _mm256_set1_pd(1.0);
  const __m256d abs_mask = _mm256_castsi256_pd(_mm256_set1_epi64x(0x7fffffffffffffffLL));
  LpsBonds4 b;
  b.intact_mask = avx2::intact_mask4(k.broken + q);
  b.intact = _mm256_and_pd(b.intact_mask, one);  // broken ? 0.0 : 1.0
  const __m256d xj0 = gather4(k.x[0], j), xj1 = gather4(k.x[1], j), xj2 = gather4(k.x[2], j);
  b.length = _mm256_sqrt_pd(
      avx2::squared_norm(_mm256_sub_pd(xj0, r.xi0), _mm256_sub_pd(xj1, r.xi1), _mm256_sub_pd(xj2, r.xi2)));
  b.e0 = _mm256_sub_pd(_mm256_add_pd(xj0, gather4(k.u[0], j)), r.yi0);
  b.e1 = _mm256_sub_pd(_mm256_add_pd(xj1, gather4(k.u[1], j)), r.yi1);
  b.e2 = _mm256_sub_pd(_mm256_add_pd(xj2, gather4(k.u[2], j)), r.yi2);
  b.y = _mm256_sqrt_pd(avx2::squared_norm(b.e0, b.e1, b.e2));
  b.raw = _mm256_sub_pd(b.y, b.length);
  const __m256d zero_below = _mm256_mul_pd(_mm256_set1_pd(kLpsStretchZero), b.length);
  b.ext = _mm256_and_pd(_mm256_cmp_pd(_mm256_and_pd(b.raw, abs_mask), zero_below, _CMP_GT_OQ), b.raw);
  return b;
}

// ω of the 4 bonds, influence_of's expression: 1 (not used: ω·x is x bit for bit, so the rows skip
// the product), 1/|ξ| by one vector division, the Gaussian by std::exp lane by lane (no vector exp
// gives its bits; influence_of itself is called, so the lane's value is the portable row's).
template <Influence kKind>
PD_AVX2 inline __m256d lps_influence4(__m256d length, double horizon) {
  if constexpr (kKind == Influence::inverse_length) {
    return _mm256_div_pd(_mm256_set1_pd(1.0), length);
  } else if constexpr (kKind == Influence::gaussian) {
    alignas(32) double l[4];
    _mm256_store_pd(l, length);
    const double w0 = influence_of<kKind>(l[0], horizon), w1 = influence_of<kKind>(l[1], horizon);
    const double w2 = influence_of<kKind>(l[2], horizon), w3 = influence_of<kKind>(l[3], horizon);
    return _mm256_set_pd(w3, w2, w1, w0);
  } else {
    return _mm256_set1_pd(1.0);
  }
}

// ω·x: x itself for ω = 1 (1·x is x, bit for bit).
template <Influence kKind>
PD_AVX2 inline __m256d lps_weigh(__m256d omega, __m256d x) {
  if constexpr (kKind == Influence::one) return x;
  else return _mm256_mul_pd(omega, x);
}

// V_j ν(|ξ|) g_q of the 4 bonds, in the portable order (V_j·ν)·g; VolumeWeight's
// min(1, max(0, (outer − |ξ|)·inv_dx)) by maxpd/minpd, which return their second operand on a NaN
// or a tie, as std::max(0.0, v) and std::min(1.0, v) return their first. Without a correction the
// portable row multiplies by g = 1, which is exact: skipped.
PD_AVX2 inline __m256d lps_weighted_volume4(const LpsKernel& k, std::int64_t q, const std::int64_t j[4], __m256d length) {
  const __m256d outer = _mm256_set1_pd(k.volume_weight.outer), inv_dx = _mm256_set1_pd(k.volume_weight.inv_dx);
  const __m256d nu = _mm256_min_pd(
      _mm256_max_pd(_mm256_mul_pd(_mm256_sub_pd(outer, length), inv_dx), _mm256_setzero_pd()), _mm256_set1_pd(1.0));
  __m256d vj = _mm256_mul_pd(gather4(k.volume, j), nu);
  if (k.factor) vj = _mm256_mul_pd(vj, _mm256_loadu_pd(k.factor + q));
  return vj;
}

// The same switches and result as dilatation_row_part over the whole of row i.
template <Influence kKind, bool kBreaking, bool kOneBlock>
PD_AVX2 DilatationSums dilatation_row_avx2(const LpsKernel& k, std::int64_t i, const double* s0_row,
                                           const std::int32_t* block) {
  const LpsRowFrame frame = lps_row_frame(k, i);
  const __m256d s0_one = _mm256_set1_pd(kBreaking && kOneBlock ? s0_row[0] : 0.0);
  __m128d sums = _mm_setzero_pd();  // (Σ ω|ξ| ext V_j, m'_i) of the row so far, in bond order
  std::int64_t over = 0;
  const std::int64_t end = k.offsets[i + 1];
  std::int64_t q = k.offsets[i];
  for (; q + 4 <= end; q += 4) {
    const std::int64_t j[4] = {k.neighbour[q], k.neighbour[q + 1], k.neighbour[q + 2], k.neighbour[q + 3]};
    const LpsBonds4 b = lps_bonds4(k, frame, q, j);
    const __m256d omega = lps_influence4<kKind>(b.length, k.horizon);
    const __m256d vj = lps_weighted_volume4(k, q, j, b.length);
    const __m256d wl = lps_weigh<kKind>(omega, b.length);                        // ω|ξ|
    const __m256d ta = _mm256_mul_pd(b.intact, _mm256_mul_pd(_mm256_mul_pd(wl, b.ext), vj));     // ((ω|ξ|)·ext)·V_j
    const __m256d tb = _mm256_mul_pd(b.intact, _mm256_mul_pd(_mm256_mul_pd(wl, b.length), vj));  // ((ω|ξ|)·|ξ|)·V_j
    if constexpr (kBreaking) {  // Bond::over of the intact bonds: raw > s0·|ξ|
      __m256d s0 = s0_one;
      if constexpr (!kOneBlock) {
        const std::int64_t bj[4] = {block[j[0]], block[j[1]], block[j[2]], block[j[3]]};
        s0 = gather4(s0_row, bj);
      }
      const __m256d over_mask = _mm256_cmp_pd(b.raw, _mm256_mul_pd(s0, b.length), _CMP_GT_OQ);
      over += __builtin_popcount(_mm256_movemask_pd(_mm256_and_pd(b.intact_mask, over_mask)));
    }
    // (ta, tb) of bonds q … q+3 → one (ta, tb) pair per bond, added in bond order.
    const __m256d lo = _mm256_unpacklo_pd(ta, tb), hi = _mm256_unpackhi_pd(ta, tb);  // bonds 0, 2 and 1, 3
    sums = _mm_add_pd(sums, _mm256_castpd256_pd128(lo));
    sums = _mm_add_pd(sums, _mm256_castpd256_pd128(hi));
    sums = _mm_add_pd(sums, _mm256_extractf128_pd(lo, 1));
    sums = _mm_add_pd(sums, _mm256_extractf128_pd(hi, 1));
  }
  alignas(16) double out[2];
  _mm_store_pd(out, sums);
  // The last 0–3 bonds: the portable row goes on from these sums, in the same order.
  return dilatation_row_part<kKind, kBreaking, kOneBlock>(k, i, s0_row, block, q, DilatationSums{out[0], out[1], over});
}

// The same result as force_row_part over the whole of row i.
template <Influence kKind>
PD_AVX2 ForceRow force_row_avx2(const LpsKernel& k, std::int64_t i, const double* theta, const double* p) {
  const LpsRowFrame frame = lps_row_frame(k, i);
  const __m256d pi = _mm256_set1_pd(p[i]), ai = _mm256_set1_pd(k.a[i]), th = _mm256_set1_pd(theta[i]);
  const __m256d d = _mm256_set1_pd(k.d), zero = _mm256_setzero_pd(), one = _mm256_set1_pd(1.0);
  __m256d sums = zero;  // (f0, f1, f2, Σ ω (e^d)² V_j) of the row so far, in bond order
  const std::int64_t end = k.offsets[i + 1];
  std::int64_t q = k.offsets[i];
  for (; q + 4 <= end; q += 4) {
    const std::int64_t j[4] = {k.neighbour[q], k.neighbour[q + 1], k.neighbour[q + 2], k.neighbour[q + 3]};
    const LpsBonds4 b = lps_bonds4(k, frame, q, j);
    // 1/y, 1 for a bond crushed to a point (y = 0).
    const __m256d inv_y = _mm256_div_pd(one, _mm256_blendv_pd(one, b.y, _mm256_cmp_pd(b.y, zero, _CMP_GT_OQ)));
    const __m256d omega = lps_influence4<kKind>(b.length, k.horizon);
    const __m256d vj = lps_weighted_volume4(k, q, j, b.length);
    const __m256d pq = gather4(p, j), aq = gather4(k.a, j);
    // tt = ω·(|ξ|·(P_i + P_j) + (a_i + a_j)·ext)
    const __m256d tt = lps_weigh<kKind>(
        omega, _mm256_add_pd(_mm256_mul_pd(b.length, _mm256_add_pd(pi, pq)), _mm256_mul_pd(_mm256_add_pd(ai, aq), b.ext)));
    const __m256d scale = _mm256_mul_pd(b.intact, _mm256_mul_pd(_mm256_mul_pd(tt, vj), inv_y));  // intact·((tt·V_j)·(1/y))
    const __m256d t0 = _mm256_mul_pd(scale, b.e0), t1 = _mm256_mul_pd(scale, b.e1), t2 = _mm256_mul_pd(scale, b.e2);
    const __m256d ed = _mm256_sub_pd(b.ext, _mm256_div_pd(_mm256_mul_pd(th, b.length), d));  // ext − (θ|ξ|)/d
    const __m256d tw = _mm256_mul_pd(b.intact, _mm256_mul_pd(_mm256_mul_pd(lps_weigh<kKind>(omega, ed), ed), vj));
    sums = avx2::add_in_bond_order(sums, t0, t1, t2, tw);  // bonds q … q+3, in order
  }
  alignas(32) double out[4];
  _mm256_store_pd(out, sums);
  // The last 0–3 bonds, and W_i from the deviatoric sum: the portable row, from these sums.
  return force_row_part<kKind>(k, i, theta, p, q, ForceSums{out[0], out[1], out[2], out[3]});
}

}  // namespace
}  // namespace pd

#endif
