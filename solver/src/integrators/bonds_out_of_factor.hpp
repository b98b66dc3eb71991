// The bonds that a breaking round broke, taken out of the factorised tangent instead of a new
// factorisation (quasi_static.cpp; the identity: linalg/woodbury.hpp).
//
// A bond-based law's tangent holds each bond (i, j) as V_i·B_ij on the diagonal blocks of i and j and
// −V_i·B_ij off them (ForceOperator::assemble_stiffness), B_ij = ∂f_i/∂u_j of the bond
// (BondModel::bond_tangent_row) at the state the tangent was assembled at. A bond that breaks adds
// nothing more: the tangent of the bonds left is the factorised one minus U C Uᵀ with U = [I; −I] on
// the two nodes' free components and C = V_i·B_ij, computed at that same state, with the bond put
// back for the computation. Newton then goes on with the tangent it had, less exactly the bonds it
// lost: a modified Newton iteration whose tangent still has the crack's new faces.
//
// Why: the re-solve after a breaking round was a new factorisation at the same load (quasi_static.hpp,
// "Then bonds over their critical stretch break"); the few bonds of a round (4–12 on plate_with_hole
// and traction before their cracks run) cost 8–24 right-hand sides of one solve instead (measured:
// quasi_static.hpp, kMaxRemovedColumns).
#pragma once
#include <cstdint>
#include <vector>

#include "core/model.hpp"
#include "linalg/sparse_matrix.hpp"
#include "linalg/woodbury.hpp"

namespace pd {

// Adds to `update` one block per bond broken since `broken_before` (the bonds' broken flags before
// the round): C at u_factor, with the definite variant if the factorisation used it. Returns the
// number of bonds added, or −1 (nothing added) when a bond broke on one side only (its two halves
// must leave together for U C Uᵀ to be the change). The model's flags are as it found them.
std::int64_t add_broken_bonds(Model& model, const std::vector<std::uint8_t>& broken_before, const Vec3Array& u_factor,
                              bool definite, const FreeDofs& dofs, Woodbury& update);

}  // namespace pd
