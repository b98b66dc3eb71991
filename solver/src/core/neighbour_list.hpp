// The contact neighbour list (a "Verlet list" in molecular-dynamics terms; named apart from the
// velocity-Verlet integrator): node pairs within the contact distance plus a skin,
// found with a cell list over current positions and rebuilt only when some node has moved more
// than half the skin since the last build (so no pair can have come within the contact distance
// unseen: each of the two nodes moved ≤ skin/2). Never O(N²).
#pragma once
#include <algorithm>
#include <cstdint>
#include <vector>

#include "core/nodes.hpp"

namespace pd {

// What the contact search needs to know, decided once from the case (core/work_plan).
struct ContactParameters {
  bool pairs = false;             // any short-range pair force at all
  bool self_contact = false;      // pairs inside one block count too
  double distance = 0.0;          // 2·r_s = 1.35·(r_i + r_j), r = dx/2: the largest contact distance [m]
  double skin = 0.0;              // [m]
  double stiffness_factor = 15.0; // c_s = factor·c
  double bond_cutoff = 0.0;       // pairs with |ξ| ≤ this have a reference bond
};

// Every pair stored from both ends (like the bond list), so a loop over nodes writes only its own
// node's force. Row i is ascending in j: the same list, and the same sums, for any thread count.
struct ContactPairs {
  std::vector<std::int64_t> offsets;
  std::vector<std::int32_t> neighbour;
  std::vector<double> distance;  // d_ij = min(0.9|ξ|, 2r_s) with a reference bond, else 2r_s (F4)
  std::size_t directed() const { return neighbour.size(); }
};

// d_ij of docs/theory.md T8 (LAMMPS pair peri/pmb, Silling's EMU): 0.9|ξ| keeps a bonded pair from
// repelling at its rest length; 2r_s = 1.35·dx for any other pair.
inline double contact_distance(double reference_length, bool bonded, double two_rs) {
  return bonded ? std::min(0.9 * reference_length, two_rs) : two_rs;
}

class NeighbourList {
 public:
  // Rebuilds the list if this is the first call or some node moved more than skin/2 since the
  // last build (max over nodes of |u − u_build|); returns true if it rebuilt.
  bool update(const Vec3Array& x, const Vec3Array& u, const std::vector<std::int32_t>& block,
              const ContactParameters& p);
  // A fresh list of the pairs within distance + skin at (x + u), ignoring the rebuild rule.
  static ContactPairs search(const Vec3Array& x, const Vec3Array& u, const std::vector<std::int32_t>& block,
                             const ContactParameters& p);

  // The buffers one search needs besides its result, kept between rebuilds: a rebuild every few
  // steps would otherwise allocate them afresh, and the page faults of that cost a quarter of
  // the search (cases/impact, perf).
  struct Scratch {
    Vec3Array y;                                   // current positions x + u
    std::vector<std::vector<std::int32_t>> found;  // per thread: the j's of its rows, row after row
  };
  // search() into `out`, reusing its storage and that of `scratch`. rows (null: every row): the
  // rows to search, 1 a row and 0 an empty one (a decomposed run searches its owned rows only,
  // forces/contact_on_piece); a searched row is the same in either case.
  static void search(const Vec3Array& x, const Vec3Array& u, const std::vector<std::int32_t>& block,
                     const ContactParameters& p, ContactPairs& out, Scratch& scratch,
                     const std::uint8_t* rows = nullptr);
  // The skin rule on u: 0 no node moved more than skin/2 since the last build, 1 one did, 2 some
  // displacement is not finite (the list cannot be binned; the time loop stops on it anyway).
  int moved_since_build(const Vec3Array& u, const ContactParameters& p) const;

  // A decomposed run keeps the list of its piece (forces/contact_on_piece) and records each build
  // here: `pairs` (swapped in; the old list comes back for reuse), the piece's displacement at the
  // build (the skin rule's and the checkpoint's u_build) and the time it took. counted: false for
  // the build that brings a restored list back, which the checkpoint has counted already.
  void record_build(ContactPairs& pairs, const Vec3Array& u_build, double seconds, bool counted);
  // A restart of a decomposed run: the count, time and displacement of the last build, without the
  // search (its owner searches on the ranks, in their next force evaluation).
  void restore_record(const Vec3Array& u_build, std::int64_t rebuilds, double seconds);

  // The list as it was after `rebuilds` builds, the last at displacement u_build (a checkpoint,
  // io/checkpoint.hpp): search() at u_build gives bitwise the pairs that build found.
  void restore(const Vec3Array& x, const Vec3Array& u_build, const std::vector<std::int32_t>& block,
               const ContactParameters& p, std::int64_t rebuilds, double seconds);
  const Vec3Array& u_build() const { return u_build_; }

  const ContactPairs& pairs() const { return pairs_; }
  std::int64_t rebuilds() const { return rebuilds_; }  // builds including the first
  double seconds() const { return seconds_; }          // wall time spent searching [s]

 private:
  ContactPairs pairs_;
  Scratch scratch_;
  Vec3Array u_build_;
  std::int64_t rebuilds_ = 0;
  double seconds_ = 0.0;
};

}  // namespace pd
