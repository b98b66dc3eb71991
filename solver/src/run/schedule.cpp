// The output and restart schedule of the time loop (run/schedule.hpp).
#include "run/schedule.hpp"

#include <algorithm>
#include <cmath>

namespace pd {

std::int64_t steps_to_reach(double end, double dt) {
  return static_cast<std::int64_t>(std::ceil(end / dt * (1.0 - kLastStepSlack)));
}

NextStep Schedule::next_step(const LoopState& s) const {
  NextStep next;
  next.target = end_;
  if (output_.every_time) next.target = std::min(end_, static_cast<double>(s.next_frame_index) * *output_.every_time);
  next.h = s.dt;
  next.landing = next.target - s.t <= s.dt * (1.0 + kLastStepSlack);
  if (next.landing) next.h = next.target - s.t;
  return next;
}

bool Schedule::frame_due(const LoopState& s, double h) const {
  return output_.every_steps ? s.step % *output_.every_steps == 0
                             : s.t >= static_cast<double>(s.next_frame_index) * *output_.every_time - 1e-9 * h;
}

void Schedule::frame_written(LoopState& s) const {
  s.last_frame_step = s.step;
  // 1 + 1e-12: a frame that landed on k·every_time counts as frame k despite the division's round-off.
  if (output_.every_time)
    s.next_frame_index = static_cast<std::int64_t>(std::floor(s.t / *output_.every_time * (1.0 + 1e-12))) + 1;
}

bool Schedule::restart_due(LoopState& s) const {
  bool due = output_.restart_every_steps && s.step % *output_.restart_every_steps == 0;
  if (output_.restart_every_time && s.t >= static_cast<double>(s.next_restart_index) * *output_.restart_every_time) {
    due = true;
    s.next_restart_index = static_cast<std::int64_t>(std::floor(s.t / *output_.restart_every_time)) + 1;
  }
  return due;
}

}  // namespace pd
