// Preconditioned conjugate gradients (Hestenes & Stiefel 1952; Saad, "Iterative methods for sparse
// linear systems", 2003, alg. 9.1) for A x = b with A symmetric positive definite and given only as
// its action y = A x (a callback: the matrix-free tangent of operator/force_operator.hpp), and a
// preconditioner (linalg/preconditioner.hpp): here block-Jacobi, M = blockdiag(A_ii), one small block
// per node (its free components); algebraic multigrid in linalg/amg.hpp.
//
// Every dot product and norm is summed in a fixed order that does not depend on the thread count
// (fixed-size chunks, each summed serially, the chunk sums added serially in chunk order), so a
// solve gives the same bits on 1 and on 2 threads, as every other part of the solver does.
#pragma once
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "linalg/preconditioner.hpp"

namespace pd {

// y = A x over the unknowns (y is sized by the caller's operator; x and y never alias).
using LinearOperator = std::function<void(const std::vector<double>& x, std::vector<double>& y)>;

// Σ a_k b_k in the fixed order above (OpenMP over the chunks).
double fixed_order_dot(const std::vector<double>& a, const std::vector<double>& b);

// M⁻¹ for M = blockdiag(M_1, …, M_n): block g covers the unknowns first[g] … first[g+1]−1 (1 to 3 of
// them: a node's free components, numbered together by FreeDofs). Each block is inverted once, by
// its LDLᵀ factorisation written out for ≤ 3×3 (a closed form, not a sparse factorisation).
class BlockJacobi : public Preconditioner {
 public:
  // blocks[9g..9g+8]: block g row-major in a 3×3 frame (only its leading k×k part is read, k its
  // size). A block whose LDLᵀ meets a pivot ≤ 1e-12 × its largest diagonal entry (not positive
  // definite: a loose node, or a compressed one whose definite variant is still singular) falls
  // back to the inverse of its diagonal, and to 1 where that is not positive either: the
  // preconditioner stays symmetric positive definite whatever the blocks are.
  void build(const std::vector<std::int64_t>& first, const std::vector<double>& blocks);
  // z = M⁻¹ r.
  void apply(const std::vector<double>& r, std::vector<double>& z) const override;
  std::int64_t fallbacks() const { return fallbacks_; }  // blocks that were not positive definite

 private:
  std::vector<std::int64_t> first_;
  std::vector<double> inverse_;  // per block, its inverse row-major 3×3
  std::int64_t fallbacks_ = 0;
};

// Σ a_k b_k over all the unknowns of the system (a decomposed run's: every rank's, parallel/dof_sums.hpp).
using DotProduct = std::function<double(const std::vector<double>& a, const std::vector<double>& b)>;

struct PcgSettings {
  double relative_tol = 1e-8;  // stop when ‖r‖ ≤ max(relative_tol × ‖b‖, absolute_tol)
  double absolute_tol = 0.0;
  int max_iterations = 1000;
  // Every dot product and norm of the iteration; empty: fixed_order_dot. A decomposed run passes
  // one an exact sum over the ranks (core/exact_sum.hpp), so every rank takes the same α and β as a
  // serial solve would, bit for bit (the vector updates are element by element).
  DotProduct dot;
};

struct PcgResult {
  enum Status { kConverged, kNotConverged, kIndefinite } status = kNotConverged;
  int iterations = 0;            // matrix–vector products after the first residual
  double initial_residual = 0.0;  // ‖b − A x₀‖
  double residual = 0.0;          // ‖b − A x‖ at the end (the recurrence's; x as returned)
  double curvature = 0.0;         // pᵀA p when status is kIndefinite
  bool converged() const { return status == kConverged; }
  // One line for run.log and errors: what happened, after how many iterations, how far.
  std::string message() const;
};

// Solves A x = b from the x given (resized to b's size and zeroed if empty). Returns, never throws
// on a failed solve: kNotConverged after max_iterations, with x the last iterate; kIndefinite when
// a search direction has pᵀA p ≤ 0 (A not positive definite), with x the iterate before it (the
// truncated CG step of Steihaug 1983, still a descent direction for the quadratic model).
PcgResult preconditioned_cg(const LinearOperator& A, const Preconditioner& M, const std::vector<double>& b,
                            std::vector<double>& x, const PcgSettings& settings);

}  // namespace pd
