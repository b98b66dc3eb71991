// Solver output (pipeline/formats.md §4): frames/frame_NNNNNN.vtu, frames.pvd, history.csv, run.log.
// Every file is written under a temporary name and renamed into place.
#pragma once
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <string>
#include <utility>
#include <vector>

#include "core/model.hpp"
#include "core/state.hpp"

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

// One frame as a VTU grid: reference points, displacement, velocity, damage, block; vertex cells
// then one line cell per broken bond (i < j); FieldData TIME and step.
void write_frame(const std::filesystem::path& path, const Model& model, const State& state, double time,
                 std::int64_t step);

class OutputWriter {
 public:
  // Creates output_dir/frames and removes frame files left by an earlier run there. extra_columns
  // name the HistoryRow::extra values (contact and indenter columns, present only when the scene
  // has contact or indenters).
  explicit OutputWriter(std::filesystem::path output_dir, const std::vector<std::string>& extra_columns = {});
  ~OutputWriter();

  void frame(const Model& model, const State& state, double time, std::int64_t step);  // + frames.pvd
  void history(const HistoryRow& row);
  // Flushes history.csv.part and renames it to history.csv; called at the end (also after a failure).
  void finish();
  int frames_written() const { return static_cast<int>(frames_.size()); }

 private:
  std::filesystem::path dir_;
  std::vector<std::pair<double, std::string>> frames_;  // (time, relative file)
  std::ofstream history_;
  bool finished_ = false;
};

// What the solver says at start and end: to stdout (unless quiet) and to run.log, rewritten
// atomically after every message so run.log is complete even if the run is killed.
class RunLog {
 public:
  RunLog(std::filesystem::path path, bool quiet) : path_(std::move(path)), quiet_(quiet) {}
  void line(const std::string& text);
  void error(const std::string& text);  // stderr always, and run.log

 private:
  std::filesystem::path path_;
  bool quiet_;
  std::string text_;
};

}  // namespace pd
