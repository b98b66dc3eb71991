// The time loop of pdsolve: read → build → loop → write (pipeline/formats.md §3–4).
#include "run.hpp"

#include <omp.h>
#include <unistd.h>

#include <csignal>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <iostream>
#include <limits>
#include <sstream>

#include "core/error.hpp"
#include "core/reactions.hpp"
#include "core/work_plan.hpp"
#include "forces/indenter.hpp"
#include "operator/force_operator.hpp"
#include "core/stability.hpp"
#include "integrators/adaptive.hpp"
#include "integrators/integrator.hpp"
#include "io/case_reader.hpp"
#include "io/checkpoint.hpp"
#include "io/node_file.hpp"
#include "io/output.hpp"

namespace pd {

namespace {

using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }

std::string format(const char* fmt, double value) {
  char buffer[64];
  std::snprintf(buffer, sizeof buffer, fmt, value);
  return buffer;
}

// The first node (lowest index) with a non-finite displacement or velocity, or −1.
std::int64_t first_non_finite(const State& s) {
  const auto n = static_cast<std::int64_t>(s.size());
  std::int64_t first = n;
#pragma omp parallel for schedule(static) reduction(min : first)
  for (std::int64_t i = 0; i < n; ++i) {
    bool ok = true;
    for (std::size_t d = 0; d < 3; ++d)
      ok = ok && std::isfinite(s.u[d][static_cast<std::size_t>(i)]) && std::isfinite(s.v[d][static_cast<std::size_t>(i)]);
    if (!ok) first = std::min(first, i);
  }
  return first == n ? -1 : first;
}

// "node 12 at (0.001, 0.002, 0) m": where something happened, for messages.
std::string node_text(const Model& m, std::int64_t node) {
  const auto i = static_cast<std::size_t>(node);
  char buffer[160];
  std::snprintf(buffer, sizeof buffer, "node %lld at (%.6g, %.6g, %.6g) m", static_cast<long long>(node),
                m.nodes.x[0][i], m.nodes.x[1][i], m.nodes.x[2][i]);
  return buffer;
}

// The node with the largest finite speed (lowest index on ties): where an instability that grows
// geometrically has grown longest, i.e. most likely where it started.
std::int64_t fastest_node(const State& s) {
  std::int64_t best = 0;
  double best_speed = -1.0;
  for (std::size_t i = 0; i < s.size(); ++i) {
    const double speed = s.v[0][i] * s.v[0][i] + s.v[1][i] * s.v[1][i] + s.v[2][i] * s.v[2][i];
    if (std::isfinite(speed) && speed > best_speed) best_speed = speed, best = static_cast<std::int64_t>(i);
  }
  return best;
}

// SIGINT / SIGTERM: the handler only records the signal; the time loop checks it after each step,
// writes a checkpoint and stops. The handler then restores the default action of both signals it
// handles, so a second SIGINT or SIGTERM kills at once. std::atomic, not volatile sig_atomic_t:
// the signal may arrive on an OpenMP worker thread while the main thread reads the flag.
std::atomic<int> g_signal{0};
static_assert(std::atomic<int>::is_always_lock_free, "a signal handler may only touch lock-free atomics");
std::atomic<bool> g_handles_int{false}, g_handles_term{false};
extern "C" void record_signal(int signal) {
  g_signal.store(signal);
  if (g_handles_int.load()) std::signal(SIGINT, SIG_DFL);  // signal() is async-signal-safe (POSIX)
  if (g_handles_term.load()) std::signal(SIGTERM, SIG_DFL);
}

class SignalGuard {
 public:
  SignalGuard() {
    g_signal = 0;
    struct sigaction action {};
    action.sa_handler = record_signal;
    sigemptyset(&action.sa_mask);
    action.sa_flags = SA_RESETHAND | SA_RESTART;
    sigaction(SIGINT, &action, &old_int_);
    sigaction(SIGTERM, &action, &old_term_);
    // A signal the caller ignores (SIGINT of a background job of a script, nohup) stays ignored.
    if (old_int_.sa_handler == SIG_IGN) sigaction(SIGINT, &old_int_, nullptr);
    if (old_term_.sa_handler == SIG_IGN) sigaction(SIGTERM, &old_term_, nullptr);
    g_handles_int = old_int_.sa_handler != SIG_IGN;
    g_handles_term = old_term_.sa_handler != SIG_IGN;
  }
  ~SignalGuard() {
    g_handles_int = false;
    g_handles_term = false;
    sigaction(SIGINT, &old_int_, nullptr);
    sigaction(SIGTERM, &old_term_, nullptr);
  }
  SignalGuard(const SignalGuard&) = delete;
  SignalGuard& operator=(const SignalGuard&) = delete;

