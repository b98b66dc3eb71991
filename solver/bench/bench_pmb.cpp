// Benchmarks (not tests): bond-list construction and the PMB force kernel on a 3D lattice, m = 3.
// Run: build/solver/pd_bench [--benchmark_filter=...]; OMP_NUM_THREADS sets the threads.
#include <benchmark/benchmark.h>

#include "materials/pmb/pmb.hpp"
#include "lattice.hpp"

namespace {

pd::Model lattice_model(int n) {
  const double dx = 1e-3;
  const pd::Case c = pdtest::lattice_case(3, "3d", dx, 3.015 * dx, 1e9, 1000.0, -1.0);
  return pd::build_model(c, pdtest::cubic_lattice(n, n, n, dx, 3));
}

void BM_BuildBonds(benchmark::State& st) {
  const int n = static_cast<int>(st.range(0));
  const pd::Nodes nodes = pdtest::cubic_lattice(n, n, n, 1e-3, 3);
  std::size_t bonds = 0;
  for (auto _ : st) {
    const pd::BondList b = pd::build_bonds(nodes.x, 3.015e-3);
    bonds = b.directed();
    benchmark::DoNotOptimize(b.neighbour.data());
  }
  st.counters["nodes"] = static_cast<double>(nodes.size());
  st.counters["bonds"] = static_cast<double>(bonds / 2);
}
BENCHMARK(BM_BuildBonds)->Arg(20)->Arg(40)->Unit(benchmark::kMillisecond);

void BM_PmbForce(benchmark::State& st) {
  const int n = static_cast<int>(st.range(0));
  const pd::Model m = lattice_model(n);
  pd::Vec3Array u = pd::make_vec3(m.nodes.size());
  for (std::size_t i = 0; i < m.nodes.size(); ++i) u[0][i] = 1e-4 * m.nodes.x[0][i] * m.nodes.x[1][i] / 1e-3;
  pd::Vec3Array f = pd::make_vec3(m.nodes.size());
  std::vector<double> w(m.nodes.size());
  const pd::PmbArrays a = pd::pmb_arrays(m, u);
  for (auto _ : st) {
    pd::add_pmb_force_density(a, f[0].data(), f[1].data(), f[2].data(), w.data());
    benchmark::ClobberMemory();
  }
  st.counters["bond_updates/s"] = benchmark::Counter(static_cast<double>(m.bonds.directed()) * static_cast<double>(st.iterations()),
                                                     benchmark::Counter::kIsRate);
}
BENCHMARK(BM_PmbForce)->Arg(40)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace

BENCHMARK_MAIN();
