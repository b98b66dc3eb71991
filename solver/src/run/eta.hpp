// The time left of a run from its recent rate of progress (issue 16 item 5), not from the average
// since the start: a run whose steps get cheaper or dearer (a crack that opens, contact that starts,
// an adaptive step that shrinks) would otherwise be misjudged for most of its length.
#pragma once
#include <cstdint>
#include <deque>

namespace pd {

class EtaEstimator {
 public:
  // window: the share of the run over which the rate is measured. 0.02: from 5 % of a run on, the
  // estimate follows a change of rate made before 3 %, and one made later within 2 % of the run.
  explicit EtaEstimator(double window = kWindow) : window_(window) {}
  static constexpr double kWindow = 0.02;

  // One sample: wall seconds since the loop started, the fraction of the run done (0 … 1) and the
  // steps done. Samples come in order; the caller takes them a few times a second at most.
  void add(double wall, double fraction, std::int64_t step);

  // Wall seconds left at the rate over the last `window` of the run (at least two samples apart);
  // negative while that rate is unknown (fewer than two samples, or no progress between them).
  double seconds_left() const;
  // Steps per wall second over the same samples; negative while unknown.
  double step_rate() const;

 private:
  struct Sample {
    double wall, fraction;
    std::int64_t step;
  };
  double window_;
  std::deque<Sample> samples_;  // the newest sample at or below (newest fraction − window), then later ones
};

}  // namespace pd
