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
// - the linearised force (the Newton solves of quasi_static, implicit and mixed): the product
//   ∂f/∂u·δu over the same list, with the contact ghosts' u and δu from their owners through the
//   same halo (δu's bond ghosts filled by ForceOperator::apply_jacobian), and the diagonal blocks
//   of the owned rows from the set's u fetched before (update_displacement); an owned row sums
//   the serial row's pairs in the serial order from exact copies, so it is the serial row's bits;
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
#include "forces/contact.hpp"
#include "parallel/decomposed.hpp"

namespace pd {

class ContactOnPiece {
 public:
  // model: the piece's model (d.piece().model).
  ContactOnPiece(const Model& model, const Decomposed& d) : model_(model), d_(d) {}
  // f += the contact force density of the owned rows at the piece's displacement u (ghosts
  // current); returns the contact potential energy [J], the serial sum's bits. Collective.
  double add_force(const Vec3Array& u, Vec3Array& f);
  // y += ∂f/∂u·du over the owned rows of the current list at the piece's displacement u; u's and
  // du's bond ghosts must be current. Collective.
  void add_jacobian_product(const Vec3Array& u, const Vec3Array& du, Vec3Array& y);
  // The set's displacements at the piece's u (bond ghosts current): from the piece, and the
  // contact ghosts' from their owners. Collective.
  void update_displacement(const Vec3Array& u);
  // block += ∂f_i/∂u_i of owned piece node i's pairs at the set's displacement of the last
  // update_displacement (or force). Reads only: callable from threads.
  void add_jacobian_diagonal(std::size_t i, double block[9], bool definite) const;

 private:
  // Finds the contact ghosts and the owned rows' pairs at the piece's displacement u. Collective.
  void build(const Vec3Array& u, bool counted);
  // The kernels' view of the set at its displacement u_ over the current list.
  ContactArrays arrays() const;
  // The owned rows' sums of the set, s_c = 0 + s exactly, into the piece's rows: f_l += s_c, the
  // serial f_i += s.
  void add_owned_rows(const Vec3Array& set_values, Vec3Array& piece_values) const;

  const Model& model_;
  const Decomposed& d_;
  // The contact set: owned nodes and kept contact ghosts, ascending global number.
  std::vector<std::int32_t> global_;
  std::vector<std::int32_t> piece_local_;  // its piece-local number, −1 for a ghost outside the piece
  std::vector<std::int32_t> owned_;        // the owned entries of the set
  std::vector<std::int32_t> set_of_piece_; // per piece node: its entry of the set, −1 if none
  Vec3Array x_, u_, f_, du_;
  std::vector<double> volume_, energy_;
  std::vector<std::int32_t> block_;
  ContactPairs pairs_;  // scratch of the search (the current list is in model.contact_list)
  NeighbourList::Scratch scratch_;
  std::unique_ptr<NodeHalo> halo_;
};

}  // namespace pd
