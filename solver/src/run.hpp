// One solver run: read the case and node file, build the model, loop over time, write output.
#pragma once
#include <cstdint>
#include <filesystem>
#include <optional>

namespace pd {

struct RunOptions {
  std::filesystem::path case_file;
  int threads = 0;                        // 0: OpenMP's default
  std::optional<double> end_time;         // overrides time.end
  std::optional<std::int64_t> max_steps;  // caps time.max_steps
  bool quiet = false;                     // nothing on stdout, no progress line
};

// Exit codes of pdsolve.
enum ExitCode : int { kOk = 0, kInputError = 1, kUsageError = 2, kRunFailed = 3 };

// Throws pd::Error for bad input, always before any output file is written; returns kRunFailed
// (after writing what is valid) if the state becomes non-finite.
int run(const RunOptions& options);

}  // namespace pd
