// Test and benchmark helpers: regular lattices and a Case built in memory.
#pragma once
#include <string>

#include "core/case.hpp"
#include "core/model.hpp"

namespace pdtest {

// nx × ny × nz nodes (nz = 1 in 2D) at spacing dx, origin at 0; V = dx³ (3D) or dx²·thickness (2D).
pd::Nodes cubic_lattice(int nx, int ny, int nz, double dx, int dimension, double thickness = 1.0);

// A case with one block; fracture_energy < 0 means unbreakable.
pd::Case lattice_case(int dimension, const std::string& analysis, double dx, double horizon, double youngs_modulus,
                      double density, double fracture_energy, double thickness = 1.0);

// The bar of the quasi-static and mixed tests: an nx × ny × nz lattice (3D, spacing dx) with the node
// sets "left" (the first two layers in x, x < 1.5 dx) and "right" (the last two, x > (nx − 2.5) dx).
pd::Nodes bar_with_grips(int nx, int ny, int nz, double dx);

// Its usual conditions, appended to c: "left" clamped in x, y and z; "right" displaced along x
// linearly from 0 at t = 0 to `pull` [m] at t = `end` (a displacement table), and held in y and z as
// well when `right_held_across`.
void clamp_left_pull_right(pd::Case& c, double pull, double end, bool right_held_across);

// The model of c on `nodes` with the node set "left" (the first two layers in x, x < 1.5 dx) held
// in every direction of c's dimension.
pd::Model held_at_left(pd::Case c, pd::Nodes nodes, double dx);

// The breakable bricks of the kernel tests: the nodes above z = 3.5 dx become a second block
// "stiff" (c's first block with the given E and G0) and the layer below z = dx/2 the no-fail set
// "bottom".
void add_stiff_top_and_no_fail_bottom(pd::Case& c, pd::Nodes& nodes, double dx, double youngs_modulus,
                                      double fracture_energy);

// Index of lattice node (i, j, k).
inline std::size_t node_index(int i, int j, int k, int nx, int ny) {
  return static_cast<std::size_t>((k * ny + j) * nx + i);
}

}  // namespace pdtest
