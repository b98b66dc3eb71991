// Regular lattices and in-memory cases for the tests and benchmarks.
#include "lattice.hpp"

namespace pdtest {

pd::Nodes cubic_lattice(int nx, int ny, int nz, double dx, int dimension, double thickness) {
  pd::Nodes nodes;
  nodes.dimension = dimension;
  nodes.grid_spacing = dx;
  const auto n = static_cast<std::size_t>(nx) * static_cast<std::size_t>(ny) * static_cast<std::size_t>(nz);
  nodes.x = pd::make_vec3(n);
  const double volume = dimension == 3 ? dx * dx * dx : dx * dx * thickness;
  nodes.volume.assign(n, volume);
  nodes.block.assign(n, 1);
  for (int k = 0; k < nz; ++k)
    for (int j = 0; j < ny; ++j)
      for (int i = 0; i < nx; ++i) {
        const std::size_t p = node_index(i, j, k, nx, ny);
        nodes.x[0][p] = i * dx;
        nodes.x[1][p] = j * dx;
        nodes.x[2][p] = k * dx;
      }
  return nodes;
}

pd::Case lattice_case(int dimension, const std::string& analysis, double dx, double horizon, double youngs_modulus,
                      double density, double fracture_energy, double thickness) {
  pd::Case c;
  c.file = "memory-case.json";
  c.nodes_file = "memory-nodes.vtu";
  c.dimension = dimension;
  c.analysis = analysis;
  c.thickness = thickness;
  c.grid_spacing = dx;
  c.horizon = horizon;
  pd::BlockMaterial b;
  b.name = "body";
  b.density = density;
  b.parameters["youngs_modulus"] = youngs_modulus;
  if (fracture_energy >= 0.0) b.parameters["fracture_energy"] = fracture_energy;
  c.blocks.push_back(b);
  c.time.end = 1.0;
  c.output.every_steps = 1;
  return c;
}

pd::Nodes bar_with_grips(int nx, int ny, int nz, double dx) {
  pd::Nodes nodes = cubic_lattice(nx, ny, nz, dx, 3);
  pd::NodeSet left{"left", std::vector<std::uint8_t>(nodes.size(), 0)}, right{"right", left.member};
  for (std::size_t i = 0; i < nodes.size(); ++i) {
    left.member[i] = nodes.x[0][i] < 1.5 * dx;
    right.member[i] = nodes.x[0][i] > (nx - 2.5) * dx;
  }
  nodes.sets = {left, right};
  return nodes;
}

void clamp_left_pull_right(pd::Case& c, double pull, double end, bool right_held_across) {
  for (int d = 0; d < 3; ++d) c.boundary_conditions.push_back({"left", "displacement", d, {0.0}, {0.0}});
  c.boundary_conditions.push_back({"right", "displacement", 0, {0.0, end}, {0.0, pull}});
  if (right_held_across)
    for (int d = 1; d < 3; ++d) c.boundary_conditions.push_back({"right", "displacement", d, {0.0}, {0.0}});
}

pd::Model held_at_left(pd::Case c, pd::Nodes nodes, double dx) {
  pd::NodeSet left{"left", std::vector<std::uint8_t>(nodes.size(), 0)};
  for (std::size_t i = 0; i < nodes.size(); ++i) left.member[i] = nodes.x[0][i] < 1.5 * dx;
  nodes.sets = {left};
  for (int d = 0; d < c.dimension; ++d) c.boundary_conditions.push_back({"left", "displacement", d, {0.0}, {0.0}});
  return pd::build_model(c, std::move(nodes));
}

void add_stiff_top_and_no_fail_bottom(pd::Case& c, pd::Nodes& nodes, double dx, double youngs_modulus,
                                      double fracture_energy) {
  pd::BlockMaterial stiff = c.blocks[0];
  stiff.name = "stiff";
  stiff.parameters["youngs_modulus"] = youngs_modulus;
  stiff.parameters["fracture_energy"] = fracture_energy;
  c.blocks.push_back(stiff);
  pd::NodeSet bottom{"bottom", std::vector<std::uint8_t>(nodes.size(), 0)};
  for (std::size_t i = 0; i < nodes.size(); ++i) {
    if (nodes.x[2][i] > 3.5 * dx) nodes.block[i] = 2;
    bottom.member[i] = nodes.x[2][i] < 0.5 * dx;
  }
  nodes.sets.push_back(bottom);
  c.no_fail_sets = {"bottom"};
}

}  // namespace pdtest
