// An exact sum of doubles (issue 15): a fixed-size integer accumulator that holds any sum of
// doubles without rounding, so the sum does not depend on the order of its terms — nor on how they
// are split over threads or MPI ranks — and is rounded once, to the nearest double, at the end.
//
// Every finite double is m·2^(e) with an integer m < 2^53 and −1074 ≤ e ≤ 971, i.e. an integer
// multiple of 2^−1074 below 2^1024: a fixed-point number of 2098 bits. The accumulator holds it as
// kDigits signed 64-bit limbs, limb k weighing 2^(32k − 1074) (the Kulisch accumulator, with
// 32-bit digits in 64-bit limbs). A term adds its mantissa, shifted to its exponent, into two
// adjacent limbs (< 2^32 into the lower, < 2^52 into the upper: a mantissa below 2^53 shifted by at
// most 31 bits, less the 32 bits of the lower), so 2^10 terms fit before a limb
// could overflow; then the carries are propagated (normalise): limbs 0 … kDigits−2 back into
// [0, 2^32), the top limb signed. That normal form is unique for each value, so two accumulators
// of the same exact sum hold the same limbs, and adding normal forms limb by limb (MPI_SUM on
// int64 over up to 2^31 ranks) is exact. 67 digits = 2144 bits: the 2098 bits of the doubles plus
// 46 bits (and the top limb's 31 more) of headroom for the carries of up to 2^46 terms of the
// largest magnitude.
//
// Infinities and NaNs are counted apart (three more limbs): the value is NaN if any term is NaN
// or terms of both infinite signs came in, else ±∞ if any term is ±∞ — what IEEE addition gives
// in any order. An exact sum whose rounding exceeds the largest double is ±∞ (IEEE overflow).
// Zero is +0.0 whatever the signs of zero added (the serial loops' 0.0 + (−0.0) = +0.0 too).
#pragma once
#include <array>
#include <cstddef>
#include <cstdint>
#include <vector>

namespace pd {

class ExactSum {
 public:
  static constexpr int kDigits = 67;             // 32-bit digits: 2144 bits from 2^−1074
  static constexpr int kLimbs = kDigits + 3;     // + counts of +∞, −∞ and NaN terms
  static constexpr int kAddsBeforeCarry = 1024;  // a limb gains < 2^52 + 2^32 a term: 2^10 terms stay below 2^63

  ExactSum() = default;
  explicit ExactSum(double start) { add(start); }

  // += x exactly.
  void add(double x) {
    std::uint64_t bits;
    static_assert(sizeof bits == sizeof x, "IEEE double");
    __builtin_memcpy(&bits, &x, sizeof bits);
    std::uint64_t mantissa = bits & ((std::uint64_t{1} << 52) - 1);
    int biased = static_cast<int>((bits >> 52) & 0x7FF);
    if (biased == 0x7FF) return add_special(bits);
    if (biased == 0) {
      if (mantissa == 0) return;  // ±0
      biased = 1;                 // subnormal: m·2^−1074, no hidden bit
    } else {
      mantissa |= std::uint64_t{1} << 52;
    }
    // x = ±m·2^(biased − 1075): the lowest bit of m is bit p = biased − 1 of the accumulator.
    const int p = biased - 1, index = p >> 5, shift = p & 31;
    auto low = static_cast<std::int64_t>((mantissa << shift) & 0xFFFFFFFFu);
    auto high = static_cast<std::int64_t>(mantissa >> (32 - shift));
    if (bits >> 63) low = -low, high = -high;
    limb_[static_cast<std::size_t>(index)] += low;
    limb_[static_cast<std::size_t>(index) + 1] += high;
    if (++adds_ == kAddsBeforeCarry) normalise();
  }
  // += every term.
  void add(const double* terms, std::size_t n) {
    for (std::size_t k = 0; k < n; ++k) add(terms[k]);
  }
  // += another exact sum, exactly.
  void add(const ExactSum& other);

  // The nearest double to the exact sum (ties to even), or ±∞/NaN as above.
  double value() const;

  // Carries propagated: the unique normal form of the value (see above).
  void normalise();
  // The limbs, for a sum over MPI ranks (MPI_Allreduce, MPI_SUM on MPI_INT64_T) of normal forms;
  // call normalise() after writing them.
  std::int64_t* limbs() { return limb_.data(); }
  const std::int64_t* limbs() const { return limb_.data(); }
  bool operator==(const ExactSum& other) const;

 private:
  void add_special(std::uint64_t bits);
  std::array<std::int64_t, kLimbs> limb_{};
  int adds_ = 0;  // terms since the last normalise
};

// start + Σ terms, exactly, rounded once.
double exact_sum(const std::vector<double>& terms, double start = 0.0);

}  // namespace pd
