// Contact on a decomposed run's piece (see contact_on_piece.hpp).
#include "forces/contact_on_piece.hpp"

#include <algorithm>
#include <chrono>
#include <limits>

#include "forces/contact.hpp"
#include "parallel/local_model.hpp"

namespace pd {

namespace {

constexpr int kWidth = 8;  // per node sent in the box exchange: u (3), x (3), V, block

// How far beyond the owned nodes' box a node may be and still pair with one of them: the search
// keeps pairs with |y_j − y_i| ≤ distance + skin, compared in floating point, so the box is grown
// by a little more than that (a node too many costs nothing: the search drops it).
double box_margin(const ContactParameters& p) { return 1.001 * (p.distance + p.skin); }

}  // namespace

void ContactOnPiece::build(const Vec3Array& u, bool counted) {
  const auto start = std::chrono::steady_clock::now();
  const LocalPiece& piece = d_.piece();
  const Model& m = model_;
  const std::size_t owned = piece.owned_local.size();
  // The owned nodes: global numbers, current positions, what a pair needs of them.
  std::vector<std::int32_t> owned_global(owned);
  Vec3Array y_owned = make_vec3(owned);
  std::vector<double> values(kWidth * owned);
  double lo[3], hi[3];
  for (std::size_t d = 0; d < 3; ++d) lo[d] = std::numeric_limits<double>::infinity(), hi[d] = -lo[d];
  for (std::size_t k = 0; k < owned; ++k) {
    const auto l = static_cast<std::size_t>(piece.owned_local[k]);
    owned_global[k] = piece.global[l];
    for (std::size_t d = 0; d < 3; ++d) {
      y_owned[d][k] = m.nodes.x[d][l] + u[d][l];  // y = x + u as the search computes it
      lo[d] = std::min(lo[d], y_owned[d][k]);
      hi[d] = std::max(hi[d], y_owned[d][k]);
      values[kWidth * k + d] = u[d][l];
      values[kWidth * k + 3 + d] = m.nodes.x[d][l];
    }
    values[kWidth * k + 6] = m.nodes.volume[l];
    values[kWidth * k + 7] = static_cast<double>(m.block_index[l]);
  }
  const double margin = box_margin(m.contact);
  for (std::size_t d = 0; d < 3; ++d) lo[d] -= margin, hi[d] += margin;
  std::vector<std::int32_t> received;
  std::vector<double> received_values;
  d_.exchange_in_boxes(lo, hi, owned_global, y_owned, values, kWidth, received, received_values);

  // The candidate set: owned and received nodes merged in ascending global order.
  const std::size_t n = owned + received.size();
  std::vector<std::int32_t> global(n), piece_local(n);
  std::vector<std::uint8_t> row(n);
  Vec3Array x = make_vec3(n), uc = make_vec3(n);
  std::vector<double> volume(n);
  std::vector<std::int32_t> block(n);
  {
    std::size_t a = 0, b = 0;
    for (std::size_t c = 0; c < n; ++c) {
      const bool mine = b == received.size() || (a < owned && owned_global[a] < received[b]);
      if (mine) {
        const auto l = static_cast<std::size_t>(piece.owned_local[a++]);
        global[c] = piece.global[l];
        piece_local[c] = static_cast<std::int32_t>(l);
        row[c] = 1;
        for (std::size_t d = 0; d < 3; ++d) x[d][c] = m.nodes.x[d][l], uc[d][c] = u[d][l];
        volume[c] = m.nodes.volume[l];
        block[c] = m.block_index[l];
      } else {
        const double* v = &received_values[kWidth * b];
        global[c] = received[b++];
        // A bond ghost's displacement comes with the bonds' halo; any other ghost needs its own.
        const auto it = std::lower_bound(piece.global.begin(), piece.global.end(), global[c]);
        piece_local[c] = it != piece.global.end() && *it == global[c] ? static_cast<std::int32_t>(it - piece.global.begin()) : -1;
        row[c] = 0;
        for (std::size_t d = 0; d < 3; ++d) uc[d][c] = v[d], x[d][c] = v[3 + d];
        volume[c] = v[6];
        block[c] = static_cast<std::int32_t>(v[7]);
      }
    }
  }
  NeighbourList::search(x, uc, block, m.contact, pairs_, scratch_, row.data());

  // Keep the owned nodes and the ghosts some owned row names; renumber the pairs (in order, so
  // each row stays ascending).
  std::vector<std::uint8_t> keep(row);
  for (std::int32_t j : pairs_.neighbour) keep[static_cast<std::size_t>(j)] = 1;
  std::vector<std::int32_t> kept_as(n, -1);
  global_.clear(), piece_local_.clear(), owned_.clear(), volume_.clear(), block_.clear();
  for (auto& a : x_) a.clear();
  std::vector<std::int32_t> extra;  // kept ghosts outside the piece: the contact halo's ghosts
  for (std::size_t c = 0; c < n; ++c) {
    if (!keep[c]) continue;
    const auto k = static_cast<std::int32_t>(global_.size());
    kept_as[c] = k;
    global_.push_back(global[c]);
    piece_local_.push_back(piece_local[c]);
    if (row[c]) owned_.push_back(k);
    else if (piece_local[c] < 0) extra.push_back(k);
    for (std::size_t d = 0; d < 3; ++d) x_[d].push_back(x[d][c]);
    volume_.push_back(volume[c]);
    block_.push_back(block[c]);
  }
  const std::size_t kept = global_.size();
  ContactPairs list;
  list.offsets.assign(kept + 1, 0);
  for (std::size_t c = 0; c < n; ++c)
    if (keep[c]) list.offsets[static_cast<std::size_t>(kept_as[c]) + 1] = pairs_.offsets[c + 1] - pairs_.offsets[c];
  for (std::size_t k = 0; k < kept; ++k) list.offsets[k + 1] += list.offsets[k];
  list.neighbour.resize(pairs_.neighbour.size());
  for (std::size_t e = 0; e < pairs_.neighbour.size(); ++e)
    list.neighbour[e] = kept_as[static_cast<std::size_t>(pairs_.neighbour[e])];
  list.distance = pairs_.distance;  // rows keep their order: the owned rows are the only non-empty ones
  set_of_piece_.assign(piece.global.size(), -1);
  for (std::size_t k = 0; k < kept; ++k)
    if (piece_local_[k] >= 0) set_of_piece_[static_cast<std::size_t>(piece_local_[k])] = static_cast<std::int32_t>(k);
  u_ = make_vec3(kept);
  f_ = make_vec3(kept);
  du_ = make_vec3(kept);
  energy_.assign(kept, 0.0);
  halo_ = d_.make_node_halo(global_, extra);
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  m.contact_list.record_build(list, u, seconds, counted);
}

double ContactOnPiece::add_force(const Vec3Array& u, Vec3Array& f) {
  const Model& m = model_;
  NeighbourList& list = m.contact_list;
  // NeighbourList::update's rule, decided by all ranks together: the serial verdict over all nodes
  // is the largest of the pieces' (a piece holds its owned nodes and copies of its bond ghosts).
  // A restart replaced the record (after the integrator's first evaluation had built a list at the
  // start's state): search again at the recorded displacement, the list the serial restore finds.
  // (restore_record leaves the pairs empty; a build leaves a row per node of the set.)
  if (list.rebuilds() > 0 && list.pairs().offsets.empty()) build(list.u_build(), false);
  if (list.rebuilds() == 0) {
    build(u, true);
  } else {
    const int moved = static_cast<int>(-d_.minimum(-static_cast<double>(list.moved_since_build(u, m.contact))));
    if (moved == 1) build(u, true);  // 2: not finite, not binned (the time loop stops on it)
  }

  update_displacement(u);
  const ContactArrays a = arrays();
  for (auto& fc : f_) std::fill(fc.begin(), fc.end(), 0.0);
  add_contact_force_density(a, f_[0].data(), f_[1].data(), f_[2].data(), energy_.data());
  add_owned_rows(f_, f);
  // The energy: the serial exact Σ e_i V_i.
  std::vector<double> per_node(f[0].size(), 0.0);
  for (std::int32_t k : owned_) {
    const auto c = static_cast<std::size_t>(k);
    per_node[static_cast<std::size_t>(piece_local_[c])] = energy_[c] * volume_[c];
  }
  return d_.exact_sum(per_node);
}

void ContactOnPiece::update_displacement(const Vec3Array& u) {
  // Owned nodes and bond ghosts from the piece, the others from their owners.
  const std::size_t n = global_.size();
  for (std::size_t c = 0; c < n; ++c)
    if (piece_local_[c] >= 0)
      for (std::size_t d = 0; d < 3; ++d) u_[d][c] = u[d][static_cast<std::size_t>(piece_local_[c])];
  halo_->exchange(u_);
}

ContactArrays ContactOnPiece::arrays() const {
  const Model& m = model_;
  const ContactPairs& pairs = m.contact_list.pairs();
  ContactArrays a;
  a.offsets = pairs.offsets.data();
  a.neighbour = pairs.neighbour.data();
  a.distance = pairs.distance.data();
  for (std::size_t d = 0; d < 3; ++d) {
    a.x[d] = x_[d].data();
    a.u[d] = u_[d].data();
  }
  a.volume = volume_.data();
  a.block = block_.data();
  a.c_pair = m.material.micromodulus_pair.data();
  a.blocks = m.material.blocks;
  a.nodes = static_cast<std::int64_t>(global_.size());
  a.stiffness_over_horizon = m.contact.stiffness_factor / m.horizon;
  return a;
}

void ContactOnPiece::add_owned_rows(const Vec3Array& set_values, Vec3Array& piece_values) const {
  // 0 + s = s exactly (a row's sum s starts at +0 and so is never −0), so the piece's row gets the
  // serial row's += s.
  for (std::int32_t k : owned_) {
    const auto c = static_cast<std::size_t>(k);
    const auto l = static_cast<std::size_t>(piece_local_[c]);
    for (std::size_t d = 0; d < 3; ++d) piece_values[d][l] += set_values[d][c];
  }
}

void ContactOnPiece::add_jacobian_product(const Vec3Array& u, const Vec3Array& du, Vec3Array& y) {
  // The serial product reads the list of the last force evaluation; a restart's record has none
  // until the first force (add_force), the same on every rank: nothing to add then, as serially.
  if (model_.contact_list.pairs().offsets.empty()) return;
  update_displacement(u);
  const std::size_t n = global_.size();
  for (std::size_t c = 0; c < n; ++c)
    if (piece_local_[c] >= 0)
      for (std::size_t d = 0; d < 3; ++d) du_[d][c] = du[d][static_cast<std::size_t>(piece_local_[c])];
  halo_->exchange(du_);
  for (auto& fc : f_) std::fill(fc.begin(), fc.end(), 0.0);
  add_contact_jacobian_product(arrays(), du_, f_[0].data(), f_[1].data(), f_[2].data());
  add_owned_rows(f_, y);
}

void ContactOnPiece::add_jacobian_diagonal(std::size_t i, double block[9], bool definite) const {
  if (model_.contact_list.pairs().offsets.empty() || i >= set_of_piece_.size() || set_of_piece_[i] < 0) return;
  add_contact_jacobian_diagonal(arrays(), set_of_piece_[i], block, definite);
}

}  // namespace pd
