// The pair rule of the material table and the analysis names (see material.hpp).
#include "core/material.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace pd {

const Registry<int>& analysis_registry() {
  static const Registry<int> registry = [] {
    Registry<int> r("analysis");
    r.add("3d", 3).add("plane_stress", 2).add("plane_strain", 2);
    return r;
  }();
  return registry;
}

int analysis_dimension(const std::string& analysis) { return analysis_registry().get(analysis); }

bool MaterialTable::can_break() const {
  return std::any_of(critical_pair.begin(), critical_pair.end(), [](double s0) { return !std::isinf(s0); });
}

bool MaterialTable::node_rule() const {
  return std::any_of(alpha_pair.begin(), alpha_pair.end(), [](double alpha) { return alpha > 0.0; });
}

MaterialTable make_pair_table(std::vector<PairConstants> per_block) {
  constexpr double kInf = std::numeric_limits<double>::infinity();
  MaterialTable table;
  table.blocks = static_cast<int>(per_block.size());
  table.block = std::move(per_block);
  const auto nb = table.block.size();
  table.micromodulus_pair.resize(nb * nb);
  table.critical_pair.resize(nb * nb);
  table.alpha_pair.resize(nb * nb);
  for (std::size_t a = 0; a < nb; ++a)
    for (std::size_t b = 0; b < nb; ++b) {
      table.micromodulus_pair[a * nb + b] = 0.5 * (table.block[a].micromodulus + table.block[b].micromodulus);
      // A bond with an end in an unbreakable block never breaks (s0 = ∞ wins over the minimum).
      const double sa = table.block[a].critical_stretch, sb = table.block[b].critical_stretch;
      table.critical_pair[a * nb + b] = (std::isinf(sa) || std::isinf(sb)) ? kInf : std::min(sa, sb);
      table.alpha_pair[a * nb + b] =
          0.5 * (table.block[a].critical_stretch_alpha + table.block[b].critical_stretch_alpha);
    }
  return table;
}

}  // namespace pd
