// Test helpers for the tests that run the solver on files: a fresh scratch folder and whole-file reads.
#pragma once
#include <filesystem>
#include <string>

namespace pdtest {

// An empty folder <tmp>/pd_test_<name>_<pid> (removed first if a crashed run left it): the pid
// keeps parallel ctest processes apart.
std::filesystem::path temp_dir(const std::string& name);

// The whole file as bytes ("" if it cannot be read).
std::string slurp(const std::filesystem::path& path);

}  // namespace pdtest
