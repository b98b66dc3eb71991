// The time loop's watches (run/watches.hpp): the blow-up watch fires at the 20th step in a row of
// ×1.5 energy growth and not before; the indenter-depth watch warns once; their messages word for word.
#include <gtest/gtest.h>

#include "run/watches.hpp"

TEST(BlowUpWatch, FiresAtTheTwentiethGrowingStepAndNotAtTheNineteenth) {
  pd::EnergyGrowth memory;
  pd::BlowUpWatch watch(memory);
  double energy = 1.0;
  EXPECT_FALSE(watch.grew_too_long(energy));  // the first energy: nothing to compare with
  for (int k = 1; k <= 19; ++k) {
    energy *= 2.0;
    EXPECT_FALSE(watch.grew_too_long(energy)) << k;
  }
  EXPECT_EQ(memory.streak, 19);
  energy *= 2.0;
  EXPECT_TRUE(watch.grew_too_long(energy));
  EXPECT_EQ(memory.streak_start, 1.0);
  EXPECT_EQ(watch.growth_message(energy, 21, 0.5, "node 3 at (1, 2, 0) m", "CAUSE"),
            "pdsolve: error: the energy grew from 1 J to 1.05e+06 J in the 20 steps up to and after step 21 (t = 0.5 s), "
            "at least ×1.5 every step: the run is unstable, most likely starting at node 3 at (1, 2, 0) m (the largest "
            "speed); CAUSE; stopped without writing this state, the last frame written is the last valid one");
}

TEST(BlowUpWatch, AStepThatGrowsLessThanOneAndAHalfRestartsTheStreak) {
  pd::EnergyGrowth memory;
  pd::BlowUpWatch watch(memory);
  double energy = 1.0;
  watch.grew_too_long(energy);
  for (int k = 0; k < 19; ++k) EXPECT_FALSE(watch.grew_too_long(energy *= 1.6));
  EXPECT_FALSE(watch.grew_too_long(energy *= 1.5));  // ×1.5 exactly is not growth above ×1.5
  EXPECT_EQ(memory.streak, 0);
  for (int k = 0; k < 19; ++k) EXPECT_FALSE(watch.grew_too_long(energy *= 1.6));
  EXPECT_TRUE(watch.grew_too_long(energy *= 1.6));
}

TEST(BlowUpWatch, ZeroEnergyNeverStartsAStreak) {
  pd::EnergyGrowth memory;
  pd::BlowUpWatch watch(memory);
  for (int k = 0; k < 30; ++k) EXPECT_FALSE(watch.grew_too_long(0.0));
  EXPECT_FALSE(watch.grew_too_long(1.0));  // from 0: not a growth ×1.5 of a positive energy
  EXPECT_EQ(memory.streak, 0);
}

TEST(BlowUpWatch, TheLikelyCauseBlamesTheStepOnlyForAnExplicitStepAboveTheLimit) {
  EXPECT_EQ(pd::BlowUpWatch::likely_cause(2e-7, 1e-7, 5e-8, true),
            "dt = 2e-07 s is 2 × the exact stability limit 1e-07 s (eq. 2.5: 5e-08 s): the time step is above the "
            "stability limit; use time.dt: stable or exact with safety_factor < 1");
  const std::string within = "the step is within the linear limit, so look for contact stiffness, large deformation or "
                             "a load that makes the state jump";
  EXPECT_EQ(pd::BlowUpWatch::likely_cause(2e-7, 1e-7, 5e-8, false),
            "dt = 2e-07 s is 2 × the exact stability limit 1e-07 s (eq. 2.5: 5e-08 s): " + within);
  // An explicit step below the linear limit: the limit dropped (large deformation); contact
  // stiffness is named only when the scene has contact (issue 17, item 12: the membrane, which has
  // none, was told to look for contact stiffness).
  EXPECT_EQ(pd::BlowUpWatch::likely_cause(5e-8, 1e-7, 5e-8, true),
            "dt = 5e-08 s is 0.5 × the exact stability limit 1e-07 s (eq. 2.5: 5e-08 s): the step is within the "
            "linear limit, which large deformation lowers; use a smaller time.safety_factor (e.g. 0.8)");
  EXPECT_EQ(pd::BlowUpWatch::likely_cause(5e-8, 1e-7, 5e-8, true, true),
            "dt = 5e-08 s is 0.5 × the exact stability limit 1e-07 s (eq. 2.5: 5e-08 s): the step is within the "
            "linear limit, which large deformation lowers and contact stiffness (contact.stiffness_factor) is not "
            "part of; use a smaller time.safety_factor (e.g. 0.8) or a smaller contact.stiffness_factor");
  EXPECT_EQ(pd::BlowUpWatch::non_finite_message("node 1 at (0, 0, 0) m", 4, 1e-6, "node 2 at (1, 0, 0) m", "CAUSE"),
            "pdsolve: error: non-finite displacement or velocity at node 1 at (0, 0, 0) m after step 4 (t = 1e-06 s; the "
            "largest finite speed is at node 2 at (1, 0, 0) m); CAUSE; stopped without writing this state, the last "
            "frame written is the last valid one");
}

