// Phase 1 of a run: read the case and the node file, build the model, choose the time step,
// construct the integrator (run/run_log.hpp says what was prepared). Every input error is
// thrown here or in the start phase, before any output file exists.
#pragma once
#include <string>
#include <vector>
#include <cstdint>
#include <memory>

#include "core/case.hpp"
#include "core/model.hpp"
#include "integrators/integrator.hpp"
#include "io/output.hpp"
#include "parallel/decomposed.hpp"
#include "run.hpp"

namespace pd {

struct Prepared {
  Case c;
  int threads = 0;  // OpenMP's, after --threads
  // The whole model. On a decomposed run every rank holds its per-node data while it sets up (the
  // decomposition and the piece are cut from it); its bond list only when whole_bonds
  // (whole_bonds_reason() in prepare.cpp says why), else just the rows' offsets — each rank built
  // only its owned rows, in decomposed->piece() (issue 15). A rank that writes no output and holds
  // only its rows frees the per-node arrays once its piece is cut (release_whole_node_data): then
  // only the scalars, the per-block data and the sets' and conditions' names stay here.
  Model model;
  bool whole_bonds = true;
  std::int64_t nodes = 0;  // nodes of the whole model, held or not
  // Directed bonds of the whole model (each bond twice), held or not.
  std::int64_t directed = 0;
  std::int64_t directed_bonds() const { return directed; }
  // Nodes without a bond (run.log's warning), counted before the whole rows' offsets may go: the
  // count and the first one, −1 if none.
  std::int64_t isolated = 0, first_isolated = -1;
  // A run on several MPI ranks (issue 15): this rank's piece, its ghosts and the exact sums; the
  // operator then works on the piece's model. Null on one rank: the serial path.
  std::unique_ptr<Decomposed> decomposed;
  bool writes_output() const { return !decomposed || decomposed->rank() == 0; }
  // output.parallel_frames: pieces on a decomposed run (one rank writes gathered frames), or on a
  // restart the format of the series it continues (resumes_pieces: a series in pieces goes on in
  // pieces on any rank count, one piece on one rank; run/start.cpp sets both from the checkpoint).
  bool resumes_pieces = false;
  bool frames_in_pieces() const { return (decomposed || resumes_pieces) && c.output.parallel_frames == "pieces"; }
  double build_seconds = 0.0;  // wall time of build_model

  // The time step (time.dt stable | exact | fixed, × safety_factor; adaptive.dt_initial first).
  double dt = 0.0;         // the first step [s]
  double dt_stable = 0.0;  // thesis eq. 2.5, without safety factor [s]
  double dt_exact = 0.0;   // 2/ω_max (core/stability) once computed, else 0 [s]; see exact_limit()
  double dt_exact_configured = 0.0;  // what the integrator's configure() was given
  std::int64_t max_steps = 0, steps_for_end = 0, steps_expected = 0;

  // The operator holds a reference to `model`, the integrator one to the operator: a Prepared never
  // moves (prepare() returns it by pointer).
  std::unique_ptr<ForceOperator> op;
  std::unique_ptr<Integrator> integrator;

  // The indenter-depth watch (run/watches.hpp): for an explicit step with indenters; ω_max² of the
  // body from the exact limit when the step is above eq. 2.5, else 0 (eq. 2.5 alone).
  bool indenter_watch = false;
  double omega2_exact = 0.0;
  std::vector<double> indenter_depths;  // per indenter: forces/indenter.hpp indenter_stable_depth, for run.log
  std::vector<std::string> step_warnings;  // a step above eq. 2.5 judged against the exact limit, for run.log

  // The exact stability limit, computed on first use (Lanczos, about as costly as tens of force
  // evaluations): for time.dt "exact", the adaptive step's default Δt_max, an indenter watch or a
  // fixed dt above eq. 2.5, or a failed run's message. On a rank that holds only its rows it runs
  // on the pieces: collective then, every rank calls it at the same point.
  double exact_limit();
  // For a message that rank 0 writes alone (a failed run's likely cause): exact_limit() if it is
  // known or needs no other rank, else NaN ("not computed").
  double known_exact_limit();

  Prepared() = default;
  Prepared(const Prepared&) = delete;
  Prepared& operator=(const Prepared&) = delete;
};

// Why a decomposed run of case c keeps the whole bond list on every rank: the feature that reads
// it, or empty when each rank can build only its own rows (issue 15).
std::string whole_bonds_reason(const Case& c);

// Throws pd::Error for bad input (naming the file), before anything is written.
std::unique_ptr<Prepared> prepare(const RunOptions& options);

// Bytes of the whole cloud's per-node arrays that p.model holds (positions, volumes, blocks, sets,
// densities, block indices, no-fail flags, the rows' offsets, conditions' node lists and flags,
// LAMMPS's s0), by their vectors' capacities; and the same of a piece's model (parallel/local_model).
std::int64_t node_data_bytes(const Model& model);
// On a decomposed run whose ranks hold only their own rows, a rank that writes no output (not rank
// 0) needs none of the whole cloud's per-node arrays once its piece is cut: prepare() frees them
// there, before the operator, the integrator and the state are made (issue 15). Does nothing
// elsewhere. The rows' offsets stay until start_or_restore has taken a checkpoint's broken flags,
// which are in the whole list's order; release_whole_rows_offsets frees them then.
void release_whole_node_data(Prepared& p);
void release_whole_rows_offsets(Prepared& p);

}  // namespace pd
