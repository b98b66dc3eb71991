// The node file nodes.vtu (pipeline/formats.md §2): read with every value checked, and written
// (the tests and benchmarks use the writer to make node files; preprocess has its own).
#pragma once
#include <filesystem>
#include <string>

#include "core/nodes.hpp"

namespace pd {

constexpr int kNodeFileVersion = 1;

// Throws pd::Error naming the file and what is wrong.
Nodes read_node_file(const std::filesystem::path& path);

// The same from the file's bytes (`file` only names it in messages); the fuzz targets call this.
Nodes parse_node_file(const std::string& text, const std::string& file);

void write_node_file(const std::filesystem::path& path, const Nodes& nodes);

}  // namespace pd
