// The one reduction over nodes (design.md "next shape"): every sum over nodes that the operator
// reports (energies, powers) goes through here, so its order never depends on threads or ranks.
// Serial (d == null): term(i) summed in node order, one by one — the code every such sum had
// before, so serial results keep their bits. Decomposed: the terms of the owned nodes are summed in
// global node order by Decomposed::ordered_sum — the same bits as the serial sum.
#pragma once
#include <cstddef>
#include <vector>

#include "parallel/decomposed.hpp"

namespace pd {

template <class Term>
double sum_over_nodes(const Decomposed* d, std::size_t n, Term term) {
  if (!d) {
    double sum = 0.0;
    for (std::size_t i = 0; i < n; ++i) sum += term(i);
    return sum;
  }
  std::vector<double> per_node(n);
  for (std::size_t i = 0; i < n; ++i) per_node[i] = term(i);
  return d->ordered_sum(per_node);
}

}  // namespace pd
