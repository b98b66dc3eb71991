// Nodes that hang from the body by bonds on one line and one side (or by none), found after bonds
// have broken, for the static solves (integrators/quasi_static.hpp).
//
// Why. A PMB bond i→j adds to K = −V ∂f/∂u the block
//   c·ν·V_j·[(1/|ξ|) n nᵀ + (s/|y|)(I − n nᵀ)]          (n = y/|y|, s the stretch)
// so across its line a bond is held only by its tension, c·ν·V_j·s/|y|. A node whose intact bonds
// all lie on one line is held across that line by nothing else; when they all lie on one side
// (a node at a crack face hanging by its bonds to the nodes 2 dx and 3 dx behind it) its equilibrium
// along the line leaves them at s ≈ 0, so its lateral stiffness vanishes there: the lateral force is
// cubic in the offset h (each bond's stretch grows as h²/(2|ξ|²)), a triple root, on which Newton
// converges only linearly (by 2/3 per full step); the line search halves the whole body's step
// for it and every iteration refactorises (docs/notes/2026-12-03-mixed-dx4-dx2.md, "Why
// plate_with_hole's tentative load step does not converge": 10 iterations, ω = 1.1e-3 against
// TOL 1e-6).
//
// What. Such a node carries no load in statics: the sum of its bonds' forces on it is zero, so
// their forces on the body are a self-equilibrated pair (zero for a single bond). So the static
// solve leaves its bonds out (mask: their broken flag set to kMasked, which every law reads as
// broken) and its dofs out of the residual, the corrections and the convergence tests; after the
// solve the bonds are put back and the node is placed where its bonds hold it (place): on the line
// of its anchors, at the point where their axial forces balance,
//   x_i = Σ_b w_b (x_b − |ξ_b| n) / Σ_b w_b,   w_b = n_bᵀ K_b n_b = c·ν·V_j/|ξ_b| (PMB)
// (n the current direction from the nearest anchor to the farthest; the reference direction for a
// single anchor, i.e. carried along by its translation): for PMB, whose axial force is linear in
// the length, that point zeroes the node's force when its anchors are collinear, and leaves its
// bonds unstretched when they keep their spacing. The next explicit step (mixed) then starts from
// a node at rest in its bonds, with no kick.
//
// A node held on both sides of its line (a link of a chain) is not hanging: it transmits load
// along the line and in tension has the lateral stiffness T/|y|. Chains: once a hanging node's
// bonds are left out, the node it hangs from may hang in turn, so the search repeats (rounds of
// a Jacobi sweep: a node's verdict in round r reads only the verdicts of rounds < r, so it does
// not depend on the order of the nodes, the threads or the ranks) until a round finds none; the
// nodes are placed from the last round to the first, each from anchors found in later rounds or
// never (a node bonded only to nodes of its own round, a free pair, stays where it is).
//
// Free fragments: once hanging nodes are out, a piece that no chain of intact bonds joins to a
// prescribed motion (the middle of a bar cracked twice) carries no load either, and inside it two
// parts may hang together by parallel bonds (measured on traction at dx × 2: two halves of the
// middle piece, joined by a few bonds across their crack, slid along x by 2/3 per Newton iteration).
// Its nodes are left out of the solve too and stay where they are (their bonds as the explicit
// phase left them: the static answer for a free piece is any rigid position; it is not relaxed).
//
// Links of linkages and strands (measured on plate_with_hole at dx = 0.25 mm:
// docs/notes/2026-12-03-mixed-hanging-nodes-pause-rule.md, "Linkages and strands"): in a round
// where no node hangs, a node with at most `dimension` intact bonds to the body is weak; a weak
// node with fewer than `dimension` of them, or bonded to another weak node, is a link of a linkage
// (Maxwell: a connected set W of weak nodes has fewer bonds than dim·|W| dofs, so a mechanism) and
// is left out too, placed after the solve at its reference place among its anchors translated by
// their weighted mean displacement. With `strands` (mixed, once the cracks have cut the load path:
// no piece carries load) a node whose bonds lie on one line on both sides (a link of an unloaded
// strand) is left out as well, placed on its anchors' line where their axial forces balance.
//
// Collinear: the reference directions ξ/|ξ| (so the verdict is a function of the broken flags
// only: the same before and after a restart) with |e × ξ/|ξ|| ≤ kCollinearSine of the first
// intact bond's e. In 3D a node held by bonds in one plane (not on one line) is not handled.
// A node with a prescribed component is never hanging (the prescription holds it).
//
// Decomposed runs (parallel/): each round's verdicts of the ghosts come from their owners (a halo
// exchange of a per-node number) and the count of new ones is summed over the ranks; the placement
// reads the anchors' displacements after a halo exchange per round. So the nodes, the masks and
// the positions are those of the serial run, bit for bit.
#pragma once
#include <array>
#include <cstdint>
#include <vector>

