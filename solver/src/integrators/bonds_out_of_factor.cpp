// The broken bonds' blocks for the Woodbury correction (see bonds_out_of_factor.hpp).
#include "integrators/bonds_out_of_factor.hpp"

#include <algorithm>

#include "materials/bond_model.hpp"

namespace pd {

std::int64_t add_broken_bonds(Model& model, const std::vector<std::uint8_t>& broken_before, const Vec3Array& u_factor,
                              bool definite, const FreeDofs& dofs, Woodbury& update) {
  auto& bonds = model.bonds;
  const auto& off = bonds.offsets;
  const std::size_t n = model.nodes.size();
  // The newly broken half-bonds, row by row; each bond once, from its lower node, with its other half.
  struct Broken {
    std::size_t i, j, k;  // nodes and the half-bond in i's row
  };
  std::vector<Broken> found;
  std::int64_t halves = 0;
  for (std::size_t i = 0; i < n; ++i)
    for (auto k = static_cast<std::size_t>(off[i]); k < static_cast<std::size_t>(off[i + 1]); ++k) {
      if (!bonds.broken[k] || broken_before[k]) continue;
      ++halves;
      const auto j = static_cast<std::size_t>(bonds.neighbour[k]);
      if (j < i) continue;
      const auto* first = bonds.neighbour.data() + off[j];
      const auto* last = bonds.neighbour.data() + off[j + 1];
      const auto* back = std::lower_bound(first, last, static_cast<std::int32_t>(i));
      const auto k_back = static_cast<std::size_t>(back - bonds.neighbour.data());
      if (back == last || *back != static_cast<std::int32_t>(i) || !bonds.broken[k_back] || broken_before[k_back]) return -1;
      found.push_back({i, j, k});
    }
  if (halves != 2 * static_cast<std::int64_t>(found.size())) return -1;
  // Per row: its newly broken halves put back, the row's blocks at u_factor, the flags restored.
  std::vector<double> blocks;
  for (std::size_t a = 0; a < found.size();) {
    const std::size_t i = found[a].i;
    std::size_t end = a;
    while (end < found.size() && found[end].i == i) bonds.broken[found[end++].k] = 0;
    const auto row_bonds = static_cast<std::size_t>(off[i + 1] - off[i]);
    blocks.assign(9 * row_bonds, 0.0);
    model.bond_model->bond_tangent_row(model, u_factor, i, blocks.data(), definite);
    for (std::size_t b = a; b < end; ++b) bonds.broken[found[b].k] = 1;
    for (std::size_t b = a; b < end; ++b) {
      const double* block = blocks.data() + 9 * (found[b].k - static_cast<std::size_t>(off[i]));
      // The components that are a dof at either end; C = V_i·B_ij on them.
      std::int64_t plus[3], minus[3];
      int kept[3], m = 0;
      for (int d = 0; d < 3; ++d) {
        const std::int64_t p = dofs.index[3 * i + static_cast<std::size_t>(d)];
        const std::int64_t q = dofs.index[3 * found[b].j + static_cast<std::size_t>(d)];
        if (p < 0 && q < 0) continue;
        plus[m] = p, minus[m] = q, kept[m++] = d;
      }
      if (m == 0) continue;
      double c[9];
      const double volume = model.nodes.volume[i];
      for (int r = 0; r < m; ++r)
        for (int s = 0; s < m; ++s) c[r * m + s] = volume * block[3 * kept[r] + kept[s]];
      update.add_block(plus, minus, c, m);
    }
    a = end;
  }
  return static_cast<std::int64_t>(found.size());
}

}  // namespace pd
