// Reads and writes nodes.vtu exactly as pipeline/formats.md §2 specifies.
#include "io/node_file.hpp"

#include <cmath>
#include <cstdio>
#include <regex>
#include <string>

#include "core/error.hpp"
#include "io/vtu.hpp"

namespace pd {

namespace {

const VtuArray& require(const VtuGrid& g, const std::vector<VtuArray>& section, const std::string& where,
                        const std::string& name, const std::string& type, int components, const std::string& file) {
  const VtuArray* a = g.find(section, name);
  if (!a) throw Error(file + ": " + where + " array '" + name + "' is missing (pipeline/formats.md §2)");
  if (a->type != type || a->components != components)
    throw Error(file + ": " + where + " array '" + name + "' is " + a->type + " × " + std::to_string(a->components) +
                ", expected " + type + " × " + std::to_string(components));
  return *a;
}

}  // namespace

namespace {

constexpr double kMaxCoordinate = 1e150;  // m: its square, 1e300, is still a finite double

std::string format_number(double value) {
  char text[32];
  std::snprintf(text, sizeof text, "%.6g", value);
  return text;
}

Nodes nodes_of(const VtuGrid& g, const std::string& file) {
  Nodes nodes;

  auto scalar_field = [&](const std::string& name, const std::string& type) -> const VtuArray& {
    const VtuArray& a = require(g, g.field_data, "FieldData", name, type, 1, file);
    if (a.tuples() != 1) throw Error(file + ": FieldData '" + name + "' must have exactly 1 tuple");
    return a;
  };
  const int version = values_of<std::int32_t>(scalar_field("pd_node_file_version", "Int32"))[0];
  if (version != kNodeFileVersion)
    throw Error(file + ": pd_node_file_version is " + std::to_string(version) + "; this solver reads version " +
                std::to_string(kNodeFileVersion));
  nodes.dimension = values_of<std::int32_t>(scalar_field("dimension", "Int32"))[0];
  if (nodes.dimension != 2 && nodes.dimension != 3)
    throw Error(file + ": dimension is " + std::to_string(nodes.dimension) + "; expected 2 or 3");
  nodes.grid_spacing = values_of<double>(scalar_field("grid_spacing", "Float64"))[0];
  if (!std::isfinite(nodes.grid_spacing) || !(nodes.grid_spacing > 0.0))
    throw Error(file + ": grid_spacing must be a finite number > 0, got " + std::to_string(nodes.grid_spacing));
  for (const auto& a : g.field_data)
    if (a.name != "pd_node_file_version" && a.name != "dimension" && a.name != "grid_spacing")
      throw Error(file + ": unexpected FieldData array '" + a.name + "'");

  const std::size_t n = g.points_count();
  const auto xyz = values_of<double>(g.points);
  nodes.x = make_vec3(n);
  for (std::size_t i = 0; i < n; ++i)
    for (std::size_t d = 0; d < 3; ++d) {
      const double value = xyz[3 * i + d];
      if (!std::isfinite(value))
        throw Error(file + ": point " + std::to_string(i) + " has a non-finite coordinate");
      // Beyond this a squared distance overflows to infinity (issue 17, item 9: a 1e300 coordinate
      // ended in "internal error … max_size()"). Coordinates are metres: no case comes near.
      if (std::fabs(value) > kMaxCoordinate)
        throw Error(file + ": point " + std::to_string(i) + " has coordinate " + "xyz"[d] + " = " + format_number(value) +
                    " m, beyond ±" + format_number(kMaxCoordinate) + " m (coordinates are in metres); fix the mesh");
      if (nodes.dimension == 2 && d == 2 && value != 0.0)
        throw Error(file + ": point " + std::to_string(i) + " has z = " + std::to_string(value) +
                    " but the file is 2D (z must be 0)");
      nodes.x[d][i] = value;
    }

  nodes.volume = values_of<double>(require(g, g.point_data, "PointData", "volume", "Float64", 1, file));
  for (std::size_t i = 0; i < n; ++i)
    if (!std::isfinite(nodes.volume[i]) || !(nodes.volume[i] > 0.0))
      throw Error(file + ": node " + std::to_string(i) + " has volume " + std::to_string(nodes.volume[i]) +
                  "; every node needs a finite volume > 0");
  nodes.block = values_of<std::int32_t>(require(g, g.point_data, "PointData", "block", "Int32", 1, file));
  for (std::size_t i = 0; i < n; ++i)
    if (nodes.block[i] < 1)
      throw Error(file + ": node " + std::to_string(i) + " has block " + std::to_string(nodes.block[i]) +
                  "; block ids start at 1");

  static const std::regex set_name("set_([A-Za-z_][A-Za-z0-9_]*)");
  for (const auto& a : g.point_data) {
    if (a.name == "volume" || a.name == "block") continue;
    std::smatch match;
    if (!std::regex_match(a.name, match, set_name))
      throw Error(file + ": unexpected PointData array '" + a.name +
                  "' (expected volume, block and set_<name> with <name> matching [A-Za-z_][A-Za-z0-9_]*)");
    if (a.type != "UInt8" || a.components != 1)
      throw Error(file + ": PointData array '" + a.name + "' is " + a.type + " × " + std::to_string(a.components) +
                  ", expected UInt8 × 1");
    NodeSet set{match[1].str(), values_of<std::uint8_t>(a)};
    for (std::size_t i = 0; i < n; ++i)
      if (set.member[i] > 1)
        throw Error(file + ": PointData array '" + a.name + "' has value " + std::to_string(set.member[i]) +
                    " at node " + std::to_string(i) + "; expected 0 or 1");
    nodes.sets.push_back(std::move(set));
  }

  // N vertex cells in point order.
  const auto conn = values_of<std::int64_t>(g.connectivity);
  const auto offs = values_of<std::int64_t>(g.offsets);
  const auto types = values_of<std::uint8_t>(g.types);
  if (types.size() != n)
    throw Error(file + ": " + std::to_string(types.size()) + " cells for " + std::to_string(n) +
                " points; expected one vertex cell per point");
  for (std::size_t i = 0; i < n; ++i)
    if (types[i] != 1 || offs[i] != static_cast<std::int64_t>(i) + 1 || conn[i] != static_cast<std::int64_t>(i))
      throw Error(file + ": cell " + std::to_string(i) + " is not the vertex cell of point " + std::to_string(i));
  if (!g.cell_data.empty()) throw Error(file + ": unexpected CellData array '" + g.cell_data[0].name + "'");
  return nodes;
}

}  // namespace

Nodes read_node_file(const std::filesystem::path& path) { return nodes_of(read_vtu(path), path.string()); }

Nodes parse_node_file(const std::string& text, const std::string& file) { return nodes_of(parse_vtu(text, file), file); }

void write_node_file(const std::filesystem::path& path, const Nodes& nodes) {
  const std::size_t n = nodes.size();
  VtuGrid g;
  g.field_data.push_back(make_array("pd_node_file_version", std::vector<std::int32_t>{kNodeFileVersion}));
  g.field_data.push_back(make_array("dimension", std::vector<std::int32_t>{nodes.dimension}));
  g.field_data.push_back(make_array("grid_spacing", std::vector<double>{nodes.grid_spacing}));
  g.points = make_vec3_array("Points", nodes.x[0], nodes.x[1], nodes.x[2]);
  g.point_data.push_back(make_array("volume", nodes.volume));
  g.point_data.push_back(make_array("block", nodes.block));
  for (const auto& set : nodes.sets) g.point_data.push_back(make_array("set_" + set.name, set.member));
  std::vector<std::int64_t> conn(n), offs(n);
  for (std::size_t i = 0; i < n; ++i) {
    conn[i] = static_cast<std::int64_t>(i);
    offs[i] = static_cast<std::int64_t>(i) + 1;
  }
  g.connectivity = make_array("connectivity", conn);
  g.offsets = make_array("offsets", offs);
  g.types = make_array("types", std::vector<std::uint8_t>(n, 1));
  write_vtu(path, g);
}

}  // namespace pd
