// The node cloud in structure-of-arrays form: reference positions x, volumes V, blocks, node sets.
#pragma once
#include <array>
#include <cstdint>
#include <string>
#include <vector>

namespace pd {

// Three contiguous arrays, one per component: positions and displacements always have three
// components, also in 2D (a membrane may move out of plane).
using Vec3Array = std::array<std::vector<double>, 3>;

inline Vec3Array make_vec3(std::size_t n, double value = 0.0) {
  return {std::vector<double>(n, value), std::vector<double>(n, value), std::vector<double>(n, value)};
}

struct NodeSet {
  std::string name;
  std::vector<std::uint8_t> member;  // 1 if the node belongs to the set
};

struct Nodes {
  int dimension = 3;
  double grid_spacing = 0.0;        // dx [m]
  Vec3Array x;                      // reference positions [m]
  std::vector<double> volume;       // V [m³] (2D: area × thickness)
  std::vector<std::int32_t> block;  // block id ≥ 1
  std::vector<NodeSet> sets;

  std::size_t size() const { return volume.size(); }

  const NodeSet* find_set(const std::string& name) const {
    for (const auto& set : sets)
      if (set.name == name) return &set;
    return nullptr;
  }
};

}  // namespace pd
