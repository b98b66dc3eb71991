// Short-range contact (forces/contact.hpp) on one rank's piece of a decomposed run (issue 15):
// the same pairs, forces and energy as the serial run, bit for bit, for any rank count.
//
// The pairs of an owned node may be owned by any rank, and they move with the bodies, so the
// contact ghosts are found anew at every Verlet-list build:
// - the build decision is collective: each rank applies the skin rule to its piece and the ranks
//   take the largest verdict (Decomposed::minimum of its negative), which is the serial verdict
//   over all nodes; so every rank rebuilds in the step the serial run does;
// - the ghosts: each rank's box around its owned nodes' current positions, grown by the contact
//   distance + skin, goes to every rank, and each rank sends the owned nodes inside another's box
//   (their displacement, reference position, volume, block) to it (Decomposed::exchange_in_boxes);
//   any node within reach of an owned node is inside that box;
// - the search runs over the owned nodes and those received, numbered in ascending global order,
//   with only the owned rows searched (NeighbourList::search's row mask): an owned row finds the
//   serial row's nodes in the serial order. The nodes no owned row names are dropped again;
// - in every force evaluation the kept ghosts that are not bond ghosts get their displacement
//   from their owners (Decomposed::make_node_halo); the bond ghosts' come from the bonds' halo;
// - the energy is the serial exact sum (Decomposed::exact_sum), and the build count is the
//   same on every rank because every rank builds together.
// The piece's NeighbourList (model.contact_list) records the builds (count, time, the piece's
// displacement at the last one) for run.log, history.csv and the checkpoint; a restart restores
// that record and the first force evaluation searches again at the recorded displacement, so a
// checkpoint continues on any rank count as the uninterrupted run.
#pragma once
#include <cstdint>
#include <memory>
#include <vector>

#include "core/model.hpp"
#include "core/neighbour_list.hpp"
#include "parallel/decomposed.hpp"

namespace pd {

class ContactOnPiece {
 public:
  // model: the piece's model (d.piece().model).
  ContactOnPiece(const Model& model, const Decomposed& d) : model_(model), d_(d) {}
  // f += the contact force density of the owned rows at the piece's displacement u (ghosts
  // current); returns the contact potential energy [J], the serial sum's bits. Collective.
  double add_force(const Vec3Array& u, Vec3Array& f);

 private:
  // Finds the contact ghosts and the owned rows' pairs at the piece's displacement u. Collective.
  void build(const Vec3Array& u, bool counted);

  const Model& model_;
  const Decomposed& d_;
  // The contact set: owned nodes and kept contact ghosts, ascending global number.
  std::vector<std::int32_t> global_;
  std::vector<std::int32_t> piece_local_;  // its piece-local number, −1 for a ghost outside the piece
  std::vector<std::int32_t> owned_;        // the owned entries of the set
  Vec3Array x_, u_, f_;
  std::vector<double> volume_, energy_;
  std::vector<std::int32_t> block_;
  ContactPairs pairs_;  // scratch of the search (the current list is in model.contact_list)
  NeighbourList::Scratch scratch_;
  std::unique_ptr<NodeHalo> halo_;
};

}  // namespace pd
