// Damage φ_i (thesis §2.2; Silling & Askari 2005), the same for every bond-breaking model: it
// depends only on which bonds are broken, not on the law that broke them.
#include <cstdint>

#include "core/model.hpp"
#include "materials/bond_model.hpp"

namespace pd {

std::vector<double> bond_damage(const Model& m) {
  const auto n = static_cast<std::int64_t>(m.nodes.size());
  std::vector<double> out(static_cast<std::size_t>(n), 0.0);
#pragma omp parallel for schedule(static)
  for (std::int64_t i = 0; i < n; ++i) {
    double all = 0.0, intact = 0.0;
    for (std::int64_t k = m.bonds.offsets[static_cast<std::size_t>(i)]; k < m.bonds.offsets[static_cast<std::size_t>(i) + 1]; ++k) {
      const double vj = m.nodes.volume[static_cast<std::size_t>(m.bonds.neighbour[static_cast<std::size_t>(k)])];
      all += vj;
      if (!m.bonds.broken[static_cast<std::size_t>(k)]) intact += vj;
    }
    out[static_cast<std::size_t>(i)] = all > 0.0 ? 1.0 - intact / all : 0.0;
  }
  return out;
}

}  // namespace pd