// E + D against E(0) + max(W, 0): ×10 stops, ×2 marks where the frames start to be dropped.
TEST(EnergyBalanceWatch, StopsAboveTenTimesTheEnergyGivenAndRemembersWhereTwoTimesBegan) {
  pd::EnergyBalanceWatch watch(true);
  watch.start(1.0, 0.0, 0.0, 0.0);                  // 1 J at step 0
  EXPECT_FALSE(watch.broken(1, 1.02, 0.0, 0.0));    // Verlet's few per cent
  EXPECT_FALSE(watch.broken(2, 0.5, 0.6, 0.0));     // damping took 0.6 J: held 1.1 J
  EXPECT_EQ(watch.suspect_from(), -1);
  EXPECT_FALSE(watch.broken(3, 2.5, 0.0, 0.0));     // 2.5 × : suspect from step 3
  EXPECT_EQ(watch.suspect_from(), 3);
  EXPECT_FALSE(watch.broken(4, 1.5, 0.0, 0.0));     // back below 2 ×: not suspect any more
  EXPECT_EQ(watch.suspect_from(), -1);
  EXPECT_FALSE(watch.broken(5, 3.0, 0.0, 0.0));
  EXPECT_FALSE(watch.broken(6, 10.0, 0.0, 0.0));    // 10 × exactly is not above
  EXPECT_TRUE(watch.broken(7, 10.5, 0.0, 0.0));
  EXPECT_EQ(watch.suspect_from(), 5);
  EXPECT_EQ(watch.message(7, 2e-3, 10.5, 0.0, 0.0, "node 3 at (1, 2, 0) m", "CAUSE"),
            "pdsolve: error: after step 7 (t = 0.002 s) the kinetic, strain and contact energy plus the damping work "
            "are 10.5 J, 10.5 × the energy the run was given (1 J at the start + 0 J of external work; a sound run "
            "stays near 1 ×, this one passed 2 × at step 5): the energy balance is broken and the run is unstable, "
            "most likely starting at node 3 at (1, 2, 0) m (the largest speed); CAUSE; stopped without writing this state");
}

TEST(EnergyBalanceWatch, ExternalWorkAndBrokenBondsAreEnergyGivenAndAnImplicitRunIsNotWatched) {
  pd::EnergyBalanceWatch watch(true);
  watch.start(0.0, 0.0, 0.0, 0.0);                  // a body at rest, then pulled
  EXPECT_FALSE(watch.broken(1, 5.0, 0.0, 0.0));     // nothing given yet: no comparison
  EXPECT_FALSE(watch.broken(2, 9.0, 0.0, 1.0));     // 9 × the 1 J of work
  EXPECT_TRUE(watch.broken(3, 11.0, 0.0, 1.0));
  pd::EnergyBalanceWatch restarted(true);
  restarted.start(3.0, 1.0, 2.0, 4.0);              // a restart: E(0) = E + D + B − W = 2 J
  EXPECT_FALSE(restarted.broken(10, 50.0, 1.0, 4.0));  // 51 J ≤ 10 × (2 + 4) J
  EXPECT_TRUE(restarted.broken(11, 60.0, 1.0, 4.0));
  pd::EnergyBalanceWatch off(false);
  off.start(1.0, 0.0, 0.0, 0.0);
  EXPECT_FALSE(off.broken(1, 1e30, 0.0, 0.0));
}

TEST(IndenterDepthWatch, WarnsOnceWhenTheStepExceedsTheIndentersLimit) {
  const auto name = [] { return std::string("ball"); };
  const auto where = [] { return std::string("node 5 at (0.1, 0, 0) m"); };
  pd::IndenterStepLimit limit;
  limit.node = 5, limit.indenter = 0, limit.depth = 2e-4, limit.dt = 1e-7;

  pd::IndenterDepthWatch off(false);
  EXPECT_FALSE(off.watching());
  EXPECT_FALSE(off.check(limit, 1, 1e-7, 2e-7, name, where));

  pd::IndenterDepthWatch watch(true);
  pd::IndenterStepLimit outside;  // no node inside: nothing
  EXPECT_FALSE(watch.check(outside, 1, 1e-7, 2e-7, name, where));
  EXPECT_FALSE(watch.check(limit, 2, 2e-7, 0.9e-7, name, where));  // below the limit
  const auto warning = watch.check(limit, 3, 3e-7, 2e-7, name, where);
  ASSERT_TRUE(warning);
  EXPECT_EQ(*warning,
            "warning: step 3 (t = 3e-07 s): indenter 'ball' is 0.0002 m deep at node 5 at (0.1, 0, 0) m; with its "
            "stiffness 2K·h the step is guaranteed stable only below 1e-07 s < dt 2e-07 s: the run may blow up (lower "
            "indenters[].stiffness or time.safety_factor); warned once");
  EXPECT_FALSE(watch.watching());
  EXPECT_FALSE(watch.check(limit, 4, 4e-7, 2e-7, name, where));  // once
}
