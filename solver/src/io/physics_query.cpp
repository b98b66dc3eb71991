// pdsolve --physics (physics_query.hpp).
#include "io/physics_query.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include "core/model.hpp"
#include "core/stability.hpp"
#include "io/case_reader.hpp"
#include "io/node_file.hpp"

namespace pd {

namespace {

// +inf (an unbreakable block, no bond) as JSON's null: nlohmann would write it as null anyway, but
// say so here rather than rely on it.
nlohmann::json finite_or_null(double value) { return std::isfinite(value) ? nlohmann::json(value) : nlohmann::json(); }

}  // namespace

nlohmann::json physics_of_case(const std::filesystem::path& case_file, bool exact) {
  const Case c = read_case(case_file);
  const Model model = build_model(c, read_node_file(c.nodes_file));
  // Eq. 2.5 per node, as stable_time_step takes it (the same expression, so the least of these is
  // its value bit for bit), and the first node that reaches it.
  const std::size_t n = model.nodes.size();
  std::vector<double> dt(n, std::numeric_limits<double>::infinity());
#pragma omp parallel for schedule(static)
  for (std::int64_t i = 0; i < static_cast<std::int64_t>(n); ++i) {
    const double sum = node_stiffness(model, static_cast<std::size_t>(i));
    if (sum > 0.0) dt[static_cast<std::size_t>(i)] = std::sqrt(2.0 * model.density[static_cast<std::size_t>(i)] / sum);
  }
  const auto least = std::min_element(dt.begin(), dt.end());
  const bool bonded = least != dt.end() && std::isfinite(*least);
  nlohmann::json out = {{"case", case_file.string()},
                        {"stable", bonded ? nlohmann::json(*least) : nlohmann::json()},
                        {"node", bonded ? nlohmann::json(least - dt.begin()) : nlohmann::json()},
                        {"safety_factor", c.time.safety_factor}};
  if (exact) out["exact"] = exact_time_step(model);
  nlohmann::json blocks = nlohmann::json::array();
  for (std::size_t b = 0; b < c.blocks.size(); ++b) {
    const PairConstants& k = model.material.block[b];
    blocks.push_back({{"name", c.blocks[b].name},
                      {"micromodulus", k.micromodulus},
                      {"critical_stretch", finite_or_null(k.critical_stretch)}});
  }
  out["blocks"] = blocks;
  double g_min = 1.0, g_max = 1.0;
  const auto bonds = static_cast<std::size_t>(model.bonds.offsets.empty() ? 0 : model.bonds.offsets.back());
  for (std::size_t k = 0; k < bonds; ++k) {
    const double g = model.bonds.factor(k);
    g_min = k == 0 ? g : std::min(g_min, g);
    g_max = k == 0 ? g : std::max(g_max, g);
  }
  out["surface_correction"] = {{"method", c.surface_correction}, {"bond_factor", {g_min, g_max}}};
  return out;
}

}  // namespace pd
