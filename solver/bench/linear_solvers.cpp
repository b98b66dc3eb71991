// pd_linear_solvers: the measurement behind quasi_static's `auto` choice (integrators/
// quasi_static.cpp, kCgFromDofs3d): on a 3D PMB bar of nx × ny × nz nodes (simple cubic lattice,
// dx = 1 mm, δ = 3.015dx, E = 1 GPa), its two left layers clamped and its two right layers pulled
// by 1e-4 of the length along x, one Newton linear system K Δu = V f at the start of the load step
// is solved
//   - by PCG with the block-Jacobi preconditioner (matrix-free, as the cg path does), to the
//     relative residuals 1e-1 (the first Eisenstat–Walker forcing term), 1e-4 and 1e-8;
//   - by CHOLMOD (assembly, symbolic analysis + numeric factorisation, one solve), unless
//     --no-direct; its memory is the factor's entries (8 bytes each, as CHOLMOD reports them) and
//     the process's peak resident set;
//   - with --amg, by PCG preconditioned by one BoomerAMG V-cycle (linalg/amg.hpp, as
//     quasi_static.preconditioner: amg does), set up on the assembled tangent: its set-up time and
//     the resident memory it added (the calibration of AmgPreconditioner::estimated_bytes).
// Prints one line per measurement.
//
//   pd_linear_solvers NX NY NZ [--no-direct] [--amg]
#include <omp.h>
#include <sys/resource.h>
#include <time.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>

#include "core/model.hpp"
#include "lattice.hpp"
#include "linalg/amg.hpp"
#include "linalg/cholesky.hpp"
#include "linalg/pcg.hpp"
#include "operator/force_operator.hpp"

