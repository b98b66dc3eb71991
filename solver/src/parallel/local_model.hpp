// One rank's piece of the model (issue 15): the nodes it owns and their ghosts — every node within
// the horizon of an owned node, i.e. every bond partner of an owned row — numbered locally in
// ascending global order, with a local Model whose rows are the owned rows (a ghost's row is empty).
//
// Why ascending global order: the kernels compare node numbers (i < j: the copy of a bond that
// counts it once, materials/pmb) and sum a row's bonds in the order of its neighbours; a local
// numbering that keeps the global order keeps both, so an owned row sums the same terms in the same
// order as the serial sweep and gives the same bits. Why ghosts have empty rows: the kernels run
// unchanged over the local arrays, and a ghost's force is its owner's business.
// Pure bookkeeping, no MPI (parallel/halo and parallel/ordered_sum move the data).
#pragma once
#include <cstdint>
#include <vector>

#include "core/model.hpp"

namespace pd {

struct LocalPiece {
  int rank = 0;
  std::int64_t global_nodes = 0;          // nodes of the whole model
  std::vector<std::int32_t> global;       // global number of local node l (ascending)
  std::vector<std::uint8_t> owned;        // 1: owned by this rank, 0: a ghost
  std::vector<std::int32_t> owned_local;  // the owned local nodes, ascending
  std::vector<std::int32_t> ghost_local;  // the ghosts, ascending
  Model model;                            // the local model (see above)

  std::size_t size() const { return global.size(); }
};

// The piece of `rank` under `owner` (parallel/decomposition): nodes, per-node data, bonds (the
// owned rows, neighbours renumbered, flags copied), material, and the conditions restricted to
// owned nodes. The law is built again from the registry on the local model.
LocalPiece make_local_piece(const Model& global, const std::vector<std::int32_t>& owner, int rank);
// The same without the whole bond list (issue 15): `global` holds the per-node data only
// (build_model_without_bonds), and owned_rows the rows of this rank's owned nodes in ascending
// node order, neighbours numbered globally (core/bonds build_bond_rows), pre-cracks cut. The piece
// is the one make_local_piece gives from the whole model, bit for bit. The rows' arrays become the
// piece's (pass them with std::move: they are then never held twice).
LocalPiece make_local_piece(const Model& global, const std::vector<std::int32_t>& owner, int rank, BondList owned_rows);

// a_local[l] = a_global[global[l]] for every local node (owned and ghost).
Vec3Array to_local(const LocalPiece& piece, const Vec3Array& a_global);
std::vector<double> to_local(const LocalPiece& piece, const std::vector<double>& a_global);
// The broken flags of the piece's owned rows from the same rows of the whole model's bond list (a
// restart: the checkpoint holds the whole model's flags). Ghost rows are empty.
void rows_to_local(const LocalPiece& piece, const BondList& global, BondList& local);
// The same for `width` values per directed bond of the whole model's `per_bond` (rows of `global`):
// the piece's per-bond array over its rows `local` (a ghost's row is empty).
std::vector<double> rows_to_local(const LocalPiece& piece, const BondList& global, const std::vector<double>& per_bond,
                                  const BondList& local, int width);
// A restart: every checkpointed array of the piece's declared state (core/state_arrays.hpp) from
// the whole model's `whole` — per node, the local nodes' entries; per bond, the owned rows' over
// `global_bonds`, the whole model's rows.
void state_to_local(const LocalPiece& piece, const BondList& global_bonds, const StateArrays& whole, StateArrays& local);

}  // namespace pd
