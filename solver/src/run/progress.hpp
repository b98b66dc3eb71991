// How far a run has come, where its user looks (issue 16 item 5): on a terminal, one line on stderr
// that updates in place twice a second; without one (make's output going to a log), a whole line on
// stderr every `interval` seconds of wall time. Either way the same line goes into run.log every
// `interval` seconds, for whoever tails it. The time left comes from run/eta.hpp. Only text: it
// never touches the state, so results are the same with or without it.
#pragma once
#include <chrono>
#include <cstdint>
#include <string>

#include "run/eta.hpp"
#include "run/run_log.hpp"

namespace pd {

struct ProgressSettings {
  bool terminal = false;  // stderr is a terminal: the updating line
  bool to_stderr = true;  // false under --quiet: run.log only
  double interval = kDefaultInterval;  // [s] of wall time between lines; <= 0: no lines
  // Every 10 s, rather than every 5 % of the run: a short run (the tests', a few seconds) then
  // writes none, and a long one (hours) still shows it is alive more often than every few minutes.
  static constexpr double kDefaultInterval = 10.0;
};

class Progress {
 public:
  // end: time.end [s]; max_steps: the step cap; steps_expected: the steps the run is expected to take,
  // 0 when its integrator sets its own step size (then the count is not known ahead: "step 38", not
  // a count from the initial step that a mixed run passed five times over, "step 38/8").
  Progress(const ProgressSettings& settings, double end, std::int64_t max_steps, std::int64_t steps_expected,
           RunLog* log);
  // After each step: t and step of the run, wall seconds since the loop started.
  void after_step(double t, std::int64_t step, double wall);
  void clear() const;  // wipes the terminal's updating line

  // The text of a line (without the updating line's carriage return), for tests and for run.log:
  // "progress: step 1200/5000, t = 1.2e-05/6e-05 s, 24.0 %, 812 steps/s, ETA 4s".
  std::string line(double t, std::int64_t step) const;

 private:
  double fraction(double t, std::int64_t step) const;
  ProgressSettings settings_;
  double end_;
  std::int64_t max_steps_, steps_expected_;
  RunLog* log_;
  EtaEstimator eta_;
  double last_sample_ = -1.0, last_terminal_ = 0.0, last_line_ = 0.0;
  bool shown_ = false;
};

// "4s", "2m31s", "1h05m"; "?" for an unknown (negative or not finite) duration.
std::string duration_text(double seconds);

}  // namespace pd
