// A sparse symmetric matrix in CSR form (both triangles stored, columns ascending in each row) over
// the free degrees of freedom of a scene, and the map between those and the nodes' components.
// The assembled tangent stiffness of the operator (operator/force_operator.hpp) is one; the linear
// solvers (linalg/cholesky.hpp, linalg/conjugate_gradient.hpp) take it.
#pragma once
#include <array>
#include <cstdint>
#include <vector>

#include "core/nodes.hpp"

namespace pd {

// The unknowns of an equilibrium solve: every component d < dimension of every node that is not
// prescribed (fixed[d][i] == 0), numbered node by node (dof k ↔ node i, component d), so that a
// node's components are neighbours in the matrix.
struct FreeDofs {
  std::vector<std::int64_t> index;   // per node i and component d at 3i + d: the dof number, or −1
  std::vector<std::int64_t> node;    // per dof: its node
  std::vector<std::uint8_t> component;  // per dof: its component
  std::size_t size() const { return node.size(); }

  // The dofs of a scene of n nodes in `dimension` dimensions with the prescribed mask `fixed`.
  static FreeDofs of(std::size_t n, int dimension, const std::array<std::vector<std::uint8_t>, 3>& fixed);
  // Vec3Array ↔ dof vector (components that are not dofs are left alone / ignored).
  void gather(const Vec3Array& a, std::vector<double>& out) const;
  void scatter(const std::vector<double>& in, Vec3Array& a) const;
};

struct SparseMatrix {
  std::int64_t rows = 0;
  std::vector<std::int64_t> row_start;  // rows + 1
  std::vector<std::int64_t> column;
  std::vector<double> value;

  std::size_t nonzeros() const { return value.size(); }
  // y = A x (each row summed in column order: the same for any thread count).
  void multiply(const std::vector<double>& x, std::vector<double>& y) const;
};

}  // namespace pd
