// What the time loop carries from one step to the next, in one struct: checkpoint.bin saves it
// whole (io/checkpoint.hpp) and a restart continues from it bitwise.
#pragma once
#include <cstdint>

namespace pd {

// The blow-up watch's memory (run/watches.hpp): the energy after the last step and the streak of
// steps in which it grew ×1.5 or more.
struct EnergyGrowth {
  double energy_before = -1.0;  // kinetic + strain + contact energy after the last step [J]; < 0: none yet
  double streak_start = 0.0;    // the energy before the first step of the streak [J]
  std::int64_t streak = 0;      // steps in a row that grew ×1.5 or more
};

struct LoopState {
  std::int64_t step = 0;
  double t = 0.0;         // [s]
  double dt = 0.0;        // the step the loop will try next (Verlet's dt, or the adaptive proposal) [s]
  double dt_taken = 0.0;  // the last step taken [s]
  // Output and restart schedule (run/schedule.hpp): frame k is due at t ≥ k·every_time, checkpoint k
  // at t ≥ k·restart_every_time.
  std::int64_t last_frame_step = -1, next_frame_index = 1, next_restart_index = 1;
  std::int64_t broken = 0;             // broken bonds so far
  std::int64_t force_evaluations = 0;  // of the whole run, rejected attempts included
  double broken_energy = 0.0;          // Σ energy of bonds at the moment they broke [J]
  double wall_time = 0.0;  // seconds of time loop before this run started (a restart goes on counting)
  EnergyGrowth growth;
};

}  // namespace pd
