// The one reduction over nodes (design.md "next shape"): every sum over nodes that the operator
// reports (energies, powers, norms) goes through here, so its bits never depend on threads or
// ranks. The terms are summed exactly (core/exact_sum.hpp) and rounded once: serially (d == null)
// over all nodes, decomposed over each rank's owned nodes and then across the ranks
// (Decomposed::exact_sum) — the same exact value, so the same bits, for any rank and thread count.
#pragma once
#include <cstddef>
#include <vector>

#include "core/exact_sum.hpp"
#include "parallel/decomposed.hpp"

namespace pd {

// Σ_i term(i) over the n local nodes (the owned ones on a decomposed run), exactly, rounded once.
// Collective on a decomposed run.
template <class Term>
double sum_over_nodes(const Decomposed* d, std::size_t n, Term term) {
  if (!d) {
    ExactSum sum;
    for (std::size_t i = 0; i < n; ++i) sum.add(term(i));
    return sum.value();
  }
  std::vector<double> per_node(n);
  for (std::size_t i = 0; i < n; ++i) per_node[i] = term(i);
  return d->exact_sum(per_node);
}

}  // namespace pd
