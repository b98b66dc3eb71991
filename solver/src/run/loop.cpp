// The time loop of a run (run/loop.hpp): step, watch, write on schedule, checkpoint, progress.
#include "run/loop.hpp"

#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <optional>

#include "forces/indenter.hpp"
#include "io/checkpoint.hpp"
#include "parallel/gather_state.hpp"
#include "run/state_checkpoint.hpp"
#include "parallel/local_model.hpp"
#include "run/measures.hpp"
#include "run/progress.hpp"
#include "run/schedule.hpp"
#include "run/signals.hpp"
#include "run/text.hpp"
#include "run/watches.hpp"

namespace pd {

namespace {

using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }

// Kinetic and strain energy of the current state, computed once per step: the blow-up watch needs
// them every step and a history row of the same step reuses them.
class Energies {
 public:
  Energies(const ForceOperator& op, const State& state) : op_(op), state_(state) {}
  void at(std::int64_t step) {
    if (step_ == step) return;
    const ForceOperator::KineticAndStrain e = op_.kinetic_and_strain_energy(state_);  // one reduction on several ranks
    kinetic = e.kinetic;
    strain = e.strain;
    step_ = step;
  }
  double kinetic = 0.0, strain = 0.0;

 private:
  const ForceOperator& op_;
  const State& state_;
  std::int64_t step_ = -1;
};

// A watch's verdict that the run cannot go on (a failed step, a blow-up, a broken energy balance):
// what the one failure exit, TimeLoop::fail, says and removes.
struct Failure {
  std::string message;          // run.log's error; composed only where there is output (rank 0)
  bool state_valid = true;      // false: the state blew up, and it is never written
  std::int64_t drop_from = -1;  // the frames written from this step on show the instability and go; −1: none
  std::string while_what;       // what the run was doing then, for run.log's line on the frames removed
};

// The loop of one run, from its start (or restored) step to the end time, a failure, a signal or
// max_steps. Its members are what the loop carries, named as in the loop's lines (state, loop,
// energies, …); every method is one thing the loop does. `dec` is the decomposed run's piece and
// its exchanges, null on one rank; `out` is null on the ranks that write nothing (not rank 0).
class TimeLoop {
 public:
  TimeLoop(const RunOptions& opt, Prepared& p, Start& s, const HistoryColumns& columns, OutputWriter* out,
           RunLog& log);
  LoopEnd run();

 private:
  std::optional<Failure> advance();
  std::optional<Failure> step(const NextStep& next, double& h);
  std::optional<Failure> watch(double h, double held_before);
  std::optional<Failure> non_finite(double h);
  Failure growth(double energy, double h);
  Failure imbalance(double energy, double h);
  void fail(const Failure& failure);
  void warn_indenter_depth();
  bool stop_or_checkpoint();
  void finish();

  const State& output_state();
  void history_row(double dt_taken);
  void frame_in_pieces();
  void frame_from_rows(const State& st);
  void frame(double dt_taken);
  template <class Write>
  void timed(Write write);
  void write_restart();
  void checkpoint(bool for_wall_time);
  void drop_frames_from(std::int64_t from_step, const std::string& while_what);
  std::string likely_cause(double h);

