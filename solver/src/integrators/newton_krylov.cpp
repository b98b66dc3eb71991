// The linear-solver choice and the matrix-free Newton solve of quasi_static and implicit (newton_krylov.hpp).
#include "integrators/newton_krylov.hpp"

#include "core/error.hpp"

namespace pd {

LinearSolverChoice choose_linear_solver(const ForceOperator& op, const Case& c, const std::string& section,
                                        const std::string& choice, int dof_dimension) {
  const int dimension = op.model().nodes.dimension;
  const Decomposed* decomposed = op.decomposed();
  const auto local_free = static_cast<std::int64_t>(op.free_dofs(dof_dimension).size());
  const auto free = static_cast<std::size_t>(decomposed ? decomposed->total(local_free) : local_free);
  const std::string missing = op.missing_assembled_stiffness(State(op.size()), 0.0);
  const std::string key = c.file.string() + ": " + section + ".linear_solver: ";
  if (choice == "direct") {
    // The factorisation is of the whole tangent on one process (no distributed one is built in):
    // on several ranks the solves are matrix-free, their products force evaluations with ghosts.
    if (decomposed)
      throw Error(key + "direct factorises the whole tangent on one process and is not decomposed over MPI ranks (here " +
                  std::to_string(decomposed->ranks()) +
                  "); use linear_solver: cg (or auto, which takes cg on several ranks), or run on one rank");
    if (!missing.empty())
      throw Error(key + "direct needs an assembled tangent, which " + missing + " does not have; use linear_solver: cg (or auto)");
    return {false, "as the case file asks"};
  }
  if (choice == "cg") return {true, "as the case file asks"};
  if (decomposed) {
    // Said in run.log when one rank's auto would factorise, since a user adds ranks to go faster:
    // CG's iterations then cost more than the factorisation's solves on a problem one process holds
    // (traction's quasi_static to 0.3 ms: 1.2 s on one rank with CHOLMOD, 19 s on two with CG;
    // README "Several processes").
    const bool one_rank_factorises = missing.empty() && !(dimension == 3 && free >= kCgFromDofs3d);
    return {true, "auto: decomposed over " + std::to_string(decomposed->ranks()) +
                      " MPI ranks (a factorisation stays on one process" +
                      (one_rank_factorises ? "; a problem that fits one process is usually solved faster by one rank "
                                             "with it"
                                           : "") +
                      ")"};
  }
  if (!missing.empty())
    return {true, missing == "contact" ? "auto: a term (contact) has no assembled tangent"
                                       : "auto: the material " + op.model().bond_model->name() + " has no assembled tangent"};
  if (dimension == 3 && free >= kCgFromDofs3d)
    return {true, "auto: " + std::to_string(free) + " free dofs in 3D, at least " + std::to_string(kCgFromDofs3d)};
  return {false, "auto: " + std::to_string(free) + " free dofs" +
                     (dimension == 3 ? ", below " + std::to_string(kCgFromDofs3d) + " in 3D" : std::string(" in 2D"))};
}

std::string why_not_linear_solver(const ForceOperator& op, const std::string& recorded) {
  if (recorded == "cg block_jacobi") return {};
  if (recorded != "direct") return "the checkpoint names a linear solver this pdsolve does not know ('" + recorded + "')";
  if (const Decomposed* decomposed = op.decomposed())
    return "direct factorises the whole tangent on one process, and this run is decomposed over " +
           std::to_string(decomposed->ranks()) + " MPI ranks";
  if (const std::string missing = op.missing_assembled_stiffness(State(op.size()), 0.0); !missing.empty())
    return "direct needs an assembled tangent, which " + missing + " does not have";
  return {};
}

PcgResult solve_newton_system(const ForceOperator& op, const State& s, double t, const FreeDofs& dofs, const DofSums& sums,
                              const std::vector<double>& diagonal, const Preconditioner& M, const std::vector<double>& rhs,
                              std::vector<double>& correction, PcgSettings settings, Vec3Array& x, Vec3Array& y) {
  const auto& volume = op.model().nodes.volume;
  // K v = −V ∂f/∂u·v + D v over the free dofs (v zero at the prescribed components and ghosts).
  const LinearOperator K = [&](const std::vector<double>& v, std::vector<double>& Kv) {
    dofs.scatter(v, x);
    op.apply_jacobian(s, t, x, y);
    Kv.resize(v.size());
    const auto n = static_cast<std::int64_t>(dofs.size());
#pragma omp parallel for schedule(static) if (n >= 32768)
    for (std::int64_t k = 0; k < n; ++k) {
      const auto q = static_cast<std::size_t>(k);
      const auto i = static_cast<std::size_t>(dofs.node[q]);
      Kv[q] = -volume[i] * y[dofs.component[q]][i] + diagonal[q] * v[q];
    }
  };
  settings.dot = [&sums](const std::vector<double>& a, const std::vector<double>& b) { return sums.dot(a, b); };
  correction.clear();  // CG from Δu = 0
  const PcgResult result = preconditioned_cg(K, M, rhs, correction, settings);
  // Negative curvature along the first direction: the preconditioned residual, a descent
  // direction of the energy, scaled by the line search (Steihaug's first step).
  if (result.status == PcgResult::kIndefinite && result.iterations == 0) M.apply(rhs, correction);
  return result;
}

}  // namespace pd
