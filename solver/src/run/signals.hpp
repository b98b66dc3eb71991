// SIGINT / SIGTERM / SIGHUP during a run: the handler only records the signal; the time loop asks after
// each step, writes a checkpoint and stops (solver/README.md, "Checkpoint and restart").
#pragma once
#include <signal.h>  // struct sigaction (POSIX)

namespace pd {

// Signals that arrive within this many seconds of the first are the same request to stop: a
// SIGTERM to a process group (timeout(1), CI runners, SLURM, systemd) reaches the solver both
// directly and forwarded by make, and the second copy must not kill the run while it writes its
// checkpoint (issue 17, item 4). A signal after the window means "stop now": it kills at once.
inline constexpr double kSameRequestSeconds = 2.0;

// Installs the handlers for its lifetime and restores the caller's on destruction. A signal the
// caller ignores (SIGINT of a background job of a script, nohup) stays ignored.
class SignalGuard {
 public:
  explicit SignalGuard(double same_request_seconds = kSameRequestSeconds);
  ~SignalGuard();
  SignalGuard(const SignalGuard&) = delete;
  SignalGuard& operator=(const SignalGuard&) = delete;

 private:
  struct sigaction old_int_ {}, old_term_ {}, old_hup_ {};
};

// The signal received since the guard was installed, or 0.
int pending_signal();

// "SIGINT", "SIGTERM", "SIGHUP", else "a signal": for messages.
const char* signal_name(int signal);

}  // namespace pd