 private:
  struct sigaction old_int_ {}, old_term_ {};
};

const char* signal_name(int signal) { return signal == SIGINT ? "SIGINT" : signal == SIGTERM ? "SIGTERM" : "a signal"; }

std::string duration_text(double seconds) {
  if (!std::isfinite(seconds) || seconds < 0) return "?";
  char buffer[32];
  const auto s = static_cast<long long>(seconds + 0.5);
  if (s >= 3600) std::snprintf(buffer, sizeof buffer, "%lldh%02lldm", s / 3600, (s / 60) % 60);
  else if (s >= 60) std::snprintf(buffer, sizeof buffer, "%lldm%02llds", s / 60, s % 60);
  else std::snprintf(buffer, sizeof buffer, "%llds", s);
  return buffer;
}

}  // namespace

int run(const RunOptions& opt) {
  const SignalGuard signals;  // from the start: a signal while reading is seen after the first step
  // ---- read and build: every input error is thrown here, before any output exists
  Case c = read_case(opt.case_file);
  if (opt.end_time) c.time.end = *opt.end_time;
  if (opt.threads > 0) omp_set_num_threads(opt.threads);
  const int threads = omp_get_max_threads();
  Nodes nodes = read_node_file(c.nodes_file);
  for (const auto& name : c.node_sets)
    if (!nodes.find_set(name))
      throw Error(c.file.string() + ": node_sets: '" + name + "' has no array 'set_" + name + "' in " +
                  c.nodes_file.string());
  const auto build_start = Clock::now();
  Model model = build_model(c, std::move(nodes));
  const double build_seconds = seconds_since(build_start);
  const std::size_t n = model.nodes.size();
  // A material whose constants come out unusable (overflow of c for extreme E, δ or thickness).
  for (std::size_t b = 0; b < model.material.block.size(); ++b) {
    const auto& k = model.material.block[b];
    if (!std::isfinite(k.micromodulus) || !(k.micromodulus > 0.0) || !(k.critical_stretch > 0.0))
      throw Error(c.file.string() + ": blocks[" + std::to_string(b) + "] '" + c.blocks[b].name +
                  "': the material gives micromodulus c = " + format("%.6g", k.micromodulus) +
                  " and critical stretch s0 = " + format("%.6g", k.critical_stretch) +
                  " (need finite c > 0 and s0 > 0): check density, youngs_modulus, fracture_energy, horizon and thickness");
  }

  const double dt_stable = stable_time_step(model);
  double dt = 0.0, dt_exact = 0.0;  // dt_exact: computed for time.dt "exact", a failed run, or indenters above eq. 2.5
  if (c.time.dt_rule == "stable") {
    if (!std::isfinite(dt_stable))
      throw Error(c.file.string() + ": time.dt: \"stable\" needs bonds, but no node has a partner within the horizon " +
                  format("%.6g", c.horizon) + " m");
    dt = dt_stable * c.time.safety_factor;
  } else if (c.time.dt_rule == "exact") {
    // The largest eigenvalue of the linearised operator (core/stability): the true linear limit.
    dt_exact = exact_time_step(model);
    if (!std::isfinite(dt_exact))
      throw Error(c.file.string() + ": time.dt: \"exact\" needs bonds, but no node has a partner within the horizon " +
                  format("%.6g", c.horizon) + " m");
    dt = dt_exact * c.time.safety_factor;
  } else {
    dt = c.time.dt_value;
  }
  // The adaptive step starts from adaptive.dt_initial when given, else from the time.dt rule.
  if (c.time.integrator == "adaptive" && c.adaptive.dt_initial) dt = *c.adaptive.dt_initial;
  std::int64_t max_steps = c.time.max_steps;
  if (opt.max_steps) max_steps = std::min(max_steps, *opt.max_steps);
  const double end = c.time.end;
  // A remainder below this fraction of dt is absorbed into the last step rather than taken alone.
  constexpr double kLastStepSlack = 1e-6;
  const auto steps_for_end = static_cast<std::int64_t>(std::ceil(end / dt * (1.0 - kLastStepSlack)));
  const std::int64_t steps_expected = std::min(steps_for_end, max_steps);
  ForceOperator op(model);
  std::unique_ptr<Integrator> integrator = integrator_registry().get(c.time.integrator)(op);
  integrator->configure(c, dt_exact);

  State state(n);
  double t = 0.0;
  const bool restarting = !opt.restart.empty();
  Checkpoint ck;
  const std::uint64_t case_hash = file_hash(opt.case_file), nodes_hash = file_hash(c.nodes_file);
  // Every refusal of a checkpoint says how to start over instead (the Makefile resumes whenever
  // checkpoint.bin is newer than the case, so a refused one would otherwise block every `make`).
  const auto start_over = [&](const std::exception& e) {
    return Error(std::string(e.what()) + "; to start the run over instead, delete " + opt.restart.string());
  };
  if (restarting) {
    try {
      ck = read_checkpoint(opt.restart);
      const std::string where = opt.restart.string() + ": ";
      if (ck.case_hash != case_hash)
        throw Error(where + "the checkpoint belongs to another case file (or " + opt.case_file.string() +
                    " changed since it was written); restart with the case.json it was written for");
      if (ck.nodes_hash != nodes_hash)
        throw Error(where + "the checkpoint belongs to another node file (or " + c.nodes_file.string() +
                    " changed since it was written)");
      if (ck.nodes != n || ck.directed_bonds != model.bonds.directed() || ck.broken_flags.size() != model.bonds.directed() ||
          ck.integrator != integrator->name() ||
          (model.contact.pairs && ck.contact_rebuilds > 0 && ck.contact_u_build[0].size() != n))
        throw Error(where + "the checkpoint does not fit this model (" + std::to_string(ck.nodes) + " nodes, " +
                    std::to_string(ck.directed_bonds / 2) + " bonds, integrator " + ck.integrator + "; here " +
                    std::to_string(n) + ", " + std::to_string(model.bonds.directed() / 2) + ", " + integrator->name() + ")");
      if (ck.frame_times.empty()) throw Error(where + "the checkpoint lists no frame; cannot restart");
      // initialize() sizes the integrator's scratch; then everything it set is replaced by the
      // checkpoint, so the run continues bitwise as if it had never stopped.
      t = ck.time;
      integrator->initialize(state, t);
      state = std::move(ck.state);  // moved: a restarted run holds one copy of the state
      model.bonds.broken = std::move(ck.broken_flags);
      if (model.contact.pairs)
        model.contact_list.restore(model.nodes.x, ck.contact_u_build, model.block_index, model.contact,
                                   ck.contact_rebuilds, ck.contact_seconds);
      try {
        integrator->load_state(ck.integrator_state);
      } catch (const std::exception& e) {
        throw Error(where + e.what());
      }
    } catch (const Error& e) {
      throw start_over(e);
    }
    dt = ck.dt;
  } else {
    apply_initial_conditions(c, model.nodes, state.u, state.v);
    integrator->initialize(state, t);
  }
  if (first_non_finite(state) >= 0)
    throw Error((restarting ? opt.restart.string() + ": the checkpoint's state" : c.file.string() + ": the initial state") +
                " is not finite");
  // Nodes without a bond move freely: only loads and contact act on them (preprocess warns too,
  // but the solver may be run alone).
  std::int64_t isolated = 0, first_isolated = -1;
  for (std::size_t i = 0; i < n; ++i)
    if (model.bonds.offsets[i + 1] == model.bonds.offsets[i] && isolated++ == 0) first_isolated = static_cast<std::int64_t>(i);

  // ---- output starts here
  // The scene's own history columns (formats.md §4): only when it has contact or indenters.
  std::vector<std::string> extra_columns;
  if (model.contact.pairs || !model.indenters.empty()) extra_columns.push_back("contact_energy");
  if (model.contact.pairs) extra_columns.push_back("contact_rebuilds");
  for (const auto& ind : model.indenters)
    for (const char* axis : {"fx", "fy", "fz"}) extra_columns.push_back("indenter_" + ind.name + "_" + axis);
  // Energy of broken bonds (validation.md C4 with breaking): when some block pair can break.
  const bool breakable = op.can_break();
  if (breakable) extra_columns.push_back("broken_bond_energy");
  for (const auto& set : c.output.reactions)
    for (const char* axis : {"fx", "fy", "fz"}) extra_columns.push_back("reaction_" + set + "_" + axis);
  OutputResume resume{ck.frame_times, ck.history_bytes};
  const auto open_output = [&]() {
    try {
      return OutputWriter(c.output_dir, extra_columns, restarting ? &resume : nullptr);
    } catch (const Error& e) {  // on a restart: history.csv shorter than recorded, a frame missing
      if (!restarting) throw;
      throw start_over(e);
    }
  };
  OutputWriter out = open_output();
  const std::filesystem::path checkpoint_file = (c.output_dir / "checkpoint.bin").lexically_normal();
  // A checkpoint of an earlier run would not match the frames this run writes.
  if (!restarting) std::filesystem::remove(checkpoint_file);
  RunLog log(c.output_dir / "run.log", opt.quiet, restarting);
  log.line("pdsolve " PD_VERSION ": case " + (c.name.empty() ? opt.case_file.string() : c.name) + " (" +
           opt.case_file.string() + ")");
  if (restarting)
    log.line("restart from " + opt.restart.string() + ": step " + std::to_string(ck.step) + ", t = " +
             format("%.6g", ck.time) + " s, " + std::to_string(ck.frame_times.size()) + " frames kept (frames after it, history.csv rows after it: dropped)");
  log.line("nodes " + std::to_string(n) + ", bonds " + std::to_string(model.bonds.directed() / 2) + " (" +
           format("%.1f", static_cast<double>(model.bonds.directed()) / static_cast<double>(n)) +
           " per node), built in " + format("%.3f", build_seconds) + " s");
  log.line("analysis " + c.analysis + ", horizon " + format("%.6g", c.horizon) + " m = " +
           format("%.4g", c.horizon / c.grid_spacing) + " dx");
  for (std::size_t b = 0; b < model.material.block.size(); ++b)
    log.line("block " + std::to_string(b + 1) + " '" + c.blocks[b].name + "': c " +
             format("%.6g", model.material.block[b].micromodulus) + ", s0 " +
             (std::isinf(model.material.block[b].critical_stretch) ? std::string("none (unbreakable)")
                                                                   : format("%.6g", model.material.block[b].critical_stretch)));
  log.line("dt " + format("%.6g", dt) + " s (" +
           (c.time.dt_rule == "stable" ? "stable " + format("%.6g", dt_stable) + " s × safety factor " + format("%g", c.time.safety_factor)
            : c.time.dt_rule == "exact" ? "exact limit " + format("%.6g", dt_exact) + " s = " + format("%.4g", dt_exact / dt_stable) +
                                              " × eq. 2.5, × safety factor " + format("%g", c.time.safety_factor)
                                        : "fixed; stable " + format("%.6g", dt_stable) + " s") +
           (c.time.integrator == "adaptive" ? ", the initial step" : "") +
           "), integrator " + integrator->name() + ", damping " + format("%g", c.damping) + " 1/s");
  if (isolated > 0)
    log.line("warning: " + std::to_string(isolated) + " of " + std::to_string(n) +
             " nodes have no bond within the horizon (isolated: only loads and contact act on them); the first is " +
             node_text(model, first_isolated));
  if (c.time.dt_rule == "fixed" && dt > dt_stable)
    log.line("warning: dt exceeds the stable time step of thesis eq. 2.5; the run may blow up");
  for (const auto& text : work_summary(op, c)) log.line(text);
  // A fixed explicit step has no room for the indenter's stiffness 2K·h, which grows with depth:
  // say how deep it may go, and (in the loop) warn once if a node gets deeper (forces/indenter.hpp).
  // A step above eq. 2.5 (dt: exact, or a fixed dt) is judged against the exact limit, computed
  // here for a fixed dt (once, about as costly as tens of force evaluations).
  const bool indenter_watch = !model.indenters.empty() && integrator->name() == "verlet";
  double omega2_exact = 0.0;
  if (indenter_watch && dt > dt_stable) {
    if (!(dt_exact > 0.0)) dt_exact = exact_time_step(model);
    if (dt_exact > 0.0 && std::isfinite(dt_exact)) omega2_exact = 4.0 / (dt_exact * dt_exact);
  }
  if (indenter_watch)
    for (const auto& ind : model.indenters)
      log.line("indenter '" + ind.name + "': dt stays stable while no node is deeper than " +
               format("%.4g", indenter_stable_depth(model, ind, dt, omega2_exact)) + " m (its stiffness 2K·h with " +
               (omega2_exact > 0.0 ? "the exact limit" : "eq. 2.5") + "; a bound, the step may hold deeper)");
  if (const auto* adaptive = dynamic_cast<const AdaptiveStep*>(integrator.get()))
    log.line("adaptive (thesis §2.2): TOL " + format("%g", adaptive->settings().tol) + ", Kd " +
             std::to_string(adaptive->settings().kd) + ", p " + format("%g", adaptive->settings().p) + ", phi " +
             format("%g", adaptive->settings().phi) + ", dt_min " + format("%.6g", adaptive->dt_min()) + " s, dt_max " +
             format("%.6g", adaptive->dt_max()) + " s" +
             (adaptive->settings().dt_max ? std::string()
              : dt_exact > 0.0
                  ? std::string(" (default: eq. 2.5 or 0.9 × the contraction limit, from the exact limit above)")
                  : " (default: eq. 2.5 or 0.9 × the contraction limit, eigenvalue estimate " +
                        format("%.3f", adaptive->limit_seconds()) + " s)"));
  log.line("end time " + format("%.6g", end) + " s, steps expected " + std::to_string(steps_expected) +
           (steps_for_end > max_steps ? " (capped by max_steps)" : "") + ", threads " + std::to_string(threads));

  // From here on output files exist: an error (a full disk, a failed rename) is a failed run, not
  // bad input (exit 3, --help), and it goes to run.log too; the frames written so far stay valid.
  try {
    const auto loop_start = Clock::now();
    const double wall_before = restarting ? ck.wall_time : 0.0;  // time loop of the run(s) before a restart
    std::int64_t step = 0, broken = broken_bond_count(model), last_frame_step = -1;
    double broken_energy = 0.0;  // Σ energy of bonds at the moment they broke [J]
    // Kinetic and strain energy of the current state, computed once per step: the blow-up watch
    // needs them every step and a history row of the same step reuses them.
    std::int64_t energies_step = -1;
    double kinetic = 0.0, strain = 0.0;
    auto update_energies = [&]() {
      if (energies_step == step) return;
      kinetic = op.kinetic_energy(state);
      strain = op.strain_energy(state);
      energies_step = step;
    };
    auto history_row = [&](double dt_taken) {
      update_energies();
      HistoryRow r;
      r.step = step;
      r.time = t;
      r.dt = dt_taken;
      r.iterations = step == 0 ? 0 : integrator->last_step().iterations;
      r.rejected = step == 0 ? 0 : integrator->last_step().rejected;
      r.kinetic_energy = kinetic;
      r.strain_energy = strain;
      r.external_work = state.external_work;
      r.damping_work = state.damping_work;
      r.broken_bonds = broken;
      r.wall_time = wall_before + seconds_since(loop_start);
      if (model.contact.pairs || !model.indenters.empty()) r.extra.push_back(state.contact_energy);
      if (model.contact.pairs) r.extra.push_back(static_cast<double>(model.contact_list.rebuilds()));
      for (std::size_t k = 0; k < model.indenters.size(); ++k)
        for (std::size_t d = 0; d < 3; ++d)  // the reaction on the indenter: minus its force on the body
          r.extra.push_back(k < state.indenter_force.size() ? -state.indenter_force[k][d] : 0.0);
      if (breakable) r.extra.push_back(broken_energy);
      for (const auto& set : c.output.reactions)
        for (double component : reaction_force(model, state, set, t)) r.extra.push_back(component);
      out.history(r);
    };
    std::int64_t next_frame_index = 1;  // every_time: frame k at t ≥ k·every_time
    // Wall time spent writing frames and history rows, reported in run.log: the share of the run
    // that output costs, measured by the run itself (issue 6 asks for under 5 %).
    double output_seconds = 0.0;
    auto frame = [&](double dt_taken) {
      out.frame(model, state, t, step);
      history_row(dt_taken);
      last_frame_step = step;
      if (c.output.every_time) next_frame_index = static_cast<std::int64_t>(std::floor(t / *c.output.every_time * (1.0 + 1e-12))) + 1;
    };
    std::int64_t next_restart_index = 1;  // restart_every_time: checkpoint k at t ≥ k·restart_every_time
    if (!restarting) {
      const auto output_start = Clock::now();
      frame(0.0);
      output_seconds += seconds_since(output_start);
    }

    const bool progress = !opt.quiet && isatty(fileno(stderr));
    auto last_progress = Clock::now();
    int status = kOk;
    bool state_valid = true;  // false after a blow-up: that state is never written
    double dt_taken = 0.0;
    std::int64_t force_evaluations = 0;
    // Blow-up watch: an explicit step above its limit makes the energy grow geometrically (×47 per
    // step at 1.5× the limit); physical loading does not keep up ×1.5 per step for 20 steps.
    constexpr double kGrowthPerStep = 1.5;
    constexpr int kGrowthSteps = 20;
    bool indenter_warned = false;
    double energy_before = -1.0, energy_streak_start = 0.0;
    int growth_streak = 0;
    if (restarting) {
      step = ck.step;
      dt_taken = ck.dt_taken;
      last_frame_step = ck.last_frame_step;
      next_frame_index = ck.next_frame_index;
      next_restart_index = ck.next_restart_index;
      broken = ck.broken;
      force_evaluations = ck.force_evaluations;
      broken_energy = ck.broken_energy;
      energy_before = ck.energy_before;
      energy_streak_start = ck.energy_streak_start;
      growth_streak = static_cast<int>(ck.growth_streak);
    }
    // Everything the loop carries from step to step, to checkpoint.bin (written atomically).
    auto write_restart = [&]() {
      out.flush_history();
      Checkpoint k;
      k.case_hash = case_hash;
      k.nodes_hash = nodes_hash;
      k.nodes = n;
      k.directed_bonds = model.bonds.directed();
      k.integrator = integrator->name();
      k.step = step;
      k.time = t;
      k.dt = dt;
      k.dt_taken = dt_taken;
      k.last_frame_step = last_frame_step;
      k.next_frame_index = next_frame_index;
      k.next_restart_index = next_restart_index;
      k.broken = broken;
      k.force_evaluations = force_evaluations;
      k.broken_energy = broken_energy;
      k.wall_time = wall_before + seconds_since(loop_start);
      k.energy_before = energy_before;
      k.energy_streak_start = energy_streak_start;
      k.growth_streak = growth_streak;
      k.integrator_state = integrator->save_state();
      k.state = state;
      k.broken_flags = model.bonds.broken;
      k.contact_rebuilds = model.contact_list.rebuilds();
      k.contact_seconds = model.contact_list.seconds();
      k.contact_u_build = model.contact_list.u_build();
      k.frame_times = out.frame_times();
      k.history_bytes = out.history_bytes();
      write_checkpoint(checkpoint_file, k);
    };
    int interrupted = 0;
    // Why a run blew up, from the true stability limit (computed now if not yet known).
    auto likely_cause = [&](double h) {
      if (!(dt_exact > 0.0)) dt_exact = exact_time_step(model);
      const double ratio = h / dt_exact;
      std::string text = "dt = " + format("%.6g", h) + " s is " + format("%.3g", ratio) + " × the exact stability limit " +
                         format("%.6g", dt_exact) + " s (eq. 2.5: " + format("%.6g", dt_stable) + " s): ";
      if (ratio > 1.0 && c.time.integrator == "verlet")
        return text + "the time step is above the stability limit; use time.dt: stable or exact with safety_factor < 1";
      return text + "the step is within the linear limit, so look for contact stiffness, large deformation or a load "
                    "that makes the state jump";
    };
    while (step < max_steps && t < end * (1.0 - 1e-12)) {
      // Land exactly on the end time and on every output time (t = k·every_time): the step that would
      // cross one is shortened (or stretched by at most kLastStepSlack); dt itself is kept for the
      // steps after it.
      double target = end;
      if (c.output.every_time) target = std::min(end, static_cast<double>(next_frame_index) * *c.output.every_time);
      double h = dt;
      const bool landing = target - t <= dt * (1.0 + kLastStepSlack);
      if (landing) h = target - t;
      const double requested = h;
      try {
        integrator->step(state, t, h);
      } catch (const StepFailed& e) {
        log.error("pdsolve: error: step " + std::to_string(step + 1) + ": " + e.what() +
                  "; stopped, the last accepted state is kept");
        status = kRunFailed;
        break;
      }
      if (landing && h == requested) t = target;  // exact, not t + (target − t) with its round-off
      dt_taken = h;
      ++step;
      broken += integrator->last_step().broken_now;
      broken_energy += integrator->last_step().broken_energy_now;
      force_evaluations += integrator->last_step().force_evaluations;
      if (integrator->last_step().next_dt > 0.0) dt = integrator->last_step().next_dt;
      if (const std::int64_t bad = first_non_finite(state); bad >= 0) {
        log.error("pdsolve: error: non-finite displacement or velocity at " + node_text(model, bad) + " after step " +
                  std::to_string(step) + " (t = " + format("%.6g", t) + " s; the largest finite speed is at " +
                  node_text(model, fastest_node(state)) + "); " + likely_cause(h) +
                  "; stopped without writing this state, the last frame written is the last valid one");
        status = kRunFailed;
        state_valid = false;
        break;
      }
      update_energies();
      const double energy = kinetic + strain + state.contact_energy;
      if (energy_before > 0.0 && energy > kGrowthPerStep * energy_before) {
        if (growth_streak++ == 0) energy_streak_start = energy_before;
      } else {
        growth_streak = 0;
      }
      energy_before = energy;
      if (growth_streak >= kGrowthSteps) {
        log.error("pdsolve: error: the energy grew from " + format("%.3g", energy_streak_start) + " J to " +
                  format("%.3g", energy) + " J in the " + std::to_string(kGrowthSteps) + " steps up to and after step " +
                  std::to_string(step) + " (t = " + format("%.6g", t) + " s), at least ×" + format("%g", kGrowthPerStep) +
                  " every step: the run is unstable, most likely starting at " + node_text(model, fastest_node(state)) +
                  " (the largest speed); " + likely_cause(h) +
                  "; stopped without writing this state, the last frame written is the last valid one");
        status = kRunFailed;
        state_valid = false;
        break;
      }
      if (indenter_watch && !indenter_warned) {
        const IndenterStepLimit limit = indenter_step_limit(model, t, state.u, omega2_exact);
        if (limit.node >= 0 && dt_taken > limit.dt) {
          const IndenterSettings& ind = model.indenters[limit.indenter];
          log.line("warning: step " + std::to_string(step) + " (t = " + format("%.6g", t) + " s): indenter '" +
                   ind.name + "' is " + format("%.4g", limit.depth) + " m deep at " + node_text(model, limit.node) +
                   "; with its stiffness 2K·h the step is guaranteed stable only below " + format("%.4g", limit.dt) +
                   " s < dt " + format("%.4g", dt_taken) + " s: the run may blow up (lower indenters[].stiffness or "
                   "time.safety_factor); warned once");
          indenter_warned = true;
        }
      }
      const bool frame_due = c.output.every_steps ? step % *c.output.every_steps == 0
                                                  : t >= static_cast<double>(next_frame_index) * *c.output.every_time - 1e-9 * h;
      const auto output_start = Clock::now();
      if (frame_due) frame(h);
      else if (step % c.output.history_every == 0) history_row(h);
      output_seconds += seconds_since(output_start);
      // Checkpoints never shorten a step, so a run that writes them takes bitwise the same steps.
      bool restart_due = c.output.restart_every_steps && step % *c.output.restart_every_steps == 0;
      if (c.output.restart_every_time && t >= static_cast<double>(next_restart_index) * *c.output.restart_every_time) {
        restart_due = true;
        next_restart_index = static_cast<std::int64_t>(std::floor(t / *c.output.restart_every_time)) + 1;
      }
      if (opt.after_step) opt.after_step(step);
      if (g_signal != 0) {
        interrupted = g_signal;
        write_restart();
        break;
      }
      if (restart_due) write_restart();
      if (progress && seconds_since(last_progress) > 0.5) {
        last_progress = Clock::now();
        const double elapsed = seconds_since(loop_start);
        const double fraction = std::max(t / end, static_cast<double>(step) / static_cast<double>(max_steps));
        std::fprintf(stderr, "\rstep %lld/%lld  t = %.4g s  %5.1f%%  ETA %s   ", static_cast<long long>(step),
                     static_cast<long long>(steps_expected), t, 100.0 * fraction,
                     duration_text(elapsed * (1.0 - fraction) / std::max(fraction, 1e-12)).c_str());
        std::fflush(stderr);
      }
    }
    if (progress) std::fprintf(stderr, "\r%70s\r", "");
    // An interrupted run writes no last frame: the restart goes on with the frames of an uninterrupted run.
    const auto output_start = Clock::now();
    if (state_valid && !interrupted && last_frame_step != step) frame(dt_taken);
    out.finish();
    output_seconds += seconds_since(output_start);

    const double wall = seconds_since(loop_start);
    const double updates = static_cast<double>(model.bonds.directed()) * static_cast<double>(step);
    log.line(std::string(interrupted ? "interrupted" : status == kOk ? "done" : "stopped") + ": " + std::to_string(step) + " steps to t = " +
             format("%.6g", t) + " s in " + format("%.3f", wall) + " s wall (" +
             format("%.3g", wall > 0 ? updates / wall : 0.0) + " bond updates/s), " +
             std::to_string(out.frames_written()) + " frames, " + std::to_string(broken) + " broken bonds, " +
             std::to_string(force_evaluations) + " force evaluations");
    log.line("output: frames and history.csv took " + format("%.3f", output_seconds) + " s wall, " +
             format("%.1f", wall > 0 ? 100.0 * output_seconds / wall : 0.0) + " % of the time loop");
    if (model.contact.pairs)
      log.line("contact: " + std::to_string(model.contact_list.rebuilds()) + " Verlet-list builds in " +
               std::to_string(step) + " steps, " + format("%.3f", model.contact_list.seconds()) + " s searching, " +
               std::to_string(model.contact_list.pairs().directed() / 2) + " pairs in the last list");
    if (interrupted) {
      log.error("pdsolve: interrupted by " + std::string(signal_name(interrupted)) + " after step " + std::to_string(step) +
                " (t = " + format("%.6g", t) + " s); checkpoint written to " + checkpoint_file.string() +
                "; continue with: pdsolve " + opt.case_file.string() + " --restart " + checkpoint_file.string());
      return kInterruptedBase + interrupted;
    }
    if (status == kOk && step >= max_steps && t < end * (1.0 - 1e-12))
      log.line("note: stopped at max_steps " + std::to_string(max_steps) + " before the end time");
    return status;
  } catch (const Error& e) {
    log.error(std::string("pdsolve: error during the run: ") + e.what() +
              "; the frames and history rows written before it are complete");
    return kRunFailed;
  }
}

}  // namespace pd
