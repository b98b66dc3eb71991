// One solver run as its phases (deal.II style): prepare → start or restore → loop → report, each in
// run/ (pipeline/formats.md §3–4).
#include "run.hpp"

#include <iostream>
#include <memory>

#include "core/error.hpp"
#include "io/atomic_file.hpp"
#include "parallel/session.hpp"
#include "run/history_columns.hpp"
#include "run/loop.hpp"
#include "run/prepare.hpp"
#include "run/report.hpp"
#include "run/run_log.hpp"
#include "run/signals.hpp"
#include "run/start.hpp"

namespace pd {

namespace {

// From the first output file on: an error (a full disk, a failed rename) is a failed run, not bad
// input (exit 3, --help), and it goes to run.log too when run.log can still be written; the frames
// and history rows written so far stay whole (issue 17, item 6).
// On a decomposed run rank 0 writes every file; the other ranks have no writer (out is null) and a
// silent log.
int run_with_output(const RunOptions& opt, Prepared& p, Start& s, const HistoryColumns& columns, OutputWriter* out) {
  std::unique_ptr<RunLog> log;
  try {
    // A checkpoint of an earlier run would not match the frames this run writes.
    // (Its pieces too: the other ranks write theirs only at a checkpoint, after collectives rank 0
    // enters once this is done.)
    if (!s.restarting && out) {
      std::filesystem::remove(checkpoint_path(p.c));
      remove_unnamed_checkpoint_pieces(checkpoint_path(p.c), nullptr);
    }
    log = std::make_unique<RunLog>(out ? p.c.output_dir / "run.log" : std::filesystem::path(), opt.quiet,
                                   s.restarting);
    log->title(opt, p);
    if (s.restarting) log->restarted(opt, s);
    if (!s.solver_changed.empty()) log->error(s.solver_changed);  // stderr once (rank 0), and run.log
    log->setup(p);
    const LoopEnd end = run_loop(opt, p, s, columns, out, *log);
    return report(opt, p, s.loop, end, out ? out->frames_written() : 0, *log);
  } catch (const Error& e) {
    const std::string message = std::string("pdsolve: error during the run: ") + e.what() +
                                "; the frames and history rows written before it are complete";
    if (!log) std::cerr << message << "\n";
    try {
      if (log) log->error(message);  // prints it, then writes run.log
    } catch (const Error&) {
      // run.log cannot be written either (the same full disk): the message is on stderr already.
    }
    // An output error is rank 0's alone (it writes every file): the other ranks wait for it in the
    // next exchange, and MPI_Finalize would wait for them. MPI_Abort ends them all (issue 15).
    if (p.decomposed) abort_ranks(kRunFailed);
    return kRunFailed;
  }
}

// open_output on rank 0 (the others write nothing), with its verdict on every rank: a restart whose
// frames or history.csv do not match the checkpoint is refused by rank 0 alone, and the other ranks
// must refuse with it rather than wait for it in the first exchange (issue 15). A full disk ends
// every rank in run() below.
std::unique_ptr<OutputWriter> open_output_on_ranks(const RunOptions& opt, const Prepared& p, const Start& s,
                                                   const HistoryColumns& columns) {
  if (!p.decomposed) return open_output(opt, p, s, columns);
  std::unique_ptr<OutputWriter> out;
  std::string failure;
  try {
    out = open_output(opt, p, s, columns);
  } catch (const DiskFull&) {
    throw;
  } catch (const Error& e) {
    failure = e.what();
  }
  failure = p.decomposed->broadcast(failure);
  if (!failure.empty()) throw Error(failure);
  return out;
}

}  // namespace

int run(const RunOptions& opt) {
  const SignalGuard signals;  // from the start: a signal while reading is seen after the first step
  // Every input error is thrown by these two, before any output exists.
  const std::unique_ptr<Prepared> prepared = prepare(opt);
  Prepared& p = *prepared;
  Start s = start_or_restore(opt, p);

  // Output starts here. open_output refuses a restart whose history.csv or frames do not match the
  // checkpoint (bad input, exit 1, before it changes a file); a full disk there is a failed run.
  // On a decomposed run the columns read the piece (the operator's model) and this rank's state.
  const HistoryColumns columns(p.decomposed ? p.op->model() : p.model, p.c, p.integrator.get(),
                               &p.op->model().contact_list, p.decomposed.get());
  try {
    const std::unique_ptr<OutputWriter> out = open_output_on_ranks(opt, p, s, columns);
    return run_with_output(opt, p, s, columns, out.get());
  } catch (const DiskFull& e) {
    std::cerr << "pdsolve: error: " << e.what() << "\n";
    if (p.decomposed) abort_ranks(kRunFailed);  // rank 0's alone, as above
    return kRunFailed;
  }
}

}  // namespace pd
