// Writes the seed corpus of the fuzz targets: small valid node files, frames, case.json files and
// checkpoints made by the solver's own writers, one directory per target (usage: pd_fuzz_seeds DIR).
#include <filesystem>
#include <fstream>
#include <iostream>
#include <string>
#include <vector>

#include "integrators/integrator.hpp"
#include "io/checkpoint.hpp"
#include "io/node_file.hpp"
#include "io/vtu.hpp"

namespace fs = std::filesystem;

namespace {

// nx × ny nodes (× nz in 3D) at spacing dx, with a node set "left" and two blocks.
pd::Nodes lattice(int nx, int ny, int nz, int dimension) {
  pd::Nodes n;
  n.dimension = dimension;
  n.grid_spacing = 0.5;
  const auto count = static_cast<std::size_t>(nx * ny * nz);
  n.x = pd::make_vec3(count);
  n.volume.assign(count, 0.125);
  n.block.assign(count, 1);
  pd::NodeSet left{"left", std::vector<std::uint8_t>(count, 0)};
  std::size_t i = 0;
  for (int k = 0; k < nz; ++k)
    for (int j = 0; j < ny; ++j)
      for (int m = 0; m < nx; ++m, ++i) {
        n.x[0][i] = 0.5 * m;
        n.x[1][i] = 0.5 * j;
        n.x[2][i] = 0.5 * k;
        left.member[i] = m == 0;
        n.block[i] = m < nx / 2 ? 1 : 2;
      }
  n.sets.push_back(left);
  return n;
}

// A result frame: vertex cells plus two broken-bond lines with CellData (pipeline/formats.md §4).
pd::VtuGrid frame() {
  pd::VtuGrid g;
  g.field_data.push_back(pd::make_array("TIME", std::vector<double>{1.5e-3}));
  g.field_data.push_back(pd::make_array("step", std::vector<std::int64_t>{42}));
  g.points = pd::make_vec3_array("Points", {0, 1, 2}, {0, 0, 1}, {0, 0, 0});
  g.point_data.push_back(pd::make_array("displacement", std::vector<double>(9, 1e-6), 3));
  g.point_data.push_back(pd::make_array("damage", std::vector<double>{0.0, 0.5, 0.25}));
  g.connectivity = pd::make_array("connectivity", std::vector<std::int64_t>{0, 1, 2, 0, 1, 1, 2});
  g.offsets = pd::make_array("offsets", std::vector<std::int64_t>{1, 2, 3, 5, 7});
  g.types = pd::make_array("types", std::vector<std::uint8_t>{1, 1, 1, 3, 3});
  g.cell_data.push_back(pd::make_array("broken_bond", std::vector<std::uint8_t>{0, 0, 0, 1, 1}));
  return g;
}

// The integrator state bytes as Integrator::save_state writes them (no model needed for that).
struct SavedReport : pd::Integrator {
  std::string name() const override { return "verlet"; }
  void initialize(pd::State&, double) override {}
  void step(pd::State&, double&, double&) override {}
};

// A checkpoint of `nodes` nodes partway through a run; `rich` fills every optional part (the
// adaptive step's proposal, indenter forces, a contact list) so the seeds reach every field.
pd::Checkpoint checkpoint(std::size_t nodes, bool rich) {
  pd::Checkpoint c;
  c.case_hash = 0x0123456789abcdefull;
  c.nodes_hash = 0xfedcba9876543210ull;
  c.nodes = nodes;
  c.directed_bonds = 2 * nodes;
  c.integrator = rich ? "adaptive" : "verlet";
  pd::LoopState& l = c.loop;
  l.step = 10, l.t = 1e-6, l.dt = 1e-7, l.dt_taken = 1e-7;
  l.last_frame_step = 10, l.next_frame_index = 2, l.next_restart_index = 1;
  l.broken = 1, l.force_evaluations = 11, l.broken_energy = 1e-9, l.wall_time = 0.25;
  l.growth.energy_before = 2e-6, l.growth.streak_start = 1e-6, l.growth.streak = 0;
  c.integrator_state = SavedReport().save_state();
  if (rich) {
    const double proposal = 1.1e-7;  // AdaptiveStep::save_state appends its proposal
    const auto* p = reinterpret_cast<const char*>(&proposal);
    c.integrator_state.insert(c.integrator_state.end(), p, p + sizeof proposal);
  }
  c.state = pd::State(nodes);
  for (std::size_t i = 0; i < nodes; ++i) c.state.u[0][i] = 1e-6 * static_cast<double>(i), c.state.w[i] = 0.5;
  if (rich) c.state.indenter_force = {{0.0, -2.5, 0.0}};
  c.broken_flags.assign(c.directed_bonds, 0);
  c.broken_flags[1] = 1;
  c.row_length.assign(nodes, 2);  // 2·nodes directed bonds
  if (rich) c.contact_rebuilds = 3, c.contact_seconds = 1e-3, c.contact_u_build = pd::make_vec3(nodes, 1e-7);
  c.frame_times = {0.0, 1e-6};
  c.history_bytes = 1234;
  return c;
}

void text(const fs::path& path, const std::string& body) { std::ofstream(path, std::ios::binary) << body; }

// The formats.md §3 example, and a 3D variant with a fixed step and every_steps output.
const char* const kCase2d = R"({"format_version": 1, "case": "membrane", "source": "cases/membrane/membrane.yaml",
 "nodes_file": "nodes.vtu", "output_dir": ".", "dimension": 2, "analysis": "plane_stress", "thickness": 0.001,
 "grid_spacing": 0.0005, "horizon": 0.0015075,
 "blocks": [{"id": 1, "name": "plate", "model": "pmb", "density": 1200.0, "youngs_modulus": 3.0e9, "fracture_energy": null}],
 "no_fail_sets": [], "node_sets": ["clamped", "centre"],
 "boundary_conditions": [{"set": "clamped", "kind": "displacement", "component": 2, "times": [0.0], "values": [0.0]}],
 "initial_conditions": [{"set": "centre", "kind": "velocity", "component": 2, "value": 5.0}],
 "damping": 200.0,
 "time": {"end": 0.01, "integrator": "verlet", "dt": "stable", "safety_factor": 0.8, "max_steps": 10000000},
 "adaptive": {"tol": 1e-3, "kd": 20, "p": 3.0, "phi": 1.0, "dt_initial": null, "dt_min": null, "dt_max": null},
 "output": {"every_time": 1e-4, "every_steps": null, "history_every": 1},
 "figures": {"times": null, "displacement_component": 2}}
)";
const char* const kCase3d = R"({"format_version": 1, "nodes_file": "n.vtu", "dimension": 3, "analysis": "3d",
 "grid_spacing": 1e-3, "horizon": 3e-3,
 "blocks": [{"id": 1, "name": "a", "density": 7800, "youngs_modulus": 2e11, "fracture_energy": 1e4},
            {"id": 2, "name": "b", "density": 2700, "youngs_modulus": 7e10}],
 "no_fail_sets": ["grip"],
 "boundary_conditions": [{"set": "grip", "kind": "velocity", "component": 0, "times": [0, 1e-3, 2e-3], "values": [0, 1, 1]},
                         {"set": "all", "kind": "body_force", "component": 1, "times": [0], "values": [-9.81]}],
 "initial_conditions": [{"set": "all", "kind": "displacement", "component": 1, "value": 0.0}],
 "time": {"end": 1e-3, "dt": 1e-8, "max_steps": 5},
 "output": {"every_steps": 10, "history_every": 2}}
)";

}  // namespace

