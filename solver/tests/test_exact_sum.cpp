// The exact sum (core/exact_sum.hpp): exact where the naive loop is not, independent of the order,
// correctly rounded, with subnormals, signs, cancellation and the IEEE special values.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <random>
#include <vector>

#include "core/exact_sum.hpp"

namespace pd {
namespace {

std::uint64_t bits_of(double x) {
  std::uint64_t b;
  std::memcpy(&b, &x, sizeof b);
  return b;
}

TEST(ExactSum, ExactWhereTheNaiveLoopIsNot) {
  const std::vector<double> terms{1e100, 1.0, -1e100};
  double naive = 0.0;
  for (double t : terms) naive += t;
  EXPECT_EQ(naive, 0.0);  // the 1 was lost
  EXPECT_EQ(exact_sum(terms), 1.0);
  // 0.1 ten times: the naive loop gives 0.9999999999999999; the nearest double to the exact sum of
  // the ten doubles 0.1 (each 0.1000000000000000055…) is 1.0.
  double ten = 0.0;
  for (int k = 0; k < 10; ++k) ten += 0.1;
  EXPECT_NE(ten, 1.0);
  EXPECT_EQ(exact_sum(std::vector<double>(10, 0.1)), 1.0);
}

TEST(ExactSum, RoundsOnceToNearestTiesToEven) {
  // 1 + 2^−53 is a tie between 1 and 1 + 2^−52: even → 1. One more 2^−105 breaks the tie upward.
  EXPECT_EQ(exact_sum({1.0, std::ldexp(1.0, -53)}), 1.0);
  EXPECT_EQ(exact_sum({1.0, std::ldexp(1.0, -53), std::ldexp(1.0, -105)}), 1.0 + std::ldexp(1.0, -52));
  // (1 + 2^−52) + 2^−53: a tie, odd below → rounds up to 1 + 2^−51.
  EXPECT_EQ(exact_sum({1.0 + std::ldexp(1.0, -52), std::ldexp(1.0, -53)}), 1.0 + std::ldexp(1.0, -51));
  // The sticky bit far below: 2^60's ulp is 256, so 2^60 + 128 is a tie (→ 2^60, even), and
  // 2^60 + 128 + 2^−1074 is above it (→ 2^60 + 256).
  const double big = std::ldexp(1.0, 60);
  EXPECT_EQ(exact_sum({big, 128.0}), big);
  EXPECT_EQ(exact_sum({big, 128.0, std::ldexp(1.0, -1074)}), big + 256.0);
  EXPECT_EQ(exact_sum({-big, -128.0, -std::ldexp(1.0, -1074)}), -big - 256.0);
}

TEST(ExactSum, AnyPermutationGivesTheSameBits) {
  std::mt19937_64 random(15);
  std::uniform_real_distribution<double> mantissa(-1.0, 1.0);
  std::uniform_int_distribution<int> exponent(-60, 60);
  std::vector<double> terms(5000);
  for (double& t : terms) t = std::ldexp(mantissa(random), exponent(random));
  const double first = exact_sum(terms);
  std::vector<double> naive_results;
  for (int trial = 0; trial < 20; ++trial) {
    std::shuffle(terms.begin(), terms.end(), random);
    EXPECT_EQ(bits_of(exact_sum(terms)), bits_of(first));
    double naive = 0.0;
    for (double t : terms) naive += t;
    naive_results.push_back(naive);
  }
  // The naive loop does depend on the order here (so the test could fail).
  EXPECT_NE(*std::min_element(naive_results.begin(), naive_results.end()),
            *std::max_element(naive_results.begin(), naive_results.end()));
  // Split into pieces summed apart and merged (as ranks and threads do): the same bits.
  ExactSum a, b, c;
  for (std::size_t k = 0; k < terms.size(); ++k) (k % 3 == 0 ? a : k % 3 == 1 ? b : c).add(terms[k]);
  c.add(a);
  c.add(b);
  EXPECT_EQ(bits_of(c.value()), bits_of(first));
}

TEST(ExactSum, MatchesTheNaiveLoopWhereThatIsExact) {
  // Terms that are integers times 2^−20 below 2^30: every partial sum is exact in a double, so the
  // naive loop is exact and must agree; more terms than kAddsBeforeCarry, so the carries run.
  std::mt19937_64 random(7);
  std::uniform_int_distribution<std::int64_t> integer(-(std::int64_t{1} << 30), std::int64_t{1} << 30);
  std::vector<double> terms(10 * ExactSum::kAddsBeforeCarry + 3);
  double naive = 0.0;
  for (double& t : terms) {
    t = std::ldexp(static_cast<double>(integer(random)), -20);
    naive += t;
  }
  EXPECT_EQ(exact_sum(terms), naive);
}

TEST(ExactSum, SubnormalsNegativesAndCancellationToZero) {
  const double tiny = std::numeric_limits<double>::denorm_min();
  EXPECT_EQ(exact_sum({tiny, tiny, tiny}), 3 * tiny);
  EXPECT_EQ(exact_sum({tiny, -tiny}), 0.0);
  EXPECT_EQ(exact_sum({std::numeric_limits<double>::min(), -tiny}), std::numeric_limits<double>::min() - tiny);
  // Cancellation to zero is +0.0, as is a sum of −0.0s (0.0 + (−0.0) = +0.0 in the serial loops).
  const double zero = exact_sum({1e300, -3.5, 2.25, -1e300, 1.25});
  EXPECT_EQ(bits_of(zero), bits_of(0.0));
  EXPECT_EQ(bits_of(exact_sum({-0.0, -0.0})), bits_of(0.0));
  EXPECT_EQ(bits_of(exact_sum({})), bits_of(0.0));
  EXPECT_EQ(exact_sum({-1.5, -2.5}), -4.0);
  EXPECT_EQ(exact_sum({-std::numeric_limits<double>::max(), 1.0}), -std::numeric_limits<double>::max());
  // The start value counts as a term.
  EXPECT_EQ(exact_sum({1.0, -1e100}, 1e100), 1.0);
}

TEST(ExactSum, OverflowAndTheSpecialValues) {
  const double max = std::numeric_limits<double>::max(), inf = std::numeric_limits<double>::infinity();
  // Beyond the largest double the exact sum rounds to ∞ — and back within range it is exact again.
  EXPECT_EQ(exact_sum({max, max}), inf);
  EXPECT_EQ(exact_sum({max, max, -max}), max);
  EXPECT_EQ(exact_sum({-max, -max}), -inf);
  EXPECT_EQ(exact_sum({1.0, inf, 2.0}), inf);
  EXPECT_EQ(exact_sum({1.0, -inf}), -inf);
  EXPECT_TRUE(std::isnan(exact_sum({inf, -inf})));
  EXPECT_TRUE(std::isnan(exact_sum({1.0, std::nan(""), 2.0})));
  ExactSum a, b;
  a.add(inf);
  b.add(-inf);
  a.add(b);  // the counts merge too
  EXPECT_TRUE(std::isnan(a.value()));
}

TEST(ExactSum, NormalFormIsUnique) {
  // The same value reached by different terms holds the same limbs (what MPI_SUM of limbs needs).
  ExactSum a, b;
  a.add(3.0);
  a.add(-0.5);
  b.add(2.0);
  b.add(0.25);
  b.add(0.25);
  EXPECT_TRUE(a == b);
  b.add(std::ldexp(1.0, -1074));
  EXPECT_FALSE(a == b);
  a.normalise();
  for (int k = 0; k + 1 < ExactSum::kDigits; ++k) {
    EXPECT_GE(a.limbs()[k], 0);
    EXPECT_LT(a.limbs()[k], std::int64_t{1} << 32);
  }
}

}  // namespace
}  // namespace pd
