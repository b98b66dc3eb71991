// The true stability limit of the explicit scheme: the largest eigenvalue of the linearised PMB
// operator M⁻¹K, found matrix-free by Lanczos, and the velocity-Verlet step 2/ω_max it allows.
#pragma once
#include <array>
#include <cstdint>
#include <vector>

#include "core/model.hpp"

namespace pd {

// Linearising the PMB force (thesis eq. 2.3) about the reference configuration, a bond pulls with
// f_i = Σ_j (c_ij V_j/|ξ|) e eᵀ (u_j − u_i), e = ξ/|ξ| (Silling & Askari 2005: C(ξ) = c/|ξ| e⊗e).
// With masses m_i = ρ_i V_i the force vector is −K u, K symmetric positive semi-definite; the
// eigenvalues of M⁻¹K are ω² and velocity Verlet is stable for Δt < 2/ω_max.
//
// Broken bonds are left out (fewer bonds only lower ω_max, so the limit found at t = 0 holds
// later too), and prescribed components are treated as free (constraining a degree of freedom
// cannot raise ω_max, Cauchy interlacing), so the limit is never optimistic on their account.
//
// period[d] > 0 makes axis d periodic for the bond direction (minimum image of x_j − x_i): only
// the tests use it, to reproduce the infinite lattice of docs/theory.md T10 with a hand-made bond list.
struct LanczosReport {
  double lambda_max = 0.0;  // ω_max² [1/s²]
  int iterations = 0;       // operator applications (each costs about one force evaluation)
  bool converged = false;
};

class Decomposed;

// On a decomposed run (decomposed non-null) `model` is this rank's piece (parallel/local_model) and
// the iteration runs on its owned rows, the ghosts' entries exchanged before each product, its sums
// those of the serial loop (stability.cpp says how): the same bits as the serial run of the whole
// model on any number of ranks. Collective then: every rank calls it at the same point.
LanczosReport largest_eigenvalue(const Model& model, std::array<double, 3> period = {0.0, 0.0, 0.0},
                                 const Decomposed* decomposed = nullptr);

// y = M^{-1/2} K M^{-1/2} x: the symmetric form of M⁻¹K whose eigenvalues Lanczos finds
// (x and y have 3 entries per node, component-major like Vec3Array).
void apply_symmetric_operator(const Model& model, const std::array<double, 3>& period, const Vec3Array& x,
                              Vec3Array& y);

// Velocity-Verlet stability limit 2/ω_max without safety factor; +inf if no node has a bond.
// Collective on a decomposed run, as largest_eigenvalue.
double exact_time_step(const Model& model, const Decomposed* decomposed = nullptr);

}  // namespace pd