int main(int argc, char** argv) {
  if (argc != 2) {
    std::cerr << "usage: pd_fuzz_seeds DIR\n";
    return 2;
  }
  const fs::path dir = argv[1];
  for (const char* target : {"pd_fuzz_node_file", "pd_fuzz_vtu", "pd_fuzz_case", "pd_fuzz_checkpoint"})
    fs::create_directories(dir / target);
  pd::write_node_file(dir / "pd_fuzz_node_file" / "lattice2d.vtu", lattice(3, 2, 1, 2));
  pd::write_node_file(dir / "pd_fuzz_node_file" / "lattice3d.vtu", lattice(2, 2, 2, 3));
  pd::write_node_file(dir / "pd_fuzz_vtu" / "nodes.vtu", lattice(2, 2, 1, 2));
  pd::write_vtu(dir / "pd_fuzz_vtu" / "frame.vtu", frame());
  text(dir / "pd_fuzz_case" / "membrane.json", kCase2d);
  text(dir / "pd_fuzz_case" / "three_d.json", kCase3d);
  pd::write_checkpoint(dir / "pd_fuzz_checkpoint" / "verlet.bin", checkpoint(4, false));
  pd::write_checkpoint(dir / "pd_fuzz_checkpoint" / "adaptive_contact.bin", checkpoint(3, true));
  return 0;
}
