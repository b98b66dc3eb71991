// The preconditioner M ≈ A of preconditioned CG (linalg/pcg.hpp): only its inverse's action
// z = M⁻¹ r is needed, and M must be symmetric positive definite for CG's recurrences (Saad 2003,
// §9.2). Two derive from it: block-Jacobi (linalg/pcg.hpp, matrix-free: the node blocks of K) and
// algebraic multigrid (linalg/amg.hpp, one V-cycle of hypre's BoomerAMG on the assembled K).
#pragma once
#include <vector>

namespace pd {

class Preconditioner {
 public:
  virtual ~Preconditioner() = default;
  // z = M⁻¹ r (z resized to r's size; r and z never alias).
  virtual void apply(const std::vector<double>& r, std::vector<double>& z) const = 0;
};

}  // namespace pd
