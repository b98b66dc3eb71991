// The solver's one way to write a file that a reader must never see half-written (frames,
// frames.pvd, run.log, checkpoint.bin): a temporary `<path>.part` beside it, renamed into place.
#pragma once
#include <cstddef>
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

#include "core/error.hpp"

namespace pd {

// Whether a file must survive a power cut once written: `synced` flushes it to the disk (fsync)
// before the rename and the folder after it, so that a crash never leaves a renamed but empty
// file in place of the last good one. The checkpoint is written so (issue 36, item 8: a power
// cut must lose minutes, not the run); frames and logs, written far more often, are not.
enum class Durability { renamed, synced };
// Writes `text` to `path` through `<path>.part` and a rename; throws pd::Error naming the file (a
// DiskFull when the disk or the quota is full). A failed write leaves no .part behind.
void write_file_atomically(const std::filesystem::path& path, const std::string& text,
                           Durability durability = Durability::renamed);
// The same for text given in pieces, written one after the other (a frame's arrays are not first
// copied into one string).
void write_file_atomically(const std::filesystem::path& path, const std::vector<std::string_view>& pieces,
                           Durability durability = Durability::renamed);

// A write that failed because the file system is full (ENOSPC) or the quota is used up (EDQUOT):
// a failed run of its own (exit 3), with the message "disk full writing <file>: free N MB and run
// make again" (issue 17, item 6).
struct DiskFull : Error {
  using Error::Error;
};

// Throws DiskFull for ENOSPC / EDQUOT, else pd::Error "<file>: <what>: <strerror>". `bytes` is the
// size of the write that failed: the space to free is at least that (1 MB at least).
[[noreturn]] void throw_write_error(const std::filesystem::path& file, const std::string& what, int error_number,
                                    std::size_t bytes);

}  // namespace pd
