// Whether the intact bonds still carry load between the prescribed motions (for the mixed scheme's
// return to quasi-static, integrators/mixed.hpp): nodes are grouped by the set of prescribed
// conditions that hold them (a grip: the same x and y conditions), and two groups are linked when a
// chain of unbroken bonds joins one of their nodes. A tension test has separated when its two grips
// were linked through the uncut body and no longer are: the halves then hang each from one grip,
// and the undamped ringing that goes on in them is not the quasi-static answer.
//
// On a decomposed run (issue 15) each rank holds the rows of its own nodes only: it finds the
// components of its piece's graph (owned nodes and ghosts, over its owned rows), and the components
// that reach another rank's nodes — those with a ghost or an owned node whose row has one — are
// joined across the ranks: each is named by its least global node, each ghost links its component
// here to its owner's (the owner's name comes by the halo), and every rank receives every rank's
// such components with their groups and links (Decomposed::gather_to_all: a graph of a few entries
// per rank boundary, not of nodes) and joins them alike. An edge joins its two ends when either of
// its two directed bonds is intact: the rank of each end adds its own, as the serial union–find
// does. So every verdict is the serial one on any rank count.
#pragma once
#include <cstdint>
#include <map>
#include <vector>

#include "core/model.hpp"

namespace pd {

class Decomposed;  // parallel/decomposed.hpp

class LoadPath {
 public:
  // The groups from the model's prescribed motions, numbered by the least node each holds (the
  // same numbers on every rank). `model`: the whole model, or with `decomposed` a rank's piece.
  // Collective then, as every call below.
  explicit LoadPath(const Model& model, const Decomposed* decomposed = nullptr);
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
  // Per node (a piece's ghosts too), the group whose prescribed motion alone holds its piece: g when
  // the intact bonds join the node to nodes of group g and of no other group; −1 when they join it
  // to none (a free fragment) or to several (a piece still loaded between two prescribed motions).
  // O(bonds).
  std::vector<std::int32_t> held_by_one_group(const BondList& bonds) const;
  std::int32_t groups() const { return groups_; }
  // Calls answered by the union–find (for the tests).
  std::int64_t full_counts() const { return full_counts_; }

 private:
  // Per node, the root of its component of the bond graph (bonds kept when use_broken or intact).
  std::vector<std::int32_t> components(const BondList& bonds, bool use_broken) const;
  // Per root of `root`, the distinct groups of its component's nodes (roots without any left out).
  std::map<std::int32_t, std::vector<std::int32_t>> groups_by_root(const std::vector<std::int32_t>& root) const;
  // A decomposed run: the piece's components that reach other ranks joined with every rank's
  // (header comment). Out: per name (least global node) of such a component of any rank, the
  // distinct groups of the whole component it belongs to; and the pairs of groups those whole
  // components link (each counted once, the same on every rank). Collective.
  std::map<std::int64_t, std::vector<std::int32_t>> joined_groups(const std::vector<std::int32_t>& root,
                                                                  const std::vector<std::uint8_t>& reaches,
                                                                  const std::map<std::int32_t, std::vector<std::int32_t>>& groups,
                                                                  std::int64_t& pairs) const;
  // Per root of `root`: 1 when its component has a boundary node (boundary_); empty on a serial run.
  std::vector<std::uint8_t> reaching(const std::vector<std::int32_t>& root) const;
  // The number of pairs of groups that share a component of the bond graph (bonds kept when
  // use_broken or intact), over the whole model.
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
  const Decomposed* decomposed_ = nullptr;
  std::vector<std::int32_t> group_;  // per node: −1 free, else its group (a piece's ghosts: −1, their owners count them)
  // A piece's nodes whose component may reach another rank: its ghosts, and owned nodes whose row
  // has a ghost (empty on a serial run).
  std::vector<std::uint8_t> boundary_;
  std::int32_t groups_ = 0;
  std::int64_t uncut_pairs_ = 0;
  bool linked_uncut_ = false;
};

}  // namespace pd
