// When the time loop writes: frames, history rows and checkpoints, and where a step must land
// (the end time, every k·every_time) — decided from output.* and time.end, nothing else.
#pragma once
#include <cstdint>

#include "core/case.hpp"
#include "run/loop_state.hpp"

namespace pd {

// A remainder below this fraction of dt is absorbed into the last step rather than taken alone.
constexpr double kLastStepSlack = 1e-6;

// The steps from t = 0 to `end` at dt, the last one absorbing a remainder below kLastStepSlack·dt.
std::int64_t steps_to_reach(double end, double dt);

// The step the loop tries next: dt, or shortened (stretched by at most kLastStepSlack) to land
// exactly on `target`; dt itself is kept for the steps after it.
struct NextStep {
  double h = 0.0;       // [s]
  bool landing = false;  // h ends at `target`
  double target = 0.0;   // [s]
};

class Schedule {
 public:
  Schedule(const OutputSettings& output, double end) : output_(output), end_(end) {}

  // True while t is before the end time (within a relative 1e-12).
  bool before_end(double t) const { return t < end_ * (1.0 - 1e-12); }
  // Where the step from s.t must land: the end time, or the next frame time k·every_time before it.
  NextStep next_step(const LoopState& s) const;
  // After the step to s.t that took h: a frame every every_steps steps, or at the first step at or
  // past k·every_time (within 1e-9 h); otherwise a history row every history_every steps.
  bool frame_due(const LoopState& s, double h) const;
  bool history_due(const LoopState& s) const { return s.step % output_.history_every == 0; }
  // Records a frame written at s.step, s.t: the next frame time lies after it.
  void frame_written(LoopState& s) const;
  // A checkpoint every restart_every_steps steps and/or at the first step at or past
  // k·restart_every_time (then k moves past s.t). Checkpoints never shorten a step, so a run that
  // writes them takes bitwise the same steps.
  bool restart_due(LoopState& s) const;

 private:
  OutputSettings output_;
  double end_;
};

}  // namespace pd
