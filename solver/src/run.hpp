// One solver run: read the case and node file, build the model, loop over time, write output.
#pragma once
#include <cstdint>
#include <filesystem>
#include <functional>
#include <optional>
#include <string>

namespace pd {

struct RunOptions {
  std::filesystem::path case_file;
  int threads = 0;                        // 0: OpenMP's default
  std::optional<double> end_time;         // overrides time.end
  std::optional<std::int64_t> max_steps;  // caps time.max_steps
  bool quiet = false;                     // nothing on stdout, no progress on stderr (run.log still has it)
  double progress_interval = 10.0;        // [s] of wall time between progress lines; 0: none (run/progress.hpp's default)
  // Overrides output.parallel_frames (bench/result_hashes.py compares gathered MPI frames with the
  // serial run's byte for byte without editing the case file).
  std::optional<std::string> parallel_frames;
  std::filesystem::path restart;          // a checkpoint.bin to continue from (empty: start at t = 0)
  // Called after every completed step with the step number (tests raise a signal from it).
  std::function<void(std::int64_t step)> after_step;
};

// Exit codes of pdsolve. Interrupted by SIGINT or SIGTERM after writing a checkpoint: 128 + the
// signal number (130, 143), as a shell reports a process killed by it.
enum ExitCode : int { kOk = 0, kInputError = 1, kUsageError = 2, kRunFailed = 3, kFolderInUse = 75 };
constexpr int kInterruptedBase = 128;

// Throws pd::Error for bad input, always before any output file is written; returns kRunFailed
// (after writing what is valid) if the state becomes non-finite, 128 + signal after SIGINT/SIGTERM
// (a checkpoint is written first; run.cpp installs the handlers for the duration of the call).
int run(const RunOptions& options);

}  // namespace pd
