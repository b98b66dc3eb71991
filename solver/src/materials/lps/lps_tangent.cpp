// The LPS tangent's diagonal blocks ∂f_i/∂u_i, one 3×3 block per node: the block-Jacobi
// preconditioner of the matrix-free Newton–Krylov solves (linalg/pcg.hpp, integrators/quasi_static).
//
// Derivation, from the force of lps.hpp (Mitchell's ordinary state-based LPS, written as the exact
// gradient of the energy): per intact bond j of i, with y = |y_j − y_i|, n = (y_j − y_i)/y,
// e = y − |ξ|, V_j = the neighbour's volume × its partial-volume weight,
//   f_i = Σ_j V_j T_ij n,   T_ij = ω (|ξ| (P_i + P_j) + (a_i + a_j) e),
//   P_k = γ_k θ_k (γ_k = P_k/θ_k: P is linear in θ at fixed m'_k, which does not depend on u),
//   θ_k = (d/m_k) Σ_l ω |ξ_kl| e_kl V_l.
// Moving node i alone: ∂e/∂u_i = −n, ∂n/∂u_i = −(I − n nᵀ)/y, and
//   ∂θ_i/∂u_i = −(d/m_i) b_i,             b_i = Σ_j ω |ξ| V_j n          (i's whole family)
//   ∂θ_j/∂u_i = −(d/m_j) ω |ξ| V_i^(j) n   (only the bond j→i of j's family; V_i^(j) = V_i × the
//                                           same partial-volume weight, a function of |ξ|)
// so
//   ∂f_i/∂u_i = −γ_i (d/m_i) b_i b_iᵀ                                            (i's dilatation)
//               − Σ_j V_j ω [(a_i + a_j) + γ_j (d/m_j) ω |ξ|² V_i^(j)] n nᵀ    (bond + j's dilatation)
//               − Σ_j V_j (T_ij / y) (I − n nᵀ)                               (rotation of a loaded bond).
// The dilatation couples i with its neighbours' neighbours (reach 2δ), but those couplings are
// off-diagonal blocks; on the diagonal only the two terms above remain. b_i vanishes for a whole,
// symmetric family at rest and is largest at a free surface. Bonds crushed to a point (y = 0)
// carry no force and have no direction: left out, as the kernel and J·x leave them out.
//
// definite: leave out what can make a block indefinite — the rank-one term when γ_i < 0 (ν < 1/4
// in 3D: 3K − 5μ < 0), a negative n nᵀ coefficient, the lateral term of a compressed bond (T < 0) —
// so that −V_i ∂f_i/∂u_i is positive semi-definite, as the preconditioner needs.
#include <algorithm>
#include <cmath>

#include "materials/lps/lps_kernel.hpp"

#include "parallel/decomposed.hpp"

namespace pd {

bool LpsModel::jacobian_diagonal_blocks(const Model& model, const Vec3Array& u, std::vector<double>& blocks,
                                        bool definite) const {
  const LpsKernel k(*this, model, u);
  const auto n = static_cast<std::size_t>(k.nodes);
  std::vector<double> p(n), gamma(n), b(3 * n);
  // Sweep 1: P_k, γ_k and b_k per node.
#pragma omp parallel for schedule(static)
  for (std::int64_t i = 0; i < k.nodes; ++i) {
    double st = 0.0, sm = 0.0, b0 = 0.0, b1 = 0.0, b2 = 0.0;
    for (std::int64_t q = k.offsets[i]; q < k.offsets[i + 1]; ++q) {
      if (k.broken[q]) continue;
      const LpsKernel::Bond t = k.bond(i, q);
      st += t.omega * t.length * t.ext * t.vj;
      sm += t.omega * t.length * t.length * t.vj;
      if (!(t.y > 0.0)) continue;
      const double w = t.omega * t.length * t.vj * t.inv_y;
      b0 += w * t.e0, b1 += w * t.e1, b2 += w * t.e2;
    }
    const auto iu = static_cast<std::size_t>(i);
    p[iu] = k.p_of(i, k.theta_of(i, st), sm);
    gamma[iu] = k.p_of(i, 1.0, sm);
    b[3 * iu] = b0, b[3 * iu + 1] = b1, b[3 * iu + 2] = b2;
  }
  // A decomposed run (issue 15): the far ends' P and γ of the ghosts from their owners.
  if (decomposed_) decomposed_->update_ghosts(NodeColumns(p).add(gamma));  // one exchange
  // Sweep 2: the block of each node, from its own bonds and the γ, m, a, P of their far ends.
  blocks.assign(9 * n, 0.0);
#pragma omp parallel for schedule(static)
  for (std::int64_t i = 0; i < k.nodes; ++i) {
    const auto iu = static_cast<std::size_t>(i);
    double out[9] = {};
    for (std::int64_t q = k.offsets[i]; q < k.offsets[i + 1]; ++q) {
      if (k.broken[q]) continue;
      const std::int64_t j = k.neighbour[q];
      const auto ju = static_cast<std::size_t>(j);
      const LpsKernel::Bond t = k.bond(i, q);
      if (!(t.y > 0.0)) continue;
      const double nv[3] = {t.e0 * t.inv_y, t.e1 * t.inv_y, t.e2 * t.inv_y};
      // V_i^(j), times the bond's surface-correction factor (both copies of a bond carry the same g)
      const double vi = k.volume[i] * k.volume_weight(t.length) * (k.factor ? k.factor[q] : 1.0);
      const double dilatation_j = k.m[j] > 0.0 ? gamma[ju] * (k.d / k.m[j]) * t.omega * t.length * t.length * vi : 0.0;
      double along = t.omega * ((k.a[i] + k.a[j]) + dilatation_j);
      double turn = t.omega * (t.length * (p[iu] + p[ju]) + (k.a[i] + k.a[j]) * t.ext) * t.inv_y;  // T/y
      if (definite) along = std::max(along, 0.0), turn = std::max(turn, 0.0);
      for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 3; ++c)
          out[3 * r + c] -= t.vj * ((along - turn) * nv[r] * nv[c] + (r == c ? turn : 0.0));
    }
    const double g = k.m[i] > 0.0 ? gamma[iu] * k.d / k.m[i] : 0.0;
    if (!definite || g > 0.0)
      for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 3; ++c) out[3 * r + c] -= g * b[3 * iu + static_cast<std::size_t>(r)] * b[3 * iu + static_cast<std::size_t>(c)];
    std::copy(out, out + 9, &blocks[9 * iu]);
  }
  return true;
}

}  // namespace pd
