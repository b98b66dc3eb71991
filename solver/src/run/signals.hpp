// SIGINT / SIGTERM during a run: the handler only records the signal; the time loop asks after
// each step, writes a checkpoint and stops (solver/README.md, "Checkpoint and restart").
#pragma once
#include <signal.h>  // struct sigaction (POSIX)

namespace pd {

// Installs the handlers for its lifetime and restores the caller's on destruction. A signal the
// caller ignores (SIGINT of a background job of a script, nohup) stays ignored.
class SignalGuard {
 public:
  SignalGuard();
  ~SignalGuard();
  SignalGuard(const SignalGuard&) = delete;
  SignalGuard& operator=(const SignalGuard&) = delete;

 private:
  struct sigaction old_int_ {}, old_term_ {};
};

// The signal received since the guard was installed, or 0.
int pending_signal();

// "SIGINT", "SIGTERM", else "a signal": for messages.
const char* signal_name(int signal);

}  // namespace pd
