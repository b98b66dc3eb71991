// Sums over the free dofs of an implicit solve (quasi_static, implicit, mixed; issue 15) whose bits
// do not depend on the rank or thread count: the norms of the Newton iterations and the dot
// products of the matrix-free CG. Each is an exact sum (core/exact_sum.hpp) of the per-dof terms,
// rounded once: serially over all dofs, decomposed over each rank's own dofs (a rank's dofs are its
// owned nodes' free components: ForceOperator::free_dofs) and then across the ranks in one
// MPI_Allreduce of the accumulators (Decomposed::reduce) — the same exact value, so the same bits.
// Cost on a decomposed run: per call, one MPI_Allreduce of ExactSum::kLimbs int64 per array summed,
// whatever the number of dofs.
#pragma once
#include <cstdint>
#include <vector>

#include "core/exact_sum.hpp"
#include "linalg/sparse_matrix.hpp"
#include "parallel/decomposed.hpp"

namespace pd {

class DofSums {
 public:
  // d: the decomposition, or null (serial). dofs: this rank's free dofs (ForceOperator::free_dofs).
  void setup(const Decomposed* d, const FreeDofs& dofs);

  // Σ_k terms[k] over the global dofs, exactly, rounded once. Collective.
  double sum(const std::vector<double>& terms) const { return sums({&terms})[0]; }
  // The same for several arrays at once (one reduction). Collective.
  std::vector<double> sums(const std::vector<const std::vector<double>*>& arrays) const;
  // Σ_k a_k b_k over the global dofs: each product rounded, their sum exact and rounded once.
  // Collective.
  double dot(const std::vector<double>& a, const std::vector<double>& b) const;

 private:
  const Decomposed* d_ = nullptr;
};

}  // namespace pd
