// Whether the intact bonds still carry load between the prescribed motions (for the mixed scheme's
// return to quasi-static, integrators/mixed.hpp): nodes are grouped by the set of prescribed
// conditions that hold them (a grip: the same x and y conditions), and two groups are linked when a
// chain of unbroken bonds joins one of their nodes. A tension test has separated when its two grips
// were linked through the uncut body and no longer are: the halves then hang each from one grip,
// and the undamped ringing that goes on in them is not the quasi-static answer.
#pragma once
#include <cstdint>
#include <vector>

#include "core/model.hpp"

namespace pd {

class LoadPath {
 public:
  // The groups from the model's prescribed motions.
  explicit LoadPath(const Model& model);
  // Some chain of bonds (broken or not: the uncut body) joins two groups.
  bool linked_uncut() const { return linked_uncut_; }
  // The groups linked by the unbroken bonds now are fewer than in the uncut body: a crack has cut
  // a load path between two prescribed motions. O(bonds) (union–find) the first time; after that,
  // when bonds have only broken since the last call (none healed), the bonds broken since are
  // checked first: if the two ends of each are still joined by intact bonds nearby (a search of at
  // most kLocalNodes nodes), no component of the bond graph has split and the last count stands
  // (exactly: a chain through a lost bond goes round it). Else the union–find again. The verdict
  // is the union–find's either way; only the work differs (mixed asks after every explicit step
  // that broke a bond: 1 ms each on plate_with_hole at dx × 2, 5 % of its run).
  bool separated(const BondList& bonds) const;
  static constexpr int kLocalNodes = 512;
  // Per node, the group whose prescribed motion alone holds its piece: g when the intact bonds join
  // the node to nodes of group g and of no other group; −1 when they join it to none (a free
  // fragment) or to several (a piece still loaded between two prescribed motions). O(bonds).
  std::vector<std::int32_t> held_by_one_group(const BondList& bonds) const;
  std::int32_t groups() const { return groups_; }
  // Calls answered by the union–find (for the tests).
  std::int64_t full_counts() const { return full_counts_; }

 private:
  // Per node, the root of its component of the bond graph (bonds kept when use_broken or intact).
  std::vector<std::int32_t> components(const BondList& bonds, bool use_broken) const;
  // The number of pairs of groups that share a component of the bond graph (bonds kept when
  // use_broken or intact).
  std::int64_t linked_pairs(const BondList& bonds, bool use_broken) const;
  // Whether nodes a and b are joined by intact bonds within kLocalNodes nodes of a (a breadth-first
  // search; an edge is intact when either of its two directed bonds is). Marks what it reaches
  // with a new generation; `reached` says whether c was reached by the last search.
  bool joined_nearby(const BondList& bonds, std::int32_t a, std::int32_t b) const;
  bool reached(std::int32_t c) const { return mark_[static_cast<std::size_t>(c)] == generation_; }
  // The last count of linked pairs and the broken flags it was made (or confirmed) with.
  mutable bool counted_ = false;
  mutable std::int64_t pairs_ = 0;
  mutable std::vector<std::uint8_t> seen_broken_;
  mutable std::vector<std::uint32_t> mark_;
  mutable std::uint32_t generation_ = 0;
  mutable std::vector<std::int32_t> queue_;
  mutable std::int64_t full_counts_ = 0;
  std::vector<std::int32_t> group_;  // per node: −1 free, else its group
  std::int32_t groups_ = 0;
  std::int64_t uncut_pairs_ = 0;
  bool linked_uncut_ = false;
};

}  // namespace pd
