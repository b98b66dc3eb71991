// Phase 2 of a run: a fresh start at t = 0 (initial conditions), or a restore from checkpoint.bin
// with every check that it belongs to this case; and its mirror, the checkpoint of a running loop.
#pragma once
#include <cstdint>
#include <filesystem>
#include <string>

#include "core/error.hpp"
#include "core/state.hpp"
#include "io/checkpoint.hpp"
#include "io/output.hpp"
#include "run.hpp"
#include "run/history_columns.hpp"
#include "run/loop_state.hpp"
#include "run/prepare.hpp"

namespace pd {

struct Start {
  bool restarting = false;
  State state;
  LoopState loop;
  OutputResume resume;  // a restart: the frames kept and history.csv's length
  std::uint64_t case_hash = 0, nodes_hash = 0;  // what a checkpoint written by this run belongs to
  // A restart that cannot keep the checkpoint's linear solver: why, and that the results will
  // differ from the uninterrupted run's (for run.log and stderr); "" otherwise.
  std::string solver_changed;
};

// Throws pd::Error for a checkpoint that does not fit (saying how to start over instead) or an
// initial state that is not finite; writes nothing.
Start start_or_restore(const RunOptions& options, Prepared& p);

// output_dir/checkpoint.bin.
std::filesystem::path checkpoint_path(const Case& c);

// The output writer: a fresh one, or on a restart one that keeps the frames and history rows up to
// the checkpoint (a refusal says how to start over).
// Null on the ranks other than 0 of a decomposed run: rank 0 writes every file.
std::unique_ptr<OutputWriter> open_output(const RunOptions& options, const Prepared& p, const Start& s,
                                          const HistoryColumns& columns);

// The index of a checkpoint (io/checkpoint.hpp): everything the loop carries from step to step
// but the arrays, which the pieces hold. loop.wall_time: the time loop's seconds up to now.
// totals: the run's State totals (State::copy_totals). integrator_state: Integrator::save_state().
// contact: the pieces hold contact's u_build (a contact list was built). pieces: every rank's, in rank order.
Checkpoint checkpoint_of(const Prepared& p, const Start& s, const State& totals, const LoopState& loop,
                         const OutputWriter& out, std::vector<char> integrator_state, bool contact,
                         std::vector<CheckpointPieceRef> pieces);

}  // namespace pd
