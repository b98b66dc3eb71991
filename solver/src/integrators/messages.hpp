// How integrators print numbers in their messages and run.log lines: six significant digits.
#pragma once
#include <cstdio>
#include <string>

namespace pd {

inline std::string message_number(double value) {
  char buffer[32];
  std::snprintf(buffer, sizeof buffer, "%.6g", value);
  return buffer;
}

// "1 factorisation", "3 factorisations": a count and its noun.
inline std::string counted(long long count, const std::string& noun) {
  return std::to_string(count) + " " + noun + (count == 1 ? "" : "s");
}

}  // namespace pd
