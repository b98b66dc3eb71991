// The estimate of the time left from the rate over a window of the run's recent progress (run/eta.hpp).
#include "run/eta.hpp"

namespace pd {

void EtaEstimator::add(double wall, double fraction, std::int64_t step) {
  samples_.push_back(Sample{wall, fraction, step});
  // Keep one sample at or before the window's start, so that the window always spans `window`
  // of the run once that much has been done; older ones are no longer needed.
  while (samples_.size() > 2 && samples_[1].fraction <= fraction - window_) samples_.pop_front();
}

double EtaEstimator::seconds_left() const {
  if (samples_.size() < 2) return -1.0;
  const Sample& first = samples_.front();
  const Sample& last = samples_.back();
  const double progress = last.fraction - first.fraction, wall = last.wall - first.wall;
  if (!(progress > 0.0) || !(wall > 0.0)) return -1.0;
  const double left = last.fraction < 1.0 ? 1.0 - last.fraction : 0.0;
  return left * wall / progress;  // (1 − p) / (Δp/Δwall)
}

double EtaEstimator::step_rate() const {
  if (samples_.size() < 2) return -1.0;
  const Sample& first = samples_.front();
  const Sample& last = samples_.back();
  const double wall = last.wall - first.wall;
  if (!(wall > 0.0)) return -1.0;
  return static_cast<double>(last.step - first.step) / wall;
}

}  // namespace pd
