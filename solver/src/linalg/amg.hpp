// Algebraic multigrid preconditioner for CG on the large 3D quasi-static systems (issue 13): one
// V-cycle of hypre's BoomerAMG (Debian's libhypre-dev; Henson & Yang 2002) per application,
// set up on the assembled tangent K (operator/force_operator.hpp, assemble_stiffness). Block-Jacobi
// only damps the error at the scale of a node, so its iteration count grows with the model's
// length in nodes; a multigrid cycle reduces it on every scale, and CG's count stays nearly flat
// (measured in cases/beam_3d/README.md and integrators/quasi_static.cpp).
//
// The three displacement components are coarsened as separate functions (the "unknown approach",
// BoomerAMG's num_functions = 3 with the component of every dof given: a node held in some
// components has fewer dofs, so hypre's default x, y, z, x, y, z, … would mislabel every dof after
// it and coarsen components together), which keeps x, y and z apart on the coarse grids as
// elasticity asks. hypre here is Debian's build, without OpenMP: a cycle gives the same bits on any thread
// count. hypre is an MPI library: set_up initialises MPI in this process when the program has
// not (a serial build, or pdsolve without mpirun) and finalises it at exit.
//
// Built from amg_hypre.cpp when CMake finds hypre (PD_HYPRE), else from amg_none.cpp, whose set_up
// refuses with a message saying how to get it.
#pragma once
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "linalg/preconditioner.hpp"
#include "linalg/sparse_matrix.hpp"

namespace pd {

class AmgPreconditioner : public Preconditioner {
 public:
  AmgPreconditioner();
  ~AmgPreconditioner() override;
  AmgPreconditioner(const AmgPreconditioner&) = delete;
  AmgPreconditioner& operator=(const AmgPreconditioner&) = delete;

  // Whether this build has hypre (PD_HYPRE).
  static bool available();
  // Bytes at the peak of a set-up for a matrix of `rows` rows and `nonzeros` stored entries: the
  // assembled K, hypre's copy of it and the hierarchy with its interpolation operators.
  // Calibrated on a 102,400-node bar (see the .cpp).
  static std::uint64_t estimated_bytes(std::uint64_t rows, std::uint64_t nonzeros);

  // Builds the hierarchy for K (symmetric positive definite), whose dof k is component
  // component[k] < functions of its node (FreeDofs::component; functions 3 in 3D). Throws
  // pd::Error when hypre is not built in.
  void set_up(const SparseMatrix& K, int functions, const std::vector<std::uint8_t>& component);
  bool ready() const;
  // z = one V-cycle from z = 0 for K z = r.
  void apply(const std::vector<double>& r, std::vector<double>& z) const override;
  // The hierarchy's levels and operator complexity (Σ nonzeros of all levels / nonzeros of K), for run.log.
  int levels() const;
  double operator_complexity() const;
  void clear();

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace pd
