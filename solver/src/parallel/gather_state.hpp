// A decomposed run's declared state (core/state_arrays.hpp) gathered on rank 0 in the whole model's
// order: what a checkpoint writes and a gathered frame shows, as a serial run holds it.
#pragma once
#include "core/model.hpp"
#include "core/state_arrays.hpp"
#include "parallel/decomposed.hpp"

namespace pd {

// Every array of the piece's declared state (d.piece().model.state_arrays) for which which(its
// declaration) is true into the same array of `whole` (the whole model's), on rank 0: per node in
// global node order, per bond over whole.bonds' rows (their offsets, which rank 0 holds). Other
// ranks' `whole` is not changed. Collective: every rank gathers the same arrays.
void gather_state(const Decomposed& d, Model& whole, bool (*which)(const StateDeclaration&));

}  // namespace pd
