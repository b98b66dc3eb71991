// The few ways run.log and the run's messages print numbers and nodes, shared by the phases.
#pragma once
#include <cstdint>
#include <string>

#include "core/model.hpp"

namespace pd {

// One number through printf's `fmt` ("%.6g", "%.3f", …).
std::string format(const char* fmt, double value);

// "node 12 at (0.001, 0.002, 0) m": where something happened.
std::string node_text(const Model& model, std::int64_t node);

}  // namespace pd
