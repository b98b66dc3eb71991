// The solver's one way to read a whole input file (case.json, node file, checkpoint): a regular
// file only, so that a directory or a device (/dev/zero) given by mistake is a clear error instead
// of "basic_filebuf::underflow" or a read that never ends (issue 17, item 9).
#pragma once
#include <filesystem>
#include <string>

namespace pd {

// The bytes of `path`; throws pd::Error "<path>: <what> is a directory / is not a regular file /
// cannot be read: <reason>", `what` naming the role of the file ("the case file", "the checkpoint").
std::string read_whole_file(const std::filesystem::path& path, const std::string& what);

}  // namespace pd
