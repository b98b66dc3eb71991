// The one reduction over nodes (docs/theory.md T17): every sum over nodes that the operator
// reports (energies, powers, norms) goes through here, so its bits never depend on threads or
// ranks. The terms are summed exactly (core/exact_sum.hpp) and rounded once: serially (d == null)
// over all nodes, decomposed over each rank's owned nodes and then across the ranks
// (Decomposed::reduce) — the same exact value, so the same bits, for any rank and thread count.
#pragma once
#include <array>
#include <cstddef>
#include <cstdint>
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

// start + Σ_i term(i) over the n local nodes (the owned ones on a decomposed run), exactly, rounded
// once. Collective on a decomposed run. `start` lets one sum continue another with one rounding
// per loop, so a run's serial and decomposed sums round at the same places.
template <class Term>
double sum_over_nodes(const Decomposed* d, std::size_t n, Term term, double start = 0.0) {
  if (!d) {
    ExactSum sum(start);
    for (std::size_t i = 0; i < n; ++i) sum.add(term(i));
    return sum.value();
  }
  // The owned nodes' terms straight into the accumulator (no per-node buffer), then the ranks'
  // accumulators, then start once (Decomposed::exact_sum's order; exact, so any order is the same).
  ExactSum sum;
  for (std::int32_t l : d->piece().owned_local) sum.add(term(static_cast<std::size_t>(l)));
  d->reduce(&sum, 1);
  sum.add(start);
  return sum.value();
}

// start + Σ_{i in nodes} term(i) over one node set (a condition's nodes, local indices; on a
// decomposed run a condition holds its owned nodes only, parallel/local_model.cpp), exactly,
// rounded once: the set's terms straight into the accumulator, then the ranks' accumulators in one
// reduction, then start (exact, so the serial and decomposed sums give the same bits). Collective
// on a decomposed run.
template <class Term>
double sum_over_set(const Decomposed* d, const std::vector<std::int32_t>& nodes, double start, Term term) {
  ExactSum sum;
  for (std::int32_t i : nodes) sum.add(term(static_cast<std::size_t>(i)));
  if (d) d->reduce(&sum, 1);
  sum.add(start);
  return sum.value();
}

}  // namespace pd
