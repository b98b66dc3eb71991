// Reads the resolved case.json (pipeline/formats.md §3) and checks every value again; an error
// names the file and the key, e.g. "out/x/case.json: time.safety_factor: must be > 0, got -1".
#pragma once
#include <filesystem>
#include <string>

#include "core/case.hpp"

namespace pd {

constexpr int kCaseFormatVersion = 1;

Case read_case(const std::filesystem::path& path);

// The same from text (the path only names the file in messages and resolves relative paths).
Case parse_case(const std::string& text, const std::filesystem::path& path);

}  // namespace pd
