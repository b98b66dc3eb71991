// Solves with a factorised matrix after a low-rank change, without a new factorisation: the
// Sherman–Morrison–Woodbury identity (Golub & Van Loan, Matrix Computations, 4th ed., §2.1.4).
//
// The change is K' = K − U C Uᵀ with C block-diagonal: each block couples the columns of one
// removed element. Given y = K⁻¹ b (from the factorisation of K), x = K'⁻¹ b is
//   x = y + W z,   W = K⁻¹ U,   S z = C Uᵀ y,   S = I − C Uᵀ W   (r × r, r = columns of U);
// which follows from (K − U C Uᵀ)(y + W z) = b − U (C Uᵀ y + C Uᵀ W z − z). This form needs no
// inverse of C (a block may be singular). W costs one solve with r right-hand sides; each later
// solve costs the usual one plus O(n r).
//
// Why (integrators/quasi_static.cpp): a bond that breaks takes its stiffness out of the tangent,
// V_i·B_ij on the diagonal blocks of i and j and −V_i·B_ij off them: exactly U C Uᵀ with U = [I; −I]
// on the two nodes' free components and C = V_i·B_ij. Removing the few bonds of a breaking round
// this way keeps the factorised tangent the tangent of the bonds that are left, at a fraction of a
// new factorisation (measured there).
//
// Every column of U here is +1 at one row and −1 at another (either may be absent, a row of a held
// component): the difference of two unknowns, which is all a bond needs.
#pragma once
#include <cstdint>
#include <vector>

#include "linalg/cholesky.hpp"

namespace pd {

class Woodbury {
 public:
  // No change (x = y).
  void clear();
  bool active() const { return columns() > 0; }
  int columns() const { return static_cast<int>(plus_.size()); }

  // Adds one block of m columns (m ≤ 3): column a is +1 at row plus[a] and −1 at row minus[a]
  // (−1: no entry), coupled by c (m × m, row-major), the block subtracted: K' = K − U c Uᵀ.
  // Its W columns and S are made by the next update().
  void add_block(const std::int64_t* plus, const std::int64_t* minus, const double* c, int m);

  // W for the blocks added since the last update (one solve with their columns), then S and its LU
  // factorisation (LAPACK dgetrf). False when S is singular to working precision (reciprocal
  // condition estimate, dgecon, below kSingularRcond): K' is then singular or nearly so, and the
  // caller factorises K' itself.
  bool update(const SparseCholesky& factor, std::size_t rows);

  // y = K⁻¹ b in, x = K'⁻¹ b out (in place).
  void apply(std::vector<double>& y) const;

  static constexpr double kSingularRcond = 1e-12;

 private:
  std::vector<std::int64_t> plus_, minus_;  // per column
  std::vector<int> block_of_;               // per column: the first column of its block
  std::vector<int> block_size_;             // per column: its block's m
  std::vector<double> c_;                   // per column a: row a of its block (3 entries, m used)
  std::vector<double> w_;                   // K⁻¹ U, column-major, rows × columns()
  int solved_ = 0;                          // columns of w_ made
  std::size_t rows_ = 0;
  std::vector<double> lu_;                  // S's LU factors (column-major) and pivots
  std::vector<int> pivots_;
  // U's column a applied to x: x[plus] − x[minus].
  double difference(const double* x, int a) const;
};

}  // namespace pd
