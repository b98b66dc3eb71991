// pdsolve --physics CASE.json: the physics of a case's set-up that the Python side needs, computed
// once, here, by the code that runs the case (issue 37, item 5), instead of a second implementation
// in Python. The pre-processor's unit checks and work plan, bench and the tests read it through
// pipeline/solver_physics.py.
#pragma once
#include <filesystem>

#include <nlohmann/json.hpp>

namespace pd {

// The model of CASE.json built exactly as run() builds it (read_case, read_node_file, build_model),
// and from it, as JSON:
//   "stable":  thesis eq. 2.5's step before time.safety_factor (core/model.hpp stable_time_step),
//              null when no node has a bond; "node": the first node (0-based, node-file order) where
//              it is reached, null then too; "safety_factor": time.safety_factor;
//   "exact":   with `exact` only, 2/ω_max (core/stability.hpp exact_time_step);
//   "blocks":  per block in id order, {"name", "micromodulus" c [N/m⁶ in 3D, N/m⁵ in 2D: c·h is the
//              3D one], "critical_stretch" s0 (null: unbreakable)}, the law's constants
//              (core/material.hpp PairConstants);
//   "surface_correction": the method and the least and largest bond factor g over the bonds
//              ([1, 1] without a correction).
nlohmann::json physics_of_case(const std::filesystem::path& case_file, bool exact);

}  // namespace pd
