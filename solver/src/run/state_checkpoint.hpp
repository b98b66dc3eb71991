// The law's declared state (core/state_arrays.hpp) in and out of a checkpoint: the arrays with
// `checkpoint`, in declaration order, in the whole model's node and bond order (io/checkpoint.hpp).
#pragma once
#include <cstddef>
#include <vector>

#include "core/model.hpp"
#include "core/state_arrays.hpp"
#include "parallel/local_model.hpp"

namespace pd {

// What a checkpoint holds of `model`'s declared state: its arrays with `checkpoint`.
std::vector<StateArray> checkpointed_state(const Model& model);

// Whether `saved` (a checkpoint's) is this law's: the same arrays with `checkpoint`, in the same
// order, each of the size a model of `nodes` nodes and `directed` directed bonds gives it.
bool fits_checkpointed_state(const std::vector<StateArray>& saved, const Model& model, std::size_t nodes,
                             std::size_t directed);

// A restart (fits_checkpointed_state checked `saved`): the whole model's arrays (per bond only where
// it holds its rows; a whole model whose rows are on the ranks keeps none), and on a decomposed run
// the piece's — owned nodes and ghosts, owned rows — from the whole model's order.
void restore_checkpointed_state(std::vector<StateArray> saved, Model& whole, LocalPiece* piece);

}  // namespace pd
