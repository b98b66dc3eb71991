// Finding, masking and placing the nodes that hang by collinear bonds (integrators/hanging_nodes.hpp).
#include "integrators/hanging_nodes.hpp"

#include <algorithm>
#include <cmath>

#include "parallel/decomposed.hpp"
#include "parallel/local_model.hpp"

namespace pd {

namespace {

// Whether the bonds of row i to the nodes `active` lets through lie on one line and on one side of
// i in the reference configuration (or there are none).
template <class Active>
bool hangs(const Model& m, std::size_t i, const Active& active, bool one_side = true) {
  const auto& X = m.nodes.x;
  const auto& bonds = m.bonds;
  bool first = true;
  double e[3] = {0.0, 0.0, 0.0};
  for (std::int64_t k = bonds.offsets[i]; k < bonds.offsets[i + 1]; ++k) {
    const auto ku = static_cast<std::size_t>(k);
    if (bonds.broken[ku]) continue;
    const auto j = static_cast<std::size_t>(bonds.neighbour[ku]);
    if (!active(j)) continue;
    const double length = bond_length(X, i, j);
    const double n[3] = {(X[0][j] - X[0][i]) / length, (X[1][j] - X[1][i]) / length, (X[2][j] - X[2][i]) / length};
    if (first) {
      std::copy(n, n + 3, e);
      first = false;
      continue;
    }
    const double cross[3] = {e[1] * n[2] - e[2] * n[1], e[2] * n[0] - e[0] * n[2], e[0] * n[1] - e[1] * n[0]};
    const double sine = std::sqrt(cross[0] * cross[0] + cross[1] * cross[1] + cross[2] * cross[2]);
    if (sine > HangingNodes::kCollinearSine || (one_side && e[0] * n[0] + e[1] * n[1] + e[2] * n[2] <= 0.0)) return false;
  }
  return true;
}

// The intact bonds of row i to nodes still in the body (round 0).
std::int64_t intact_degree(const Model& m, std::size_t i, const std::vector<double>& round) {
  const auto& bonds = m.bonds;
  std::int64_t degree = 0;
  for (std::int64_t k = bonds.offsets[i]; k < bonds.offsets[i + 1]; ++k) {
    const auto ku = static_cast<std::size_t>(k);
    if (!bonds.broken[ku] && round[static_cast<std::size_t>(bonds.neighbour[ku])] == 0.0) ++degree;
  }
  return degree;
}

// A link of a linkage (hanging_nodes.hpp): weak (at most `dimension` intact bonds to the body) and
// either with fewer than `dimension` of them, or bonded to another weak node. Row i must be owned
// (its bonds); the neighbours' weak verdicts come from `weak` (ghosts' from their owners).
bool linkage(const Model& m, std::size_t i, const std::vector<double>& round, const std::vector<double>& weak, int dimension) {
  if (weak[i] == 0.0) return false;
  const auto& bonds = m.bonds;
  std::int64_t degree = 0;
  bool weak_neighbour = false;
  for (std::int64_t k = bonds.offsets[i]; k < bonds.offsets[i + 1]; ++k) {
    const auto ku = static_cast<std::size_t>(k);
    const auto j = static_cast<std::size_t>(bonds.neighbour[ku]);
    if (bonds.broken[ku] || round[j] != 0.0) continue;
    ++degree;
    weak_neighbour = weak_neighbour || weak[j] != 0.0;
  }
  return degree < dimension || weak_neighbour;
}

}  // namespace

void HangingNodes::find(const Model& m, const std::array<std::vector<std::uint8_t>, 3>& fixed, const Decomposed* d,
                        bool strands) {
  const std::size_t n = m.nodes.size();
  round_.assign(n, 0.0);
  masked_.clear();
  rounds_ = 0;
  total_ = 0;
  const int dimension = m.nodes.dimension;
  std::vector<std::uint8_t> candidate(n, 0);
  for (std::size_t i = 0; i < n; ++i) {
    bool free = !d || d->piece().owned[i];
    for (int c = 0; c < dimension; ++c) free = free && !fixed[static_cast<std::size_t>(c)][i];
    candidate[i] = free ? 1 : 0;
  }
  const auto count = static_cast<std::int64_t>(n);
  std::vector<std::uint8_t> now_found(n, 0);
  kind_.assign(n, 0);
  linkage_total_ = 0;
  std::vector<double> weak(n, 0.0);  // per local node, ghosts from their owners: see linkage()
  for (int r = 1;; ++r) {
    // Round r: a node still in the body hangs when its bonds to the nodes that were still in the body
    // at the start of the round hang; a Jacobi sweep (the verdicts written after it), so they do
    // not depend on the order in which the threads reach the nodes. Only a round in which no node
    // hangs looks for links of linkages and strands (the same Jacobi sweep): so the hanging nodes
    // and their rounds are those found without them, and a link's anchors are placed before it.
    std::int64_t found = 0, linkages = 0;
#pragma omp parallel for schedule(dynamic, 512) reduction(+ : found)
    for (std::int64_t q = 0; q < count; ++q) {
      const auto i = static_cast<std::size_t>(q);
      now_found[i] = 0;
      if (!candidate[i] || round_[i] > 0.0) continue;
      if (hangs(m, i, [&](std::size_t j) { return round_[j] == 0.0; })) {
        now_found[i] = 1;
        ++found;
      }
    }
    if (d) found = d->total(found);
    if (found == 0) {
#pragma omp parallel for schedule(dynamic, 512)
      for (std::int64_t q = 0; q < count; ++q) {
        const auto i = static_cast<std::size_t>(q);
        weak[i] = candidate[i] && round_[i] == 0.0 && intact_degree(m, i, round_) <= dimension ? 1.0 : 0.0;
      }
      if (d) d->update_ghosts(weak);
#pragma omp parallel for schedule(dynamic, 512) reduction(+ : linkages)
      for (std::int64_t q = 0; q < count; ++q) {
        const auto i = static_cast<std::size_t>(q);
        if (!candidate[i] || round_[i] > 0.0) continue;
        if (linkage(m, i, round_, weak, dimension)) {
          now_found[i] = 2;
          ++linkages;
        } else if (strands && hangs(m, i, [&](std::size_t j) { return round_[j] == 0.0; }, false)) {
          now_found[i] = 3;
          ++linkages;
        }
      }
      if (d) linkages = d->total(linkages);
      found = linkages;
    }
    for (std::size_t i = 0; i < n; ++i)
      if (now_found[i]) round_[i] = r, kind_[i] = now_found[i];
    if (d) d->update_ghosts(round_);
    if (found == 0) break;
    rounds_ = r;
    total_ += found;
    linkage_total_ += linkages;
  }
  find_free(m, fixed, d);
}

void HangingNodes::find_free(const Model& m, const std::array<std::vector<std::uint8_t>, 3>& fixed, const Decomposed* d) {
  // held_: reached from a node with a prescribed component through intact bonds between nodes that
  // do not hang. A breadth-first search over the rows this piece owns, seeded with the held nodes
  // and the owned neighbours of held ghosts; on a decomposed run the ghosts' verdicts are exchanged
  // and the search goes on until no rank finds more (the closure is unique: the same nodes as the
  // serial search).
  const std::size_t n = m.nodes.size();
  const auto& bonds = m.bonds;
  held_.assign(n, 0.0);
  free_total_ = 0;
  const auto owned = [&](std::size_t i) { return !d || d->piece().owned[i] != 0; };
  std::vector<std::size_t> queue;
  for (std::size_t i = 0; i < n; ++i)
    if (owned(i) && (fixed[0][i] || fixed[1][i] || fixed[2][i])) held_[i] = 1.0, queue.push_back(i);
  const auto link = [&](std::size_t k, std::size_t i) {
    const auto j = static_cast<std::size_t>(bonds.neighbour[k]);
    return bonds.broken[k] == 0 && round_[i] == 0.0 && round_[j] == 0.0 ? j : n;
  };
  for (;;) {
    for (std::size_t at = 0; at < queue.size(); ++at) {
      const std::size_t i = queue[at];
      for (std::int64_t k = bonds.offsets[i]; k < bonds.offsets[i + 1]; ++k) {
        const std::size_t j = link(static_cast<std::size_t>(k), i);
        if (j == n || held_[j] != 0.0) continue;
        held_[j] = 1.0;
        if (owned(j)) queue.push_back(j);
      }
    }
    if (!d) break;
    d->update_ghosts(held_);
    // Owned nodes bonded to a ghost held on its owner's side: the search goes on from them.
    queue.clear();
    for (std::size_t i = 0; i < n; ++i) {
      if (!owned(i) || held_[i] != 0.0) continue;
      for (std::int64_t k = bonds.offsets[i]; k < bonds.offsets[i + 1]; ++k) {
        const std::size_t j = link(static_cast<std::size_t>(k), i);
        if (j != n && held_[j] != 0.0) {
          held_[i] = 1.0, queue.push_back(i);
          break;
        }
      }
    }
    if (d->total(static_cast<std::int64_t>(queue.size())) == 0) break;
  }
  std::int64_t free_here = 0;
  for (std::size_t i = 0; i < n; ++i)
    if (owned(i) && free(i)) ++free_here;
  free_total_ = d ? d->total(free_here) : free_here;
}

void HangingNodes::mask(BondList& bonds) {
  masked_.clear();
  if (total_ == 0) return;
  const std::size_t n = bonds.nodes();
  for (std::size_t i = 0; i < n; ++i)
    for (std::int64_t k = bonds.offsets[i]; k < bonds.offsets[i + 1]; ++k) {
      const auto ku = static_cast<std::size_t>(k);
      if (bonds.broken[ku]) continue;
      if (round_[i] > 0.0 || round_[static_cast<std::size_t>(bonds.neighbour[ku])] > 0.0) {
        bonds.broken[ku] = kMasked;
        masked_.push_back(k);
      }
    }
}

void HangingNodes::unmask(BondList& bonds) {
  for (std::int64_t k : masked_) bonds.broken[static_cast<std::size_t>(k)] = 0;
  masked_.clear();
}

void HangingNodes::place(const Model& m, Vec3Array& u, const Decomposed* d) const {
  if (total_ == 0) return;
  const auto& X = m.nodes.x;
  const auto& bonds = m.bonds;
  const std::size_t n = m.nodes.size();
  const int dimension = m.nodes.dimension;
  for (int r = rounds_; r >= 1; --r) {
    // The anchors of round r's nodes are placed (later rounds) or in the body: their ghosts' u first.
    if (d) d->update_ghosts(u);
    const double now = r;
    // Two passes: the new positions from u as it is (a node of this round may be bonded to another
    // of this round, read by the law's tangent row), then written.
    std::vector<std::int64_t> nodes;
    for (std::size_t i = 0; i < n; ++i)
      if (round_[i] == now) nodes.push_back(static_cast<std::int64_t>(i));
    const auto members = static_cast<std::int64_t>(nodes.size());
    std::vector<double> placed(3 * nodes.size());
    std::vector<std::uint8_t> moved(nodes.size(), 0);
#pragma omp parallel
    {
      std::vector<double> blocks;
#pragma omp for schedule(dynamic, 64)
      for (std::int64_t g = 0; g < members; ++g) {
        const auto i = static_cast<std::size_t>(nodes[static_cast<std::size_t>(g)]);
        const auto first = bonds.offsets[i], last = bonds.offsets[i + 1];
        // The axial stiffness of each bond from the law's own tangent row at u, w_b = n_bᵀ K_b n_b.
        blocks.assign(static_cast<std::size_t>(9 * (last - first)), 0.0);
        const bool have_tangent = m.bond_model->bond_tangent_row(m, u, i, blocks.data());
        const auto position = [&](std::size_t j, int c) {
          return X[static_cast<std::size_t>(c)][j] + u[static_cast<std::size_t>(c)][j];
        };
        // w_b = n_bᵀ K_b n_b of bond `slot` of row i to j, from the law's tangent row at u.
        const auto axial_weight = [&](std::int64_t slot, std::size_t i_, std::size_t j) {
          double w = 0.0;
          if (have_tangent) {
            double y[3], norm = 0.0;
            for (int c = 0; c < 3; ++c) y[c] = position(j, c) - position(i_, c), norm += y[c] * y[c];
            norm = std::sqrt(norm);
            const double* b = &blocks[static_cast<std::size_t>(9 * slot)];
            if (norm > 0.0)
              for (int a = 0; a < 3; ++a)
                for (int c = 0; c < 3; ++c) w += y[a] * b[3 * a + c] * y[c] / (norm * norm);
          }
          if (!(w > 0.0) || !std::isfinite(w)) w = 1.0 / bond_length(X, i_, j);  // a law without a tangent row: ν·V equal
          return w;
        };
        // The anchors: intact bonds to nodes in the body or placed in a later round.
        const auto anchor = [&](std::int64_t k) {
          const auto ku = static_cast<std::size_t>(k);
          const auto j = static_cast<std::size_t>(bonds.neighbour[ku]);
          return !bonds.broken[ku] && (round_[j] == 0.0 || round_[j] > now);
        };
        // Σ w_b target_b / Σ w_b over the anchors (w_b = axial_weight), target(j, out) their targets:
        // where the anchors' axial forces balance, for each kind of node below.
        const auto weighted_mean = [&](auto target, double mean[3]) {
          double weight_sum = 0.0, sum[3] = {0.0, 0.0, 0.0}, at[3];
          for (std::int64_t k = first; k < last; ++k) {
            if (!anchor(k)) continue;
            const auto j = static_cast<std::size_t>(bonds.neighbour[static_cast<std::size_t>(k)]);
            const double w = axial_weight(k - first, i, j);
            weight_sum += w;
            target(j, at);
            for (int c = 0; c < 3; ++c) sum[c] += w * at[c];
          }
          for (int c = 0; c < 3; ++c) mean[c] = sum[c] / weight_sum;
        };
        double* const place = &placed[3 * static_cast<std::size_t>(g)];
        std::int64_t nearest = -1, farthest = -1;
        double near_length = HUGE_VAL, far_length = -HUGE_VAL;
        for (std::int64_t k = first; k < last; ++k) {
          if (!anchor(k)) continue;
          const double length = bond_length(X, i, static_cast<std::size_t>(bonds.neighbour[static_cast<std::size_t>(k)]));
          if (length < near_length) near_length = length, nearest = k;
          if (length > far_length) far_length = length, farthest = k;
        }
        if (nearest < 0) continue;  // hangs by nothing that holds it: stays
        if (kind_[i] == 3) {
          // A link of a strand (bonds on one line, on both sides): on its anchors' line where their
          // axial forces balance, x_i = Σ w_b (x_b − (ξ_b·e) e_now) / Σ w_b, e the reference line
          // and e_now the line of its two outermost anchors now (e alone for one anchor).
          const auto jn = static_cast<std::size_t>(bonds.neighbour[static_cast<std::size_t>(nearest)]);
          double e[3], along_low = HUGE_VAL, along_high = -HUGE_VAL;
          for (int c = 0; c < 3; ++c) e[c] = (X[static_cast<std::size_t>(c)][jn] - X[static_cast<std::size_t>(c)][i]) / near_length;
          std::size_t low = jn, high = jn;
          // ξ_b·e of the anchor j: where it lies along the reference line.
          const auto along_line = [&](std::size_t j) {
            double along = 0.0;
            for (int c = 0; c < 3; ++c) along += (X[static_cast<std::size_t>(c)][j] - X[static_cast<std::size_t>(c)][i]) * e[c];
            return along;
          };
          for (std::int64_t k = first; k < last; ++k) {
            if (!anchor(k)) continue;
            const auto j = static_cast<std::size_t>(bonds.neighbour[static_cast<std::size_t>(k)]);
            const double along = along_line(j);
            if (along < along_low) along_low = along, low = j;
            if (along > along_high) along_high = along, high = j;
          }
          double e_now[3] = {e[0], e[1], e[2]};
          if (along_high > along_low) {
            double norm = 0.0;
            for (int c = 0; c < 3; ++c) e_now[c] = position(high, c) - position(low, c), norm += e_now[c] * e_now[c];
            norm = std::sqrt(norm);
            for (double& component : e_now) component /= norm;
          }
          weighted_mean([&](std::size_t j, double* at) {
            const double along = along_line(j);
            for (int c = 0; c < 3; ++c) at[c] = position(j, c) - along * e_now[c];
          }, place);
          moved[static_cast<std::size_t>(g)] = 1;
          continue;
        }
        if (kind_[i] == 2) {
          // A link of a linkage: carried by its anchors' translation, at its reference place among
          // them (x_i = X_i + Σ w_b u_b / Σ w_b, w_b the axial stiffness as below): its bonds to
          // them unstretched while they translate together.
          double carried[3];
          weighted_mean([&](std::size_t j, double* at) {
            for (int c = 0; c < 3; ++c) at[c] = u[static_cast<std::size_t>(c)][j];
          }, carried);
          for (int c = 0; c < 3; ++c) place[c] = X[static_cast<std::size_t>(c)][i] + carried[c];
          moved[static_cast<std::size_t>(g)] = 1;
          continue;
        }
        // n: from the nearest anchor to the farthest now (the line rotates with them), or the
        // reference direction of a single anchor (the node is carried by its translation).
        double line[3] = {0.0, 0.0, 0.0};
        {
          const auto jn = static_cast<std::size_t>(bonds.neighbour[static_cast<std::size_t>(nearest)]);
          const auto jf = static_cast<std::size_t>(bonds.neighbour[static_cast<std::size_t>(farthest)]);
          double norm = 0.0;
          if (far_length > near_length) {
            for (int c = 0; c < 3; ++c) line[c] = position(jf, c) - position(jn, c);
          } else {
            for (int c = 0; c < 3; ++c) line[c] = X[static_cast<std::size_t>(c)][jn] - X[static_cast<std::size_t>(c)][i];
          }
          for (int c = 0; c < 3; ++c) norm += line[c] * line[c];
          norm = std::sqrt(norm);
          for (double& component : line) component /= norm;
        }
        weighted_mean([&](std::size_t j, double* at) {
          const double length = bond_length(X, i, j);
          for (int c = 0; c < 3; ++c) at[c] = position(j, c) - length * line[c];
        }, place);
        moved[static_cast<std::size_t>(g)] = 1;
      }
    }
    for (std::size_t g = 0; g < nodes.size(); ++g)
      if (moved[g])
        for (int c = 0; c < dimension; ++c) {
          const auto i = static_cast<std::size_t>(nodes[g]);
          u[static_cast<std::size_t>(c)][i] = placed[3 * g + static_cast<std::size_t>(c)] - X[static_cast<std::size_t>(c)][i];
        }
  }
}

}  // namespace pd
