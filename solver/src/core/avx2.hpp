// What the bond kernels' hand-written AVX2 rows share (materials/pmb/pmb_row_avx2.hpp,
// materials/lps/lps_row_avx2.hpp; docs/performance.md §2): whether this build and this CPU have
// them, the switch that turns them off, and the few vector steps both rows take alike. Every step is the IEEE operation of the
// portable rows, in their order: the rows' results are bitwise those of the portable code.
#pragma once

#include <atomic>

#if defined(__GNUC__) && !defined(__clang__) && defined(__x86_64__)
// GCC on x86-64: the rows are compiled for AVX2 (target "avx2" without "fma", so no product and
// sum are fused) and chosen at run time, so one binary still runs on any x86-64.
#define PD_HAVE_AVX2_ROWS 1
#define PD_AVX2 __attribute__((target("avx2")))

#include <immintrin.h>

#include <cstdint>
#include <cstring>

namespace pd::avx2 {

// p[j[0]], …, p[j[3]] in one vector: 4 scalar loads (hardware gathers were 0.6× on the PMB row).
PD_AVX2 inline __m256d gather4(const double* p, const std::int64_t j[4]) {
  return _mm256_set_pd(p[j[3]], p[j[2]], p[j[1]], p[j[0]]);
}

// d0·d0 + d1·d1 + d2·d2 in the portable rows' order, (d0·d0 + d1·d1) + d2·d2.
PD_AVX2 inline __m256d squared_norm(__m256d d0, __m256d d1, __m256d d2) {
  return _mm256_add_pd(_mm256_add_pd(_mm256_mul_pd(d0, d0), _mm256_mul_pd(d1, d1)), _mm256_mul_pd(d2, d2));
}

// All ones in the lanes of the 4 bonds from `broken` on whose flag byte is 0 (intact), else 0.
PD_AVX2 inline __m256d intact_mask4(const std::uint8_t* broken) {
  std::int32_t flags;
  std::memcpy(&flags, broken, 4);
  return _mm256_castsi256_pd(
      _mm256_cmpeq_epi64(_mm256_cvtepu8_epi64(_mm_cvtsi32_si128(flags)), _mm256_setzero_si256()));
}

// sums + (a, b, c, d) of bond 0, then of bond 1, 2 and 3, where a = (a of bonds 0 … 3) etc.: a
// 4×4 transpose (4 unpacks, 4 lane permutes) and 4 additions, so that each of the 4 sums adds its
// terms in bond order, as the portable rows' scalar loops do.
PD_AVX2 inline __m256d add_in_bond_order(__m256d sums, __m256d a, __m256d b, __m256d c, __m256d d) {
  const __m256d lo_ab = _mm256_unpacklo_pd(a, b), hi_ab = _mm256_unpackhi_pd(a, b);  // bonds 0, 2 | 1, 3
  const __m256d lo_cd = _mm256_unpacklo_pd(c, d), hi_cd = _mm256_unpackhi_pd(c, d);
  sums = _mm256_add_pd(sums, _mm256_permute2f128_pd(lo_ab, lo_cd, 0x20));
  sums = _mm256_add_pd(sums, _mm256_permute2f128_pd(hi_ab, hi_cd, 0x20));
  sums = _mm256_add_pd(sums, _mm256_permute2f128_pd(lo_ab, lo_cd, 0x31));
  return _mm256_add_pd(sums, _mm256_permute2f128_pd(hi_ab, hi_cd, 0x31));
}

}  // namespace pd::avx2
#endif

namespace pd {

// Whether this CPU runs AVX2 (false where this build has no AVX2 rows). Asked once, on first use:
// not by a static initialiser, whose order across files is unspecified.
inline bool cpu_has_avx2() {
#ifdef PD_HAVE_AVX2_ROWS
  static const bool has = __builtin_cpu_supports("avx2");
  return has;
#else
  return false;
#endif
}

// Whether the PMB and LPS kernels may use their AVX2 rows: on by default; off, every row is the
// portable code. The results are the same bits either way: the switch is for the tests that say so
// and for `pd_speed`/`pd_mpi_halo --kernel portable`, which measure what the AVX2 rows gain. Read
// when a kernel's arrays are made (PmbArrays::avx2, LpsKernel::avx2).
inline std::atomic<bool> avx2_rows_enabled{true};
inline void set_avx2_rows(bool enabled) { avx2_rows_enabled.store(enabled, std::memory_order_relaxed); }
inline bool avx2_rows() { return avx2_rows_enabled.load(std::memory_order_relaxed) && cpu_has_avx2(); }

}  // namespace pd
