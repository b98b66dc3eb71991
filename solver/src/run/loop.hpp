// Phase 3 of a run: the time loop, from the start (or the restored step) to the end time, a
// failure, a signal or max_steps; writes frames, history rows and checkpoints on its schedule.
#pragma once
#include "io/output.hpp"
#include "run.hpp"
#include "run/history_columns.hpp"
#include "run/prepare.hpp"
#include "run/run_log.hpp"
#include "run/start.hpp"

namespace pd {

// How the loop ended, for the report.
struct LoopEnd {
  int status = kOk;          // kRunFailed: a step failed or the state blew up
  bool state_valid = true;   // false after a blow-up: that state is never written
  int interrupted = 0;       // the signal that stopped it, or 0
  double output_seconds = 0.0;  // wall time writing frames and history rows
  double wall = 0.0;         // wall time of this run's loop, the last frame and closing the output included
  std::int64_t steps = 0;    // steps this run took (a restarted run's steps before its restart not counted)
};

// A TimeLoop (loop.cpp) from s's step: its methods step, watch (each watch's verdict goes to the one
// failure exit), write on schedule and checkpoint. s.loop and s.state are advanced in place. Throws pd::Error if output fails (a full disk).
// out is null on the ranks other than 0 of a decomposed run: they take part in every gather and
// sum, and write nothing.
LoopEnd run_loop(const RunOptions& options, Prepared& p, Start& s, const HistoryColumns& columns, OutputWriter* out,
                 RunLog& log);

}  // namespace pd
