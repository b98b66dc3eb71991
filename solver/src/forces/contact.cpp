// The short-range contact kernel over the Verlet list (see contact.hpp).
#include "forces/contact.hpp"

#include "core/exact_sum.hpp"
#include "forces/contact_on_piece.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>
#include <vector>

namespace pd {

void add_contact_force_density(const ContactArrays& a, double* f0, double* f1, double* f2, double* e) {
#pragma omp parallel for schedule(static)
  for (std::int64_t i = 0; i < a.nodes; ++i) {
    const double* c_row = a.c_pair + a.block[i] * a.blocks;
    const double yi0 = a.x[0][i] + a.u[0][i], yi1 = a.x[1][i] + a.u[1][i], yi2 = a.x[2][i] + a.u[2][i];
    double s0 = 0.0, s1 = 0.0, s2 = 0.0, energy = 0.0;
    for (std::int64_t k = a.offsets[i]; k < a.offsets[i + 1]; ++k) {
      const std::int64_t j = a.neighbour[k];
      // y_j − y_i: the exact negative of what j computes for i, so r is bitwise symmetric.
      const double e0 = (a.x[0][j] + a.u[0][j]) - yi0;
      const double e1 = (a.x[1][j] + a.u[1][j]) - yi1;
      const double e2 = (a.x[2][j] + a.u[2][j]) - yi2;
      const double r = std::sqrt(e0 * e0 + e1 * e1 + e2 * e2);
      // Repulsive only (the min{0, ·} of eq. 1.13): the gap d_ij − r counts only where positive.
      // Selects rather than branches, so the loop vectorises like the bond kernel; two nodes at
      // one point have no direction and get no force.
      const double gap = std::max(a.distance[k] - r, 0.0);
      const double k_vj = a.stiffness_over_horizon * c_row[a.block[j]] * a.volume[j];
      const double scale = r > 0.0 ? k_vj * gap / r : 0.0;
      s0 -= scale * e0;
      s1 -= scale * e1;
      s2 -= scale * e2;
      energy += 0.25 * k_vj * gap * gap;
    }
    f0[i] += s0;
    f1[i] += s1;
    f2[i] += s2;
    if (e) e[i] = energy;
  }
}

double ShortRangeForce::AddMult(const Vec3Array& u, Vec3Array& f) const {
  model_.contact_list.update(model_.nodes.x, u, model_.block_index, model_.contact);
  return AddMult(model_.contact_list.pairs(), u, f);
}

ContactArrays ShortRangeForce::arrays(const ContactPairs& pairs, const Vec3Array& u) const {
  const Model& m = model_;
  ContactArrays a;
  a.offsets = pairs.offsets.data();
  a.neighbour = pairs.neighbour.data();
  a.distance = pairs.distance.data();
  for (std::size_t d = 0; d < 3; ++d) {
    a.x[d] = m.nodes.x[d].data();
    a.u[d] = u[d].data();
  }
  a.volume = m.nodes.volume.data();
  a.block = m.block_index.data();
  a.c_pair = m.material.micromodulus_pair.data();
  a.blocks = m.material.blocks;
  a.nodes = static_cast<std::int64_t>(m.nodes.size());
  a.stiffness_over_horizon = m.contact.stiffness_factor / m.horizon;
  return a;
}

double ShortRangeForce::AddMult(const ContactPairs& pairs, const Vec3Array& u, Vec3Array& f) const {
  const Model& m = model_;
  const ContactArrays a = arrays(pairs, u);
  std::vector<double> e(m.nodes.size());
  add_contact_force_density(a, f[0].data(), f[1].data(), f[2].data(), e.data());
  ExactSum total;  // exact (core/exact_sum.hpp): the bits of the decomposed run's sum (contact_on_piece)
  for (std::size_t i = 0; i < e.size(); ++i) total.add(e[i] * m.nodes.volume[i]);
  return total.value();
}

void add_contact_jacobian_product(const ContactArrays& a, const Vec3Array& du, double* y0, double* y1, double* y2) {
#pragma omp parallel for schedule(static)
  for (std::int64_t i64 = 0; i64 < a.nodes; ++i64) {
    const auto i = static_cast<std::size_t>(i64);
    const double* c_row = a.c_pair + a.block[i] * a.blocks;
    const double yi0 = a.x[0][i] + a.u[0][i], yi1 = a.x[1][i] + a.u[1][i], yi2 = a.x[2][i] + a.u[2][i];
    double s0 = 0.0, s1 = 0.0, s2 = 0.0;
    for (std::int64_t k = a.offsets[i]; k < a.offsets[i + 1]; ++k) {
      const auto j = static_cast<std::size_t>(a.neighbour[k]);
      const double e0 = (a.x[0][j] + a.u[0][j]) - yi0, e1 = (a.x[1][j] + a.u[1][j]) - yi1, e2 = (a.x[2][j] + a.u[2][j]) - yi2;
      const double r = std::sqrt(e0 * e0 + e1 * e1 + e2 * e2);
      const double gap = a.distance[k] - r;
      if (!(gap > 0.0) || !(r > 0.0)) continue;  // apart, or at one point (no direction, no force)
      const double k_vj = a.stiffness_over_horizon * c_row[a.block[j]] * a.volume[j];
      // f_i = −k (d − r) n, n = e/r: δf_i = k [n nᵀ − ((d − r)/r)(I − n nᵀ)] (δu_j − δu_i)
      const double n0 = e0 / r, n1 = e1 / r, n2 = e2 / r;
      const double d0 = du[0][j] - du[0][i], d1 = du[1][j] - du[1][i], d2 = du[2][j] - du[2][i];
      const double along = n0 * d0 + n1 * d1 + n2 * d2, lateral = -k_vj * gap / r;
      s0 += k_vj * along * n0 + lateral * (d0 - along * n0);
      s1 += k_vj * along * n1 + lateral * (d1 - along * n1);
      s2 += k_vj * along * n2 + lateral * (d2 - along * n2);
    }
    y0[i] += s0;
    y1[i] += s1;
    y2[i] += s2;
  }
}

void add_contact_jacobian_diagonal(const ContactArrays& a, std::int64_t i, double block[9], bool definite) {
  const double* c_row = a.c_pair + a.block[i] * a.blocks;
  const double yi0 = a.x[0][i] + a.u[0][i], yi1 = a.x[1][i] + a.u[1][i], yi2 = a.x[2][i] + a.u[2][i];
  for (std::int64_t k = a.offsets[i]; k < a.offsets[i + 1]; ++k) {
    const auto j = static_cast<std::size_t>(a.neighbour[k]);
    const double e[3] = {(a.x[0][j] + a.u[0][j]) - yi0, (a.x[1][j] + a.u[1][j]) - yi1, (a.x[2][j] + a.u[2][j]) - yi2};
    const double r = std::sqrt(e[0] * e[0] + e[1] * e[1] + e[2] * e[2]);
    const double gap = a.distance[k] - r;
    if (!(gap > 0.0) || !(r > 0.0)) continue;
    const double k_vj = a.stiffness_over_horizon * c_row[a.block[j]] * a.volume[j];
    // ∂f_i/∂u_i = −k [n nᵀ − ((d − r)/r)(I − n nᵀ)] (the product with δu_j = 0).
    const double lateral = definite ? 0.0 : -k_vj * gap / r;
    for (int p = 0; p < 3; ++p)
      for (int q = 0; q < 3; ++q) {
        const double nn = e[p] * e[q] / (r * r);
        block[3 * p + q] -= k_vj * nn + lateral * ((p == q ? 1.0 : 0.0) - nn);
      }
  }
}

void ShortRangeForce::AddJacobianProduct(const Vec3Array& u, const Vec3Array& x, Vec3Array& y) const {
  add_contact_jacobian_product(arrays(model_.contact_list.pairs(), u), x, y[0].data(), y[1].data(), y[2].data());
}

void ShortRangeForce::AddJacobianDiagonal(const Vec3Array& u, std::size_t i, double block[9], bool definite) const {
  add_contact_jacobian_diagonal(arrays(model_.contact_list.pairs(), u), static_cast<std::int64_t>(i), block, definite);
}

namespace {

// Contact as a term of the operator (forces/force_term.hpp).
class ContactTerm : public ForceTerm {
 public:
  explicit ContactTerm(const Model& model) : model_(model) {}
  void add_force(State& s, double) const override {
    if (decomposed_) {  // a piece of a decomposed run: its pairs reach other ranks (forces/contact_on_piece)
      if (!on_piece_) on_piece_ = std::make_unique<ContactOnPiece>(model_, *decomposed_);
      add_energy(s, "contact", on_piece_->add_force(s.u, s.f));
      return;
    }
    add_energy(s, "contact", ShortRangeForce(model_).AddMult(s.u, s.f));
  }
  void add_power(const State&, double, double&) const override {}  // conservative, at rest
  void add_jacobian_product(const State& s, double, const Vec3Array& x, Vec3Array& y) const override {
    if (decomposed_) {  // collective: the pairs' ghosts get u and δu from their owners
      if (on_piece_) on_piece_->add_jacobian_product(s.u, x, y);
      return;  // no force evaluated yet: no list, as serially
    }
    ShortRangeForce(model_).AddJacobianProduct(s.u, x, y);
  }
  bool add_tangent_diagonal(const State&, double, std::size_t, double*) const override { return false; }
  void prepare_jacobian_diagonal(const State& s, double) const override {
    if (decomposed_ && on_piece_) on_piece_->update_displacement(s.u);
  }
  void add_jacobian_diagonal(const State& s, double, std::size_t i, double block[9], bool definite) const override {
    if (decomposed_) {
      if (on_piece_) on_piece_->add_jacobian_diagonal(i, block, definite);
      return;
    }
    ShortRangeForce(model_).AddJacobianDiagonal(s.u, i, block, definite);
  }
  std::vector<std::string> work_plan() const override {
    char buffer[256];
    std::snprintf(buffer, sizeof buffer, ", contact distance 2r_s %.4g m, skin %.4g m, c_s = %.4g·c",
                  model_.contact.distance, model_.contact.skin, model_.contact.stiffness_factor);
    return {std::string("work: contact search (cell list + Verlet list) ") +
            (model_.contact.self_contact ? "between all nodes (self_contact)" : "between blocks") + buffer};
  }

 private:
  const Model& model_;
  mutable std::unique_ptr<ContactOnPiece> on_piece_;  // a decomposed run's (made at the first force)
};

}  // namespace

std::unique_ptr<ForceTerm> make_contact_term(const Model& model) {
  if (!model.contact.pairs) return nullptr;
  return std::make_unique<ContactTerm>(model);
}

}  // namespace pd
