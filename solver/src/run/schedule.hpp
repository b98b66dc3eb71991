// When the time loop writes: frames, history rows and checkpoints, and where a step must land
// (the end time, every k·every_time) — decided from output.* and time.end, nothing else; and the
// checkpoints of wall time (WallCheckpoints), decided from a clock the caller reads.
#pragma once
#include <algorithm>
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

// A checkpoint every output.restart_every_wall seconds of wall time (0: none; default 600 s), so
// that a run killed without a signal it can catch (SIGKILL, a machine going down) loses at most that
// much: a plate_with_hole run killed at step 7,360 of 8,027 lost everything (issue 36, item 8).
// Times are seconds on the caller's clock (the time loop's since it started; a test's own numbers),
// so the decision can be tested without waiting. A checkpoint is written between steps and changes
// no step, history row or frame: only when it comes depends on the clock.
class WallCheckpoints {
 public:
  // Checkpoints may take at most this share of the wall time. A big model on a slow disk can take
  // a good part of restart_every_wall to write (the state and every bond's broken flag); after one
  // that took w seconds the next comes no sooner than w / kMaxShare after it began, so a run spends
  // about 3 % of its time on them at most, whatever the disk (as long as a checkpoint takes about
  // as long as the one before it).
  static constexpr double kMaxShare = 0.03;

  // every: restart_every_wall [s]; start: the clock when the time loop began.
  WallCheckpoints(double every, double start) : every_(every), next_(start + every) {}
  // True when a checkpoint is due at `now`.
  bool due(double now) const { return every_ > 0.0 && now >= next_; }
  // A checkpoint (for any reason: a wall-time one, restart_every_steps/_time) began at `began` and
  // was written at `ended`: the next is due every seconds, or w / kMaxShare, after it began.
  void written(double began, double ended) { next_ = began + std::max(every_, (ended - began) / kMaxShare); }
  // When the next checkpoint is due (for run.log).
  double next() const { return next_; }

 private:
  double every_;
  double next_;
};

}  // namespace pd
