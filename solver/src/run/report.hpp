// Phase 4 of a run: the closing lines of run.log and the exit status.
#pragma once
#include "run.hpp"
#include "run/loop.hpp"
#include "run/run_log.hpp"

namespace pd {

// kOk, kRunFailed, or 128 + the signal that interrupted the run.
int report(const RunOptions& options, const Prepared& p, const LoopState& loop, const LoopEnd& end,
           std::int64_t frames_written, RunLog& log);

}  // namespace pd
