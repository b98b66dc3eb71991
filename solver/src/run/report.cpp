// The closing lines of a run and its exit status (run/report.hpp).
#include "run/report.hpp"

#include "run/schedule.hpp"

namespace pd {

int report(const RunOptions& opt, const Prepared& p, const LoopState& loop, const LoopEnd& end, std::int64_t frames_written,
           RunLog& log) {
  log.summary(p, loop, end, frames_written);
  if (end.interrupted) {
    log.interrupted(opt, p, loop, end.interrupted);
    return kInterruptedBase + end.interrupted;
  }
  if (end.status == kOk && loop.step >= p.max_steps && Schedule(p.c.output, p.c.time.end).before_end(loop.t))
    log.stopped_at_max_steps(p.max_steps);
  return end.status;
}

}  // namespace pd
