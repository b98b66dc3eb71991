// The one reduction over nodes (design.md "next shape"): every sum over nodes that the operator
// reports (energies, powers, norms) goes through here, so its bits never depend on threads or
// ranks. The terms are summed exactly (core/exact_sum.hpp) and rounded once: serially (d == null)
// over all nodes, decomposed over each rank's owned nodes and then across the ranks
// (Decomposed::reduce) — the same exact value, so the same bits, for any rank and thread count.
#pragma once
#include <array>
#include <cstddef>
#include <vector>

#include "core/exact_sum.hpp"
#include "parallel/decomposed.hpp"
#include "parallel/local_model.hpp"

namespace pd {

// Σ_i terms(i)[k] for k < K over the n local nodes (the owned ones on a decomposed run), each sum
// exact and rounded once. terms(i) returns std::array<double, K>. On a decomposed run the K sums
// go in one MPI_Allreduce (Decomposed::reduce): one point per call where the ranks wait for each
// other, not K. Collective on a decomposed run.
template <std::size_t K, class Terms>
std::array<double, K> sums_over_nodes(const Decomposed* d, std::size_t n, Terms terms) {
  std::array<ExactSum, K> sum;
  const auto add = [&](std::size_t i) {
    const std::array<double, K> t = terms(i);
    for (std::size_t k = 0; k < K; ++k) sum[k].add(t[k]);
  };
  if (!d) {
    for (std::size_t i = 0; i < n; ++i) add(i);
  } else {
    // The owned nodes only: a ghost's terms are its owner's (Decomposed::exact_sum ignores them too).
    for (std::int32_t l : d->piece().owned_local) add(static_cast<std::size_t>(l));
    d->reduce(sum.data(), static_cast<int>(K));
  }
  std::array<double, K> out{};
  for (std::size_t k = 0; k < K; ++k) out[k] = sum[k].value();
  return out;
}

// Σ_i term(i) over the n local nodes (the owned ones on a decomposed run), exactly, rounded once.
// Collective on a decomposed run.
template <class Term>
double sum_over_nodes(const Decomposed* d, std::size_t n, Term term) {
  return sums_over_nodes<1>(d, n, [&](std::size_t i) { return std::array<double, 1>{term(i)}; })[0];
}

}  // namespace pd
