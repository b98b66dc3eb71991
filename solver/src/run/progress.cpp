// The progress line of a run (run/progress.hpp).
#include "run/progress.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace pd {

namespace {

// Samples for the time-left estimate at most this often [s]: a clock read per step is cheap, a
// sample kept per step of a million-step run is not.
constexpr double kSampleEvery = 0.25;
constexpr double kTerminalEvery = 0.5;  // the updating line, as before issue 16

}  // namespace

std::string duration_text(double seconds) {
  if (!std::isfinite(seconds) || seconds < 0) return "?";
  char buffer[32];
  const auto s = static_cast<long long>(seconds + 0.5);
  if (s >= 3600) std::snprintf(buffer, sizeof buffer, "%lldh%02lldm", s / 3600, (s / 60) % 60);
  else if (s >= 60) std::snprintf(buffer, sizeof buffer, "%lldm%02llds", s / 60, s % 60);
  else std::snprintf(buffer, sizeof buffer, "%llds", s);
  return buffer;
}

Progress::Progress(const ProgressSettings& settings, double end, std::int64_t max_steps, std::int64_t steps_expected,
                   RunLog* log)
    : settings_(settings), end_(end), max_steps_(max_steps), steps_expected_(steps_expected), log_(log) {}

double Progress::fraction(double t, std::int64_t step) const {
  // The larger of the two limits that end a run: time.end or the step cap.
  return std::min(1.0, std::max(t / end_, static_cast<double>(step) / static_cast<double>(max_steps_)));
}

std::string Progress::line(double t, std::int64_t step) const {
  const double rate = eta_.step_rate();
  char buffer[256], of[32] = "";
  if (steps_expected_ > 0) std::snprintf(of, sizeof of, "/%lld", static_cast<long long>(steps_expected_));
  std::snprintf(buffer, sizeof buffer, "progress: step %lld%s, t = %.4g/%.4g s, %.1f %%, %s steps/s, ETA %s",
                static_cast<long long>(step), of, t, end_,
                100.0 * fraction(t, step), rate >= 0.0 ? std::to_string(std::lround(rate)).c_str() : "?",
                duration_text(eta_.seconds_left()).c_str());
  return buffer;
}

void Progress::after_step(double t, std::int64_t step, double wall) {
  const bool terminal = settings_.terminal && settings_.to_stderr;
  const bool lines = settings_.interval > 0.0;
  if (!terminal && !lines) return;
  if (last_sample_ < 0.0 || wall - last_sample_ >= kSampleEvery) {
    last_sample_ = wall;
    eta_.add(wall, fraction(t, step), step);
  }
  if (terminal && wall - last_terminal_ > kTerminalEvery) {
    last_terminal_ = wall;
    std::fprintf(stderr, "\r%s   ", line(t, step).c_str() + 10);  // without "progress: "
    std::fflush(stderr);
    shown_ = true;
  }
  if (lines && wall - last_line_ >= settings_.interval) {
    last_line_ = wall;
    const std::string text = line(t, step);
    if (settings_.to_stderr && !settings_.terminal) {
      std::fprintf(stderr, "%s\n", text.c_str());
      std::fflush(stderr);
    }
    if (log_) log_->note(text);
  }
}

void Progress::clear() const {
  if (shown_) std::fprintf(stderr, "\r%100s\r", "");
}

}  // namespace pd
