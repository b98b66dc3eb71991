// Numbers and nodes as run.log prints them (run/text.hpp).
#include "run/text.hpp"

#include <cstdio>

namespace pd {

std::string format(const char* fmt, double value) {
  char buffer[64];
  std::snprintf(buffer, sizeof buffer, fmt, value);
  return buffer;
}

std::string node_text(const Model& m, std::int64_t node) {
  const auto i = static_cast<std::size_t>(node);
  char buffer[160];
  std::snprintf(buffer, sizeof buffer, "node %lld at (%.6g, %.6g, %.6g) m", static_cast<long long>(node),
                m.nodes.x[0][i], m.nodes.x[1][i], m.nodes.x[2][i]);
  return buffer;
}

}  // namespace pd
