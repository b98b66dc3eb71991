// The output and restart schedule (run/schedule.hpp): where steps land, when frames, history rows
// and checkpoints are due.
#include <gtest/gtest.h>

#include <vector>

#include "run/schedule.hpp"

namespace {

// Steps a loop from 0 to `end` at dt as run/loop.cpp does; returns the times of the frames due.
std::vector<double> frame_times(const pd::OutputSettings& output, double end, double dt) {
  const pd::Schedule schedule(output, end);
  pd::LoopState s;
  s.dt = dt;
  std::vector<double> times;
  while (schedule.before_end(s.t)) {
    const pd::NextStep next = schedule.next_step(s);
    s.t = next.landing ? next.target : s.t + next.h;
    ++s.step;
    if (schedule.frame_due(s, next.h)) {
      times.push_back(s.t);
      schedule.frame_written(s);
    }
  }
  EXPECT_EQ(s.t, end);  // the last step lands on the end time exactly
  return times;
}

}  // namespace

TEST(Schedule, EveryTimeLandsExactlyOnEachOutputTime) {
  pd::OutputSettings output;
  output.every_time = 0.1;
  const auto times = frame_times(output, 0.35, 0.03);
  ASSERT_EQ(times.size(), 3u);
  EXPECT_EQ(times[0], 0.1);
  EXPECT_EQ(times[1], 2 * 0.1);
  EXPECT_EQ(times[2], 3 * 0.1);
}

TEST(Schedule, EveryStepsWritesEveryNthStepAndHistoryEveryM) {
  pd::OutputSettings output;
  output.every_steps = 4;
  output.history_every = 3;
  const pd::Schedule schedule(output, 1.0);
  pd::LoopState s;
  std::vector<std::int64_t> frames, rows;
  for (s.step = 1; s.step <= 12; ++s.step) {
    if (schedule.frame_due(s, 0.1)) frames.push_back(s.step);
    else if (schedule.history_due(s)) rows.push_back(s.step);
  }
  EXPECT_EQ(frames, (std::vector<std::int64_t>{4, 8, 12}));
  EXPECT_EQ(rows, (std::vector<std::int64_t>{3, 6, 9}));
}

TEST(Schedule, RestartEveryStepsFiresAtMultiples) {
  pd::OutputSettings output;
  output.every_time = 1.0;
  output.restart_every_steps = 3;
  const pd::Schedule schedule(output, 1.0);
  pd::LoopState s;
  std::vector<std::int64_t> due;
  for (s.step = 1; s.step <= 7; ++s.step)
    if (schedule.restart_due(s)) due.push_back(s.step);
  EXPECT_EQ(due, (std::vector<std::int64_t>{3, 6}));
}

TEST(Schedule, RestartEveryTimeFiresAtTheFirstStepPastEachMultipleWithoutShorteningSteps) {
  pd::OutputSettings output;
  output.every_time = 10.0;
  output.restart_every_time = 0.3;
  const pd::Schedule schedule(output, 1.0);
  pd::LoopState s;
  s.dt = 0.125;
  std::vector<double> due;
  while (s.t < 1.0) {
    EXPECT_EQ(schedule.next_step(s).h, 0.125);  // checkpoints never shorten a step
    s.t += 0.125;
    ++s.step;
    if (schedule.restart_due(s)) due.push_back(s.t);
  }
  EXPECT_EQ(due, (std::vector<double>{0.375, 0.625, 1.0}));
  EXPECT_EQ(s.next_restart_index, 4);
}

TEST(Schedule, AFrameMovesTheNextFrameTimePastIt) {
  pd::OutputSettings output;
  output.every_time = 0.1;
  const pd::Schedule schedule(output, 1.0);
  pd::LoopState s;
  s.step = 7;
  s.t = 0.25;  // a frame off the grid (the last one of a shortened run, say)
  schedule.frame_written(s);
  EXPECT_EQ(s.last_frame_step, 7);
  EXPECT_EQ(s.next_frame_index, 3);
}

TEST(Schedule, TheLastStepAbsorbsATinyRemainder) {
  EXPECT_EQ(pd::steps_to_reach(1.0, 0.1), 10);
  EXPECT_EQ(pd::steps_to_reach(1.0, 0.3), 4);
  pd::OutputSettings output;
  output.every_time = 1.0;
  const pd::Schedule schedule(output, 1.0);
  pd::LoopState s;
  s.dt = 0.1;
  s.t = 1.0 - 0.1 * (1.0 + 0.5e-6);  // a remainder of 1.0000005 dt: stretched, not split
  pd::NextStep next = schedule.next_step(s);
  EXPECT_TRUE(next.landing);
  EXPECT_EQ(next.target, 1.0);
  s.t = 0.5;
  next = schedule.next_step(s);
  EXPECT_FALSE(next.landing);
  EXPECT_EQ(next.h, 0.1);
}

// output.restart_every_wall (issue 36, item 8), on a clock the test sets: due every `every` seconds
// of wall time, never with 0, and after a slow write no sooner than 1/kMaxShare times its length
// after it began, so that checkpoints take at most 3 % of a run.
TEST(WallCheckpoints, DueEveryIntervalOfWallTimeAndNeverWithZero) {
  pd::WallCheckpoints wall(600.0, 0.0);  // the default
  EXPECT_FALSE(wall.due(0.0));
  EXPECT_FALSE(wall.due(599.9));
  EXPECT_TRUE(wall.due(600.0));
  wall.written(600.5, 601.0);  // written in 0.5 s: the interval counts from its start
  EXPECT_FALSE(wall.due(1200.0));
  EXPECT_TRUE(wall.due(1200.5));
  EXPECT_EQ(pd::OutputSettings().restart_every_wall, 600.0);

  const pd::WallCheckpoints off(0.0, 0.0);
  for (const double now : {0.0, 600.0, 1e9}) EXPECT_FALSE(off.due(now)) << now;
}

TEST(WallCheckpoints, ASlowCheckpointPushesTheNextOneToKeepTheirShareAt3Percent) {
  pd::WallCheckpoints wall(10.0, 100.0);  // a loop that started at 100 s on this clock
  EXPECT_FALSE(wall.due(109.0));
  EXPECT_TRUE(wall.due(110.0));
  wall.written(110.0, 116.0);  // 6 s to write: the next no sooner than 6 / 0.03 = 200 s after it began
  EXPECT_NEAR(wall.next(), 310.0, 1e-9);  // 6 / 0.03 in floating point
  EXPECT_FALSE(wall.due(309.9));
  EXPECT_TRUE(wall.due(310.001));
  wall.written(310.0, 310.1);  // fast again: back to every 10 s
  EXPECT_EQ(wall.next(), 320.0);
  // Any checkpoint (also one of restart_every_steps) restarts the count: the wall-time one follows it.
  wall.written(315.0, 315.1);
  EXPECT_FALSE(wall.due(320.0));
  EXPECT_TRUE(wall.due(325.0));
  EXPECT_EQ(pd::WallCheckpoints::kMaxShare, 0.03);
}
