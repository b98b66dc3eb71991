// One quasi-static load step: prescribed motion at the new load, Newton to equilibrium, breaking
// and re-solving, the eq. 2.8 proposal (see quasi_static.hpp).
#include "integrators/quasi_static.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <sstream>

#include "control/zohdi.hpp"
#include "core/error.hpp"
#include "parallel/decomposed.hpp"
#include "parallel/node_sum.hpp"
#include "integrators/bonds_out_of_factor.hpp"
#include "integrators/messages.hpp"
#include "integrators/newton_krylov.hpp"

namespace pd {

void QuasiStatic::configure(const Case& c, double) {
  settings_ = c.quasi_static;
  end_ = c.time.end;
  dt_max_ = settings_.dt_max.value_or(end_ / 10.0);
  dt_min_ = settings_.dt_min.value_or(std::min(1e-6 * end_, dt_max_));
  dt_initial_ = std::min(settings_.dt_initial.value_or(end_ / 100.0), dt_max_);
  if (dt_min_ > dt_max_)
    throw Error(c.file.string() + ": quasi_static.dt_min = " + message_number(dt_min_) + " s is above dt_max = " +
                message_number(dt_max_) + " s");
  if (op_.damping() != 0.0)
    throw Error(c.file.string() + ": damping: quasi_static solves for equilibrium, where damping does nothing; "
                "set damping: 0 (or use time.integrator: verlet)");
  choose_linear_solver(c);
  // Whether the law is bond-based (has bond_tangent_row): only then are hanging nodes left out.
  const Model& m = op_.model();
  std::vector<double> probe(9 * (m.bonds.offsets.size() > 1 ? static_cast<std::size_t>(m.bonds.offsets[1]) : 0) + 9);
  bond_based_ = m.nodes.size() == 0 || m.bond_model->bond_tangent_row(m, make_vec3(m.nodes.size()), 0, probe.data());
}

// direct or cg, and why (for describe()). The 3D threshold kCgFromDofs3d is measured with
// bench/linear_solvers.cpp (pd_linear_solvers: a clamped bar pulled along x, δ = 3.015dx, one Newton
// system at the start of a load step; 2 threads on a machine shared with other jobs, load ~15, so
// CPU seconds are quoted): at 6,912 free dofs CHOLMOD's analysis + factorisation took 3.6 s CPU and
// block-Jacobi PCG to a 1e-8 relative residual 0.32 s CPU (11×); at 27,648 dofs 87 s CPU (factor
// 5.95e7 entries, 0.48 GB, peak 0.97 GB resident) against 1.3 s CPU (67×; 0.2 s to the first
// Eisenstat–Walker tolerance 0.1); at 67,200 dofs PCG 7.3 s CPU. The factor's fill grew as
// dofs^1.5 and its time as dofs^2.3: above some 20,000 dofs a factorisation costs more than the
// Newton iterations it can serve once bonds break (a breaking round of more than a few bonds
// refactorises: kMaxRemovedColumns), so auto
// takes cg; at 10⁵ nodes (3·10⁵ dofs) the factor would hold some 2·10⁹ entries, 17 GB.
// In 2D the factor stays small (the traction lattice, 47,871 dofs, factorises in seconds and one
// factorisation serves the elastic range): auto keeps direct whatever the size there, unless a term
// has no assembled form.
void QuasiStatic::choose_linear_solver(const Case& c) {
  linear_.choose(op_, c, "quasi_static", settings_.linear_solver, op_.model().nodes.dimension);
  // The preconditioner needs the whole model's free dofs and whether its tangent can be assembled.
  const Decomposed* decomposed = op_.decomposed();
  const auto local_free = static_cast<std::int64_t>(op_.free_dofs(op_.model().nodes.dimension).size());
  const auto free = static_cast<std::size_t>(decomposed ? decomposed->total(local_free) : local_free);
  choose_preconditioner(c, free, op_.missing_assembled_stiffness(State(op_.size()), 0.0).empty());
}

namespace {

std::string format_gib(double value) {
  char buffer[32];
  std::snprintf(buffer, sizeof buffer, "%.1f", value);
  return buffer;
}

// MemAvailable of /proc/meminfo in bytes (0 when it cannot be read: then the guard does not refuse).
std::uint64_t available_memory() {
  std::ifstream in("/proc/meminfo");
  std::string line;
  while (std::getline(in, line))
    if (line.rfind("MemAvailable:", 0) == 0) {
      std::istringstream fields(line.substr(13));
      std::uint64_t kib = 0;
      fields >> kib;
      return kib * 1024;
    }
  return 0;
}

}  // namespace

// block_jacobi or amg, and why (for describe()). Measured on a clamped 3D bar pulled along x
// (tests and cases/beam_3d/README.md): at 102,400 nodes one Newton system to a 1e-8 residual took
// block-Jacobi CG some 130 iterations and AMG-CG some 17; the hierarchy costs about its CG time
// again to set up and ~30× block-Jacobi's memory, hence the guard. Below some 20,000 dofs the
// set-up is not repaid.
void QuasiStatic::choose_preconditioner(const Case& c, std::size_t free, bool assembled) {
  const int dimension = op_.model().nodes.dimension;
  const std::string& choice = settings_.preconditioner;
  use_amg_ = false;
  if (!linear_.uses_cg()) {
    preconditioner_reason_.clear();
    return;
  }
  if (choice == "block_jacobi") {
    preconditioner_reason_ = "block_jacobi: as the case file asks";
    return;
  }
  // hypre is set up here on one process's assembled tangent: a decomposed run keeps block Jacobi,
  // which is per node and so decomposes as it is.
  const Decomposed* decomposed = op_.decomposed();
  if (choice == "amg") {
    if (decomposed)
      throw Error(c.file.string() + ": quasi_static.preconditioner: amg is set up on one process and is not decomposed "
                  "over MPI ranks (here " + std::to_string(decomposed->ranks()) +
                  "); use preconditioner: block_jacobi (or auto), or run on one rank");
    if (!assembled)
      throw Error(c.file.string() + ": quasi_static.preconditioner: amg is set up on the assembled tangent, which " +
                  op_.missing_assembled_stiffness(State(op_.size()), 0.0) +
                  " does not have; use preconditioner: block_jacobi (or auto)");
    if (!AmgPreconditioner::available())
      throw Error(c.file.string() + ": quasi_static.preconditioner: amg needs hypre's BoomerAMG, which this pdsolve "
                  "was built without: install libhypre-dev (pipeline/install-deps.sh) and rebuild, or use "
                  "preconditioner: block_jacobi (or auto)");
    use_amg_ = true;
    preconditioner_reason_ = "amg: as the case file asks";
    return;
  }
  const std::string dofs = std::to_string(free) + " free dofs";
  if (decomposed) {
    preconditioner_reason_ = "block_jacobi: auto, decomposed over " + std::to_string(decomposed->ranks()) + " MPI ranks";
  } else if (dimension != 3 || free < kAmgFromDofs3d) {
    preconditioner_reason_ = "block_jacobi: auto, " + dofs + (dimension == 3 ? ", below " + std::to_string(kAmgFromDofs3d) + " in 3D" : " in 2D");
  } else if (!assembled) {
    preconditioner_reason_ = "block_jacobi: auto, no assembled tangent for amg";
  } else if (!AmgPreconditioner::available()) {
    preconditioner_reason_ = "block_jacobi: auto, this pdsolve has no hypre for amg";
  } else {
    // The tangent's stored entries: a 3×3 block per node and two per bond (upper bound over free dofs).
    const auto nonzeros = 3 * static_cast<std::uint64_t>(free) + 9 * static_cast<std::uint64_t>(op_.model().bonds.directed());
    const std::uint64_t need = AmgPreconditioner::estimated_bytes(free, nonzeros), have = available_memory();
    const double gib = 1024.0 * 1024.0 * 1024.0;
    if (have > 0 && static_cast<double>(need) > kAmgMemoryShare * static_cast<double>(have)) {
      preconditioner_reason_ = "block_jacobi: auto, amg would need about " + format_gib(static_cast<double>(need) / gib) +
                               " GB, more than half of the " + format_gib(static_cast<double>(have) / gib) +
                               " GB available (set preconditioner: amg to use it anyway)";
    } else {
      use_amg_ = true;
      preconditioner_reason_ = "amg: auto, " + dofs + " in 3D, at least " + std::to_string(kAmgFromDofs3d) + "; about " +
                               format_gib(static_cast<double>(need) / gib) + " GB for its hierarchy";
    }
  }
}

// The preconditioner is the checkpoint's too: AMG and block Jacobi give other CG iterates. AMG is
// kept on one process with hypre and an assembled tangent, even where auto's memory guard would
// now refuse it: the run that wrote the checkpoint held its hierarchy.
std::string QuasiStatic::keep_linear_solver(const std::string& recorded) {
  checkpoint_solver_ = recorded;  // load_state reads the bytes that solver wrote
  const std::string here = linear_solver();
  if (recorded == here) return {};
  const bool amg = recorded == "cg amg";
  if (amg) {
    if (const Decomposed* decomposed = op_.decomposed())
      return "amg is set up on one process, and this run is decomposed over " + std::to_string(decomposed->ranks()) + " MPI ranks";
    if (!AmgPreconditioner::available()) return "amg needs hypre's BoomerAMG, which this pdsolve was built without";
    if (const std::string missing = op_.missing_assembled_stiffness(State(op_.size()), 0.0); !missing.empty())
      return "amg is set up on the assembled tangent, which " + missing + " does not have";
  } else if (std::string why = why_not_linear_solver(op_, recorded); !why.empty()) {
    return why;
  }
  linear_.keep_recorded(recorded != "direct", here,
                        preconditioner_reason_.empty() ? "" : ", preconditioner " + preconditioner_reason_);
  use_amg_ = amg;
  preconditioner_reason_ = linear_.uses_cg() ? (amg ? "amg" : "block_jacobi") + std::string(": as the checkpoint was written") : "";
  return {};
}

void QuasiStatic::set_up_amg(const State& s, double t1) {
  const auto start = std::chrono::steady_clock::now();
  if (linear_.remembering() && !at_start_.amg_u_saved && at_start_.amg_ready) {  // the step's start's, for restore_solver
    at_start_.amg_u = amg_u_;
    at_start_.amg_u_saved = true;
  }
  // The definite variant, shifted: positive definite even with compressed bonds and loose nodes.
  SparseMatrix K = op_.assemble_stiffness(s, t1, dofs_, true);
  amg_shift_ = shift_diagonal(K);
  amg_.set_up(K, op_.model().nodes.dimension, dofs_.component);
  ++amg_setups_;
  amg_u_ = s.u;
  amg_t_ = t1;
  amg_rate_ = 0.0;
  amg_seconds_ += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

void QuasiStatic::initialize(State& state, double t) {
  op_.start(state, t);
  dofs_ = op_.free_dofs(op_.model().nodes.dimension);
  sums_.setup(op_.decomposed(), dofs_);
  // Equilibrium fixes u only up to the rigid motions nothing holds: a direction in which no node
  // is prescribed is one (rotations are caught by the factorisation, singular then).
  static const char* const axis[3] = {"x", "y", "z"};
  for (int d = 0; d < op_.model().nodes.dimension; ++d) {
    const auto& held = op_.fixed()[static_cast<std::size_t>(d)];
    const bool here = std::any_of(held.begin(), held.end(), [](std::uint8_t f) { return f != 0; });
    if (!(op_.decomposed() ? op_.decomposed()->total(here ? 1 : 0) > 0 : here))
      throw Error(std::string("time.integrator: quasi_static: the body can move freely in ") + axis[d] +
                  " (no node has a displacement or velocity condition in " + axis[d] +
                  "): quasi_static needs one, or use time.integrator: verlet");
  }
  trial_ = State(state.size());
  report_ = StepReport{};
  hanging_ = HangingNodes{};
  skip_dof_.clear();
  carried_load_ = 0.0;
  started_cold_ = false;
  if (linear_.uses_cg()) linear_.size_cg(state.size());
}

// Block-Jacobi of K's 3×3 node blocks at (s, t1), shifted after bonds have broken; returns the shift.
double QuasiStatic::build_block_jacobi(const State& s, double t1) {
  // A law with neither bond_tangent_row nor jacobian_diagonal_blocks: unpreconditioned CG (1×1 blocks of 1).
  linear_.stiffness_blocks(op_, s, t1, dofs_, 1.0);
  // After bonds have broken, the same shift of the diagonal as the direct path (see
  // solve_equilibrium): kDiagonalShift × the largest diagonal entry of K, here of its blocks.
  double shift = 0.0;
  if (broken_since_start_) {
    double largest = 0.0;
    linear_.each_block_diagonal([&](double& entry, std::size_t) { largest = std::max(largest, std::fabs(entry)); });
    if (op_.decomposed()) largest = -op_.decomposed()->minimum(-largest);  // over every rank's blocks: exact
    shift = kDiagonalShift * largest;
    linear_.each_block_diagonal([shift](double& entry, std::size_t) { entry += shift; });
  }
  linear_.build_block_jacobi();
  return shift;
}

bool QuasiStatic::solve_krylov(const State& s, double t1, double eta, double floor) {
  double shift = 0.0;
  const Preconditioner* M = nullptr;  // block Jacobi
  if (use_amg_) {
    // AMG never reads block-Jacobi's 3×3 blocks: they are not assembled. After bonds have broken
    // the operator's shift is the one the hierarchy was set up with (kDiagonalShift × the largest
    // diagonal entry of its K): a regularisation, which any fixed one of that size serves.
    if (!amg_.ready()) set_up_amg(s, t1);
    M = &amg_;
    if (broken_since_start_) shift = amg_shift_;
  } else {
    shift = build_block_jacobi(s, t1);
  }
  PcgSettings settings;
  settings.relative_tol = eta;
  settings.absolute_tol = floor;
  settings.max_iterations = settings_.cg_max_iterations;
  linear_.cg_diagonal().assign(dofs_.size(), shift);  // K + shift·I
  const PcgResult result = linear_.solve_cg(op_, s, t1, dofs_, sums_, rhs_, correction_, settings, M);
  if (use_amg_ && result.iterations > 0 && result.residual > 0.0 && result.residual < result.initial_residual) {
    // The rebuild rule (2) of quasi_static.hpp: iterations per tenfold reduction against the first
    // solve's after the set-up.
    const double rate = result.iterations / std::log10(result.initial_residual / result.residual);
    if (amg_rate_ == 0.0) amg_rate_ = rate;
    else if (rate > kAmgRebuildGrowth * amg_rate_) amg_.clear();
  }
  report_.force_evaluations += result.iterations + 1;  // a matvec costs about one force evaluation
  if (result.status == PcgResult::kNotConverged && !(result.residual < result.initial_residual)) {
    cg_failure_ = result.message();
    return false;
  }
  return true;
}

double QuasiStatic::residual_norm(const State& s) const {
  const auto& volume = op_.model().nodes.volume;
  // Σ r_k², exactly (over the ranks: parallel/dof_sums.hpp): the same bits for any thread and rank
  // count.
  terms_.resize(dofs_.size());
  for (std::size_t k = 0; k < dofs_.size(); ++k) {
    const auto i = static_cast<std::size_t>(dofs_.node[k]);
    const double r = volume[i] * s.f[dofs_.component[k]][i];
    terms_[k] = r * r;
  }
  for (std::size_t k = 0; k < skip_dof_.size(); ++k)
    if (skip_dof_[k]) terms_[k] = 0.0;  // a hanging or free node's (hanging_nodes.hpp)
  return std::sqrt(sums_.sum(terms_));
}

double QuasiStatic::load_scale(const State& s, double t) const {
  // The load the residual is measured against: the reactions at prescribed components plus the
  // body forces, as force vectors [N].
  const Model& m = op_.model();
  const Decomposed* d = op_.decomposed();
  // One exact sum of r² per condition, continuing the last (parallel/node_sum.hpp), as
  // ForceOperator's powers: the same bits serially and on any number of ranks.
  double sum = 0.0;
  for (const auto& p : m.conditions.prescribed) {
    const auto& fc = s.f[static_cast<std::size_t>(p.component)];
    sum = sum_over_set(d, p.nodes, sum, [&](std::size_t i) {
      const double r = m.nodes.volume[i] * fc[i];
      return r * r;
    });
  }
  for (const auto& b : m.conditions.body_forces) {
    const double value = b.table.value(t);
    sum = sum_over_set(d, b.nodes, sum, [&](std::size_t i) {
      const double r = m.nodes.volume[i] * value;
      return r * r;
    });
  }
  return std::sqrt(sum);
}

double QuasiStatic::shift_diagonal(SparseMatrix& K) const {
  double largest = 0.0;
  for (std::int64_t r = 0; r < K.rows; ++r)
    for (std::int64_t q = K.row_start[static_cast<std::size_t>(r)]; q < K.row_start[static_cast<std::size_t>(r) + 1]; ++q)
      if (K.column[static_cast<std::size_t>(q)] == r) largest = std::max(largest, std::fabs(K.value[static_cast<std::size_t>(q)]));
  for (std::int64_t r = 0; r < K.rows; ++r)
    for (std::int64_t q = K.row_start[static_cast<std::size_t>(r)]; q < K.row_start[static_cast<std::size_t>(r) + 1]; ++q)
      if (K.column[static_cast<std::size_t>(q)] == r) K.value[static_cast<std::size_t>(q)] += kDiagonalShift * largest;
  return kDiagonalShift * largest;
}

bool QuasiStatic::factorize_at(const State& s, double t1, bool definite, bool shifted) {
  FactorPoint at;
  at.t = t1, at.definite = definite, at.shifted = shifted;
  return linear_.factorize(op_, s, dofs_, at, "quasi_static", [&](SparseMatrix& K) {
    if (shifted) shift_diagonal(K);
  });
}

void QuasiStatic::limit(int max_breaking_rounds, double dt_min, bool fail_on_steady_breaking) {
  settings_.max_breaking_rounds = max_breaking_rounds;
  fail_on_steady_breaking_ = fail_on_steady_breaking;
  dt_min_ = std::min(dt_min, dt_max_);
}

std::vector<char> QuasiStatic::save_state() const {
  std::vector<char> bytes = Integrator::save_state();
  auto put = [&bytes](const auto& value) {
    const auto* p = reinterpret_cast<const char*>(&value);
    bytes.insert(bytes.end(), p, p + sizeof value);
  };
  const FactorPoint& at = linear_.factor_point();
  const std::uint8_t have = linear_.have_factor() ? 1 : 0, definite = at.definite ? 1 : 0, shifted = at.shifted ? 1 : 0;
  const int factorisations = linear_.factorisations();
  put(have), put(definite), put(shifted), put(at.t), put(factorisations);
  if (linear_.have_factor())
    for (const auto& component : linear_.factor_u())
      bytes.insert(bytes.end(), reinterpret_cast<const char*>(component.data()),
                   reinterpret_cast<const char*>(component.data() + component.size()));
  if (uses_amg()) {  // where the hierarchy was set up (nothing added without amg: old checkpoints read)
    const std::uint8_t have_amg = amg_.ready() ? 1 : 0;
    put(have_amg), put(amg_t_), put(amg_rate_);
    if (have_amg)
      for (const auto& component : amg_u_)
        bytes.insert(bytes.end(), reinterpret_cast<const char*>(component.data()),
                     reinterpret_cast<const char*>(component.data() + component.size()));
  }
  // Last: a checkpoint of a solver without them reads (carried_load_ = 0, started_cold_ = false).
  const std::uint8_t cold = started_cold_ ? 1 : 0;
  put(carried_load_), put(cold);
  put(bonds_taken_out_);  // after them: older checkpoints read with 0 (run.log's summary only)
  return bytes;
}

void QuasiStatic::load_state(const std::vector<char>& bytes) {
  constexpr std::size_t fixed_part = 3 + sizeof(double) + sizeof(int);
  if (bytes.size() < kReportBytes + fixed_part) throw std::runtime_error("integrator state of the wrong size");
  // The checkpoint's arrays are the whole model's: a factor and a hierarchy are made on one process,
  // and a decomposed run that resumes from one (keep_linear_solver could not keep it) drops them.
  const Decomposed* decomposed = op_.decomposed();
  const std::size_t n = decomposed ? static_cast<std::size_t>(decomposed->piece().global_nodes) : op_.size();
  const bool have = bytes[kReportBytes] != 0;
  const std::size_t extra = fixed_part + (have ? 3 * n * sizeof(double) : 0);
  load_report(std::vector<char>(bytes.begin(), bytes.begin() + static_cast<std::ptrdiff_t>(kReportBytes)), 0);
  constexpr std::size_t amg_part = 1 + 2 * sizeof(double);
  // Whether the bytes hold the hierarchy's part: the writer's solver, if the restart said it.
  const bool amg_saved = checkpoint_solver_.empty() ? uses_amg() : checkpoint_solver_ == "cg amg";
  const bool amg = uses_amg();
  const bool have_amg = amg_saved && bytes.size() > kReportBytes + extra && bytes[kReportBytes + extra] != 0;
  const std::size_t amg_extra = amg_saved ? amg_part + (have_amg ? 3 * n * sizeof(double) : 0) : 0;
  const std::size_t known = kReportBytes + extra + amg_extra;
  const std::size_t tail = sizeof(double) + 1, counted_out = sizeof(std::int64_t);
  if (bytes.size() != known && bytes.size() != known + tail && bytes.size() != known + tail + counted_out)
    throw std::runtime_error("integrator state of the wrong size");
  carried_load_ = 0.0;
  started_cold_ = false;
  bonds_taken_out_ = 0;
  if (bytes.size() > known) {
    std::memcpy(&carried_load_, bytes.data() + known, sizeof carried_load_);
    started_cold_ = bytes[known + sizeof(double)] != 0;
  }
  if (bytes.size() == known + tail + counted_out) std::memcpy(&bonds_taken_out_, bytes.data() + known + tail, counted_out);
  const char* at = bytes.data() + kReportBytes + 1;
  const bool definite = *at++ != 0, shifted = *at++ != 0;
  double t = 0.0;
  int factorisations = 0;
  std::memcpy(&t, at, sizeof t), at += sizeof t;
  std::memcpy(&factorisations, at, sizeof factorisations), at += sizeof factorisations;
  linear_.forget_factor();
  // The factorisation and the hierarchy were made with the hanging nodes' bonds masked, if there were
  // any: the same nodes now (a function of the broken flags, which have not changed since: breaking
  // forgets both), so the same masked K.
  broken_since_start_ = op_.any_broken();
  find_hanging();
  MaskedBonds masked(hanging_, op_.model().bonds, !skip_dof_.empty());
  if (have && linear_.uses_cg()) {
    at += 3 * n * sizeof(double);  // a factor, of no use to CG
  } else if (have) {
    State s(n);
    for (auto& component : s.u) std::memcpy(component.data(), at, n * sizeof(double)), at += n * sizeof(double);
    // Needs the bonds of the checkpoint (restored before load_state, run/start.cpp).
    if (!factorize_at(s, t, definite, shifted))
      throw std::runtime_error("the saved tangent could not be factorised again");
  }
  linear_.set_factorisations(factorisations);
  amg_.clear();
  if (amg_saved) {
    ++at;  // have_amg, read above
    double amg_t = 0.0, amg_rate = 0.0;
    std::memcpy(&amg_t, at, sizeof amg_t), at += sizeof amg_t;
    std::memcpy(&amg_rate, at, sizeof amg_rate), at += sizeof amg_rate;
    if (have_amg && amg) {
      State s(n);
      for (auto& component : s.u) std::memcpy(component.data(), at, n * sizeof(double)), at += n * sizeof(double);
      set_up_amg(s, amg_t);  // the same K, the same hierarchy (hypre's serial set-up is deterministic)
      amg_rate_ = amg_rate;
    }
  }
}

void QuasiStatic::find_hanging() {
  skip_dof_.clear();
  // Only a bond-based law: masking a bond of a state-based one (LPS) would change its neighbours'
  // dilatation, not only the hanging node's force. Before any bond has broken the lattice is whole
  // (and a node hanging from the start makes the first factorisation fail with its own message).
  if (!bond_based_ || !broken_since_start_) {
    hanging_ = HangingNodes{};
    return;
  }
  hanging_.find(op_.model(), op_.fixed(), op_.decomposed(), strands_);
  if (hanging_.count() == 0 && hanging_.free_count() == 0) return;
  skip_dof_.assign(dofs_.size(), 0);
  for (std::size_t q = 0; q < dofs_.size(); ++q) skip_dof_[q] = hanging_.left_out(static_cast<std::size_t>(dofs_.node[q])) ? 1 : 0;
}

// Newton with the hanging nodes' bonds and the free fragments left out, then the hanging nodes placed
// on their bonds' line and the force evaluated with every bond (hanging_nodes.hpp): what a caller and
// the next explicit step see. Without either: Newton alone, as before (the same operations, the same
// bits).
bool QuasiStatic::solve_equilibrium(State& s, double t1, const Vec3Array& u_start, int& iterations, double& omega) {
  find_hanging();
  // Nodes left hanging by the bonds taken out: the factor has no masks for them (it was made without
  // any); a new one is made with them masked.
  if (linear_.bonds_out().active() && !skip_dof_.empty()) linear_.forget_factor();
  if (skip_dof_.empty()) return newton(s, t1, u_start, iterations, omega);
  // A free fragment stays where the last state left it: not where the predictor would carry it (its
  // last mean velocity, extrapolated, would go on stretching it load step after load step).
  for (std::size_t q = 0; q < dofs_.size(); ++q) {
    const auto i = static_cast<std::size_t>(dofs_.node[q]);
    if (hanging_.free(i)) s.u[dofs_.component[q]][i] = u_start[dofs_.component[q]][i];
  }
  MaskedBonds masked(hanging_, op_.model().bonds, hanging_.count() > 0);
  const bool converged = newton(s, t1, u_start, iterations, omega);
  masked.release();
  if (!converged) return false;
  if (hanging_.count() == 0) return true;  // only free fragments: nothing was masked, s.f stands
  hanging_.place(op_.model(), s.u, op_.decomposed());
  op_.evaluate(s, t1);
  ++report_.force_evaluations;
  return true;
}

bool QuasiStatic::newton(State& s, double t1, const Vec3Array& u_start, int& iterations, double& omega) {
  double previous = HUGE_VAL;
  double eta = kEtaMax;  // the forcing term of the matrix-free path
  bool evaluated = false;  // s.f is already the force at s.u (the line search's accepted trial)
  const int max_iterations = iteration_cap_ > 0 ? std::min(iteration_cap_, settings_.max_iterations) : settings_.max_iterations;
  for (int k = 1; k <= max_iterations; ++k) {
    if (!evaluated) {
      op_.evaluate(s, t1);
      ++report_.force_evaluations;
    }
    evaluated = false;
    const double residual = residual_norm(s);
    if (!std::isfinite(residual)) return false;
    // The force scale of the residual test: the load now, but never less than the largest load an
    // accepted load step has carried. Once a crack has cut the body (or it is unloaded past its
    // peak) the reactions fall to ~0 while the unloaded pieces' residual sits at the round-off of
    // their stretches, which scales with the forces the bonds have carried, not with today's
    // reactions: residual_tol × the reactions is then out of reach, Newton ends only on stagnation
    // (4–8 iterations, measured on traction after the cut) and refactorises on the way. Peridigm's
    // quasi-static solver measures its residual against the reactions the same way and has an
    // absolute tolerance for when that fails (Peridigm.cpp, executeQuasiStatic: "Relative
    // Tolerance" × ‖reactions‖ or "Absolute Tolerance"); the largest load carried is that absolute
    // scale, taken from the run itself. While the load grows it is the load now: unchanged.
    const double load = force_scale(s, t1);
    // Equilibrium: the residual below its tolerance and the last correction below TOL. Or the
    // correction below TOL and the residual no longer falling: it is at the round-off floor of the
    // stretches (about 1e-16/strain of the load), and no further iteration changes u.
    if (k > 1 && omega <= settings_.tol && (residual <= settings_.residual_tol * load || residual >= 0.5 * previous))
      return true;
    // The separated pieces carried rigidly by their grips are unstrained: when that already meets the
    // residual test, it is the equilibrium, and no tangent is needed (carry_rigidly).
    if (k == 1 && !carried_.empty() && residual <= settings_.residual_tol * load) {
      accepted_carried_ = true;
      return omega = 0.0, true;
    }
    if (residual == 0.0) return omega = 0.0, true;  // nothing loads the body
    // A try with a cap on its tangents (try_once) is a guess that an equilibrium is near: an
    // iteration that takes the residual down by less than kStallRatio says Newton has stalled where
    // it is (measured: see kStallRatio), and more tangents only buy linear convergence there. Only
    // on what it was measured on: a direct factorisation made in this step with the bonds as they
    // are (not one from an earlier step, nor one with bonds taken out, whose slow convergence a new
    // tangent cures: the 4× rule below), and a residual still above its tolerance.
    if (factorisation_cap_ > 0 && !linear_.uses_cg() && linear_.have_factor() && !linear_.bonds_out().active() &&
        linear_.factorisations() > factorisations_at_step_ && std::isfinite(previous) &&
        residual > settings_.residual_tol * load && residual > stall_ratio_limit_ * previous) {
      stall_ratio_ = residual / previous;
      stalled_at_ = k - 1;  // the iteration whose correction gave this residual
      return false;
    }
    // Reuse the factorisation while it keeps the residual falling fast; else assemble anew (also
    // when only ω is above TOL: an old factor then reduces ω only linearly).
    if (!linear_.uses_cg() && (!linear_.have_factor() || residual > 0.25 * previous)) {
      // A tentative step that has used its factorisations fails here: Newton that needs yet another
      // tangent is still far from an equilibrium (try_once).
      if (factorisation_cap_ > 0 && linear_.factorisations() - factorisations_at_step_ >= factorisation_cap_) {
        factorisation_cap_hit_ = true;
        return false;
      }
      // Once bonds have broken, a node or a fragment may hang by nothing: its rows are zero and K
      // is singular although the residual does not drive it. A shift of the diagonal by
      // kDiagonalShift × its largest entry lets it be factorised; the residual, not K, decides
      // convergence, so the equilibrium found is unchanged (a modified Newton iteration).
      // From an explicit step's state (mixed's return) the first tangent is the definite variant at
      // once: the ringing state's compressed bonds make the full tangent indefinite (measured on
      // plate_with_hole and traction at dx × 2: the full one failed to factorise at every return),
      // and a failed factorisation costs as much as one that succeeds.
      const bool definite_now = definite_first_ && broken_since_start_;
      definite_first_ = false;
      bool factorised = !definite_now && factorize_at(s, t1, false, broken_since_start_);
      if (!factorised && broken_since_start_) {
        // Indefinite after damage (compressed bonds lose their stiffness across their line, a node
        // may hang by collinear bonds): the definite variant, shifted, still leads Newton to the
        // same equilibrium.
        factorised = factorize_at(s, t1, true, true);
      }
      if (!factorised) {
        linear_.forget_factor();
        if (!std::isfinite(previous) && !broken_since_start_) {  // nothing broken: the body is not held
          throw StepFailed("the tangent stiffness is singular or indefinite (" + linear_.factor().failure() +
                           "): the body can move freely or a part of it has come loose; quasi_static needs "
                           "displacement conditions that hold every body in every direction, or use "
                           "time.integrator: verlet");
        }
        return false;
      }
    }
    // K Δu = V f at the free components.
    const auto& volume = op_.model().nodes.volume;
    rhs_.resize(dofs_.size());
    for (std::size_t q = 0; q < dofs_.size(); ++q) {
      const auto i = static_cast<std::size_t>(dofs_.node[q]);
      rhs_[q] = volume[i] * s.f[dofs_.component[q]][i];
    }
    // A hanging node's force (its bonds masked: only a body force or contact, if any) is not solved
    // for: it is placed after the solve; nor a free fragment's (it carries no load: it stays).
    for (std::size_t q = 0; q < skip_dof_.size(); ++q)
      if (skip_dof_[q]) rhs_[q] = 0.0;
    if (linear_.uses_cg()) {
      // Eisenstat–Walker choice 2: η_k = γ (‖F_k‖/‖F_{k−1}‖)², γ = 0.9, kept ≥ γ η_{k−1}² when that is
      // above 0.1 (so that η does not fall too fast), ≤ kEtaMax; and no tighter than half the
      // equilibrium tolerance asks of this residual (Kelley 1995, eq. 6.20).
      if (std::isfinite(previous)) {
        const double ratio = residual / previous, safeguard = 0.9 * eta * eta;
        eta = 0.9 * ratio * ratio;
        if (safeguard > 0.1) eta = std::max(eta, safeguard);
        eta = std::min(eta, kEtaMax);
      }
      const double floor = 0.5 * settings_.residual_tol * load;
      if (!solve_krylov(s, t1, eta, floor)) return false;
    } else {
      linear_.solve(rhs_, correction_);  // with the bonds broken since the factorisation taken out
    }
    for (std::size_t q = 0; q < skip_dof_.size(); ++q)
      if (skip_dof_[q]) correction_[q] = 0.0;
    previous = residual;
    // Backtracking: the full step unless it raises the residual (then ½, ¼, … up to 1/32).
    double alpha = 1.0, step_norm = 0.0, motion = 0.0;
    trial_ = s;
    for (int halving = 0;; ++halving) {
      for (std::size_t q = 0; q < dofs_.size(); ++q) {
        const auto i = static_cast<std::size_t>(dofs_.node[q]);
        trial_.u[dofs_.component[q]][i] = s.u[dofs_.component[q]][i] + alpha * correction_[q];
      }
      if (halving == 5) break;
      op_.evaluate(trial_, t1);
      ++report_.force_evaluations;
      if (residual_norm(trial_) < residual) {
        evaluated = true;  // the next iteration's force is this one (the force is a function of u)
        break;
      }
      alpha *= 0.5;
    }
    // Σ Δu² and Σ (u − u_n)², exactly (over the ranks: parallel/dof_sums.hpp).
    terms_.resize(dofs_.size());
    motion_terms_.resize(dofs_.size());
    for (std::size_t q = 0; q < dofs_.size(); ++q) {
      const auto i = static_cast<std::size_t>(dofs_.node[q]);
      const double du = alpha * correction_[q], from_start = trial_.u[dofs_.component[q]][i] - u_start[dofs_.component[q]][i];
      terms_[q] = du * du;
      motion_terms_[q] = from_start * from_start;
    }
    for (std::size_t q = 0; q < skip_dof_.size(); ++q)
      if (skip_dof_[q]) terms_[q] = motion_terms_[q] = 0.0;  // placed after the solve, or staying: not in ω
    const std::vector<double> norms = sums_.sums({&terms_, &motion_terms_});
    step_norm = norms[0];
    motion = norms[1];
    // The whole state when trial_ was evaluated at the accepted u (its force, energy densities and
    // term energies), else only u: trial_ was copied from s, so nothing else differs.
    if (evaluated) std::swap(s, trial_);
    else std::swap(s.u, trial_.u);
    omega = motion > 0.0 ? std::sqrt(step_norm / motion) : 0.0;  // eq. 2.6 for Newton
    iterations = k;
    if (!std::isfinite(omega)) return false;
  }
  if (!evaluated) {
    op_.evaluate(s, t1);
    ++report_.force_evaluations;
  }
  return residual_norm(s) <= settings_.residual_tol * force_scale(s, t1) && omega <= settings_.tol;
}

void QuasiStatic::remember_solver() {
  linear_.remember_factor();
  at_start_.amg_ready = amg_.ready();
  at_start_.amg_t = amg_t_;
  at_start_.amg_rate = amg_rate_;
  at_start_.amg_setups = amg_setups_;
  at_start_.amg_u_saved = false;
}

// After a cut trial: the factorisation (and the hierarchy) the step started with, in use again, so
// that the redone step sees what a step asked for directly would. A factor the trial made is
// dropped (without one at the start, a direct step would factorise at its own first iterate). A
// hierarchy is set up again where it was: the bonds have not changed since (every breaking forgets
// it), so the same hanging nodes are masked and hypre's serial set-up gives the same one (as
// load_state).
void QuasiStatic::restore_solver() {
  const std::size_t n = op_.size();
  linear_.restore_factor();
  if (uses_amg() && (amg_setups_ != at_start_.amg_setups || amg_.ready() != at_start_.amg_ready)) {
    amg_.clear();
    if (at_start_.amg_ready) {
      find_hanging();
      MaskedBonds masked(hanging_, op_.model().bonds, hanging_.count() > 0);
      State s(n);
      s.u = at_start_.amg_u_saved ? at_start_.amg_u : amg_u_;
      set_up_amg(s, at_start_.amg_t);
    }
  }
  amg_rate_ = at_start_.amg_rate;
  at_start_.amg_setups = amg_setups_;  // the start's hierarchy is the one in use again
  at_start_.amg_u_saved = false;
}

// Each node whose piece is held by one group of prescribed motions alone (carried_) takes that
// motion's displacement at t1 in its free components, when every node the group prescribes in every
// component has the same one (a translation): the piece is then unstrained, which is its
// equilibrium when nothing else loads it. Newton checks: the residual test decides, and needs no
// factorisation when it passes. A group that prescribes only some components, or moves its nodes
// apart, carries nothing: its pieces keep the state they had. On a decomposed run the least and the
// largest displacement of a group are taken over the ranks, so every rank carries alike.
void QuasiStatic::carry_rigidly(State& s) const {
  const auto dim = static_cast<std::size_t>(op_.model().nodes.dimension);
  const auto& fixed = op_.fixed();
  const auto held_in_full = [&](std::size_t i) {
    for (std::size_t d = 0; d < dim; ++d)
      if (!fixed[d][i]) return false;
    return true;
  };
  // Per group and component (entry 3g + d), the least and the largest displacement of its nodes.
  const auto at = [](std::int32_t g, std::size_t d) { return 3 * static_cast<std::size_t>(g) + d; };
  std::vector<double> low(at(carried_groups_, 0), HUGE_VAL), high(low.size(), -HUGE_VAL);
  // Owned nodes only: a ghost's prescribed components are its owner's to advance (not yet at t1 here).
  const Decomposed* dec = op_.decomposed();
  for (std::size_t i = 0; i < s.size(); ++i) {
    const std::int32_t g = carried_[i];
    if (g < 0 || !held_in_full(i) || (dec && !dec->piece().owned[i])) continue;
    for (std::size_t d = 0; d < dim; ++d) {
      low[at(g, d)] = std::min(low[at(g, d)], s.u[d][i]);
      high[at(g, d)] = std::max(high[at(g, d)], s.u[d][i]);
    }
  }
  if (dec)
    for (std::size_t q = 0; q < low.size(); ++q) low[q] = dec->minimum(low[q]), high[q] = -dec->minimum(-high[q]);
  for (std::size_t i = 0; i < s.size(); ++i) {
    const std::int32_t g = carried_[i];
    if (g < 0) continue;
    bool translation = true;
    for (std::size_t d = 0; d < dim; ++d) translation = translation && low[at(g, d)] == high[at(g, d)];
    if (!translation) continue;  // no node held in full (±inf), or two that move apart
    for (std::size_t d = 0; d < dim; ++d)
      if (!fixed[d][i]) s.u[d][i] = low[at(g, d)];
  }
}

void QuasiStatic::step(State& state, double& t, double& dt) {
  report_ = StepReport{};
  failure_reason_.clear();
  iteration_cap_ = try_once_iterations_;  // this step only
  factorisation_cap_ = try_once_factorisations_;
  stalled_at_ = 0;
  try_once_iterations_ = try_once_factorisations_ = 0;
  factorisations_at_step_ = linear_.factorisations();
  // The carried pieces are for this step only; a step that fails and is halved redoes it from them.
  struct Drop {
    std::vector<std::int32_t>& carried;
    ~Drop() { carried.clear(); }
  } drop{carried_};
  report_.force_evaluations = 0;
  // From the bonds themselves, not a flag carried along: a restarted run (or a pre-cracked body)
  // shifts its tangent exactly as the uninterrupted run does.
  if (!broken_since_start_) broken_since_start_ = op_.any_broken();
  double h = std::min(dt, dt_max_);
  // The cut to the first bond failure (quasi_static.hpp): at most two per step, r0 from the start.
  // The solver at the start is kept for a cut trial only when a cut can happen in this step (see
  // its condition below): otherwise a new factorisation is made in place, on the symbolic analysis
  // already there (the spare would need one of its own: 0.27 s of plate_with_hole-mixed's 4.3 s
  // at dx × 2, in the step where the crack starts to grow).
  if (settings_.cut_to_first_failure && !broken_since_start_ && guess_from_velocity_) remember_solver();
  struct Off {  // the snapshot is for this step only, however it ends
    LinearSolve& linear;
    ~Off() { linear.end_remembering(); }
  } off{linear_};
  int cuts = 0;
  cut_to_ = 0.0;
  // Bonds broken by attempts that then failed: they stay broken (below), so the accepted step
  // reports them with its own (history.csv's broken bonds and their energy).
  BreakReport broken_by_failed_attempts;
  std::optional<StretchRatio> start_ratio;
  for (;;) {
    const double t1 = t + h;
    State s = state;
    op_.advance_prescribed_motion(state.u, s.u, s.v, t, t1, h, false);
    // The predictor (see quasi_static.hpp); v_n = 0 at the start. Not after a step that started from
    // an explicit step's state either: its mean velocity is the jump from the ringing state to the
    // equilibrium, not the rate of the load path, and extrapolating it puts the ringing back.
    if (guess_from_velocity_ && !started_cold_)
      for (std::size_t d = 0; d < 3; ++d)
        for (std::size_t i = 0; i < s.size(); ++i)
          if (!op_.fixed()[d][i]) s.u[d][i] = state.u[d][i] + h * state.v[d][i];
    accepted_carried_ = false;
    if (!carried_.empty()) carry_rigidly(s);
    int iterations = 0, total = 0, rounds = 0;
    std::int64_t last_broken = 0;  // bonds broken by the last breaking round
    definite_first_ = !guess_from_velocity_;
    double omega = 0.0;
    bool converged = true;
    BreakReport broke_total;
    double cut_to = 0.0;  // > 0: redo the step with this h (the cut)
    for (;;) {
      converged = solve_equilibrium(s, t1, state.u, iterations, omega);
      total += iterations;
      if (!converged) break;
      // Not from an explicit step's state: it is no equilibrium, so r is not linear in the load from it.
      // Only before any bond has broken (the first failure): once a crack grows, a load step cut to
      // its next bond left the traction quasi_static run (full resolution) in loads where Newton
      // found no equilibrium down to dt_min, where the uncut step had let the crack run through.
      if (settings_.cut_to_first_failure && !broken_since_start_ && rounds == 0 && cuts < 2 && guess_from_velocity_ &&
          h > dt_min_ * (1.0 + 1e-12))
        cut_to = cut_step(state, s, h, start_ratio);
      if (cut_to > 0.0) break;
      // The flags before the round, for taking its bonds out of the factor (only when there is one).
      const bool can_take_out = max_removed_columns_ > 0 && linear_.have_factor() && !linear_.uses_cg() && bond_based_ && !op_.decomposed() && skip_dof_.empty();
      if (can_take_out) broken_before_round_ = op_.model().bonds.broken;
      const BreakReport broke = op_.break_bonds(s);
      if (broke.broken == 0) break;
      linear_.end_remembering();  // no cut can follow (one needs no bond broken in the run)
      // Unstable crack growth, seen early (limit()): a re-solve that broke at least as many bonds
      // as the one before it. The energy released by the crack's advance at a fixed load is not
      // falling, so the rounds would not end (the plate's: 4, 4, 8 bonds; traction's: 4, 8, 12).
      const bool not_slowing = fail_on_steady_breaking_ && rounds > 0 && broke.broken >= last_broken;
      last_broken = broke.broken;
      broke_total += broke;
      // The tangent lost bonds: taken out of the factor, or a new factorisation at the re-solve.
      if (can_take_out) take_out_broken_bonds(broken_before_round_);
      else linear_.forget_factor();
      amg_.clear();          // and the hierarchy too (rule (1) of quasi_static.hpp)
      broken_since_start_ = true;
      if (++rounds >= settings_.max_breaking_rounds || not_slowing) {
        if (linear_.bonds_out().active()) linear_.forget_factor();  // the bonds taken out are this step's
        linear_.bonds_out().clear();
        failure_reason_ = "bonds kept breaking through " + std::to_string(rounds) + " re-solves at one load (" +
                          std::to_string(broke_total.broken) + " bonds" +
                          (not_slowing ? ", the last re-solve " + std::to_string(broke.broken) + ", no fewer than the one before" : "") +
                          "): unstable crack growth";
        throw StepFailed("bonds kept breaking at t = " + message_number(t1) + " s through " + std::to_string(rounds) +
                         " re-solves at the same load (" + std::to_string(broke_total.broken) +
                         " bonds): the crack grows unstably, which a quasi-static solve cannot follow; use "
                         "time.integrator: mixed (explicit steps while the crack runs) or verlet, or raise "
                         "quasi_static.max_breaking_rounds");
      }
    }
    if (converged && cut_to > 0.0) {
      // Nothing was broken in the trial; its factorisation (or hierarchy), if it made one, is put back.
      restore_solver();
      ++cuts, ++cuts_;
      h = cut_to_ = cut_to;
      continue;
    }
    if (converged) {
      // Accepted: the mean velocity over the load step, the force and the work at t1.
      for (std::size_t d = 0; d < 3; ++d)
        for (std::size_t i = 0; i < s.size(); ++i)
          if (!op_.fixed()[d][i]) s.v[d][i] = (s.u[d][i] - state.u[d][i]) / h;
      // s.f is already the force at the equilibrium with these bonds: solve_equilibrium returns true
      // only just after evaluating it, and a breaking round that broke nothing changed no bond.
      op_.update_work(s, t1, h);
      if (linear_.bonds_out().active()) linear_.forget_factor();  // for one step only (see .hpp)
      carried_load_ = std::max(carried_load_, load_scale(s, t1));
      started_cold_ = !guess_from_velocity_;
      state = std::move(s);
      report_.iterations = std::max(total, 1);
      BreakReport broken_in_step = broken_by_failed_attempts;
      broken_in_step += broke_total;
      report_.broken_now = broken_in_step.broken;
      report_.broken_energy_now = broken_in_step.energy;
      t = t1;
      dt = h;
      double next = std::min(zohdi_step_factor(settings_.tol, omega, std::max(iterations, 1), settings_.kd, settings_.p), 2.0) * h;
      if (broke_total.broken > 0) next = std::min(next, h);  // a crack grows: no longer steps
      report_.next_dt = std::max(std::min(next, dt_max_), dt_min_);
      return;
    }
    // Not converged (or lost a factorisation to a failed pivot): redo the step from t, halved. The
    // bonds broken on the way stay broken (breaking is irreversible, as in the explicit scheme).
    broken_by_failed_attempts += broke_total;
    linear_.forget_factor();
    if (iteration_cap_ > 0) {
      const std::string spent =
          stalled_at_ > 0 ? counted(linear_.factorisations() - factorisations_at_step_, "factorisation") + " of the tangent: Newton "
                            "iteration " + std::to_string(stalled_at_) + " of its solve took the residual down only ×" +
                            message_number(stall_ratio_) + ", a stall"
          : factorisation_cap_hit_ ? std::to_string(factorisation_cap_) + " factorisations of the tangent and " +
                                         std::to_string(total) + " Newton iterations"
                                   : std::to_string(iteration_cap_) + " Newton iterations";
      factorisation_cap_hit_ = false;
      stalled_at_ = 0;
      failure_reason_ = "the tentative load step reached no equilibrium in " + spent + " (last correction ω = " +
                        message_number(omega) + ")";
      throw StepFailed("the tentative quasi-static load step at t = " + message_number(t1) + " s reached no equilibrium in " +
                       spent);
    }
    if (h <= dt_min_ * (1.0 + 1e-12)) {
      failure_reason_ = "no equilibrium at the smallest load step " + message_number(dt_min_) + " s (last correction ω = " +
                        message_number(omega) + ")";
      throw StepFailed("the quasi-static load step did not reach equilibrium at dt_min = " + message_number(dt_min_) +
                       " s (t = " + message_number(t) + " s, " + std::to_string(report_.rejected + 1) +
                       " attempts, last correction ω = " + message_number(omega) + "); the load may exceed what the "
                       "body can carry (unstable fracture or buckling): use time.integrator: mixed (explicit steps "
                       "where no equilibrium is found, load steps again once the motion has settled) or verlet, or "
                       "raise quasi_static.max_iterations");
    }
    ++report_.rejected;
    h = std::max(0.5 * h, dt_min_);
  }
}

double QuasiStatic::cut_step(State& start, State& end, double h, std::optional<StretchRatio>& start_ratio) {
  const StretchRatio r1 = op_.stretch_ratio(end);
  if (r1.over == 0 || !(r1.largest > 1.0 + kCutMargin)) return 0.0;  // no bond over, or within the margin
  if (!start_ratio) start_ratio = op_.stretch_ratio(start);
  const StretchRatio& r0 = *start_ratio;
  // Only from a start with no bond over (else bonds are breaking anyway: the current behaviour).
  if (r0.over > 0 || !(r0.largest < 1.0) || !(r1.largest > r0.largest)) return 0.0;
  const double target = r0.largest < 1.0 - kCutMargin ? 1.0 - 0.5 * kCutMargin : 1.0 + 0.5 * kCutMargin;
  // r linear in the load between the start and this equilibrium (quasi_static.hpp).
  const double cut = std::max(h * ((target - r0.largest) / (r1.largest - r0.largest)), dt_min_);
  return cut < h ? cut : 0.0;
}

void QuasiStatic::take_out_broken_bonds(const std::vector<std::uint8_t>& broken_before) {
  const auto start = std::chrono::steady_clock::now();
  // On any failure the factor is dropped (a new factorisation at the re-solve, as without this), so
  // the blocks are added in place.
  Woodbury& bonds_out = linear_.bonds_out();
  const std::int64_t bonds = add_broken_bonds(op_.model(), broken_before, linear_.factor_u(), linear_.factor_point().definite,
                                              dofs_, bonds_out);
  // W is dofs × columns doubles: at most kMaxRemovedBytes of it, whatever the cap in columns.
  const auto byte_cap = static_cast<int>(std::min<std::size_t>(kMaxRemovedBytes / (sizeof(double) * std::max<std::size_t>(dofs_.size(), 1)),
                                                                static_cast<std::size_t>(max_removed_columns_)));
  const bool fits = bonds >= 0 && bonds_out.columns() <= byte_cap && bonds_out.update(linear_.factor(), dofs_.size());
  if (fits) {
    bonds_taken_out_ += bonds;
  } else {
    linear_.forget_factor();
  }
  bonds_out_seconds_ += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

std::string QuasiStatic::linear_algebra_summary() const {
  char buffer[160];
  std::snprintf(buffer, sizeof buffer, "%d factorisations in %.3f s, %lld solves in %.3f s",
                linear_.factorisations(), linear_.factorise_seconds(), static_cast<long long>(linear_.solves()),
                linear_.solve_seconds());
  std::string cut_text;
  if (!linear_.uses_cg() && analyses() > 0) {
    char analyses_text[96];
    std::snprintf(analyses_text, sizeof analyses_text, ", %d symbolic %s in %.3f s", analyses(),
                  analyses() == 1 ? "analysis" : "analyses", analysis_seconds());
    cut_text = analyses_text;
  }
  if (cuts_ > 0) cut_text += ", " + std::to_string(cuts_) + " load steps cut to the first bond failure";
  if (bonds_taken_out_ > 0) {
    char out_text[112];
    std::snprintf(out_text, sizeof out_text, ", %lld broken bonds taken out of the factorisation in %.3f s",
                  static_cast<long long>(bonds_taken_out_), bonds_out_seconds_);
    cut_text += out_text;
  }
  if (!linear_.uses_cg()) return buffer + cut_text;
  // On the matrix-free path every CG iteration is one J·x product, about one force evaluation.
  std::string text = std::string(buffer) + ", " + std::to_string(linear_.cg_solves()) + " CG solves with " +
                     std::to_string(linear_.cg_iterations()) + " iterations (J·x products)";
  if (use_amg_) {
    std::snprintf(buffer, sizeof buffer, ", %d AMG set-ups in %.3f s (last: %d levels, operator complexity %.2f)",
                  amg_setups_, amg_seconds_, amg_.levels(), amg_.operator_complexity());
    text += buffer;
  }
  return text + cut_text;
}

std::vector<std::string> QuasiStatic::describe(double) const {
  return {"quasi_static: Newton with line search to residual " + message_number(settings_.residual_tol) +
          " × the load and correction TOL " + message_number(settings_.tol) + ", Kd " + std::to_string(settings_.kd) + ", p " +
          message_number(settings_.p) +
          (linear_.uses_cg() ? std::string("; linear solves by matrix-free CG with ") +
                         (use_amg_ ? "algebraic multigrid (hypre BoomerAMG, one V-cycle)" : "block-Jacobi") +
                         ", Eisenstat-Walker forcing (cg, "
                   : std::string("; tangent factorised by CHOLMOD (direct, ")) +
          linear_.reason() + ")" + (linear_.uses_cg() ? "; preconditioner " + preconditioner_reason_ : std::string()) + "; load steps dt_initial " + message_number(dt_initial_.value_or(0.0)) + " s, dt_min " + message_number(dt_min_) +
          " s, dt_max " + message_number(dt_max_) + " s" +
          (settings_.cut_to_first_failure ? "; a load step past the first bond failure is cut back to it" : "") +
          (bond_based_ ? "; once bonds have broken, nodes hanging by bonds on one line and one side are left out of "
                         "each solve and placed on their bonds' line after it, and free fragments stay where they are"
                       : std::string())};
}

}  // namespace pd