#include "core/model.hpp"
#include "core/nodes.hpp"

namespace pd {

class Decomposed;

class HangingNodes {
 public:
  // The broken-flag value of a bond left out of a static solve (any nonzero flag is broken).
  static constexpr std::uint8_t kMasked = 2;
  static constexpr double kCollinearSine = 1e-6;

  // Finds them from the model's broken flags and reference positions (see above). Collective on a
  // decomposed run (d not null).
  // strands: links of strands (collinear bonds on both sides) too: only where no piece carries load.
  void find(const Model& m, const std::array<std::vector<std::uint8_t>, 3>& fixed, const Decomposed* d,
            bool strands = false);
  std::int64_t count() const { return total_; }  // over the whole model, links of linkages included
  std::int64_t linkage_count() const { return linkage_total_; }  // the links of linkages among them
  bool hanging(std::size_t i) const { return !round_.empty() && round_[i] > 0.0; }
  // A node of a free fragment: no chain of intact bonds (between nodes that do not hang) joins it
  // to a prescribed motion (see above). Over the whole model: free_count().
  bool free(std::size_t i) const { return !held_.empty() && held_[i] == 0.0 && round_[i] == 0.0; }
  std::int64_t free_count() const { return free_total_; }
  // Left out of the static solve: hanging or free.
  bool left_out(std::size_t i) const { return hanging(i) || free(i); }
  // Sets kMasked on every intact bond with a hanging end (both copies: the ghost ends' verdicts
  // are known), and back to intact.
  void mask(BondList& bonds);
  void unmask(BondList& bonds);
  // Places every hanging node (see above) in u; the bonds must be unmasked. Collective.
  void place(const Model& m, Vec3Array& u, const Decomposed* d) const;

 private:
  void find_free(const Model& m, const std::array<std::vector<std::uint8_t>, 3>& fixed, const Decomposed* d);
  std::vector<double> round_;  // per local node, ghosts included: 0 not hanging, r found in round r
  std::vector<std::uint8_t> kind_;  // per local node: 1 hanging by collinear bonds, 2 a link of a linkage, 3 of a strand
  std::int64_t linkage_total_ = 0;
  std::vector<double> held_;   // per local node: 1 joined to a prescribed motion (free(): 0 and not hanging)
  std::int64_t free_total_ = 0;
  std::vector<std::int64_t> masked_;
  int rounds_ = 0;
  std::int64_t total_ = 0;
};

// Masks a model's hanging nodes' bonds for a scope (the static solve) and unmasks them however it
// ends.
class MaskedBonds {
 public:
  MaskedBonds(HangingNodes& nodes, BondList& bonds, bool active) : nodes_(nodes), bonds_(bonds), active_(active) {
    if (active_) nodes_.mask(bonds_);
  }
  ~MaskedBonds() { release(); }
  void release() {
    if (active_) nodes_.unmask(bonds_);
    active_ = false;
  }
  MaskedBonds(const MaskedBonds&) = delete;
  MaskedBonds& operator=(const MaskedBonds&) = delete;

 private:
  HangingNodes& nodes_;
  BondList& bonds_;
  bool active_;
};

}  // namespace pd
