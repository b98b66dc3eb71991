// Pre-cracks (notches): bonds whose reference segment crosses a crack segment start broken, the
// usual way to put a sharp notch into a peridynamic body (Bobaru & Zhang 2015, the crack-branching
// set-up of docs/theory.md C7; PDMATLAB2D CrackBranching.m cuts the bonds the same way).
#pragma once
#include <cstdint>
#include <vector>

#include "core/bonds.hpp"
#include "core/case.hpp"
#include "core/nodes.hpp"

namespace pd {

// True if the segments p–q and a–b cross in the xy plane (in 3D: the bond crosses the plane through
// a–b parallel to z). Touching (an end exactly on the other segment's line) does not count, so a
// crack laid between two lattice rows cuts exactly the bonds that straddle it.
bool segments_cross(const double p[2], const double q[2], const double a[2], const double b[2]);

// Marks every bond crossing one of the cracks as broken (both stored copies); returns how many
// bonds that is, each counted once.
// rows: row r of `bonds` is node rows[r]'s (build_bond_rows); null: row i is node i's. The count
// is of the bonds cut from their lower-numbered end (each once over the whole model).
std::int64_t cut_crossing_bonds(const std::vector<CrackSegment>& cracks, const Vec3Array& x, BondList& bonds,
                                const std::vector<std::int32_t>* rows = nullptr);

}  // namespace pd
