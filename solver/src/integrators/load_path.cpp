// Groups of held nodes and their links through the bonds (see load_path.hpp).
#include "integrators/load_path.hpp"

#include <algorithm>
#include <map>
#include <numeric>

namespace pd {

LoadPath::LoadPath(const Model& model) {
  const std::size_t n = model.bonds.nodes();
  // Per node, the indices of the prescribed conditions that hold it; one group per distinct set.
  std::vector<std::vector<std::int32_t>> held(n);
  const auto& prescribed = model.conditions.prescribed;
  for (std::size_t c = 0; c < prescribed.size(); ++c)
    for (std::int32_t i : prescribed[c].nodes) held[static_cast<std::size_t>(i)].push_back(static_cast<std::int32_t>(c));
  std::map<std::vector<std::int32_t>, std::int32_t> ids;
  group_.assign(n, -1);
  for (std::size_t i = 0; i < n; ++i)
    if (!held[i].empty()) group_[i] = ids.emplace(held[i], static_cast<std::int32_t>(ids.size())).first->second;
  groups_ = static_cast<std::int32_t>(ids.size());
  uncut_pairs_ = groups_ > 1 ? linked_pairs(model.bonds, true) : 0;
  linked_uncut_ = uncut_pairs_ > 0;
}

std::vector<std::int32_t> LoadPath::components(const BondList& bonds, bool use_broken) const {
  const std::size_t n = bonds.nodes();
  std::vector<std::int32_t> parent(n);
  std::iota(parent.begin(), parent.end(), 0);
  auto root = [&parent](std::int32_t i) {
    while (parent[static_cast<std::size_t>(i)] != i) {
      parent[static_cast<std::size_t>(i)] = parent[static_cast<std::size_t>(parent[static_cast<std::size_t>(i)])];  // path halving
      i = parent[static_cast<std::size_t>(i)];
    }
    return i;
  };
  for (std::size_t i = 0; i < n; ++i)
    for (std::int64_t k = bonds.offsets[i]; k < bonds.offsets[i + 1]; ++k) {
      const auto q = static_cast<std::size_t>(k);
      if (!use_broken && bonds.broken[q]) continue;
      const std::int32_t a = root(static_cast<std::int32_t>(i)), b = root(bonds.neighbour[q]);
      if (a != b) parent[static_cast<std::size_t>(std::max(a, b))] = std::min(a, b);
    }
  for (std::size_t i = 0; i < n; ++i) parent[i] = root(static_cast<std::int32_t>(i));
  return parent;
}

std::int64_t LoadPath::linked_pairs(const BondList& bonds, bool use_broken) const {
  const std::vector<std::int32_t> root = components(bonds, use_broken);
  const std::size_t n = root.size();
  // The groups in each component, and the pairs of groups that share one.
  std::map<std::int32_t, std::vector<std::int32_t>> in_component;
  for (std::size_t i = 0; i < n; ++i)
    if (group_[i] >= 0) in_component[root[i]].push_back(group_[i]);
  std::int64_t pairs = 0;
  for (auto& [component, groups] : in_component) {
    std::sort(groups.begin(), groups.end());
    const auto distinct = static_cast<std::int64_t>(std::unique(groups.begin(), groups.end()) - groups.begin());
    pairs += distinct * (distinct - 1) / 2;
  }
  return pairs;
}

bool LoadPath::separated(const BondList& bonds) const {
  return linked_uncut_ && linked_pairs(bonds, false) < uncut_pairs_;
}

}  // namespace pd
