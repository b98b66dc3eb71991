// The short-range contact force (thesis §1.1.3, eq. 1.13; docs/theory.md T8): a repulsion between
// any two nodes closer than d_ij in their current positions, bonded or not, along the line
// joining them. Form of Silling's EMU code as LAMMPS pair peri/pmb implements it:
//   f_i += −(c_s/δ)·(d_ij − |y_j − y_i|)·V_j·(y_j − y_i)/|y_j − y_i|   when |y_j − y_i| < d_ij,
// c_s = 15c, d_ij = min(0.9|ξ|, 1.35(r_i + r_j)) for a pair with a reference bond, 1.35(r_i + r_j)
// otherwise, r = dx/2. LAMMPS puts V_j on both ends; we put V_j on i and V_i on j, so that the
// forces V_i f_i and V_j f_j are equal and opposite for any volumes (momentum is conserved to
// round-off); the two agree when the volumes are equal.
#pragma once
#include <cstdint>

#include "core/model.hpp"
#include "core/state.hpp"
#include "core/neighbour_list.hpp"
#include "forces/force_term.hpp"

namespace pd {

struct ContactArrays {
  const std::int64_t* offsets;
  const std::int32_t* neighbour;
  const double* distance;  // d_ij
  const double* x[3];
  const double* u[3];
  const double* volume;
  const std::int32_t* block;
  const double* c_pair;    // micromodulus per block pair
  std::int64_t blocks;
  std::int64_t nodes;
  double stiffness_over_horizon;  // stiffness_factor/δ, so c_s/δ = this·c
};

// f_i += the contact force density of every listed pair closer than d_ij. Each node writes only
// its own f_i (the list holds every pair from both ends): bitwise the same for any thread count.
// If e is not null, e[i] = Σ_j ¼ (c_s/δ)(d_ij − r)² V_j: node i's half of the pair potential
// ½ (c_s/δ) V_i V_j (d_ij − r)², per unit volume (overwritten, not accumulated).
void add_contact_force_density(const ContactArrays& a, double* f0, double* f1, double* f2, double* e = nullptr);

// y_i += Σ_j ∂f_i/∂u·δu over row i's listed pairs closer than d_ij, for every row of `a` (each pair
// a spring along its line and, for the pressed gap, a negative lateral stiffness). Each row writes
// only its own y_i: bitwise the same for any thread count, and on a piece of a decomposed run
// (forces/contact_on_piece) for the same rows with exact copies of u and δu.
void add_contact_jacobian_product(const ContactArrays& a, const Vec3Array& du, double* y0, double* y1, double* y2);
// block += ∂f_i/∂u_i of row i's pairs (row-major 3×3); definite: without the pressed gaps'
// negative lateral stiffness.
void add_contact_jacobian_diagonal(const ContactArrays& a, std::int64_t i, double block[9], bool definite);

// The force term: refreshes the model's Verlet list when the skin rule asks for it, then adds the
// forces. Returns the contact potential energy [J], summed serially in node order.
class ShortRangeForce {
 public:
  explicit ShortRangeForce(const Model& model) : model_(model) {}
  double AddMult(const Vec3Array& u, Vec3Array& f) const;
  // The same force from a given list (the tests compare the Verlet list with a fresh search).
  double AddMult(const ContactPairs& pairs, const Vec3Array& u, Vec3Array& f) const;
  // y += ∂f/∂u·x over the pairs of the current list (each pair closer than d_ij is a spring along
  // its line and, for the pressed gap, a negative lateral stiffness).
  void AddJacobianProduct(const Vec3Array& u, const Vec3Array& x, Vec3Array& y) const;
  // block += ∂f_i/∂u_i of the same pairs (row-major 3×3); definite: without the pressed gaps'
  // negative lateral stiffness.
  void AddJacobianDiagonal(const Vec3Array& u, std::size_t i, double block[9], bool definite) const;

 private:
  // The kernels' view of the whole model at u over a list.
  ContactArrays arrays(const ContactPairs& pairs, const Vec3Array& u) const;
  const Model& model_;
};

}  // namespace pd