namespace {

double seconds_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

// CPU seconds of the process (all threads): on a shared machine the wall time alone says little.
double cpu_seconds() {
  timespec ts{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

// The resident set now (/proc/self/statm's second field, in pages).
double rss_gb() {
  long pages = 0, resident = 0;
  if (FILE* f = std::fopen("/proc/self/statm", "r")) {
    if (std::fscanf(f, "%ld %ld", &pages, &resident) != 2) resident = 0;
    std::fclose(f);
  }
  return static_cast<double>(resident) * 4096.0 / (1024.0 * 1024.0 * 1024.0);
}

double peak_rss_gb() {
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  return static_cast<double>(usage.ru_maxrss) / (1024.0 * 1024.0);  // ru_maxrss is in kB on Linux
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 4) {
    std::fprintf(stderr, "usage: pd_linear_solvers NX NY NZ [--no-direct] [--amg]\n");
    return 2;
  }
  const int nx = std::atoi(argv[1]), ny = std::atoi(argv[2]), nz = std::atoi(argv[3]);
  bool direct = true, amg = false;
  for (int a = 4; a < argc; ++a) {
    if (std::strcmp(argv[a], "--no-direct") == 0) direct = false;
    else if (std::strcmp(argv[a], "--amg") == 0) amg = true;
  }
  const double dx = 1e-3;
  pd::Case c = pdtest::lattice_case(3, "3d", dx, 3.015 * dx, 1e9, 1000.0, -1.0);
  pd::Nodes nodes = pdtest::cubic_lattice(nx, ny, nz, dx, 3);
  pd::NodeSet left{"left", std::vector<std::uint8_t>(nodes.size(), 0)}, right{"right", left.member};
  for (std::size_t i = 0; i < nodes.size(); ++i) {
    left.member[i] = nodes.x[0][i] < 1.5 * dx;
    right.member[i] = nodes.x[0][i] > (nx - 2.5) * dx;
  }
  nodes.sets = {left, right};
  for (int d = 0; d < 3; ++d) c.boundary_conditions.push_back({"left", "displacement", d, {0.0}, {0.0}});
  c.boundary_conditions.push_back({"right", "displacement", 0, {0.0, 1.0}, {0.0, 1e-4 * (nx - 1) * dx}});
  for (int d = 1; d < 3; ++d) c.boundary_conditions.push_back({"right", "displacement", d, {0.0}, {0.0}});
  auto start = std::chrono::steady_clock::now();
  pd::Model m = pd::build_model(c, std::move(nodes));
  const pd::ForceOperator op(m);
  pd::State s(m.nodes.size());
  op.impose_prescribed_motion(s, 1.0);
  op.evaluate(s, 1.0);
  const pd::FreeDofs dofs = pd::FreeDofs::of(s.size(), 3, m.conditions.fixed);
  std::vector<double> b(dofs.size());
  for (std::size_t k = 0; k < dofs.size(); ++k) {
    const auto i = static_cast<std::size_t>(dofs.node[k]);
    b[k] = m.nodes.volume[i] * s.f[dofs.component[k]][i];
  }
  std::printf("lattice %d x %d x %d: %zu nodes, %lld bonds, %zu free dofs, %d threads, set-up %.2f s\n", nx, ny, nz,
              s.size(), static_cast<long long>(m.bonds.directed() / 2), dofs.size(), omp_get_max_threads(),
              seconds_since(start));

  // PCG, matrix-free.
  pd::Vec3Array xa = pd::make_vec3(s.size()), ya = pd::make_vec3(s.size());
  std::int64_t products = 0;
  const pd::LinearOperator K = [&](const std::vector<double>& x, std::vector<double>& y) {
    ++products;
    dofs.scatter(x, xa);
    op.apply_jacobian(s, 1.0, xa, ya);
    y.resize(x.size());
    for (std::size_t k = 0; k < x.size(); ++k) y[k] = -m.nodes.volume[static_cast<std::size_t>(dofs.node[k])] * ya[dofs.component[k]][static_cast<std::size_t>(dofs.node[k])];
  };
  start = std::chrono::steady_clock::now();
  std::vector<std::int64_t> first;
  std::vector<double> blocks;
  op.stiffness_diagonal_blocks(s, 1.0, dofs, first, blocks);
  pd::BlockJacobi M;
  M.build(first, blocks);
  const double setup = seconds_since(start);
  std::printf("block-Jacobi set-up %.3f s\n", setup);
  for (double tol : {1e-1, 1e-4, 1e-8}) {
    pd::PcgSettings settings;
    settings.relative_tol = tol;
    settings.max_iterations = 100000;
    std::vector<double> x;
    products = 0;
    start = std::chrono::steady_clock::now();
    const double cpu0 = cpu_seconds();
    const pd::PcgResult r = pd::preconditioned_cg(K, M, b, x, settings);
    const double time = seconds_since(start), cpu = cpu_seconds() - cpu0;
    std::printf("PCG to %.0e: %d iterations, %.2f s wall, %.2f s CPU (%.1f ms wall per iteration), %s\n", tol, r.iterations,
                time, cpu, 1e3 * time / std::max(r.iterations, 1), r.message().c_str());
    std::fflush(stdout);
  }
  std::printf("peak RSS after PCG %.2f GB (resident now %.2f GB)\n", peak_rss_gb(), rss_gb());
  std::fflush(stdout);
  if (amg) {
    start = std::chrono::steady_clock::now();
    double cpu0 = cpu_seconds();
    const pd::SparseMatrix A = op.assemble_stiffness(s, 1.0, dofs);
    std::printf("assembly %.2f s wall, %.2f s CPU, %zu nonzeros, resident %.2f GB\n", seconds_since(start),
                cpu_seconds() - cpu0, A.nonzeros(), rss_gb());
    const double before = rss_gb();
    pd::AmgPreconditioner hierarchy;
    start = std::chrono::steady_clock::now();
    cpu0 = cpu_seconds();
    hierarchy.set_up(A, 3, dofs.component);
    std::printf("AMG set-up %.2f s wall, %.2f s CPU: %d levels, operator complexity %.2f, resident +%.2f GB "
                "(estimated %.2f GB), peak RSS %.2f GB\n",
                seconds_since(start), cpu_seconds() - cpu0, hierarchy.levels(), hierarchy.operator_complexity(),
                rss_gb() - before, static_cast<double>(pd::AmgPreconditioner::estimated_bytes(dofs.size(), A.nonzeros())) / (1024.0 * 1024.0 * 1024.0),
                peak_rss_gb());
    std::fflush(stdout);
    for (double tol : {1e-1, 1e-4, 1e-8}) {
      pd::PcgSettings settings;
      settings.relative_tol = tol;
      settings.max_iterations = 100000;
      std::vector<double> x;
      start = std::chrono::steady_clock::now();
      cpu0 = cpu_seconds();
      const pd::PcgResult r = pd::preconditioned_cg(K, hierarchy, b, x, settings);
      std::printf("AMG-PCG to %.0e: %d iterations, %.2f s wall, %.2f s CPU, %s\n", tol, r.iterations, seconds_since(start),
                  cpu_seconds() - cpu0, r.message().c_str());
      std::fflush(stdout);
    }
  }
  if (!direct) return 0;

  start = std::chrono::steady_clock::now();
  const pd::SparseMatrix A = op.assemble_stiffness(s, 1.0, dofs);
  const double assembly = seconds_since(start);
  std::printf("assembly %.2f s, %zu nonzeros (CSR %.2f GB)\n", assembly, A.nonzeros(), 16.0 * static_cast<double>(A.nonzeros()) / 1e9);
  std::fflush(stdout);
  pd::SparseCholesky chol;
  start = std::chrono::steady_clock::now();
  const double cpu0 = cpu_seconds();
  const bool ok = chol.factorize(A);
  const double factor = seconds_since(start), factor_cpu = cpu_seconds() - cpu0;
  std::printf("CHOLMOD analysis + factorisation %.2f s wall, %.2f s CPU (%s), factor %.3g entries (%.2f GB), peak RSS %.2f GB\n", factor, factor_cpu,
              ok ? "ok" : chol.failure().c_str(), chol.factor_nonzeros(), 8.0 * chol.factor_nonzeros() / 1e9, peak_rss_gb());
  std::fflush(stdout);
  if (!ok) return 1;
  std::vector<double> x;
  start = std::chrono::steady_clock::now();
  chol.solve(b, x);
  std::printf("CHOLMOD solve %.3f s\n", seconds_since(start));
  return 0;
}
