// The run's state in and out of a checkpoint (io/checkpoint.hpp): a rank's piece — its owned
// nodes' state, the law's declared state (core/state_arrays.hpp) with `checkpoint` and its owned
// rows' broken flags — written, and on a restart streamed back from the pieces of any rank count.
// Below the piece functions, the whole model's view that tests and tools read (read_checkpoint).
#pragma once
#include <cstddef>
#include <vector>

#include "core/model.hpp"
#include "core/state.hpp"
#include "io/checkpoint.hpp"
#include "core/state_arrays.hpp"
#include "parallel/local_model.hpp"

namespace pd {

// What a checkpoint holds of `model`'s declared state: its arrays with `checkpoint`.
std::vector<StateArray> checkpointed_state(const Model& model);

// Whether `saved` (a checkpoint's) is this law's: the same arrays with `checkpoint`, in the same
// order, each of the size a model of `nodes` nodes and `directed` directed bonds gives it.
bool fits_checkpointed_state(const std::vector<StateArray>& saved, const Model& model, std::size_t nodes,
                             std::size_t directed);

// The whole model's arrays from a whole checkpoint's (read_checkpoint: tests and tools; a run
// restores from the pieces, restore_from_pieces), after fits_checkpointed_state checked `saved`.
void restore_checkpointed_state(std::vector<StateArray> saved, Model& whole);

// ---- A rank's piece of a checkpoint (io/checkpoint.hpp). `local` is the model the operator works
// on: the piece's (owned nodes and ghosts, owned rows) on a decomposed run, whose `piece` maps it
// to global numbers; the whole model on one rank (piece null: one piece of every node).

// The sections this rank writes and reads: the state, `local`'s declared arrays with
// `checkpoint`, `integrator_arrays` per-node arrays of the integrator, contact's u_build if `contact`.
std::vector<CheckpointSection> checkpoint_sections_of(const Model& local, std::size_t integrator_arrays, bool contact);

// What this rank writes: its owned nodes (ascending global numbers) and rows, in the order of
// checkpoint_sections_of. contact_u_build: the contact list's displacement at its last build, or null.
CheckpointPieceOut checkpoint_piece_of(const Model& local, const LocalPiece* piece, const State& state,
                                       const std::vector<Vec3Array*>& integrator_arrays, const Vec3Array* contact_u_build);

// A restart: streams every piece of `index` (at `index_path`) and keeps what this rank holds —
// per node, every local node (owned and ghost: exact copies, as a halo exchange makes them); per
// bond, its owned rows — into `state`'s u, v, f, w (sized to the local nodes), `local`'s declared
// arrays with `checkpoint` and broken flags, the integrator's arrays and contact_u_build (sized
// here when the index has it). whole_rows (a decomposed run that holds the whole bond list too):
// also its broken flags, from every row. Throws pd::Error naming the file that is missing, damaged
// or does not fit; no rank ever holds more than its piece and one chunk of a file.
void restore_from_pieces(const std::filesystem::path& index_path, const Checkpoint& index, Model& local,
                         const LocalPiece* piece, State& state, const std::vector<Vec3Array*>& integrator_arrays,
                         Vec3Array* contact_u_build, BondList* whole_rows);

}  // namespace pd
