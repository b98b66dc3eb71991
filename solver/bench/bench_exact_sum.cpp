// The cost per term of the exact sum (core/exact_sum.hpp) against the naive loop it replaced
// (a dependent chain of adds in node order), on terms like an energy sum's: positive, of one sign,
// spread over a few binades; and on terms of both signs over 120 binades.
#include <benchmark/benchmark.h>

#include <cmath>
#include <random>
#include <vector>

#include "core/exact_sum.hpp"

namespace {

std::vector<double> terms(std::size_t n, bool wide) {
  std::mt19937_64 random(42);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  std::vector<double> t(n);
  for (double& x : t)
    x = wide ? std::ldexp(unit(random) - 0.5, static_cast<int>(120 * unit(random)) - 60) : 1e-6 * (1.0 + unit(random));
  return t;
}

void naive(benchmark::State& state, bool wide) {
  const std::vector<double> t = terms(static_cast<std::size_t>(state.range(0)), wide);
  for (auto _ : state) {
    double sum = 0.0;
    for (double x : t) sum += x;
    benchmark::DoNotOptimize(sum);
  }
  state.SetItemsProcessed(state.iterations() * state.range(0));
}

void exact(benchmark::State& state, bool wide) {
  const std::vector<double> t = terms(static_cast<std::size_t>(state.range(0)), wide);
  for (auto _ : state) {
    benchmark::DoNotOptimize(pd::exact_sum(t));
  }
  state.SetItemsProcessed(state.iterations() * state.range(0));
}

void BM_NaiveSum(benchmark::State& state) { naive(state, false); }
void BM_ExactSum(benchmark::State& state) { exact(state, false); }
void BM_NaiveSumWide(benchmark::State& state) { naive(state, true); }
void BM_ExactSumWide(benchmark::State& state) { exact(state, true); }
BENCHMARK(BM_NaiveSum)->Arg(64000)->Arg(1000000);
BENCHMARK(BM_ExactSum)->Arg(64000)->Arg(1000000);
BENCHMARK(BM_NaiveSumWide)->Arg(64000);
BENCHMARK(BM_ExactSumWide)->Arg(64000);

}  // namespace
