// The exact sum's carries and its rounding to the nearest double (core/exact_sum.hpp).
#include "core/exact_sum.hpp"

#include <cmath>
#include <limits>

namespace pd {

namespace {

constexpr std::size_t kPlusInf = ExactSum::kDigits, kMinusInf = kPlusInf + 1, kNaN = kPlusInf + 2;

}  // namespace

void ExactSum::add_special(std::uint64_t bits) {
  if (bits & ((std::uint64_t{1} << 52) - 1)) ++limb_[kNaN];
  else ++limb_[(bits >> 63) ? kMinusInf : kPlusInf];
}

void ExactSum::normalise() {
  // limb k = low 32 bits + 2^32·carry, exactly (arithmetic shift: floor, so the low part is ≥ 0).
  for (std::size_t k = 0; k + 1 < static_cast<std::size_t>(kDigits); ++k) {
    const std::int64_t carry = limb_[k] >> 32;
    limb_[k] &= 0xFFFFFFFF;
    limb_[k + 1] += carry;
  }
  adds_ = 0;
}

void ExactSum::add(const ExactSum& other) {
  ExactSum b = other;
  b.normalise();
  normalise();  // both in normal form: every digit limb < 2^32, so their sum cannot overflow
  for (std::size_t k = 0; k < limb_.size(); ++k) limb_[k] += b.limb_[k];
  normalise();
}

bool ExactSum::operator==(const ExactSum& other) const {
  ExactSum a = *this, b = other;
  a.normalise();
  b.normalise();
  return a.limb_ == b.limb_;
}

double ExactSum::value() const {
  if (limb_[kNaN] > 0 || (limb_[kPlusInf] > 0 && limb_[kMinusInf] > 0)) return std::numeric_limits<double>::quiet_NaN();
  if (limb_[kPlusInf] > 0) return HUGE_VAL;
  if (limb_[kMinusInf] > 0) return -HUGE_VAL;
  ExactSum a = *this;
  a.normalise();
  const bool negative = a.limb_[kDigits - 1] < 0;
  if (negative) {  // the magnitude: −(Σ limb_k 2^32k) = Σ (−limb_k) 2^32k, normalised again
    for (int k = 0; k < kDigits; ++k) a.limb_[static_cast<std::size_t>(k)] = -a.limb_[static_cast<std::size_t>(k)];
    a.normalise();
  }
  // The magnitude as 32-bit digits (the top limb, ≥ 0 now, may hold up to 63 bits: two more digits).
  constexpr int kAll = kDigits + 1;
  std::array<std::uint32_t, kAll> digit{};
  for (int k = 0; k + 1 < kDigits; ++k) digit[static_cast<std::size_t>(k)] = static_cast<std::uint32_t>(a.limb_[static_cast<std::size_t>(k)]);
  const auto top = static_cast<std::uint64_t>(a.limb_[kDigits - 1]);
  digit[kDigits - 1] = static_cast<std::uint32_t>(top);
  digit[kDigits] = static_cast<std::uint32_t>(top >> 32);
  int h = kAll - 1;
  while (h >= 0 && digit[static_cast<std::size_t>(h)] == 0) --h;
  if (h < 0) return 0.0;
  const auto bit = [&](int i) { return (digit[static_cast<std::size_t>(i >> 5)] >> (i & 31)) & 1u; };
  const int msb = 32 * h + 31 - __builtin_clz(digit[static_cast<std::size_t>(h)]);  // highest set bit
  double magnitude;
  if (msb <= 52) {
    // Fewer than 54 bits from 2^−1074: exactly a double (subnormal, or normal below 2^−1021).
    const std::uint64_t m = digit[0] | (static_cast<std::uint64_t>(digit[1]) << 32);
    magnitude = std::ldexp(static_cast<double>(m), -1074);
  } else {
    // 53 bits from the highest, then round to nearest, ties to even: the round bit below them and
    // whether any lower bit is set (sticky).
    std::uint64_t m = 0;
    for (int i = msb; i > msb - 53; --i) m = (m << 1) | bit(i);
    const int round = msb - 53;
    bool sticky = false;
    for (int k = 0; k < (round >> 5) && !sticky; ++k) sticky = digit[static_cast<std::size_t>(k)] != 0;
    if (!sticky) sticky = (digit[static_cast<std::size_t>(round >> 5)] & ((1u << (round & 31)) - 1u)) != 0;
    int exponent = msb - 52 - 1074;  // m's lowest bit weighs 2^exponent
    if (bit(round) && (sticky || (m & 1u))) {
      if (++m == (std::uint64_t{1} << 53)) m >>= 1, ++exponent;
    }
    magnitude = std::ldexp(static_cast<double>(m), exponent);  // exact, or +∞ past the largest double
  }
  return negative ? -magnitude : magnitude;
}

double exact_sum(const std::vector<double>& terms, double start) {
  ExactSum sum(start);
  sum.add(terms.data(), terms.size());
  return sum.value();
}

}  // namespace pd
