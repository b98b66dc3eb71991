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

std::vector<std::int32_t> LoadPath::held_by_one_group(const BondList& bonds) const {
  const std::vector<std::int32_t> root = components(bonds, false);
  const std::size_t n = root.size();
  constexpr std::int32_t kNone = -1, kSeveral = -2;
  std::vector<std::int32_t> of_root(n, kNone);  // per root: the one group in its component, or none, or several
  for (std::size_t i = 0; i < n; ++i) {
    const std::int32_t g = group_[i];
    std::int32_t& held = of_root[static_cast<std::size_t>(root[i])];
    if (g < 0 || held == kSeveral || held == g) continue;
    held = held == kNone ? g : kSeveral;
  }
  std::vector<std::int32_t> group(n);
  for (std::size_t i = 0; i < n; ++i) group[i] = std::max(of_root[static_cast<std::size_t>(root[i])], kNone);
  return group;
}

namespace {

// Whether the directed bond b → a (the reverse of a → b) is intact; a row's neighbours ascend.
bool reverse_intact(const BondList& bonds, std::int32_t a, std::int32_t b) {
  const auto first = bonds.neighbour.begin() + bonds.offsets[static_cast<std::size_t>(b)];
  const auto last = bonds.neighbour.begin() + bonds.offsets[static_cast<std::size_t>(b) + 1];
  const auto at = std::lower_bound(first, last, a);
  return at != last && *at == a && bonds.broken[static_cast<std::size_t>(at - bonds.neighbour.begin())] == 0;
}

}  // namespace

bool LoadPath::joined_nearby(const BondList& bonds, std::int32_t a, std::int32_t b) const {
  if (mark_.size() != bonds.nodes()) mark_.assign(bonds.nodes(), 0), generation_ = 0;
  if (++generation_ == 0) std::fill(mark_.begin(), mark_.end(), 0), generation_ = 1;
  queue_.clear();
  queue_.push_back(a);
  mark_[static_cast<std::size_t>(a)] = generation_;
  for (std::size_t head = 0; head < queue_.size(); ++head) {
    const std::int32_t u = queue_[head];
    for (std::int64_t k = bonds.offsets[static_cast<std::size_t>(u)]; k < bonds.offsets[static_cast<std::size_t>(u) + 1]; ++k) {
      const auto q = static_cast<std::size_t>(k);
      const std::int32_t v = bonds.neighbour[q];
      if (reached(v) || (bonds.broken[q] != 0 && !reverse_intact(bonds, u, v))) continue;
      if (v == b) return true;
      if (static_cast<int>(queue_.size()) >= kLocalNodes) return false;
      mark_[static_cast<std::size_t>(v)] = generation_;
      queue_.push_back(v);
    }
  }
  return false;
}

bool LoadPath::separated(const BondList& bonds) const {
  if (!linked_uncut_) return false;
  bool same = counted_ && seen_broken_.size() == bonds.broken.size();
  if (same) {
    // The bonds broken since the last count (and none healed: else count again).
    const std::size_t n = bonds.nodes();
    for (std::size_t i = 0; i < n && same; ++i) {
      const auto first = static_cast<std::size_t>(bonds.offsets[i]), last = static_cast<std::size_t>(bonds.offsets[i + 1]);
      if (std::equal(bonds.broken.begin() + first, bonds.broken.begin() + last, seen_broken_.begin() + first)) continue;
      for (std::size_t q = first; q < last && same; ++q) {
        const bool now = bonds.broken[q] != 0, then = seen_broken_[q] != 0;
        if (now == then) continue;
        if (!now) same = false;  // healed
        // Lost: i and its neighbour must still be joined (directly by the reverse bond, or nearby).
        else if (!reverse_intact(bonds, static_cast<std::int32_t>(i), bonds.neighbour[q]) &&
                 !joined_nearby(bonds, static_cast<std::int32_t>(i), bonds.neighbour[q]))
          same = false;
      }
    }
  }
  if (!same) {
    pairs_ = linked_pairs(bonds, false);
    counted_ = true;
    ++full_counts_;
  }
  seen_broken_ = bonds.broken;
  return pairs_ < uncut_pairs_;
}

}  // namespace pd