  const Clock::time_point loop_start = Clock::now();
  const RunOptions& opt;
  Prepared& p;
  Start& s;
  const HistoryColumns& columns;
  OutputWriter* out;
  RunLog& log;
  const Model& model;
  Integrator& integrator;
  State& state;
  LoopState& loop;
  const Decomposed* dec;
  const double wall_before;      // time loop of the run(s) before a restart
  const std::int64_t first_step;  // steps of this run: loop.step − first_step
  const Schedule schedule;
  WallCheckpoints wall_checkpoints;  // on the clock seconds_since(loop_start)
  const std::filesystem::path checkpoint_file;
  Energies energies;
  BlowUpWatch blow_up;
  EnergyBalanceWatch balance;
  IndenterDepthWatch indenter_depth;
  Progress progress;
  LoopEnd end;
  State gathered;  // a decomposed run's state on rank 0: for gathered frames, failures and reactions
  std::vector<std::pair<std::int64_t, double>> frames_here;  // (step, t) of the frames this process wrote
  const std::string while_growing = "while the energy grew ×" + format("%g", BlowUpWatch::kGrowthPerStep) + " a step";
  const std::string while_unbalanced = "while the energy held was more than " + format("%g", EnergyBalanceWatch::kSuspect) +
                                       " × the energy given";
};

// Rank 0 only (the one with output): stderr's updating line on a terminal, else whole lines on
// stderr; run.log's lines in both cases (run/progress.hpp).
ProgressSettings progress_settings(const RunOptions& opt, const OutputWriter* out) {
  ProgressSettings settings;
  settings.terminal = out && isatty(fileno(stderr)) != 0;
  settings.to_stderr = !opt.quiet;
  settings.interval = out ? opt.progress_interval : 0.0;
  return settings;
}

TimeLoop::TimeLoop(const RunOptions& opt, Prepared& p, Start& s, const HistoryColumns& columns, OutputWriter* out,
                   RunLog& log)
    : opt(opt),
      p(p),
      s(s),
      columns(columns),
      out(out),
      log(log),
      model(p.model),
      integrator(*p.integrator),
      state(s.state),
      loop(s.loop),
      dec(p.decomposed.get()),
      wall_before(loop.wall_time),
      first_step(loop.step),
      schedule(p.c.output, p.c.time.end),
      wall_checkpoints(p.c.output.restart_every_wall, 0.0),
      checkpoint_file(checkpoint_path(p.c)),
      energies(*p.op, state),
      blow_up(loop.growth),
      balance(p.integrator->explicit_step()),
      indenter_depth(p.indenter_watch),
      progress(progress_settings(opt, out), p.c.time.end, p.max_steps,
               integrator.controls_step() ? 0 : p.steps_expected, out ? &log : nullptr) {}

LoopEnd TimeLoop::run() {
  // The balance's constant: the energy at step 0, or E + D + B − W of the state a restart read back.
  energies.at(loop.step);
  balance.start(state.plus_term_energies(energies.kinetic + energies.strain), state.damping_work,
                loop.broken_energy,
                state.external_work);

  if (!s.restarting) timed([&] { frame(0.0); });
  while (loop.step < p.max_steps && schedule.before_end(loop.t)) {
    if (const std::optional<Failure> failure = advance()) {
      fail(*failure);
      break;
    }
    if (stop_or_checkpoint()) break;
    progress.after_step(loop.t, loop.step, seconds_since(loop_start));
  }
  finish();
  return end;
}

// One step: take it, watch the state it gave, write the frame or history row due.
std::optional<Failure> TimeLoop::advance() {
  const NextStep next = schedule.next_step(loop);
  double h = next.h;
  // E + D + B − W before the step (docs/theory.md C4), for a quasi-static load step's ledger in
  // watch(); without the kinetic energy when the last step was a load step too (see there).
  const bool after_load_step = integrator.step_mode().value_or(0) == 1;
  const double held_before = state.plus_term_energies((after_load_step ? 0.0 : energies.kinetic) + energies.strain) +
                             state.damping_work + loop.broken_energy - state.external_work;
  if (std::optional<Failure> failed = step(next, h)) return failed;
  if (std::optional<Failure> failed = watch(h, held_before)) return failed;
  warn_indenter_depth();
  timed([&] {
    if (schedule.frame_due(loop, h)) frame(h);
    else if (schedule.history_due(loop)) history_row(h);
  });
  return std::nullopt;
}

// The integrator's step from loop.t, h in (the schedule's) and out (the step taken), and the loop's
// counts after it; a step the integrator could not take is the verdict.
std::optional<Failure> TimeLoop::step(const NextStep& next, double& h) {
  try {
    integrator.step(state, loop.t, h);
  } catch (const StepFailed& e) {
    Failure failure;  // the last accepted state stays valid: the last frame is written
    failure.message = "pdsolve: error: step " + std::to_string(loop.step + 1) + ": " + e.what() +
                      "; stopped, the last accepted state is kept";
    return failure;
  }
  if (next.landing && h == next.h) loop.t = next.target;  // exact, not t + (target − t) with its round-off
  loop.dt_taken = h;
  ++loop.step;
  const StepReport& report = integrator.last_step();
  for (const std::string& text : integrator.take_log_lines()) log.line(text);
  loop.broken += report.broken_now;
  loop.broken_energy += report.broken_energy_now;
  loop.force_evaluations += report.force_evaluations;
  if (report.next_dt > 0.0) loop.dt = report.next_dt;
  return std::nullopt;
}

// The blow-up and energy-balance watches after step h (run/watches.hpp), and a quasi-static load
// step's share of the ledger: the verdict of the first that stops the run, if one does.
std::optional<Failure> TimeLoop::watch(double h, double held_before) {
  if (std::optional<Failure> failed = non_finite(h)) return failed;
  energies.at(loop.step);
  const double energy = state.plus_term_energies(energies.kinetic + energies.strain);
  // A quasi-static load step neglects inertia: it jumps to the next equilibrium, and what the jump
  // gives up is dissipated by that assumption, not lost from the book — the kinetic energy left by
  // explicit steps before a return (mixed), and the strain energy that bonds breaking at a fixed
  // load release beyond what they held, which a real body would radiate as motion. It is booked as
  // damping work, so that the balance stays the run's constant (before this, traction's
  // quasi_static run ended at −68 % of the external work, its mixed run at −25 %). A load step's
  // velocity is its mean rate (u₁ − u₀)/h, which seeds the next step's predictor and Verlet after a
  // switch, not motion the static balance holds: its kinetic energy stays out of the ledger on
  // both sides (booked, it made the damping work fall and rise with the rate: −3.9 × W on the
  // step that cut the test plate of test_end_to_end.cpp), and energy.png leaves it out of the
  // balance of a load step's row.
  if (integrator.step_mode().value_or(0) == 1)
    state.damping_work = held_before - (energy - energies.kinetic + loop.broken_energy - state.external_work);
  if (blow_up.grew_too_long(energy)) return growth(energy, h);
  if (balance.broken(loop.step, energy, state.damping_work, state.external_work)) return imbalance(energy, h);
  return std::nullopt;
}

// A non-finite displacement or velocity anywhere. The frames go from where the imbalance or the
// growth began, if either had begun.
std::optional<Failure> TimeLoop::non_finite(double h) {
  std::int64_t bad = first_non_finite(state);
  const State* whole = &state;
  if (dec) {  // the first non-finite node of the whole model, the same decision on every rank
    const double first = dec->minimum(bad >= 0 ? static_cast<double>(dec->piece().global[static_cast<std::size_t>(bad)]) : HUGE_VAL);
    bad = std::isfinite(first) ? static_cast<std::int64_t>(first) : -1;
    if (bad >= 0) whole = &output_state();
  }
  if (bad < 0) return std::nullopt;
  Failure failure;
  failure.state_valid = false;
  if (out)
    failure.message = BlowUpWatch::non_finite_message(node_text(model, bad), loop.step, loop.t,
                                                      node_text(model, fastest_node(*whole)), likely_cause(h));
  if (balance.suspect_from() >= 0) {
    failure.drop_from = balance.suspect_from();
    failure.while_what = while_unbalanced;
  } else if (loop.growth.streak > 0) {
    failure.drop_from = loop.step - loop.growth.streak;
    failure.while_what = while_growing;
  }
  return failure;
}

// The energy grew ×1.5 a step for 20 steps: the frames of the streak go.
Failure TimeLoop::growth(double energy, double h) {
  const State& st = output_state();
  Failure failure{std::string(), false, loop.step - loop.growth.streak + 1, while_growing};
  if (out)
    failure.message = blow_up.growth_message(energy, loop.step, loop.t, node_text(model, fastest_node(st)), likely_cause(h));
  return failure;
}

// The run holds far more energy than it was given: the frames from where it first passed ×2 go.
Failure TimeLoop::imbalance(double energy, double h) {
  const State& st = output_state();
  Failure failure{std::string(), false, balance.suspect_from() >= 0 ? balance.suspect_from() : loop.step, while_unbalanced};
  if (out)
    failure.message = balance.message(loop.step, loop.t, energy, state.damping_work, state.external_work,
                                      node_text(model, fastest_node(st)), likely_cause(h));
  return failure;
}

// The one way a run fails: its error in run.log (and on stderr), the frames that show the
// instability removed, and no last frame of a state that blew up.
void TimeLoop::fail(const Failure& failure) {
  if (out) log.error(failure.message);
  if (failure.drop_from >= 0) drop_frames_from(failure.drop_from, failure.while_what);
  end.status = kRunFailed;
  end.state_valid = failure.state_valid;
}

// The indenter-depth watch: a warning, once, not a stop.
void TimeLoop::warn_indenter_depth() {
  if (!indenter_depth.watching()) return;
  // The operator's model: the piece's on a decomposed run (its owned nodes are looked at), else the whole.
  const IndenterStepLimit limit = indenter_step_limit(p.op->model(), loop.t, state.u, p.omega2_exact, dec);
  if (const auto warning = indenter_depth.check(
          limit, loop.step, loop.t, loop.dt_taken, [&] { return model.indenters[limit.indenter].name; },
          [&] { return node_text(model, limit.node); }))
    log.line(*warning);
}

// After a step's output: a signal stops the run with a checkpoint (true: stop); else the
// checkpoint the schedule or the wall clock asks for.
bool TimeLoop::stop_or_checkpoint() {
  const bool restart_due = schedule.restart_due(loop);
  if (opt.after_step) opt.after_step(loop.step);
  int signal = pending_signal();
  bool wall_due = out && wall_checkpoints.due(seconds_since(loop_start));
  if (dec) {
    // Every rank stops, or writes its part of a checkpoint, after the same step: one reduction
    // carries both, 2·signal + (rank 0's wall-time checkpoint due), the largest over the ranks.
    const int both = -static_cast<int>(dec->minimum(-(2 * signal + (wall_due ? 1 : 0))));
    signal = both / 2;
    wall_due = both % 2 == 1;
  }
  if (signal != 0) {
    end.interrupted = signal;
    write_restart();
    return true;
  }
  if (restart_due || wall_due) checkpoint(!restart_due);
  return false;
}

// The last frame, closing the output, and the run's measures.
void TimeLoop::finish() {
  progress.clear();
  // An interrupted run writes no last frame: the restart goes on with the frames of an uninterrupted run.
  timed([&] {
    if (end.state_valid && !end.interrupted && loop.last_frame_step != loop.step) frame(loop.dt_taken);
    if (out) out->finish();
  });
  end.wall = seconds_since(loop_start);
  end.steps = loop.step - first_step;
  // What the ranks exchanged, per step of this run (issue 15's measures; bench/mpi_ranks.py reads them).
  if (dec) {
    for (const std::string& text : dec->traffic_report(end.steps)) log.line(text);
    if (model.contact.pairs)
      for (const std::string& text : dec->contact_traffic_report(end.steps)) log.line(text);
  }
}

// What a gathered frame and a failure's message read: the run's state, or on a decomposed run
// every rank's owned part gathered on rank 0 in the whole model's numbering, with the broken flags
// (frames' damage). Frames in pieces and checkpoints need no gather. Collective.
const State& TimeLoop::output_state() {
  if (!dec) return state;
  gathered.u = dec->gather(state.u);
  gathered.v = dec->gather(state.v);
  gathered.f = dec->gather(state.f);
  gathered.w = dec->gather(state.w);
  gathered.copy_totals(state);
  if (p.whole_bonds) dec->gather_broken(dec->piece().model.bonds, p.model.bonds);
  gather_state(*dec, p.model, [](const StateDeclaration& d) { return d.frames; });  // the frames' declared fields
  return gathered;
}

// Collective: every rank fills the columns from its own state (run/history_columns.hpp), rank 0
// writes the row.
void TimeLoop::history_row(double dt_taken) {
  energies.at(loop.step);
  HistoryRow r;
  r.step = loop.step;
  r.time = loop.t;
  r.dt = dt_taken;
  r.iterations = loop.step == 0 ? 0 : integrator.last_step().iterations;
  r.rejected = loop.step == 0 ? 0 : integrator.last_step().rejected;
  r.kinetic_energy = energies.kinetic;
  r.strain_energy = energies.strain;
  r.external_work = state.external_work;
  r.damping_work = state.damping_work;
  r.broken_bonds = loop.broken;
  r.wall_time = wall_before + seconds_since(loop_start);
  columns.fill(r, HistoryInputs{state, loop.t, loop.broken_energy});
  if (out) out->history(r);
}

// output.parallel_frames: pieces. Every rank writes its piece (its nodes and ghosts, io/output.hpp
// frame_grid), then rank 0 the .pvtu naming them. Collective. The frame number is rank 0's (the
// broadcast also keeps the other ranks from writing before rank 0's OutputWriter has cleared the
// frames of an earlier run). On one rank (a restart continuing a series in pieces) one piece of
// every node.
void TimeLoop::frame_in_pieces() {
  std::vector<double> k{out ? static_cast<double>(out->frames_written()) : 0.0};
  if (dec) dec->broadcast(k);
  FrameFormat format = frame_format_of(p.c.output);
  std::vector<std::uint8_t> all;
  std::vector<std::int32_t> identity;
  if (!dec) {
    all.assign(model.nodes.size(), 1);
    identity.resize(model.nodes.size());
    for (std::size_t i = 0; i < identity.size(); ++i) identity[i] = static_cast<std::int32_t>(i);
  }
  const FramePiece nodes = dec ? FramePiece{dec->piece().owned, dec->piece().global} : FramePiece{all, identity};
  const VtuGrid grid = frame_grid(dec ? dec->piece().model : model, state, loop.t, loop.step, format, &nodes);
  write_vtu(p.c.output_dir / frame_piece_file(static_cast<std::size_t>(k[0]), dec ? dec->rank() : 0), grid,
            format.zlib ? VtuCompression::zlib : VtuCompression::none);
  if (dec) dec->total(0);  // every piece is on disk before the .pvtu names it
  if (out) out->frame_of_pieces(grid, dec ? dec->ranks() : 1, loop.t);
}

// A gathered frame of a run whose ranks hold only their rows: the damage per node and the broken
// bonds' line cells come from the pieces (Decomposed::gather_broken_lines), not the whole list.
void TimeLoop::frame_from_rows(const State& st) {
  const LocalPiece& piece = dec->piece();
  const std::vector<double> damage = dec->gather(piece.model.bond_model->damage(piece.model));  // owned rows: the serial bits
  BondList lines;
  dec->gather_broken_lines(piece.model.bonds, lines);
  const FrameBonds bonds{damage, lines};
  if (out) out->frame(model, st, loop.t, loop.step, &bonds);
}

// A frame and the history row of its step. Collective.
void TimeLoop::frame(double dt_taken) {
  if (p.frames_in_pieces()) {
    frame_in_pieces();  // no gather: each rank writes its own nodes
  } else {
    const State& st = output_state();
    if (!p.whole_bonds) frame_from_rows(st);
    else if (out) out->frame(model, st, loop.t, loop.step);
  }
  frames_here.emplace_back(loop.step, loop.t);
  history_row(dt_taken);
  schedule.frame_written(loop);
}

// Wall time spent writing frames and history rows, reported in run.log: the share of the run
// that output costs, measured by the run itself (issue 6 asks for under 5 %).
template <class Write>
void TimeLoop::timed(Write write) {
  const auto output_start = Clock::now();
  write();
  end.output_seconds += seconds_since(output_start);
}

// Written in pieces (io/checkpoint.hpp), after the history rows so far are on disk: every rank
// its owned nodes and rows, no gather; then rank 0 the index naming them, once every piece is on
// disk (the per_rank below returns only when every rank has written), so a crash in between leaves
// the previous index and its pieces as they were. Collective.
void TimeLoop::write_restart() {
  const Model& local = p.op->model();  // the piece's on a decomposed run
  const NeighbourList& contact_list = local.contact_list;
  const bool contact = model.contact.pairs && contact_list.rebuilds() > 0;
  std::vector<char> integrator_state = p.integrator->save_state();
  if (out) out->flush_history();
  const int rank = dec ? dec->rank() : 0;
  CheckpointPieceRef mine;
  std::string failure;
  try {
    mine = write_checkpoint_piece(checkpoint_file, checkpoint_piece_file(loop.step, rank),
                                  checkpoint_piece_of(local, dec ? &dec->piece() : nullptr, state,
                                                      integrator.checkpointed_node_arrays(),
                                                      contact ? &contact_list.u_build() : nullptr));
  } catch (const Error& e) {
    if (!dec) throw;
    failure = e.what();
  }
  std::vector<CheckpointPieceRef> pieces{mine};
  if (dec) {
    // Every rank's reference on rank 0 (the numbers as bits: per_rank moves doubles unchanged).
    if (dec->minimum(failure.empty() ? 1.0 : 0.0) == 0.0) {
      if (!failure.empty()) throw Error(failure);
      throw Error(checkpoint_file.string() + ": another rank could not write its piece of the checkpoint (its error is on its stderr)");
    }
    auto bits = [](std::uint64_t v) { double d; std::memcpy(&d, &v, sizeof d); return d; };
    auto back = [](double d) { std::uint64_t v; std::memcpy(&v, &d, sizeof v); return v; };
    const std::vector<double> nodes = dec->per_rank(bits(mine.nodes)), bonds = dec->per_rank(bits(mine.bonds)),
                              bytes = dec->per_rank(bits(mine.bytes)), sums = dec->per_rank(bits(mine.checksum));
    pieces.clear();
    for (std::size_t r = 0; r < nodes.size(); ++r)
      pieces.push_back({checkpoint_piece_file(loop.step, static_cast<int>(r)), back(nodes[r]),
                        back(bonds[r]), back(bytes[r]), back(sums[r])});
  }
  if (!out) return;
  LoopState saved = loop;
  saved.wall_time = wall_before + seconds_since(loop_start);
  write_checkpoint_index(checkpoint_file,
                         checkpoint_of(p, s, state, saved, *out, std::move(integrator_state), contact, std::move(pieces)));
}

// write_restart timed for the wall-time schedule (only rank 0's clock decides it, stop_or_checkpoint).
void TimeLoop::checkpoint(bool for_wall_time) {
  const double began = seconds_since(loop_start);
  write_restart();
  const double ended = seconds_since(loop_start);
  wall_checkpoints.written(began, ended);
  if (for_wall_time && out) log.checkpoint_written(p, loop, ended - began);
}

// A blow-up found after a streak of energy growth: the frames written during the streak show the
// instability, not the physics (a kept "last valid" frame had max|v| = 1.2·10⁹ m/s, issue 17,
// item 12). They go, so the last frame kept is the last before the growth began at `from_step`.
void TimeLoop::drop_frames_from(std::int64_t from_step, const std::string& while_what) {
  double keep_until = -1.0;
  bool suspect = false;
  for (const auto& [step, t] : frames_here) {
    if (step < from_step) keep_until = t;
    else suspect = true;
  }
  if (!out || !suspect || keep_until < 0.0) return;
  if (const int dropped = out->drop_frames_after(keep_until); dropped > 0)
    log.frames_dropped(dropped, from_step, while_what, keep_until);
}

// An explicit run is judged by the step it was given (dt, safety_factor), not by a step shortened
// to land on an output time.
std::string TimeLoop::likely_cause(double h) {
  const double step = integrator.explicit_step() && p.dt > 0.0 ? std::max(h, p.dt) : h;
  return BlowUpWatch::likely_cause(step, p.known_exact_limit(), p.dt_stable, integrator.explicit_step(), model.contact.pairs);
}

}  // namespace

LoopEnd run_loop(const RunOptions& opt, Prepared& p, Start& s, const HistoryColumns& columns, OutputWriter* out,
                 RunLog& log) {
  return TimeLoop(opt, p, s, columns, out, log).run();
}

}  // namespace pd
