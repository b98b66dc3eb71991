// The solver's one way to write a file that a reader must never see half-written (frames,
// frames.pvd, run.log, checkpoint.bin): a temporary `<path>.part` beside it, renamed into place.
#pragma once
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

namespace pd {

// Writes `text` to `path` through `<path>.part` and a rename; throws pd::Error naming the file.
void write_file_atomically(const std::filesystem::path& path, const std::string& text);
// The same for text given in pieces, written one after the other (a frame's arrays are not first
// copied into one string).
void write_file_atomically(const std::filesystem::path& path, const std::vector<std::string_view>& pieces);

}  // namespace pd
