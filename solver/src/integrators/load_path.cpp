// Groups of held nodes and their links through the bonds (see load_path.hpp).
#include "integrators/load_path.hpp"

#include <algorithm>
#include <map>
#include <numeric>

#include "parallel/decomposed.hpp"
#include "parallel/local_model.hpp"

namespace pd {

LoadPath::LoadPath(const Model& model, const Decomposed* decomposed) : decomposed_(decomposed) {
  const std::size_t n = model.bonds.nodes();
  // Per node, the indices of the prescribed conditions that hold it; one group per distinct set (a
  // piece's conditions hold its owned nodes only).
  std::vector<std::vector<std::int32_t>> held(n);
  const auto& prescribed = model.conditions.prescribed;
  for (std::size_t c = 0; c < prescribed.size(); ++c)
    for (std::int32_t i : prescribed[c].nodes) held[static_cast<std::size_t>(i)].push_back(static_cast<std::int32_t>(c));
  const auto global = [&](std::size_t i) -> std::int64_t {
    return decomposed_ ? decomposed_->piece().global[i] : static_cast<std::int64_t>(i);
  };
  // The groups numbered by the least node each holds, over every rank: each rank's sets with their
  // least node here, [node, count, conditions …] per set, gathered to all.
  std::map<std::vector<std::int32_t>, std::int64_t> least;
  for (std::size_t i = 0; i < n; ++i)
    if (!held[i].empty()) least.emplace(held[i], global(i));  // ascending i: the first is the least
  std::vector<std::int64_t> sets;
  for (const auto& [conditions, node] : least) {
    sets.push_back(node);
    sets.push_back(static_cast<std::int64_t>(conditions.size()));
    sets.insert(sets.end(), conditions.begin(), conditions.end());
  }
  if (decomposed_) sets = decomposed_->gather_to_all(sets);
  least.clear();
  for (std::size_t at = 0; at < sets.size();) {
    const std::int64_t node = sets[at], count = sets[at + 1];
    std::vector<std::int32_t> conditions(sets.begin() + static_cast<std::ptrdiff_t>(at + 2),
                                         sets.begin() + static_cast<std::ptrdiff_t>(at + 2 + static_cast<std::size_t>(count)));
    at += 2 + static_cast<std::size_t>(count);
    const auto [it, added] = least.emplace(std::move(conditions), node);
    if (!added) it->second = std::min(it->second, node);
  }
  std::vector<std::pair<std::int64_t, const std::vector<std::int32_t>*>> order;
  for (const auto& [conditions, node] : least) order.emplace_back(node, &conditions);
  std::sort(order.begin(), order.end());
  std::map<std::vector<std::int32_t>, std::int32_t> ids;
  for (const auto& [node, conditions] : order) ids.emplace(*conditions, static_cast<std::int32_t>(ids.size()));
  group_.assign(n, -1);
  for (std::size_t i = 0; i < n; ++i)
    if (!held[i].empty()) group_[i] = ids.at(held[i]);
  groups_ = static_cast<std::int32_t>(ids.size());
  if (decomposed_) {
    const LocalPiece& piece = decomposed_->piece();
    boundary_.assign(n, 0);
    for (std::int32_t g : piece.ghost_local) boundary_[static_cast<std::size_t>(g)] = 1;
    for (std::size_t i = 0; i < n; ++i)
      for (std::int64_t k = model.bonds.offsets[i]; k < model.bonds.offsets[i + 1] && !boundary_[i]; ++k)
        if (!piece.owned[static_cast<std::size_t>(model.bonds.neighbour[static_cast<std::size_t>(k)])]) boundary_[i] = 1;
  }
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

namespace {

// The pairs of distinct groups among `groups` (sorted, without repeats).
std::int64_t pairs_of(const std::vector<std::int32_t>& groups) {
  const auto distinct = static_cast<std::int64_t>(groups.size());
  return distinct * (distinct - 1) / 2;
}

void sort_distinct(std::vector<std::int32_t>& v) {
  std::sort(v.begin(), v.end());
  v.erase(std::unique(v.begin(), v.end()), v.end());
}

// The one group among `groups` (sorted, without repeats), or −1 for none or several.
std::int32_t the_one(const std::vector<std::int32_t>& groups) { return groups.size() == 1 ? groups[0] : -1; }

}  // namespace

std::map<std::int32_t, std::vector<std::int32_t>> LoadPath::groups_by_root(const std::vector<std::int32_t>& root) const {
  std::map<std::int32_t, std::vector<std::int32_t>> in_component;
  for (std::size_t i = 0; i < root.size(); ++i)
    if (group_[i] >= 0) in_component[root[i]].push_back(group_[i]);
  for (auto& [component, groups] : in_component) sort_distinct(groups);
  return in_component;
}

std::vector<std::uint8_t> LoadPath::reaching(const std::vector<std::int32_t>& root) const {
  std::vector<std::uint8_t> reaches(boundary_.empty() ? 0 : root.size(), 0);
  for (std::size_t i = 0; i < boundary_.size(); ++i)
    if (boundary_[i]) reaches[static_cast<std::size_t>(root[i])] = 1;
  return reaches;
}

std::map<std::int64_t, std::vector<std::int32_t>> LoadPath::joined_groups(
    const std::vector<std::int32_t>& root, const std::vector<std::uint8_t>& reaches,
    const std::map<std::int32_t, std::vector<std::int32_t>>& groups, std::int64_t& pairs) const {
  const LocalPiece& piece = decomposed_->piece();
  const std::size_t n = root.size();
  // A component's name: its least global node, which is its root's (the union–find keeps the least
  // local node as the root, and local numbers ascend with global ones).
  const auto name = [&](std::int32_t r) -> std::int64_t { return piece.global[static_cast<std::size_t>(r)]; };
  // This rank's part: [components, (name, count, groups …) …, links, (name here, owner's name) …].
  std::vector<std::int64_t> mine{0};
  for (std::size_t r = 0; r < n; ++r) {
    if (!reaches[r]) continue;
    ++mine[0];
    mine.push_back(name(static_cast<std::int32_t>(r)));
    const auto it = groups.find(static_cast<std::int32_t>(r));
    mine.push_back(it == groups.end() ? 0 : static_cast<std::int64_t>(it->second.size()));
    if (it != groups.end()) mine.insert(mine.end(), it->second.begin(), it->second.end());
  }
  // Each ghost's component on its owner, by name (exact in a double: fewer than 2^53 nodes).
  std::vector<double> owner_name(n, 0.0);
  for (std::size_t i = 0; i < n; ++i) owner_name[i] = static_cast<double>(name(root[i]));
  decomposed_->update_ghosts(owner_name);
  std::vector<std::pair<std::int64_t, std::int64_t>> links;
  for (std::int32_t g : piece.ghost_local) {
    const std::int64_t here = name(root[static_cast<std::size_t>(g)]), there = static_cast<std::int64_t>(owner_name[static_cast<std::size_t>(g)]);
    if (here != there) links.emplace_back(here, there);
  }
  std::sort(links.begin(), links.end());
  links.erase(std::unique(links.begin(), links.end()), links.end());
  mine.push_back(static_cast<std::int64_t>(links.size()));
  for (const auto& [a, b] : links) mine.push_back(a), mine.push_back(b);
  const std::vector<std::int64_t> all = decomposed_->gather_to_all(mine);

  // Every rank's components and links, joined by a union–find over their names (in the same order
  // on every rank: the same answer everywhere).
  std::map<std::int64_t, std::vector<std::int32_t>> of_name;
  links.clear();
  for (std::size_t at = 0; at < all.size();) {
    const std::int64_t components = all[at++];
    for (std::int64_t c = 0; c < components; ++c) {
      std::vector<std::int32_t>& to = of_name[all[at]];
      const auto count = static_cast<std::size_t>(all[at + 1]);
      to.insert(to.end(), all.begin() + static_cast<std::ptrdiff_t>(at + 2), all.begin() + static_cast<std::ptrdiff_t>(at + 2 + count));
      at += 2 + count;
    }
    const std::int64_t count = all[at++];
    for (std::int64_t l = 0; l < count; ++l, at += 2) links.emplace_back(all[at], all[at + 1]);
  }
  for (const auto& [a, b] : links) of_name[a], of_name[b];  // a name met in a link only holds no group
  std::vector<std::int64_t> names;
  for (const auto& entry : of_name) names.push_back(entry.first);
  const auto index = [&names](std::int64_t v) {
    return static_cast<std::int32_t>(std::lower_bound(names.begin(), names.end(), v) - names.begin());
  };
  std::vector<std::int32_t> parent(names.size());
  std::iota(parent.begin(), parent.end(), 0);
  const auto find = [&parent](std::int32_t i) {
    while (parent[static_cast<std::size_t>(i)] != i) i = parent[static_cast<std::size_t>(i)] = parent[static_cast<std::size_t>(parent[static_cast<std::size_t>(i)])];
    return i;
  };
  for (const auto& [a, b] : links) {
    const std::int32_t ra = find(index(a)), rb = find(index(b));
    if (ra != rb) parent[static_cast<std::size_t>(std::max(ra, rb))] = std::min(ra, rb);
  }
  std::map<std::int32_t, std::vector<std::int32_t>> whole;  // per joined root, its groups
  for (std::size_t k = 0; k < names.size(); ++k) {
    const std::vector<std::int32_t>& g = of_name[names[k]];
    std::vector<std::int32_t>& to = whole[find(static_cast<std::int32_t>(k))];
    to.insert(to.end(), g.begin(), g.end());
  }
  pairs = 0;
  for (auto& [r, g] : whole) {
    sort_distinct(g);
    pairs += pairs_of(g);
  }
  std::map<std::int64_t, std::vector<std::int32_t>> out;
  for (std::size_t k = 0; k < names.size(); ++k) out.emplace(names[k], whole[find(static_cast<std::int32_t>(k))]);
  return out;
}

std::int64_t LoadPath::linked_pairs(const BondList& bonds, bool use_broken) const {
  const std::vector<std::int32_t> root = components(bonds, use_broken);
  const std::map<std::int32_t, std::vector<std::int32_t>> groups = groups_by_root(root);
  const std::vector<std::uint8_t> reaches = reaching(root);
  std::int64_t pairs = 0;  // of the components within this rank (all of them on a serial run)
  for (const auto& [component, g] : groups)
    if (reaches.empty() || !reaches[static_cast<std::size_t>(component)]) pairs += pairs_of(g);
  if (!decomposed_) return pairs;
  std::int64_t joined = 0;
  joined_groups(root, reaches, groups, joined);
  return decomposed_->total(pairs) + joined;
}

std::vector<std::int32_t> LoadPath::held_by_one_group(const BondList& bonds) const {
  const std::vector<std::int32_t> root = components(bonds, false);
  const std::map<std::int32_t, std::vector<std::int32_t>> groups = groups_by_root(root);
  const std::vector<std::uint8_t> reaches = reaching(root);
  std::int64_t pairs = 0;
  const std::map<std::int64_t, std::vector<std::int32_t>> joined =
      decomposed_ ? joined_groups(root, reaches, groups, pairs) : std::map<std::int64_t, std::vector<std::int32_t>>{};
  const std::size_t n = root.size();
  std::vector<std::int32_t> of_root(n, -1);
  for (const auto& [component, g] : groups) of_root[static_cast<std::size_t>(component)] = the_one(g);
  for (std::size_t r = 0; r < reaches.size(); ++r)  // roots of components that reach other ranks
    if (reaches[r]) of_root[r] = the_one(joined.at(decomposed_->piece().global[r]));
  std::vector<std::int32_t> group(n);
  for (std::size_t i = 0; i < n; ++i) group[i] = of_root[static_cast<std::size_t>(root[i])];
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
  // Every rank counts again if one must (a lost bond whose ends its piece cannot join nearby: the
  // search stops at a ghost, whose row is elsewhere; counting again is never wrong).
  if (decomposed_) same = decomposed_->minimum(same ? 1.0 : 0.0) == 1.0;
  if (!same) {
    pairs_ = linked_pairs(bonds, false);
    counted_ = true;
    ++full_counts_;
  }
  seen_broken_ = bonds.broken;
  return pairs_ < uncut_pairs_;
}

}  // namespace pd
