// run.log as RunLog writes it (run/run_log.hpp): the file holds every line said so far after each
// one, a restart appends, the ranks without output say nothing, and the loop's notes read as they
// always have (tests and users grep them).
#include <gtest/gtest.h>

#include <filesystem>
#include <string>

#include "files.hpp"
#include "run/run_log.hpp"

namespace {

TEST(RunLog, TheFileHoldsEveryLineAfterEachAndARestartAppends) {
  const std::filesystem::path dir = pdtest::temp_dir("run_log_append");
  const std::filesystem::path path = dir / "run.log";
  {
    pd::RunLog log(path, /*quiet=*/true);
    log.line("first");
    EXPECT_EQ(pdtest::slurp(path), "first\n");
    log.note("a note");
    log.stopped_at_max_steps(12);
    EXPECT_EQ(pdtest::slurp(path), "first\na note\nnote: stopped at max_steps 12 before the end time\n");
  }
  pd::RunLog restarted(path, true, /*append=*/true);
  restarted.line("after the restart");
  EXPECT_EQ(pdtest::slurp(path),
            "first\na note\nnote: stopped at max_steps 12 before the end time\nafter the restart\n");
  pd::RunLog fresh(path, true);  // a run from t = 0 starts run.log anew
  fresh.line("anew");
  EXPECT_EQ(pdtest::slurp(path), "anew\n");
  std::filesystem::remove_all(dir);
}

TEST(RunLog, TheFramesRemovedAfterABlowUpAreCountedWithWhereTheyStarted) {
  const std::filesystem::path dir = pdtest::temp_dir("run_log_dropped");
  pd::RunLog log(dir / "run.log", true);
  log.frames_dropped(3, 120, "while the energy grew ×1.5 a step", 2.5e-6);
  EXPECT_EQ(pdtest::slurp(dir / "run.log"),
            "removed 3 frame(s) written from step 120 on, while the energy grew ×1.5 a step; the last frame kept, at "
            "t = 2.5e-06 s, is the last before the growth\n");
  std::filesystem::remove_all(dir);
}

TEST(RunLog, ARankWithoutOutputWritesNothing) {
  const std::filesystem::path dir = pdtest::temp_dir("run_log_silent");
  testing::internal::CaptureStdout();
  testing::internal::CaptureStderr();
  pd::RunLog silent(std::filesystem::path(), /*quiet=*/false);
  silent.line("a line");
  silent.error("an error");
  silent.frames_dropped(1, 2, "while", 0.0);
  EXPECT_EQ(testing::internal::GetCapturedStdout(), "");
  EXPECT_EQ(testing::internal::GetCapturedStderr(), "");
  EXPECT_TRUE(std::filesystem::is_empty(dir));
  std::filesystem::remove_all(dir);
}

TEST(RunLog, LinesGoToStdoutUnlessQuietErrorsToStderrAlwaysNotesToTheFileOnly) {
  const std::filesystem::path dir = pdtest::temp_dir("run_log_streams");
  testing::internal::CaptureStdout();
  testing::internal::CaptureStderr();
  pd::RunLog log(dir / "run.log", /*quiet=*/false);
  log.line("a line");
  log.note("a note");
  log.error("an error");
  EXPECT_EQ(testing::internal::GetCapturedStdout(), "a line\n");
  EXPECT_EQ(testing::internal::GetCapturedStderr(), "an error\n");
  EXPECT_EQ(pdtest::slurp(dir / "run.log"), "a line\na note\nan error\n");
  std::filesystem::remove_all(dir);
}

}  // namespace
