// run.log: what the solver says at start and end, on stdout (unless --quiet) and in the file. The
// phases say what happened (a checkpoint written, frames dropped, the run done) and RunLog words
// it, so that every user-facing line of run.log is composed here; the watches word their own
// errors (run/watches.hpp), the integrators their own lines (Integrator::take_log_lines).
#pragma once
#include <cstdint>
#include <filesystem>
#include <string>

#include "run.hpp"

namespace pd {

struct Prepared;
struct Start;
struct LoopState;
struct LoopEnd;

// The file is rewritten atomically after every line, so run.log is complete even if the run is
// killed. On a decomposed run only rank 0 has a file; the other ranks' RunLog says nothing, yet
// they make the same calls, since some lines need a sum over the ranks (marked "Collective").
class RunLog {
 public:
  // append: keep what run.log holds already (a restarted run adds to it). An empty path: a log that
  // says nothing (the ranks other than 0 of a decomposed run).
  RunLog(std::filesystem::path path, bool quiet, bool append = false);
  void line(const std::string& text);
  void error(const std::string& text);  // stderr always, and run.log
  void note(const std::string& text);   // run.log only (the progress lines: run/progress.hpp)

  // The first line: the version and the case.
  void title(const RunOptions& options, const Prepared& p);
  // The line after the title on a restart: where it continues and what it keeps.
  void restarted(const RunOptions& options, const Start& s);
  // The rest of the header: model, materials, time step, warnings, what runs, the integrator, the
  // end. Collective.
  void setup(const Prepared& p);
  // A checkpoint written for output.restart_every_wall, `seconds` of wall time after it began.
  void checkpoint_written(const Prepared& p, const LoopState& loop, double seconds);
  // Frames removed after a blow-up: `dropped` of them, written from step `from_step` on, `while_what`
  // (the growth or the imbalance); the last one kept is at `kept_until`.
  void frames_dropped(int dropped, std::int64_t from_step, const std::string& while_what, double kept_until);
  // The closing lines: steps, rate, frames, broken bonds; output's share of the time loop; the
  // contact list. Collective.
  void summary(const Prepared& p, const LoopState& loop, const LoopEnd& end, std::int64_t frames_written);
  // The error of a run stopped by `signal`, with the command that continues it.
  void interrupted(const RunOptions& options, const Prepared& p, const LoopState& loop, int signal);
  // A run that ended at max_steps before its end time.
  void stopped_at_max_steps(std::int64_t max_steps);

 private:
  std::filesystem::path path_;
  bool quiet_;
  std::string text_;
};

}  // namespace pd
