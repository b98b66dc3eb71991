// Solver output (pipeline/formats.md §4): frames/frame_NNNNNN.vtu, frames.pvd, history.csv (run.log:
// run/run_log.hpp).
// Frames and frames.pvd are written under a temporary name and renamed into place;
// history.csv grows in place by whole lines (see OutputWriter).
#pragma once
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "core/case.hpp"
#include "core/model.hpp"
#include "core/state.hpp"
#include "io/output_lock.hpp"
#include "io/vtu.hpp"

namespace pd {

struct HistoryRow {
  std::int64_t step = 0;
  double time = 0.0, dt = 0.0;
  int iterations = 1, rejected = 0;
  double kinetic_energy = 0.0, strain_energy = 0.0, external_work = 0.0, damping_work = 0.0;
  std::int64_t broken_bonds = 0;
  double wall_time = 0.0;
  std::vector<double> extra;  // the scene's own columns, after wall_time (formats.md §4)
};

// The header line of history.csv, exactly the columns of formats.md §4.
extern const char* const kHistoryHeader;

// How a frame is stored (output.precision, output.compression, output.fields of case.json).
struct FrameFormat {
  bool float32 = true;  // point fields as Float32 (the reference points stay Float64)
  bool zlib = true;     // vtkZLibDataCompressor blocks
  std::vector<std::string> fields = {"displacement", "velocity", "damage", "block"};
  // output.parallel_frames: pieces, on a decomposed run (several ranks) only: frames.pvd names
  // frame_NNNNNN.pvtu files, each naming one frame_NNNNNN_pR.vtu per rank R.
  bool pieces = false;
};

// The FrameFormat that a case's output section asks for.
FrameFormat frame_format_of(const OutputSettings& output);

// The point fields a frame can carry, in the order a frame writes them: the one list that the case
// reader checks output.fields against and --describe prints.
const std::vector<std::string>& frame_fields();

// One frame as a VTU grid: reference points, the chosen point fields (displacement, velocity,
// damage, block); vertex cells then one line cell per broken bond (i < j); FieldData TIME and step.
struct FrameBonds;
void write_frame(const std::filesystem::path& path, const Model& model, const State& state, double time,
                 std::int64_t step, const FrameFormat& format = FrameFormat{}, const FrameBonds* bonds = nullptr);

// What a frame reads from the bonds, given instead of model.bonds by a decomposed run whose ranks
// build only their own rows (issue 15): the damage per node and the broken bonds as rows (only
// those with j > i need be there; Decomposed::gather_broken_lines), both in global node order.
struct FrameBonds {
  const std::vector<double>& damage;
  const BondList& broken_lines;
};

// A decomposed run's nodes (parallel/local_model.hpp's LocalPiece): 1 for a node this rank owns, 0
// for a ghost, and every local node's global number.
struct FramePiece {
  const std::vector<std::uint8_t>& owned;
  const std::vector<std::int32_t>& global;
};
// The grid write_frame writes; with `piece`, a rank's piece of the frame: its local nodes (owned and
// ghosts: a broken bond to a ghost keeps its line cell) with vtkGhostType marking the ghosts' points
// and vertex cells as duplicates (VTK's DUPLICATEPOINT and DUPLICATECELL, 1), so a reader shows each
// node once, and the point array node_id (the global node number).
VtuGrid frame_grid(const Model& model, const State& state, double time, std::int64_t step, const FrameFormat& format,
                   const FramePiece* piece = nullptr, const FrameBonds* bonds = nullptr);
// frames/frame_NNNNNN_pR.vtu: rank R's piece of frame k (output.parallel_frames: pieces).
std::string frame_piece_file(std::size_t k, int rank);

// Where a restarted run picks up its output (io/checkpoint.hpp): the frames written so far and
// the length of history.csv at the checkpoint.
struct OutputResume {
  std::vector<double> frame_times;  // frame k is frames/frame_k.vtu at time frame_times[k]
  std::uint64_t history_bytes = 0;
};

// history.csv is written in place, only ever extended by whole lines: rows are buffered and
// written with one write(2) per flush (at every frame, every second of wall time, when 64 KiB
// are buffered and at the end), so a killed run leaves complete rows up to its last flush.
class OutputWriter {
 public:
  // Creates output_dir/frames and removes frame files left by an earlier run there. extra_columns
  // name the HistoryRow::extra values (contact and indenter columns, present only when the scene
  // has contact or indenters). With `resume`: keeps the frames it lists (throws pd::Error if one
  // is missing), removes later ones, and cuts history.csv back to history_bytes (throws if it is
  // shorter or its header differs).
  explicit OutputWriter(std::filesystem::path output_dir, const std::vector<std::string>& extra_columns = {},
                        const OutputResume* resume = nullptr, FrameFormat format = FrameFormat{});
  ~OutputWriter();
  // Keeps the output folder's lock for as long as this writer lives (io/output_lock.hpp).
  void hold(std::unique_ptr<OutputLock> lock) { lock_ = std::move(lock); }
  OutputWriter(const OutputWriter&) = delete;
  OutputWriter& operator=(const OutputWriter&) = delete;

  void frame(const Model& model, const State& state, double time, std::int64_t step,
             const FrameBonds* bonds = nullptr);  // + frames.pvd
  // Frame frames_written() of a decomposed run in pieces, once every rank wrote its piece
  // (frame_piece_file): frame_NNNNNN.pvtu naming the `ranks` pieces, declaring the arrays of
  // `rank0_grid` (every piece has the same arrays), + frames.pvd.
  void frame_of_pieces(const VtuGrid& rank0_grid, int ranks, double time);
  void history(const HistoryRow& row);
  // Writes the buffered rows to history.csv (whole lines, one write); throws pd::Error on failure.
  void flush_history();
  // Flushes and closes history.csv; called at the end (also after a failure or an interruption).
  void finish();
  // Removes the frames later than `time` from frames.pvd (rewritten first) and from disk: those
  // written while a run was blowing up (run/loop.cpp). Returns how many were removed.
  int drop_frames_after(double time);
  int frames_written() const { return static_cast<int>(frames_.size()); }
  std::vector<double> frame_times() const;
  std::uint64_t history_bytes() const { return history_bytes_; }  // on disk, after flush_history()

 private:
  void write_pvd() const;
  std::string frame_file(std::size_t k) const;  // relative to dir_: a .vtu, or a .pvtu in pieces
  std::filesystem::path dir_;
  FrameFormat format_;
  std::vector<std::pair<double, std::string>> frames_;  // (time, relative file)
  int history_fd_ = -1;
  std::unique_ptr<OutputLock> lock_;  // released once ~OutputWriter has closed the files
  std::string history_buffer_;
  std::uint64_t history_bytes_ = 0;
  double last_flush_ = 0.0;  // steady-clock seconds
  bool finished_ = false;
};

}  // namespace pd
