// Sums over the free dofs of an implicit solve (quasi_static, implicit, mixed; issue 15) whose bits do
// not depend on the rank count. The serial solver sums per-dof terms in dof order (node by node,
// components ascending: linalg/sparse_matrix.hpp FreeDofs) — one by one for its norms, in
// fixed-size chunks for CG's dot products (linalg/pcg.hpp fixed_order_dot). A decomposed run's dofs
// are spread over the ranks, so every rank's owned per-dof terms are gathered on rank 0, put in
// global dof order, summed there exactly as the serial loop sums them, and the sums broadcast: the
// serial bits on every rank, for any rank count. Serially (no decomposition) the sums are the
// serial loops themselves, so serial results keep their bits.
// Cost on a decomposed run: per call, one MPI_Gatherv of 3 doubles per owned node (per array
// summed) to rank 0 and one broadcast of the sums — fine for the small and middle-sized runs
// this serves; an exact integer-accumulator sum would scale better but change serial bits.
#pragma once
#include <cstdint>
#include <vector>

#include "linalg/sparse_matrix.hpp"
#include "parallel/decomposed.hpp"

namespace pd {

class DofSums {
 public:
  // d: the decomposition, or null (serial). dofs: this rank's free dofs (ForceOperator::free_dofs).
  // Collective on a decomposed run (rank 0 learns which components of each owned node are dofs).
  void setup(const Decomposed* d, const FreeDofs& dofs);

  // Σ_k terms[k] one by one in global dof order, starting at 0. Collective.
  double sum(const std::vector<double>& terms) const { return sums({&terms})[0]; }
  // The same for several arrays at once (one gather). Collective.
  std::vector<double> sums(const std::vector<const std::vector<double>*>& arrays) const;
  // Σ_k a_k b_k in fixed_order_dot's chunked order over the global dofs. Collective.
  double dot(const std::vector<double>& a, const std::vector<double>& b) const;

 private:
  // The arrays' entries in global dof order, on rank 0 (empty elsewhere). Collective.
  std::vector<std::vector<double>> in_global_order(const std::vector<const std::vector<double>*>& arrays) const;

  const Decomposed* d_ = nullptr;
  std::size_t nodes_ = 0;                   // local nodes (owned and ghosts)
  std::vector<std::size_t> node_of_dof_;    // per dof: its local node
  std::vector<std::uint8_t> component_of_dof_;
  std::vector<std::uint8_t> merged_mask_;   // rank 0, per global node: bit c set when component c is a dof
};

}  // namespace pd
