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

// Index of lattice node (i, j, k).
inline std::size_t node_index(int i, int j, int k, int nx, int ny) {
  return static_cast<std::size_t>((k * ny + j) * nx + i);
}

}  // namespace pdtest
