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
  // a load path between two prescribed motions. O(bonds) (union–find).
  bool separated(const BondList& bonds) const;

 private:
  // Per node, the root of its component of the bond graph (bonds kept when use_broken or intact).
  std::vector<std::int32_t> components(const BondList& bonds, bool use_broken) const;
  // The number of pairs of groups that share a component of the bond graph (bonds kept when
  // use_broken or intact).
  std::int64_t linked_pairs(const BondList& bonds, bool use_broken) const;
  std::vector<std::int32_t> group_;  // per node: −1 free, else its group
  std::int32_t groups_ = 0;
  std::int64_t uncut_pairs_ = 0;
  bool linked_uncut_ = false;
};

}  // namespace pd
