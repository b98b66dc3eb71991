// pdsolve: the command-line front end of the solver library (see run.hpp for the work itself).
#include <algorithm>
#include <cstdlib>
#include <iostream>
#include <string>

#include <nlohmann/json.hpp>

#include "build_info.hpp"
#include "core/error.hpp"
#include "core/model.hpp"
#include "core/stability.hpp"
#include "io/case_reader.hpp"
#include "io/describe.hpp"
#include "io/node_file.hpp"
#include "io/output_lock.hpp"
#include "io/physics_query.hpp"
#include "parallel/session.hpp"
#include "run.hpp"

#ifdef _OPENMP
#include <malloc.h>
#include <omp.h>
#endif

namespace {

const char* const kUsage =
    "usage: pdsolve CASE.json [--restart CHECKPOINT] [--threads N] [--end-time T] [--max-steps N] [--quiet]\n"
    "               [--progress S] [--parallel-frames gathered|pieces] [--help] [--version]\n"
    "       pdsolve --stable-dt CASE.json [--exact] [--threads N]\n"
    "       pdsolve --physics CASE.json [--exact] [--threads N]\n"
    "       pdsolve --describe\n"
    "\n"
    "Bond-based PMB peridynamics solver. Reads the resolved case CASE.json and its node file\n"
    "(pipeline/formats.md), writes frames/*.vtu, frames.pvd, history.csv and run.log to the\n"
    "case's output_dir.\n"
    "\n"
    "  --restart CHECKPOINT\n"
    "                  continue the run of CASE.json from CHECKPOINT (its output_dir/checkpoint.bin),\n"
    "                  bitwise as if it had never stopped; refused for another case or node file\n"
    "  --threads N     OpenMP threads (default: OMP_NUM_THREADS or all cores); at most max(64, 4 × the\n"
    "                  processors), and OMP_NUM_THREADS is held to the same limit\n"
    "  --end-time T    simulated end time [s], overrides time.end\n"
    "  --max-steps N   stop after step N at most (counted from the start of the run, also on a restart)\n"
    "  --quiet         print nothing on stdout and no progress on stderr (run.log is still written)\n"
    "  --progress S    a progress line (step, t, %, steps/s, ETA) every S seconds of wall time in\n"
    "                  run.log, and on stderr when it is not a terminal (a terminal gets one updating\n"
    "                  line); default 10, 0: none\n"
    "  --parallel-frames gathered|pieces\n"
    "                  overrides output.parallel_frames: on several MPI ranks, one gathered .vtu per\n"
    "                  frame written by rank 0, or one .vtu piece per rank named by a .pvtu (the\n"
    "                  default); one rank always writes the gathered .vtu; a restart goes on in the\n"
    "                  format its series was written in\n"
    "  --help          this text\n"
    "  --version       the solver version and how it was built (compiler, flags, OpenMP, sanitizers)\n"
    "  --stable-dt     print, as JSON, the stable step of thesis eq. 2.5 that a run of CASE.json would\n"
    "                  compute (before time.safety_factor; null if no node has a bond):\n"
    "                  {\"stable\": s, \"safety_factor\": f}. Writes nothing.\n"
    "  --physics       print, as JSON, what the Python side needs of CASE.json's set-up: --stable-dt's\n"
    "                  step and the node where it is reached (\"node\"), each block's micromodulus and\n"
    "                  critical stretch, the surface correction's range of bond factors\n"
    "                  (io/physics_query.hpp). Writes nothing.\n"
    "  --exact         with --stable-dt or --physics: also \"exact\": 2/omega_max, the Lanczos limit of\n"
    "                  time.dt \"exact\"\n"
    "  --describe      print, as JSON, every case.json key this solver reads: {\"keys\": {\"time.dt\":\n"
    "                  {\"type\", \"default\" | \"required\", \"choices\", \"minimum\", \"maximum\", \"above\",\n"
    "                  \"below\", \"unit\", \"note\"}, ...}, \"registries\": {name: [keys]}}\n"
    "                  (pipeline/formats.md §6)\n"
    "\n"
    "SIGINT (Ctrl-C) or SIGTERM: the run finishes its step, writes output_dir/checkpoint.bin and\n"
    "stops; more signals within 2 s are the same request (make forwards a SIGTERM sent to its\n"
    "process group), a signal after that kills it at once. output.restart_every_wall (default\n"
    "600 s of wall time; 0: none) and output.restart_every_time / _steps write a checkpoint without\n"
    "stopping.\n"
    "\n"
    "Exit codes: 0 done; 1 bad input (reported before any output file is written); 2 bad command\n"
    "line; 3 the run failed (e.g. the state became non-finite, or the disk is full: \"disk full\n"
    "writing FILE: free N MB and run make again\"; the frames and rows written before are whole);\n"
    "75 the output folder is in use by another run (make, peridyn or pdsolve: output_dir/.lock);\n"
    "129 / 130 / 143 interrupted by SIGHUP / SIGINT / SIGTERM after writing the checkpoint.\n";

#ifdef _OPENMP
// The specification version of an _OPENMP date (OpenMP's own table).
std::string openmp_version(long date) {
  switch (date) {
    case 201307: return "4.0";
    case 201511: return "4.5";
    case 201811: return "5.0";
    case 202011: return "5.1";
    case 202111: return "5.2";
    default: return std::to_string(date);
  }
}
#endif

// --version: enough to tell which binary, built how, produced a result.
void print_version() {
  std::cout << "pdsolve " << pd::build::kVersion << "\n"
            << "build type: " << (*pd::build::kBuildType ? pd::build::kBuildType : "(none)") << "\n"
            << "compiler: " << pd::build::kCompiler << "\n"
            << "flags: " << pd::build::kFlags << "\n"
#ifdef _OPENMP
            << "OpenMP: " << openmp_version(_OPENMP) << " (up to " << omp_get_max_threads() << " threads here)\n"
#else
            << "OpenMP: off\n"
#endif
            << "sanitizers: " << pd::build::kSanitizers << "\n"
            << "MPI: " << (pd::built_with_mpi() ? "on (PD_MPI; mpirun -np R pdsolve CASE.json)" : "off") << "\n";
}

// The options are read before MPI starts, so the rank is not known yet; the launcher puts it in the
// environment (Open MPI: OMPI_COMM_WORLD_RANK; MPICH's and PMIx's launchers: PMI_RANK, PMIX_RANK).
// True for rank 0, and for a process started without a launcher.
bool launched_as_rank_zero() {
  for (const char* name : {"OMPI_COMM_WORLD_RANK", "PMI_RANK", "PMIX_RANK"})
    if (const char* value = std::getenv(name)) return std::string(value) == "0";
  return true;
}

// Under mpiexec every rank finds the same mistake: rank 0 alone says it (not R copies of the usage).
[[noreturn]] void usage_error(const std::string& what) {
  if (launched_as_rank_zero()) std::cerr << "pdsolve: " << what << "\n" << kUsage;
  std::exit(pd::kUsageError);
}

double parse_number(const std::string& option, const std::string& text) {
  std::size_t used = 0;
  double value = 0.0;
  try {
    value = std::stod(text, &used);
  } catch (...) {
    used = 0;
  }
  if (used != text.size() || !(value > 0.0)) usage_error(option + " needs a number > 0, got '" + text + "'");
  return value;
}

// The whole of `text` as an integer ≥ 1, or 0 if it is not one.
long long whole_positive(const std::string& text) {
  std::size_t used = 0;
  long long value = 0;
  try {
    value = std::stoll(text, &used);
  } catch (...) {
    used = 0;
  }
  return used == text.size() && value >= 1 ? value : 0;
}

long long parse_integer(const std::string& option, const std::string& text) {
  const long long value = whole_positive(text);
  if (value < 1) usage_error(option + " needs an integer ≥ 1, got '" + text + "'");
  return value;
}

// More threads than max(64, 4 × the processors) only slow a run down, and 100000 OpenMP threads
// crashed the runtime (issue 17, item 9): refused with the limit.
long long thread_limit() {
#ifdef _OPENMP
  return std::max(64, 4 * omp_get_num_procs());
#else
  return 64;  // ignored without OpenMP
#endif
}

std::string too_many_threads(const std::string& what) {
  return what + ": at most " + std::to_string(thread_limit()) + " threads here (max(64, 4 × the processors))";
}

int parse_threads(const std::string& option, const std::string& text) {
  const long long threads = parse_integer(option, text);
  if (threads > thread_limit()) usage_error(too_many_threads(option + " " + text) + "; the default uses every core");
  return static_cast<int>(threads);
}

// OMP_NUM_THREADS reaches the OpenMP runtime without passing parse_threads: 100000 there crashed it
// at the first parallel region, 20000 ran for minutes, and 65–5000 were taken though --threads
// stops at the limit (issue 36, item 10). So when it decides (no --threads), every entry of its
// list (the threads of each nesting level, "4,2") gets the same check, and text the runtime would
// drop with a warning for its default is refused too: a run should not use another thread count
// than the one asked for without a word. OMP_THREAD_LIMIT is not checked: it only caps the count.
void check_thread_environment() {
  const char* value = std::getenv("OMP_NUM_THREADS");
  if (!value || !*value) return;  // unset or empty (`OMP_NUM_THREADS= pdsolve …`): the default
  const std::string text = value, shown = "OMP_NUM_THREADS=" + text;
  const std::string fix = "; unset it, or give --threads N, which overrides it";
  std::size_t begin = 0;
  while (true) {
    const std::size_t comma = text.find(',', begin);
    const std::string entry = text.substr(begin, comma == std::string::npos ? std::string::npos : comma - begin);
    const long long threads = whole_positive(entry);
    if (threads < 1)
      usage_error(shown + ": needs a thread count ≥ 1, or a list of them for nested levels (such as 4,2); got '" +
                  entry + "'" + fix);
    if (threads > thread_limit()) usage_error(too_many_threads(shown) + fix);
    if (comma == std::string::npos) break;
    begin = comma + 1;
  }
}

// --stable-dt: eq. 2.5 on the model built exactly as run() builds it (read_case, read_node_file,
// build_model), so that tests can hold --physics's step, which preprocess asks
// (pipeline/solver_physics.py), equal to the one a run of the written files computes.
int print_stable_dt(const std::filesystem::path& case_file, bool exact) {
  const pd::Case c = pd::read_case(case_file);
  const pd::Model model = pd::build_model(c, pd::read_node_file(c.nodes_file));
  nlohmann::json out = {{"case", case_file.string()},
                        {"stable", pd::stable_time_step(model)},  // +inf (no bond) dumps as null
                        {"safety_factor", c.time.safety_factor}};
  if (exact) out["exact"] = pd::exact_time_step(model);
  std::cout << out.dump(1) << "\n";
  return pd::kOk;
}

}  // namespace

