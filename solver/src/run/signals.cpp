// The SIGINT / SIGTERM handler of a run and its guard (run/signals.hpp).
#include "run/signals.hpp"

#include <csignal>

#include <atomic>

namespace pd {

namespace {

// std::atomic, not volatile sig_atomic_t: the signal may arrive on an OpenMP worker thread while
// the main thread reads the flag.
std::atomic<int> g_signal{0};
static_assert(std::atomic<int>::is_always_lock_free, "a signal handler may only touch lock-free atomics");
std::atomic<bool> g_handles_int{false}, g_handles_term{false};

// Records the signal, then restores the default action of both signals it handles, so a second
// SIGINT or SIGTERM kills at once.
extern "C" void record_signal(int signal) {
  g_signal.store(signal);
  if (g_handles_int.load()) std::signal(SIGINT, SIG_DFL);  // signal() is async-signal-safe (POSIX)
  if (g_handles_term.load()) std::signal(SIGTERM, SIG_DFL);
}

}  // namespace

SignalGuard::SignalGuard() {
  g_signal = 0;
  struct sigaction action {};
  action.sa_handler = record_signal;
  sigemptyset(&action.sa_mask);
  action.sa_flags = SA_RESETHAND | SA_RESTART;
  sigaction(SIGINT, &action, &old_int_);
  sigaction(SIGTERM, &action, &old_term_);
  if (old_int_.sa_handler == SIG_IGN) sigaction(SIGINT, &old_int_, nullptr);
  if (old_term_.sa_handler == SIG_IGN) sigaction(SIGTERM, &old_term_, nullptr);
  g_handles_int = old_int_.sa_handler != SIG_IGN;
  g_handles_term = old_term_.sa_handler != SIG_IGN;
}

SignalGuard::~SignalGuard() {
  g_handles_int = false;
  g_handles_term = false;
  sigaction(SIGINT, &old_int_, nullptr);
  sigaction(SIGTERM, &old_term_, nullptr);
}

int pending_signal() { return g_signal.load(); }

const char* signal_name(int signal) { return signal == SIGINT ? "SIGINT" : signal == SIGTERM ? "SIGTERM" : "a signal"; }

}  // namespace pd
