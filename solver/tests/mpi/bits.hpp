// Test helper of the decomposed-run tests: "bitwise the serial run" as code — two doubles with the
// same bits, and the count of values of two fields whose bits differ.
#pragma once
#include <cstdint>
#include <cstring>

#include "core/nodes.hpp"

namespace pdtest {

inline bool same_bits(double a, double b) { return std::memcmp(&a, &b, sizeof a) == 0; }

inline std::int64_t differing(const pd::Vec3Array& a, const pd::Vec3Array& b) {
  std::int64_t bad = 0;
  for (std::size_t d = 0; d < 3; ++d)
    for (std::size_t i = 0; i < a[d].size(); ++i) bad += !same_bits(a[d][i], b[d][i]);
  return bad;
}

}  // namespace pdtest
