// The SIGINT / SIGTERM / SIGHUP handler of a run and its guard (run/signals.hpp).
#include "run/signals.hpp"

#include <csignal>
#include <ctime>

#include <atomic>
#include <cstdint>

namespace pd {

namespace {

// std::atomic, not volatile sig_atomic_t: the signal may arrive on an OpenMP worker thread while
// the main thread reads the flag.
std::atomic<int> g_signal{0};
std::atomic<std::int64_t> g_first_ns{0}, g_window_ns{0};
static_assert(std::atomic<int>::is_always_lock_free, "a signal handler may only touch lock-free atomics");
static_assert(std::atomic<std::int64_t>::is_always_lock_free, "a signal handler may only touch lock-free atomics");

// clock_gettime is async-signal-safe (POSIX.1-2008, signal-safety(7)); CLOCK_MONOTONIC does not
// jump with the wall clock.
std::int64_t monotonic_ns() {
  timespec now{};
  clock_gettime(CLOCK_MONOTONIC, &now);
  return std::int64_t{now.tv_sec} * 1'000'000'000 + now.tv_nsec;
}

// The first signal is recorded for the loop; a second within the window is the same request and
// is dropped; a later one restores the default action and raises itself, so it kills at once.
// Killing then is safe for the files: every file the solver writes is written under a temporary
// name and renamed (io/atomic_file.hpp), so the previous checkpoint stays whole.
extern "C" void record_signal(int signal) {
  const std::int64_t now = monotonic_ns();
  int none = 0;
  if (g_signal.compare_exchange_strong(none, signal)) {
    g_first_ns.store(now);
    return;
  }
  if (now - g_first_ns.load() < g_window_ns.load()) return;
  std::signal(signal, SIG_DFL);  // signal() and raise() are async-signal-safe (POSIX)
  std::raise(signal);            // blocked inside its own handler: delivered, and fatal, on return
}

}  // namespace

SignalGuard::SignalGuard(double same_request_seconds) {
  g_signal = 0;
  g_first_ns = 0;
  g_window_ns = static_cast<std::int64_t>(same_request_seconds * 1e9);
  struct sigaction action {};
  action.sa_handler = record_signal;
  sigemptyset(&action.sa_mask);
  sigaddset(&action.sa_mask, SIGINT);   // one handler at a time: the first signal is recorded
  sigaddset(&action.sa_mask, SIGTERM);  // with its time before a second one is looked at
  sigaddset(&action.sa_mask, SIGHUP);
  action.sa_flags = SA_RESTART;
  sigaction(SIGINT, &action, &old_int_);
  sigaction(SIGTERM, &action, &old_term_);
  // SIGHUP: the terminal closed (an ssh session dropped) under a run in it. It killed the solver
  // with no checkpoint (issue 36 probe); now it stops the run as SIGTERM does. Under nohup it is
  // ignored, and stays so, as SIGINT and SIGTERM ignored by the parent do.
  sigaction(SIGHUP, &action, &old_hup_);
  if (old_int_.sa_handler == SIG_IGN) sigaction(SIGINT, &old_int_, nullptr);
  if (old_term_.sa_handler == SIG_IGN) sigaction(SIGTERM, &old_term_, nullptr);
  if (old_hup_.sa_handler == SIG_IGN) sigaction(SIGHUP, &old_hup_, nullptr);
}

SignalGuard::~SignalGuard() {
  sigaction(SIGINT, &old_int_, nullptr);
  sigaction(SIGTERM, &old_term_, nullptr);
  sigaction(SIGHUP, &old_hup_, nullptr);
}

int pending_signal() { return g_signal.load(); }

const char* signal_name(int signal) {
  return signal == SIGINT ? "SIGINT" : signal == SIGTERM ? "SIGTERM" : signal == SIGHUP ? "SIGHUP" : "a signal";
}

}  // namespace pd
