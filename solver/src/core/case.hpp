// The resolved case (pipeline/formats.md §3) as plain values, after io/case_reader checked them.
#pragma once
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "core/material.hpp"

namespace pd {

struct BoundaryCondition {
  std::string set;
  std::string kind;  // displacement | velocity | body_force
  int component = 0;
  std::vector<double> times, values;  // piecewise linear, held constant outside
};

struct InitialCondition {
  std::string set;
  std::string kind;  // velocity | displacement
  int component = 0;
  double value = 0.0;
};

struct TimeSettings {
  double end = 0.0;
  std::string integrator = "verlet";
  std::string dt_rule = "stable";  // "stable" or "fixed"
  double dt_value = 0.0;           // the number when dt_rule == "fixed"
  double safety_factor = 0.8;
  std::int64_t max_steps = 100000000;
};

struct OutputSettings {
  std::optional<double> every_time;        // s
  std::optional<std::int64_t> every_steps;
  std::int64_t history_every = 1;
};

struct Case {
  std::filesystem::path file;  // case.json itself
  std::string name, source, title;
  std::filesystem::path nodes_file, output_dir;  // resolved against the case.json directory
  int dimension = 3;
  std::string analysis = "3d";
  double thickness = 0.0;  // h [m], 2D only
  double grid_spacing = 0.0;
  double horizon = 0.0;
  std::vector<BlockMaterial> blocks;
  std::vector<std::string> no_fail_sets, node_sets;
  std::vector<BoundaryCondition> boundary_conditions;
  std::vector<InitialCondition> initial_conditions;
  double damping = 0.0;  // α [1/s]
  TimeSettings time;
  OutputSettings output;
};

}  // namespace pd
