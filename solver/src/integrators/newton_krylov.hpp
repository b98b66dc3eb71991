// What quasi_static and implicit share on their matrix-free path (issues 13 and 15): the choice of
// the linear solver of their Newton iterations, and one Newton system K Δu = rhs solved by
// preconditioned CG (linalg/pcg.hpp) with K x = −V ∂f/∂u·x + D x, the products from
// ForceOperator::apply_jacobian (force evaluations with ghosts on a decomposed run), D a diagonal
// the integrator adds (quasi_static's shift after damage, implicit's mass term c m), and every dot
// product an exact sum (parallel/dof_sums.hpp): the same bits for any rank count.
#pragma once
#include <string>
#include <vector>

#include "core/case.hpp"
#include "linalg/pcg.hpp"
#include "linalg/sparse_matrix.hpp"
#include "operator/force_operator.hpp"
#include "parallel/dof_sums.hpp"

namespace pd {

// Auto picks cg at or above this many free dofs in 3D (measured: integrators/quasi_static.cpp).
constexpr std::size_t kCgFromDofs3d = 20000;

struct LinearSolverChoice {
  bool use_cg = false;
  std::string reason;  // for run.log: "as the case file asks", or auto's reason
};
// choice: the case file's `<section>.linear_solver` (auto | direct | cg). dof_dimension: the
// components per node that are unknowns (quasi_static: the model's dimension; implicit: 3). Auto
// takes cg on several MPI ranks, for a law or term without an assembled tangent (lps, contact), and
// for 3D models with at least kCgFromDofs3d free dofs; direct otherwise. direct is refused (pd::Error
// naming the file and the key) on several ranks and without an assembled tangent. Collective on a
// decomposed run.
LinearSolverChoice choose_linear_solver(const ForceOperator& op, const Case& c, const std::string& section,
                                        const std::string& choice, int dof_dimension);

// "direct" or "cg block_jacobi" (Integrator::linear_solver) for a scheme whose CG is preconditioned
// by block Jacobi.
inline std::string linear_solver_name(bool use_cg) { return use_cg ? "cg block_jacobi" : "direct"; }

// Why this run cannot solve by `recorded` (a checkpoint's Integrator::linear_solver: "direct" or
// "cg block_jacobi"), or "": direct needs one process and an assembled tangent, CG runs anywhere.
std::string why_not_linear_solver(const ForceOperator& op, const std::string& recorded);

// correction = the PCG solution of K Δu = rhs from Δu = 0 (K x = −V ∂f/∂u(s, t)·x + diagonal[q] x[q]
// over dofs), preconditioned by M; settings.dot is set to sums.dot. A direction of negative
// curvature at the first iteration gives M⁻¹ rhs (Steihaug's first step, a descent direction for the
// line search). x, y: scratch per node, sized to the state. Collective on a decomposed run.
PcgResult solve_newton_system(const ForceOperator& op, const State& s, double t, const FreeDofs& dofs, const DofSums& sums,
                              const std::vector<double>& diagonal, const Preconditioner& M, const std::vector<double>& rhs,
                              std::vector<double>& correction, PcgSettings settings, Vec3Array& x, Vec3Array& y);

}  // namespace pd
