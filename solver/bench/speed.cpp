// pd_speed: one measurement of `make bench` (bench/speed.py runs it per size and thread
// count): a 3D PMB brick on a simple cubic lattice, δ = 3.0002·dx (122 bonds per interior node),
// free faces, the top layers given an initial velocity, advanced by the velocity-Verlet integrator
// pdsolve uses (bond breaking on). Prints one CSV row (header with --header).
//
//   pd_speed --side N [--steps S] [--threads T] [--dir D] [--nodes FILE] [--model pmb|lps] [--kernel auto|portable]
//            [--influence one|inverse_length|gaussian]
//
// --nodes FILE reads the brick from a node file instead of writing the x-fastest lattice (the
// brick must be the side³ lattice of spacing 1 mm at the origin, in any node order): speed.py uses
// it to measure what the node numbering costs (x-fastest, shuffled, Morton as the pre-processor
// writes it: preprocess/ordering.py).
//
// --model lps: the same brick in the linear peridynamic solid (ν = 0.25, ω = 1: PMB's elastic constants),
// for LPS's rate per directed bond beside PMB's (materials/lps); --influence sets its ω (one by default).
//
// --kernel portable: PMB and LPS rows by the portable code even where the CPU has AVX2 (the same
// bits; docs/performance.md §3 gives what the AVX2 rows gain with it, side by side).
//
// set-up = reading the node file (written to D first, not timed) + build_model (bonds, material);
// loop = S integrator steps, timed; directed bond updates/s = directed bonds × S / loop time, each
// bond counted from both ends as LAMMPS's own accounting does.
#include <omp.h>
#include <sys/resource.h>
#include <time.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>

#include "core/avx2.hpp"
#include "core/model.hpp"
#include "materials/pmb/pmb.hpp"
#include "integrators/integrator.hpp"
#include "io/node_file.hpp"
#include "lattice.hpp"

namespace {

using Clock = std::chrono::steady_clock;
double since(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }
// CPU time of the process, all threads: on a busy machine a steadier measure than the wall clock
// (with one thread, CPU seconds ≈ the wall time the loop would take on an idle core).
double cpu_seconds() {
  timespec ts{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

const char* const kHeader =
    "nodes,side,threads,steps,directed_bonds,bonds_per_node,setup_s,setup_us_per_node,loop_s,step_s,"
    "step_ns_per_node,bond_updates_per_s,loop_cpu_s,bond_updates_per_cpu_s,bond_bytes_per_directed_bond,peak_rss_mb,"
    "broken_bonds,model";

int usage() {
  std::fprintf(stderr, "usage: pd_speed --side N [--steps S] [--threads T] [--dir D] [--nodes FILE] [--model pmb|lps] [--kernel auto|portable] [--influence one|inverse_length|gaussian] | --header\n");
  return 2;
}

}  // namespace

int main(int argc, char** argv) {
  int side = 0, steps = 20, threads = 0;
  std::filesystem::path dir = "out/bench/tmp", nodes;
  std::string material = "pmb";
  std::string kernel = "auto";
  std::string influence = "one";
  for (int k = 1; k < argc; ++k) {
    const std::string a = argv[k];
    if (a == "--header") {
      std::printf("%s\n", kHeader);
      return 0;
    }
    if (k + 1 >= argc) return usage();
    if (a == "--side") side = std::atoi(argv[++k]);
    else if (a == "--steps") steps = std::atoi(argv[++k]);
    else if (a == "--threads") threads = std::atoi(argv[++k]);
    else if (a == "--dir") dir = argv[++k];
    else if (a == "--nodes") nodes = argv[++k];
    else if (a == "--model") material = argv[++k];
    else if (a == "--kernel") kernel = argv[++k];
    else if (a == "--influence") influence = argv[++k];
    else return usage();
  }
  if (side < 4 || steps < 1 || (kernel != "auto" && kernel != "portable")) return usage();
  pd::set_avx2_rows(kernel == "auto");
  if (threads > 0) omp_set_num_threads(threads);
  threads = omp_get_max_threads();

  // Silica-glass-like brick, dx = 1 mm: the material only sets the time step and the stretch scale.
  const double dx = 1e-3, horizon = 3.0002 * dx;
  pd::Case c = pdtest::lattice_case(3, "3d", dx, horizon, 72e9, 2440.0, /*fracture_energy=*/4.0);
  if (material == "lps") {
    c.blocks[0].model = "lps";
    c.blocks[0].parameters["poisson_ratio"] = 0.25;
    c.blocks[0].choices["influence"] = influence;
  } else if (material != "pmb") {
    return usage();
  }
  std::filesystem::path node_file = nodes;
  if (nodes.empty()) {
    std::filesystem::create_directories(dir);
    node_file = dir / ("brick-" + std::to_string(side) + ".vtu");
    pd::write_node_file(node_file, pdtest::cubic_lattice(side, side, side, dx, 3));
  }

  const auto setup_start = Clock::now();
  pd::Model model = pd::build_model(c, pd::read_node_file(node_file));
  const double setup = since(setup_start);
  if (nodes.empty()) std::filesystem::remove(node_file);
  const std::size_t n = model.nodes.size();

  // The top three layers move down at 0.1 m/s: the brick rings with stretches of order v/c ≈ 2e-5,
  // below s0 ≈ 1.2e-4, so the loop measures the steady state (breaking tested every step, not taken).
  pd::State state(n);
  const double top = (side - 3) * dx - 0.5 * dx;
  for (std::size_t i = 0; i < n; ++i)
    if (model.nodes.x[2][i] > top) state.v[2][i] = -0.1;
  pd::ForceOperator op_integrator(model);
  auto integrator = pd::integrator_registry().get("verlet")(op_integrator);
  double t = 0.0;
  integrator->initialize(state, t);
  const double dt0 = 0.8 * pd::stable_time_step(model);

  std::int64_t broken = 0;
  const double cpu_start = cpu_seconds();
  const auto loop_start = Clock::now();
  for (int s = 0; s < steps; ++s) {
    double dt = dt0;
    integrator->step(state, t, dt);
    broken += integrator->last_step().broken_now;
  }
  const double loop = since(loop_start);
  const double loop_cpu = cpu_seconds() - cpu_start;

  const double directed = static_cast<double>(model.bonds.directed());
  // What the bond list stores: 4-byte neighbour + 1-byte flag per directed bond, 8-byte offsets per node.
  const double bond_bytes = static_cast<double>(model.bonds.neighbour.size() * sizeof(std::int32_t) +
                                                model.bonds.broken.size() * sizeof(std::uint8_t) +
                                                model.bonds.offsets.size() * sizeof(std::int64_t));
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  std::printf("%zu,%d,%d,%d,%.0f,%.3f,%.4f,%.4f,%.4f,%.6f,%.3f,%.4e,%.4f,%.4e,%.3f,%.1f,%lld,%s\n", n, side, threads,
              steps, directed, directed / static_cast<double>(n), setup, 1e6 * setup / static_cast<double>(n), loop,
              loop / steps, 1e9 * loop / steps / static_cast<double>(n), directed * steps / loop, loop_cpu,
              directed * steps / loop_cpu,
              bond_bytes / directed, static_cast<double>(usage.ru_maxrss) / 1024.0, static_cast<long long>(broken), material.c_str());
  return 0;
}
