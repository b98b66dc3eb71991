// Benchmarks (not tests): on a 2D lattice with self-contact, the cost of one contact-force pass
// over the Verlet list and of one full rebuild of the list, next to one PMB bond-force pass.
#include <benchmark/benchmark.h>

#include "core/neighbour_list.hpp"
#include "forces/contact.hpp"
#include "materials/pmb/pmb.hpp"
#include "lattice.hpp"

namespace {

pd::Model contact_lattice(int n) {
  const double dx = 1e-3;
  pd::Case c = pdtest::lattice_case(2, "plane_stress", dx, 3.015 * dx, 1e9, 1000.0, -1.0, 1e-3);
  c.contact.self_contact = true;
  return pd::build_model(c, pdtest::cubic_lattice(n, n, 1, dx, 2, 1e-3));
}

pd::Vec3Array shear(const pd::Model& m) {
  pd::Vec3Array u = pd::make_vec3(m.nodes.size());
  for (std::size_t i = 0; i < m.nodes.size(); ++i) u[0][i] = 1e-2 * m.nodes.x[1][i];
  return u;
}

void BM_Bond2D(benchmark::State& st) {
  const pd::Model m = contact_lattice(static_cast<int>(st.range(0)));
  const pd::Vec3Array u = shear(m);
  pd::Vec3Array f = pd::make_vec3(m.nodes.size());
  for (auto _ : st) {
    pd::add_pmb_force(m, u, f);
    benchmark::ClobberMemory();
  }
  st.counters["nodes"] = static_cast<double>(m.nodes.size());
}
BENCHMARK(BM_Bond2D)->Arg(200)->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_ContactForce2D(benchmark::State& st) {
  const pd::Model m = contact_lattice(static_cast<int>(st.range(0)));
  const pd::Vec3Array u = shear(m);
  pd::Vec3Array f = pd::make_vec3(m.nodes.size());
  pd::ShortRangeForce(m).AddMult(u, f);  // builds the list once
  for (auto _ : st) {
    pd::ShortRangeForce(m).AddMult(u, f);  // the skin rule finds nothing moved: no rebuild
    benchmark::ClobberMemory();
  }
  st.counters["pairs"] = static_cast<double>(m.contact_list.pairs().directed() / 2);
}
BENCHMARK(BM_ContactForce2D)->Arg(200)->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_ContactRebuild2D(benchmark::State& st) {
  const pd::Model m = contact_lattice(static_cast<int>(st.range(0)));
  const pd::Vec3Array u = shear(m);
  for (auto _ : st) {
    const pd::ContactPairs p = pd::NeighbourList::search(m.nodes.x, u, m.block_index, m.contact);
    benchmark::DoNotOptimize(p.neighbour.data());
  }
}
BENCHMARK(BM_ContactRebuild2D)->Arg(200)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace
