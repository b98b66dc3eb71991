// Domain decomposition for MPI runs (issue 15): which rank owns which node. Contiguous pieces of the
// Morton (Z-order) curve through the reference positions, cut so that every piece holds about the
// same number of bonds (the force sweep's work is one pass over a row's bonds). Pure arithmetic, no
// MPI: every rank computes the same decomposition from the same reference positions.
#pragma once
#include <cstdint>
#include <vector>

#include "core/bonds.hpp"
#include "core/nodes.hpp"

namespace pd {

struct Decomposition {
  int ranks = 1;
  std::vector<std::int32_t> owner;        // rank per node
  std::vector<std::int64_t> order;        // the nodes along the Morton curve (MpiDecomposed frees it after the cut)
  std::vector<std::int64_t> piece_start;  // piece r = order[piece_start[r], piece_start[r+1])
  std::vector<std::int64_t> piece_work;   // Σ (1 + bonds in the row) over piece r's nodes
};

// The Morton key of every node: each coordinate scaled to 21 bits over the bounding box's largest
// side (cubic cells, so the curve's locality is isotropic) and the bits interleaved x, y, z.
std::vector<std::uint64_t> morton_keys(const Vec3Array& x);

// Cuts the Morton order of x into `ranks` contiguous pieces of about equal work, a node's work
// being 1 + the bonds of its row (broken ones too: the sweep visits them). Node p along the curve
// goes to rank ⌊W_p·R/W⌋, W_p the work of the nodes before it and W the total: integer arithmetic,
// so every rank computes the same owner array. Throws pd::Error if there are more ranks than nodes,
// if a rank would get no node, or if a piece fits inside one horizon (its largest side < δ: its
// ghosts would outnumber its own nodes and a rank would compute mostly copies).
Decomposition decompose(const Vec3Array& x, const BondList& bonds, int ranks, double horizon);
// The same from the rows' offsets alone (core/bonds count_bonds): what a rank that builds only its
// own rows knows before it builds them.
Decomposition decompose(const Vec3Array& x, const std::vector<std::int64_t>& offsets, int ranks, double horizon);

}  // namespace pd
