// Rigid indenters (LAMMPS fix indent): a sphere, a cylinder (a disk in 2D) or a plane moving at a
// prescribed velocity pushes every node inside it out along the surface normal with the force
// density K·h², h the depth of the node below the indenter surface (LAMMPS: F(r) = −K(r − R)²
// for r < R). In a PERI model LAMMPS's f is a force density, so K is in N/m⁵ here too.
#pragma once
#include <array>
#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

#include "core/case.hpp"
#include "core/model.hpp"
#include "core/registry.hpp"
#include "forces/force_term.hpp"
#include "parallel/decomposed.hpp"

namespace pd {

// Depth h ≥ 0 of point y inside the indenter (0 outside) and the unit push direction n.
// `centre` is where the indenter is now (centre at t = 0 + velocity·t).
using IndenterShape = double (*)(const IndenterSettings& ind, const double centre[3], const double y[3], double n[3]);
const Registry<IndenterShape>& indenter_shape_registry();

// Where an indenter's centre (or plane point) is at time t.
std::array<double, 3> indenter_position(const IndenterSettings& ind, double t);

// The indenter in the stable step. A node h deep is pushed with K·h², so along the push it feels a
// spring of stiffness d(K h²)/dh = 2K·h per unit volume [N/m⁴], tied to the rigid indenter: it adds
// to the diagonal of the stiffness only. Two sufficient conditions for velocity Verlet to stay stable
// with it (the true limit is above both):
//  (a) thesis eq. 2.5 with it: √(2ρ_i/(Σ_i + K·h_i)) at every node. Eq. 2.5 counts each bond's
//      spring c·V/|ξ| once although a bond has two moving ends (the worst mode doubles it: the
//      Gershgorin bound of the row is 2Σ_i); a one-ended spring 2K·h counts once, i.e. as K·h in
//      eq. 2.5's sum (a node with no bonds: √(2ρ/(K·h)) = 2/ω, ω² = 2K·h/ρ).
//  (b) when the exact limit ω_max (core/stability) is known: a positive diagonal D raises the
//      largest eigenvalue of M⁻¹K by at most max_i D_i/ρ_i (Weyl), so 2/√(ω_max² + max_i 2K·h_i/ρ_i).
struct IndenterStepLimit {
  double dt = HUGE_VAL;      // the larger of (a), minimised over nodes, and (b) [s]
  std::int64_t node = -1;    // the node that sets (a) (the lowest index if several); −1: no node inside
  std::size_t indenter = 0;  // its indenter
  double depth = 0.0;        // its depth h [m]
};
// omega2_exact: ω_max² of the body without indenters [1/s²], or 0 if not computed (then (a) only).
// On a decomposed run (d not null; model and u a rank's piece): over the owned nodes, reduced over
// the ranks to the serial result (the least dt, the lowest global node number among equals, which
// `node` then is). Collective.
IndenterStepLimit indenter_step_limit(const Model& model, double t, const Vec3Array& u, double omega2_exact = 0.0,
                                      const Decomposed* d = nullptr);

// How deep indenter `ind` may push any node while step dt keeps satisfying (a) or (b): the larger of
// min_i (2ρ_i/dt² − Σ_i)/K and (4/dt² − ω_max²)·min_i ρ_i/(2K), ≥ 0. A lower bound of the depth
// at which the step actually becomes unstable. On a decomposed run (d not null; model a rank's
// piece): the minima over the owned nodes, then over the ranks (exact), the serial value. Collective.
double indenter_stable_depth(const Model& model, const IndenterSettings& ind, double dt, double omega2_exact = 0.0,
                             const Decomposed* d = nullptr);

class IndenterForce {
 public:
  explicit IndenterForce(const Model& model) : model_(model) {}
  // f_i += K·h_i²·n_i for every node inside every indenter. force_on_body[k] = Σ_i V_i·K h_i² n_i
  // [N], the force indenter k exerts on the body (its reaction is the negative), summed exactly
  // (core/exact_sum.hpp) so that it does not depend on the thread count. Returns the potential
  // Σ_k Σ_i V_i·K h_i³/3 [J] (−d/dh of it is the force), summed exactly over all indenters.
  double AddMult(double t, const Vec3Array& u, Vec3Array& f, std::vector<std::array<double, 3>>& force_on_body) const;
  // The same on a decomposed run (issue 15; the model a rank's piece): f of the owned nodes, and
  // force_on_body and the potential of the whole body, the serial sums' bits on every rank: each
  // rank's exact sums over its owned nodes, added across the ranks (Decomposed::reduce). Collective.
  double AddMult(double t, const Vec3Array& u, Vec3Array& f, std::vector<std::array<double, 3>>& force_on_body,
                 const Decomposed& d) const;
  // y += ∂f/∂u·x at (u, t): the stiffness of the push, 2K·h along n, and for a curved surface the
  // turn of n with the node, K h²/r across it.
  void AddJacobianProduct(double t, const Vec3Array& u, const Vec3Array& x, Vec3Array& y) const;
  // block += the same as node q's 3×3 matrix (an indenter couples no nodes).
  void AddTangentDiagonal(double t, const Vec3Array& u, std::size_t q, double block[9]) const;

 private:
  const Model& model_;
};

}  // namespace pd
