// Reads the resolved case.json (pipeline/formats.md §3) and checks every value again; an error
// names the file and the key, e.g. "out/x/case.json: time.safety_factor: must be > 0, got -1".
#pragma once
#include <array>
#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include "core/case.hpp"

namespace pd {

constexpr int kCaseFormatVersion = 1;

// Defaults the reader fills in that no struct of core/case.hpp holds (pdsolve --describe prints them).
inline constexpr const char* kDefaultOutputDir = ".";
inline constexpr std::array<double, 3> kDefaultCylinderAxis{0.0, 0.0, 1.0};  // z: a disk in a 2D case

// The keys parse_case accepts in each object of case.json, by where the object sits: "" (the top
// level), "boundary_conditions[]", "initial_conditions[]", "indenters[]", "cracks[]", and the
// settings sections ("time", "adaptive", "quasi_static", "implicit", "mixed", "output",
// "contact"), whose keys are their tables' (io/case_settings.cpp). The block keys are read_block's
// (io/describe.hpp describe_material_keys).
const std::map<std::string, std::vector<std::string>>& case_keys();

Case read_case(const std::filesystem::path& path);

// The same from text (the path only names the file in messages and resolves relative paths).
Case parse_case(const std::string& text, const std::filesystem::path& path);

}  // namespace pd
