// The interior and boundary rows of a piece (parallel/row_split.hpp says why).
#include "parallel/row_split.hpp"

#include "parallel/local_model.hpp"

namespace pd {

RowSplit split_rows(const LocalPiece& piece) {
  RowSplit split;
  const BondList& bonds = piece.model.bonds;
  for (std::int32_t i : piece.owned_local) {
    bool reads_ghost = false;
    for (std::int64_t k = bonds.offsets[static_cast<std::size_t>(i)]; k < bonds.offsets[static_cast<std::size_t>(i) + 1]; ++k)
      reads_ghost = reads_ghost || !piece.owned[static_cast<std::size_t>(bonds.neighbour[static_cast<std::size_t>(k)])];
    (reads_ghost ? split.boundary : split.interior).push_back(i);
  }
  return split;
}

}  // namespace pd