// MPI's ranks for the lifetime of main (parallel/session.hpp; nothing without PD_MPI).
struct Ranks {
  Ranks(int* argc, char*** argv) { pd::start_ranks(argc, argv); }
  ~Ranks() { pd::stop_ranks(); }
  Ranks(const Ranks&) = delete;
  Ranks& operator=(const Ranks&) = delete;
};

int main(int argc, char** argv) {
  const Ranks ranks(&argc, &argv);
  // Keep freed memory in the heap. A frame of 10⁵ nodes is built in buffers of ~10 MB; glibc would
  // map and unmap them at every frame, and touching fresh pages costs more than writing the file
  // (cases/branching: output 44 % → 9.5 % of the time loop, docs/notes/2026-12-01-bond-kernel.md §3). Buffers over
  // 256 MB (the bond list of a big model, allocated once) are still mapped on their own.
  mallopt(M_MMAP_THRESHOLD, 256 << 20);
  mallopt(M_TRIM_THRESHOLD, 512 << 20);
  mallopt(M_TOP_PAD, 16 << 20);
  pd::RunOptions options;
  bool stable_dt = false, physics = false, exact = false;
  for (int k = 1; k < argc; ++k) {
    const std::string arg = argv[k];
    auto value = [&]() -> std::string {
      if (k + 1 >= argc) usage_error(arg + " needs a value");
      return argv[++k];
    };
    if (arg == "--help" || arg == "-h") {
      std::cout << kUsage;
      return pd::kOk;
    } else if (arg == "--version") {
      print_version();
      return pd::kOk;
    } else if (arg == "--threads") {
      options.threads = parse_threads(arg, value());
    } else if (arg == "--end-time") {
      options.end_time = parse_number(arg, value());
    } else if (arg == "--max-steps") {
      options.max_steps = parse_integer(arg, value());
    } else if (arg == "--parallel-frames") {
      const std::string how = value();
      if (how != "gathered" && how != "pieces") usage_error("--parallel-frames takes gathered or pieces, not '" + how + "'");
      options.parallel_frames = how;
    } else if (arg == "--restart") {
      options.restart = value();
    } else if (arg == "--describe") {
      std::cout << pd::describe_case().dump(1) << "\n";
      return pd::kOk;
    } else if (arg == "--stable-dt") {
      stable_dt = true;
    } else if (arg == "--physics") {
      physics = true;
    } else if (arg == "--exact") {
      exact = true;
    } else if (arg == "--quiet") {
      options.quiet = true;
    } else if (arg == "--progress") {
      const std::string seconds = value();
      options.progress_interval = seconds == "0" ? 0.0 : parse_number(arg, seconds);  // 0: no lines
    } else if (!arg.empty() && arg[0] == '-') {
      usage_error("unknown option '" + arg + "'");
    } else if (options.case_file.empty()) {
      options.case_file = arg;
    } else {
      usage_error("more than one case file ('" + options.case_file.string() + "', '" + arg + "')");
    }
  }
  if (options.case_file.empty()) usage_error("no case file given");
  if (exact && !stable_dt && !physics) usage_error("--exact goes with --stable-dt");
  if (options.threads == 0) check_thread_environment();  // before any parallel region
  try {
    if (stable_dt || physics) {
#ifdef _OPENMP
      if (options.threads > 0) omp_set_num_threads(options.threads);
#endif
      if (stable_dt) return print_stable_dt(options.case_file, exact);
      std::cout << pd::physics_of_case(options.case_file, exact).dump(1) << "\n";
      return pd::kOk;
    }
    return pd::run(options);
  } catch (const pd::FolderInUse& e) {
    // Another run writes into the output folder (io/output_lock.hpp): EX_TEMPFAIL, as make's lock.
    std::cerr << "pdsolve: error: " << e.what() << "\n";
    return pd::kFolderInUse;
  } catch (const pd::Error& e) {
    // Bad input is found by every rank of a decomposed run alike (each reads the same files): one says it.
    if (pd::world_ranks().rank == 0) std::cerr << "pdsolve: error: " << e.what() << "\n";
    return pd::kInputError;
  } catch (const std::exception& e) {
    std::cerr << "pdsolve: internal error: " << e.what() << "\n";
    return pd::kRunFailed;
  }
}
