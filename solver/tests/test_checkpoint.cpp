// Checkpoint and restart (io/checkpoint.hpp): a run stopped by SIGTERM, or cut off after a periodic
// checkpoint, and restarted writes bitwise the frames and history rows of an uninterrupted run, for
// Verlet and the adaptive step, with breaking and with contact; a checkpoint of another case, or a
// damaged one, is refused. Also the blow-up report, the isolated-node warning and the material check.
#include <gtest/gtest.h>

#include <algorithm>
#include <unistd.h>

#include <cmath>
#include <csignal>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

#include "../fuzz/checkpoint_seal.hpp"
#include "core/error.hpp"
#include "integrators/adaptive.hpp"
#include "io/checkpoint.hpp"
#include "io/node_file.hpp"
#include "io/vtu.hpp"
#include "files.hpp"
#include "lattice.hpp"
#include "run.hpp"
#include "run/prepare.hpp"
#include "run/start.hpp"
#include "pmb_s0.hpp"

namespace fs = std::filesystem;

namespace {

fs::path temp_dir(const std::string& name) { return pdtest::temp_dir("ckpt_" + name); }
using pdtest::slurp;

void replace(std::string& text, const std::string& from, const std::string& to) {
  const auto at = text.find(from);
  ASSERT_NE(at, std::string::npos) << from;
  text.replace(at, from.size(), to);
}

// A 2D glass plate, 16 × 8 nodes, left edge clamped, the right edge pulled until bonds break.
// `integrator`: verlet | adaptive; `contact`: self-contact on (a Verlet list to carry over).
// `lammps`: LAMMPS's breaking order and α rule (a per-node critical stretch to carry over).
void write_case(const fs::path& dir, const std::string& integrator, bool contact, const std::string& output_extra = "",
                bool isolated_node = false, bool lammps = false) {
  const double dx = 1e-3;
  pd::Nodes nodes = pdtest::cubic_lattice(16, 8, 1, dx, 2, 1e-3);
  if (isolated_node) {  // one node 20 dx away from the plate: no bond
    for (std::size_t d = 0; d < 3; ++d) nodes.x[d].push_back(d == 0 ? 40 * dx : d == 1 ? 3 * dx : 0.0);
    nodes.volume.push_back(nodes.volume.back());
    nodes.block.push_back(1);
  }
  pd::NodeSet left{"left", std::vector<std::uint8_t>(nodes.size(), 0)};
  pd::NodeSet right{"right", std::vector<std::uint8_t>(nodes.size(), 0)};
  for (std::size_t i = 0; i < nodes.size(); ++i) {
    left.member[i] = nodes.x[0][i] < 2.5 * dx;
    right.member[i] = nodes.x[0][i] > 12.5 * dx && nodes.x[0][i] < 20 * dx;
  }
  nodes.sets = {left, right};
  pd::write_node_file(dir / "nodes.vtu", nodes);
  std::ofstream(dir / "case.json") << R"({
    "format_version": 1, "case": "plate", "title": "test plate", "source": "plate.yaml",
    "nodes_file": "nodes.vtu", "output_dir": "out", "dimension": 2, "analysis": "plane_stress",
    "thickness": 0.001, "grid_spacing": 0.001, "horizon": 0.003015,
    "blocks": [{"id": 1, "name": "plate", "model": "pmb", "density": 2440.0, "youngs_modulus": 7.2e10,
                "fracture_energy": 3.8)" + std::string(lammps ? R"(, "critical_stretch_alpha": 0.25}],
    "breaking_order": "lammps",)" : "}],") + R"(
    "no_fail_sets": ["left"], "node_sets": ["left", "right"],
    "boundary_conditions": [
      {"set": "left", "kind": "displacement", "component": 0, "times": [0.0], "values": [0.0]},
      {"set": "right", "kind": "velocity", "component": 0, "times": [0.0, 1e-6], "values": [0.0, 40.0]}],
    "initial_conditions": [{"set": "right", "kind": "velocity", "component": 1, "value": 1.0}],
    "damping": 1000.0,)" + std::string(contact ? R"(
    "contact": {"enabled": "on", "self_contact": true, "skin": 0.00002, "stiffness_factor": 15.0},)" : "") + R"(
    "time": {"end": 4e-6, "integrator": ")" + integrator + R"(", "dt": "stable", "safety_factor": 0.8,
             "max_steps": 100000},
    "output": {"every_time": 5e-7, "every_steps": null, "history_every": 3)" + output_extra + R"(},
    "figures": {"times": null, "displacement_component": 0}
  })";
}

int run(const fs::path& case_file, std::function<void(std::int64_t)> after_step = {}, const fs::path& restart = {},
        std::optional<std::int64_t> max_steps = {}) {
  pd::RunOptions o;
  o.case_file = case_file;
  o.quiet = true;
  o.after_step = std::move(after_step);
  o.restart = restart;
  o.max_steps = max_steps;
  return pd::run(o);
}

std::vector<std::string> lines(const std::string& text) {
  std::vector<std::string> out;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) out.push_back(line);
  return out;
}

// history.csv without the wall_time column (the only one that may differ).
std::vector<std::string> history_without_wall_time(const fs::path& file) {
  std::vector<std::string> rows = lines(slurp(file));
  if (rows.empty()) return rows;
  std::vector<std::string> header;
  {
    std::istringstream in(rows[0]);
    for (std::string cell; std::getline(in, cell, ',');) header.push_back(cell);
  }
  const auto wall = static_cast<std::size_t>(std::find(header.begin(), header.end(), "wall_time") - header.begin());
  for (auto& row : rows) {
    std::istringstream in(row);
    std::string kept, cell;
    for (std::size_t k = 0; std::getline(in, cell, ','); ++k)
      if (k != wall) kept += cell + ",";
    row = kept;
  }
  return rows;
}

std::int64_t total_steps(const fs::path& history) {
  const auto rows = lines(slurp(history));
  return std::stoll(rows.back().substr(0, rows.back().find(',')));
}

// The value of `column` in the last row of history.csv.
double last_value(const fs::path& history, const std::string& column) {
  const auto rows = lines(slurp(history));
  std::istringstream head(rows.front()), row(rows.back());
  for (std::string name, cell; std::getline(head, name, ',') && std::getline(row, cell, ',');)
    if (name == column) return std::stod(cell);
  ADD_FAILURE() << "no column " << column;
  return 0.0;
}

// Every frame, frames.pvd and history.csv (but wall_time) of `b` are those of `a`, byte for byte.
void expect_same_output(const fs::path& a, const fs::path& b) {
  std::size_t frames = 0;
  for (const auto& entry : fs::directory_iterator(a / "frames")) {
    ++frames;
    const fs::path name = fs::path("frames") / entry.path().filename();
    ASSERT_TRUE(fs::exists(b / name)) << name;
    EXPECT_TRUE(slurp(a / name) == slurp(b / name)) << name << " differs";
  }
  std::size_t frames_b = 0;
  for ([[maybe_unused]] const auto& entry : fs::directory_iterator(b / "frames")) ++frames_b;
  EXPECT_EQ(frames, frames_b);
  EXPECT_GE(frames, 5u);
  EXPECT_EQ(slurp(a / "frames.pvd"), slurp(b / "frames.pvd"));
  const auto ha = history_without_wall_time(a / "history.csv"), hb = history_without_wall_time(b / "history.csv");
  ASSERT_EQ(ha.size(), hb.size());
  for (std::size_t k = 0; k < ha.size(); ++k) EXPECT_EQ(ha[k], hb[k]) << "history.csv row " << k;
}

struct Variant {
  std::string integrator;
  bool contact;
  bool lammps = false;  // LAMMPS's breaking order and α rule (docs/lammps.md)
};

void PrintTo(const Variant& v, std::ostream* os) {
  *os << v.integrator << (v.contact ? " with contact" : "") << (v.lammps ? " with LAMMPS's rules" : "");
}

class Restart : public ::testing::TestWithParam<Variant> {};

TEST_P(Restart, SigtermThenRestartIsBitwiseTheUninterruptedRun) {
  const Variant v = GetParam();
  const std::string tag = v.integrator + (v.lammps ? "_lammps" : "");
  const fs::path whole = temp_dir("whole_" + tag), cut = temp_dir("cut_" + tag);
  write_case(whole, v.integrator, v.contact, "", false, v.lammps);
  write_case(cut, v.integrator, v.contact, "", false, v.lammps);
  ASSERT_EQ(slurp(whole / "case.json"), slurp(cut / "case.json"));
  ASSERT_EQ(run(whole / "case.json"), pd::kOk);
  const std::int64_t steps = total_steps(whole / "out" / "history.csv");
  ASSERT_GE(steps, 20);
  EXPECT_GT(last_value(whole / "out" / "history.csv", "broken_bonds"), 0);  // else the broken flags go untested
  if (v.contact)  // rebuilt during the run, so the list's state at the checkpoint matters
    EXPECT_GT(last_value(whole / "out" / "history.csv", "contact_rebuilds"), 5);

  // Stop just before a step that lands on an output time: that step is shortened, which the
  // adaptive step tells from its last proposal (integrator state that must survive the restart).
  std::vector<std::int64_t> landings;
  for (const auto& row : lines(slurp(whole / "out" / "history.csv"))) {
    if (row.rfind("step", 0) == 0) continue;
    std::istringstream in(row);
    std::string step_text, time_text;
    std::getline(in, step_text, ','), std::getline(in, time_text, ',');
    const double k = std::stod(time_text) / 5e-7;
    if (k > 0.5 && std::fabs(k - std::round(k)) < 1e-9) landings.push_back(std::stoll(step_text));
  }
  ASSERT_GE(landings.size(), 5u);
  const std::int64_t stop = landings[landings.size() / 2] - 1;
  const int code = run(cut / "case.json", [stop](std::int64_t step) {
    if (step == stop) std::raise(SIGTERM);
  });
  EXPECT_EQ(code, pd::kInterruptedBase + SIGTERM);
  ASSERT_TRUE(fs::exists(cut / "out" / "checkpoint.bin"));
  EXPECT_LE(total_steps(cut / "out" / "history.csv"), stop);
  const pd::Checkpoint ck = pd::read_checkpoint(cut / "out" / "checkpoint.bin");
  EXPECT_EQ(ck.loop.step, stop);
  EXPECT_EQ(ck.integrator, v.integrator);
  EXPECT_EQ(ck.linear_solver, "");  // an explicit scheme solves no linear system
  // LAMMPS's α rule: the per-node s0 is state the checkpoint carries (and has moved off s00).
  ASSERT_EQ(ck.state_arrays.size(), v.lammps ? 1u : 0u);  // PMB's declared state: s0_i with α > 0
  if (v.lammps) {
    const std::vector<double>& s0 = ck.state_arrays[0].values;
    EXPECT_EQ(ck.state_arrays[0].declaration.name, pd::kNodeCriticalStretch);
    EXPECT_EQ(s0.size(), 16u * 8u);
    EXPECT_NE(*std::min_element(s0.begin(), s0.end()), *std::max_element(s0.begin(), s0.end()));
  }
  EXPECT_EQ(ck.history_bytes, fs::file_size(cut / "out" / "history.csv"));  // whole rows only, all on disk
  EXPECT_NE(slurp(cut / "out" / "run.log").find("interrupted by SIGTERM after step " + std::to_string(stop)),
            std::string::npos)
      << slurp(cut / "out" / "run.log");

  ASSERT_EQ(run(cut / "case.json", {}, cut / "out" / "checkpoint.bin"), pd::kOk);
  expect_same_output(whole / "out", cut / "out");
  EXPECT_NE(slurp(cut / "out" / "run.log").find("restart from"), std::string::npos);
  fs::remove_all(whole);
  fs::remove_all(cut);
}

// A periodic checkpoint, then the run goes on (and writes frames and rows) until it is cut off
// (here by max_steps, as a kill would): the restart drops what came after the checkpoint.
TEST_P(Restart, PeriodicCheckpointThenCutOffRunRestartsBitwise) {
  const Variant v = GetParam();
  const std::string tag = v.integrator + (v.lammps ? "_lammps" : "");
  const fs::path whole = temp_dir("pwhole_" + tag), cut = temp_dir("pcut_" + tag);
  write_case(whole, v.integrator, v.contact, R"(, "restart_every_steps": 7)", false, v.lammps);
  write_case(cut, v.integrator, v.contact, R"(, "restart_every_steps": 7)", false, v.lammps);
  ASSERT_EQ(run(whole / "case.json"), pd::kOk);
  const std::int64_t steps = total_steps(whole / "out" / "history.csv");
  const std::int64_t stop = steps * 2 / 3 + 1;
  ASSERT_EQ(run(cut / "case.json", {}, {}, stop), pd::kOk);
  const pd::Checkpoint ck = pd::read_checkpoint(cut / "out" / "checkpoint.bin");
  EXPECT_EQ(ck.loop.step, stop / 7 * 7);
  EXPECT_LT(ck.history_bytes, fs::file_size(cut / "out" / "history.csv"));
  ASSERT_EQ(run(cut / "case.json", {}, cut / "out" / "checkpoint.bin"), pd::kOk);
  expect_same_output(whole / "out", cut / "out");
  fs::remove_all(whole);
  fs::remove_all(cut);
}

INSTANTIATE_TEST_SUITE_P(Checkpoint, Restart,
                         ::testing::Values(Variant{"verlet", false}, Variant{"adaptive", false},
                                           Variant{"verlet", true}, Variant{"adaptive", true},
                                           Variant{"verlet", false, true}),
                         [](const auto& info) {
                           return info.param.integrator + (info.param.contact ? "_contact" : "") +
                                  (info.param.lammps ? "_lammps" : "");
                         });

// LAMMPS's α rule: the per-node critical stretch is state. It moves with every breaking pass, so a
// stale one after a restart would only show in the step after it (the bitwise Restart variant
// verlet_lammps cannot see that); here the restored model holds the checkpoint's values exactly.
TEST(Checkpoint, RestoresThePerNodeCriticalStretchOfTheAlphaRule) {
  const fs::path dir = temp_dir("alpha");
  write_case(dir, "verlet", false, R"(, "restart_every_steps": 10)", false, true);
  ASSERT_EQ(run(dir / "case.json", {}, {}, 25), pd::kOk);
  const pd::Checkpoint ck = pd::read_checkpoint(dir / "out" / "checkpoint.bin");
  ASSERT_EQ(ck.loop.step, 20);
  ASSERT_EQ(ck.state_arrays.size(), 1u);
  const std::vector<double>& saved = ck.state_arrays[0].values;
  ASSERT_EQ(saved.size(), 16u * 8u);
  pd::RunOptions o;
  o.case_file = dir / "case.json";
  o.quiet = true;
  o.restart = dir / "out" / "checkpoint.bin";
  std::unique_ptr<pd::Prepared> p = pd::prepare(o);
  const std::vector<double> fresh = pdtest::s0_of(p->model);  // at rest: s00 everywhere
  pd::start_or_restore(o, *p);
  EXPECT_EQ(pdtest::s0_of(p->model), saved);
  EXPECT_NE(pdtest::s0_of(p->model), fresh);  // the stretched plate moved s0 off s00
  fs::remove_all(dir);
}

TEST(Checkpoint, RestartTimeEveryTimeWritesCheckpoints) {
  const fs::path dir = temp_dir("every_time");
  write_case(dir, "verlet", false, R"(, "restart_every_time": 1.5e-6)");
  ASSERT_EQ(run(dir / "case.json"), pd::kOk);
  const pd::Checkpoint ck = pd::read_checkpoint(dir / "out" / "checkpoint.bin");
  EXPECT_GE(ck.loop.t, 3e-6);  // the last: the first step at or after 2 × 1.5e-6
  EXPECT_LT(ck.loop.t, 3e-6 + 2 * ck.loop.dt);
  EXPECT_EQ(ck.loop.next_restart_index, 3);
  fs::remove_all(dir);
}

// The index's writer deletes the pieces no index names (an earlier checkpoint's), and only those:
// a file of the user's in checkpoint.pieces/ stays.
TEST(Checkpoint, OnlyPiecesNoIndexNamesAreDeleted) {
  const fs::path dir = temp_dir("stray_pieces");
  write_case(dir, "verlet", false, R"(, "restart_every_time": 1.5e-6)");
  const fs::path pieces = dir / "out" / "checkpoint.pieces";
  fs::create_directories(pieces);
  std::ofstream(pieces / "notes.txt") << "mine";
  std::ofstream(pieces / "s999.p7.bin") << "an old piece";
  ASSERT_EQ(run(dir / "case.json"), pd::kOk);
  const pd::Checkpoint ck = pd::read_checkpoint(dir / "out" / "checkpoint.bin");
  EXPECT_TRUE(fs::exists(pieces / "notes.txt"));
  EXPECT_FALSE(fs::exists(pieces / "s999.p7.bin"));
  std::size_t files = 0;
  for (const auto& entry : fs::directory_iterator(pieces)) files += entry.is_regular_file() ? 1 : 0;
  EXPECT_EQ(files, ck.pieces.size() + 1);  // the last checkpoint's pieces and the user's file
  fs::remove_all(dir);
}

// output.restart_every_wall (issue 36, item 8): checkpoints by wall time, on by default, so that a
// run killed with SIGKILL has one. They are written between steps and change no bit of the frames
// and history rows; the last one before a run was cut off continues it bitwise. Each step here
// sleeps 40 ms so that a 1 ns interval, held back only by the 3 % bound, gives several checkpoints:
// the bound spaces them by 33 × a checkpoint's write time, and with fsync that took 5.5 ms on a
// quiet machine and 37 ms under load, where 2 ms steps (a 0.1 s run) gave one checkpoint only.
TEST(Checkpoint, WallClockCheckpointsChangeNoBitAndContinueBitwise) {
  const fs::path off = temp_dir("wall_off"), on = temp_dir("wall_on"), cut = temp_dir("wall_cut");
  write_case(off, "adaptive", false, R"(, "restart_every_wall": 0)");
  write_case(on, "adaptive", false, R"(, "restart_every_wall": 1e-9)");
  write_case(cut, "adaptive", false, R"(, "restart_every_wall": 1e-9)");
  const auto slow = [](std::int64_t) { usleep(40000); };
  ASSERT_EQ(run(off / "case.json", slow), pd::kOk);
  EXPECT_FALSE(fs::exists(off / "out" / "checkpoint.bin"));  // 0: none

  ASSERT_EQ(run(on / "case.json", slow), pd::kOk);
  expect_same_output(off / "out", on / "out");
  const std::string log = slurp(on / "out" / "run.log");
  const std::regex line(R"(checkpoint: \S+checkpoint\.bin at step (\d+), t = \S+ s \(output\.restart_every_wall 1e-09 s\), written in \S+ s wall)");
  const auto written = std::distance(std::sregex_iterator(log.begin(), log.end(), line), std::sregex_iterator());
  EXPECT_GE(written, 2) << log;
  EXPECT_TRUE(fs::exists(on / "out" / "checkpoint.bin"));

  // Cut off two thirds in (as a SIGKILL would): the last wall-time checkpoint continues the run.
  const std::int64_t stop = total_steps(off / "out" / "history.csv") * 2 / 3;
  ASSERT_EQ(run(cut / "case.json", slow, {}, stop), pd::kOk);
  const pd::Checkpoint ck = pd::read_checkpoint(cut / "out" / "checkpoint.bin");
  EXPECT_GT(ck.loop.step, 0);
  EXPECT_LE(ck.loop.step, stop);
  ASSERT_EQ(run(cut / "case.json", {}, cut / "out" / "checkpoint.bin"), pd::kOk);
  expect_same_output(off / "out", cut / "out");
  for (const auto& dir : {off, on, cut}) fs::remove_all(dir);
}

TEST(Checkpoint, RefusedForAnotherCaseOrWhenDamaged) {
  const fs::path dir = temp_dir("refuse");
  write_case(dir, "verlet", false);
  const int code = run(dir / "case.json", [](std::int64_t step) {
    if (step == 10) std::raise(SIGINT);
  });
  EXPECT_EQ(code, pd::kInterruptedBase + SIGINT);
  const fs::path ck = dir / "out" / "checkpoint.bin";
  const std::string good = slurp(ck);
  auto error_of = [&](const fs::path& case_file) -> std::string {
    try {
      run(case_file, {}, ck);
    } catch (const pd::Error& e) {
      return e.what();
    }
    return "(no error)";
  };
  // Another case: the same nodes, another damping.
  std::string text = slurp(dir / "case.json");
  replace(text, "\"damping\": 1000.0", "\"damping\": 999.0");
  std::ofstream(dir / "other.json") << text;
  EXPECT_NE(error_of(dir / "other.json").find("belongs to another case file"), std::string::npos)
      << error_of(dir / "other.json");
  // Another node file under the same name.
  const fs::path other = temp_dir("refuse_other");
  write_case(other, "verlet", false, "", true);
  fs::copy_file(dir / "nodes.vtu", dir / "nodes.keep");
  fs::copy_file(other / "nodes.vtu", dir / "nodes.vtu", fs::copy_options::overwrite_existing);
  EXPECT_NE(error_of(dir / "case.json").find("belongs to another node file"), std::string::npos)
      << error_of(dir / "case.json");
  fs::rename(dir / "nodes.keep", dir / "nodes.vtu");
  fs::remove_all(other);
  // Damaged: one payload byte flipped, or cut short.
  std::string bad = good;
  bad[bad.size() / 2] = static_cast<char>(bad[bad.size() / 2] ^ 0x10);
  std::ofstream(ck, std::ios::binary) << bad;
  EXPECT_NE(error_of(dir / "case.json").find("checksum mismatch"), std::string::npos) << error_of(dir / "case.json");
  std::ofstream(ck, std::ios::binary) << good.substr(0, good.size() - 100);
  EXPECT_NE(error_of(dir / "case.json").find("truncated"), std::string::npos) << error_of(dir / "case.json");
  std::ofstream(ck, std::ios::binary) << "not a checkpoint";
  EXPECT_NE(error_of(dir / "case.json").find("not a pdsolve checkpoint"), std::string::npos);
  // Of version 5, one file holding the whole model (issue 37): refused, saying how to start over.
  std::string old = good;
  old[8] = 5;  // the uint32 version after the 8-byte magic, little-endian
  std::ofstream(ck, std::ios::binary) << old;
  EXPECT_NE(error_of(dir / "case.json").find("checkpoint format version 5, this pdsolve reads version 6; to start the "
                                             "run over instead, delete"),
            std::string::npos) << error_of(dir / "case.json");
  // Its piece (a serial run writes one): damaged, cut short or missing, it is named; the history
  // the restart would have cut stays as it was.
  std::ofstream(ck, std::ios::binary) << good;
  const pd::Checkpoint index = pd::parse_checkpoint(good, ck.string());
  ASSERT_EQ(index.pieces.size(), 1u);
  const fs::path piece = ck.parent_path() / index.pieces[0].file;
  EXPECT_EQ(piece.parent_path().filename(), "checkpoint.pieces");
  EXPECT_EQ(std::distance(fs::directory_iterator(piece.parent_path()), fs::directory_iterator()), 1);  // earlier pieces went
  const std::string good_piece = slurp(piece);
  const std::string history = slurp(dir / "out" / "history.csv");
  std::string bad_piece = good_piece;
  bad_piece[bad_piece.size() - 20] = static_cast<char>(bad_piece[bad_piece.size() - 20] ^ 0x01);
  std::ofstream(piece, std::ios::binary) << bad_piece;
  EXPECT_NE(error_of(dir / "case.json").find(piece.string() + ": checkpoint piece checksum mismatch"), std::string::npos)
      << error_of(dir / "case.json");
  std::ofstream(piece, std::ios::binary) << good_piece.substr(0, good_piece.size() - 8);
  EXPECT_NE(error_of(dir / "case.json").find(piece.string() + ": " + std::to_string(good_piece.size() - 8) + " bytes, but"),
            std::string::npos) << error_of(dir / "case.json");
  fs::remove(piece);
  EXPECT_NE(error_of(dir / "case.json").find(piece.string() + ": missing, but " + ck.string() + " names it as piece 0 of 1"),
            std::string::npos) << error_of(dir / "case.json");
  EXPECT_EQ(slurp(dir / "out" / "history.csv"), history);
  std::ofstream(piece, std::ios::binary) << good_piece;
  // Still good after all that.
  std::ofstream(ck, std::ios::binary) << good;
  EXPECT_EQ(run(dir / "case.json", {}, ck), pd::kOk);
  fs::remove_all(dir);
}

// Two inputs the fuzzer's regression set keeps (solver/fuzz/regressions/pd_fuzz_checkpoint): a
// header whose payload size is 2⁶⁴ − 1 is named as stored (kHead + size + 8 would wrap around to
// a small number), and a checksum-valid file with indenter forces that are not whole triples is
// refused rather than silently shortened.
TEST(Checkpoint, ReaderNamesAHugePayloadSizeAndRefusesPartialIndenterTriples) {
  const fs::path inputs = fs::path(PD_SOURCE_DIR) / "fuzz" / "regressions" / "pd_fuzz_checkpoint";
  auto error_of = [](const std::string& bytes) -> std::string {
    try {
      pd::parse_checkpoint(bytes, "ck.bin");
    } catch (const pd::Error& e) {
      return e.what();
    }
    return "(no error)";
  };
  const std::string huge = error_of(slurp(inputs / "huge-payload-size"));
  EXPECT_NE(huge.find("ck.bin: checkpoint truncated or padded: 770 bytes, the header says a payload of "
                      "18446744073709551615 bytes"),
            std::string::npos)
      << huge;
  const std::string triples = error_of(pd_fuzz::sealed_checkpoint(slurp(inputs / "indenter-force-not-triple-sealed")));
  EXPECT_NE(triples.find("indenter forces are not whole (x, y, z) triples"), std::string::npos) << triples;
}

// A blow-up names the step, the time and the node (index and position) where it most likely
// started; the frames written before stay, and frames.pvd lists exactly those.
TEST(Checkpoint, BlowUpNamesStepTimeAndNodeAndKeepsAValidPvd) {
  const fs::path dir = temp_dir("blowup");
  write_case(dir, "verlet", false);
  std::string text = slurp(dir / "case.json");
  replace(text, "\"dt\": \"stable\"", "\"dt\": 6e-7");  // about 3× the stable step
  replace(text, "\"end\": 4e-6", "\"end\": 1e-3");
  replace(text, "\"fracture_energy\": 3.8", "\"fracture_energy\": null");
  std::ofstream(dir / "case.json") << text;
  EXPECT_EQ(run(dir / "case.json"), pd::kRunFailed);
  const std::string log = slurp(dir / "out" / "run.log");
  EXPECT_TRUE(std::regex_search(log, std::regex(R"(after step [0-9]+ \(t = [0-9.e+-]+ s)"))) << log;
  EXPECT_TRUE(std::regex_search(log, std::regex(R"(node [0-9]+ at \([-0-9.e+]+, [-0-9.e+]+, [-0-9.e+]+\) m)"))) << log;
  const std::string pvd = slurp(dir / "out" / "frames.pvd");
  std::size_t listed = 0;
  static const std::regex file_attr("file=\"([^\"]+)\"");
  for (std::sregex_iterator it(pvd.begin(), pvd.end(), file_attr), end; it != end; ++it) {
    ++listed;
    const pd::VtuGrid g = pd::read_vtu(dir / "out" / (*it)[1].str());  // each one reads back
    EXPECT_EQ(g.points.tuples(), 128u);
  }
  EXPECT_GE(listed, 1u);
  std::size_t files = 0;
  for ([[maybe_unused]] const auto& entry : fs::directory_iterator(dir / "out" / "frames")) ++files;
  EXPECT_EQ(files, listed);  // no .part, no frame of the bad state
  EXPECT_EQ(slurp(dir / "out" / "history.csv").back(), '\n');
  fs::remove_all(dir);
}

TEST(Checkpoint, IsolatedNodesAreReportedWithTheFirstPosition) {
  const fs::path dir = temp_dir("isolated");
  write_case(dir, "verlet", false, "", true);
  ASSERT_EQ(run(dir / "case.json", {}, {}, 3), pd::kOk);
  const std::string log = slurp(dir / "out" / "run.log");
  EXPECT_NE(log.find("warning: 1 of 129 nodes have no bond within the horizon"), std::string::npos) << log;
  EXPECT_NE(log.find("node 128 at (0.04, 0.003, 0) m"), std::string::npos) << log;
  fs::remove_all(dir);
}

TEST(Checkpoint, UnusableMaterialConstantsAreAnInputError) {
  const fs::path dir = temp_dir("material");
  write_case(dir, "verlet", false);
  std::string text = slurp(dir / "case.json");
  replace(text, "\"youngs_modulus\": 7.2e10", "\"youngs_modulus\": 1e300");  // c overflows
  std::ofstream(dir / "case.json") << text;
  try {
    run(dir / "case.json");
    FAIL() << "no error";
  } catch (const pd::Error& e) {
    EXPECT_NE(std::string(e.what()).find("blocks[0] 'plate': the material gives micromodulus c = inf"), std::string::npos)
        << e.what();
  }
  EXPECT_FALSE(fs::exists(dir / "out"));
  fs::remove_all(dir);
}

// The adaptive step's own state (its last proposal) survives save_state/load_state: after a step
// shortened to land on an output time, a restored integrator proposes what the original does, and
// one that lost the proposal does not.
TEST(Checkpoint, AdaptiveIntegratorStateCarriesItsProposal) {
  pd::Case c = pdtest::lattice_case(2, "plane_stress", 1e-3, 3.015e-3, 1e9, 1000.0, -1.0, 1e-3);
  auto model = [&] { return pd::build_model(c, pdtest::cubic_lattice(12, 12, 1, 1e-3, 2, 1e-3)); };
  pd::Model m1 = model(), m2 = model(), m3 = model();
  const double dt_sa = pd::stable_time_step(m1);
  c.adaptive.dt_max = 100.0 * dt_sa;  // only the controller limits the step
  c.adaptive.kd = 1;  // accepted at K = 1 or rejected: the regime where a shortened step keeps its proposal
  pd::State s(m1.nodes.size());
  for (std::size_t i = 0; i < s.size(); ++i) s.v[2][i] = std::sin(300.0 * m1.nodes.x[0][i]) * std::sin(250.0 * m1.nodes.x[1][i]);
  pd::ForceOperator op_a(m1);
  pd::AdaptiveStep a(op_a);
  a.configure(c);
  double t = 0.0, dt = 10.0 * dt_sa;
  a.initialize(s, t);
  for (int k = 0; k < 40; ++k) {  // the controller settles
    double h = dt;
    a.step(s, t, h);
    dt = a.last_step().next_dt;
  }
  const std::vector<char> saved = a.save_state();
  pd::ForceOperator op_m2(m2), op_m3(m3);
  auto restored = [&](pd::ForceOperator& op, bool load) {
    auto b = std::make_unique<pd::AdaptiveStep>(op);
    b->configure(c);
    pd::State scratch(op.size());
    b->initialize(scratch, t);
    if (load) b->load_state(saved);
    return b;
  };
  {
    auto b = restored(op_m2, true);
    EXPECT_EQ(b->save_state(), saved);
    EXPECT_THROW(b->load_state(std::vector<char>(saved.begin(), saved.end() - 1)), std::runtime_error);
  }
  // A step shortened to land on an output time, from the same state: the restored integrator
  // proposes exactly what the original does; for some shortening, one without the state does not.
  int differs = 0;
  for (double fraction : {0.99, 0.95, 0.9, 0.8, 0.6, 0.4, 0.2}) {
    pd::AdaptiveStep orig(a);  // a copy of the original integrator itself, never saved or loaded
    auto b = restored(op_m2, true), fresh = restored(op_m3, false);
    pd::State sa = s, sb = s, sc = s;
    double ta = t, tb = t, tc = t, ha = fraction * dt, hb = ha, hc = ha;
    orig.step(sa, ta, ha);
    b->step(sb, tb, hb);
    fresh->step(sc, tc, hc);
    EXPECT_EQ(orig.last_step().next_dt, b->last_step().next_dt) << fraction;
    EXPECT_EQ(sa.u[2], sb.u[2]) << fraction;
    differs += orig.last_step().next_dt != fresh->last_step().next_dt;
  }
  EXPECT_GT(differs, 0) << "the proposal never mattered: the test shows nothing";
}

}  // namespace

// A directory or a device given as the checkpoint (issue 17, item 9): a clear error, without the
// advice to delete it; /dev/zero was read until memory ran out, a directory was
// "internal error: basic_filebuf::underflow".
TEST(Checkpoint, ADirectoryOrADeviceIsNoCheckpoint) {
  const fs::path dir = temp_dir("not_a_file");
  write_case(dir, "verlet", false);
  const std::vector<std::pair<fs::path, std::string>> cases = {
      {dir, dir.string() + ": a directory, not the checkpoint; give the path of the file"},
      {"/dev/zero", "/dev/zero: not a regular file, not the checkpoint; give the path of the file"}};
  for (const auto& [restart, expected] : cases) {
    try {
      run(dir / "case.json", {}, restart);
      ADD_FAILURE() << "no error for " << restart;
    } catch (const pd::Error& e) {
      EXPECT_EQ(std::string(e.what()), expected);
    }
  }
  EXPECT_FALSE(fs::exists(dir / "out" / "history.csv"));  // refused before any output
  fs::remove_all(dir);
}

namespace {

// history.csv's `mode` column, row by row.
std::vector<int> modes_of(const fs::path& history) {
  const auto rows = lines(slurp(history));
  std::vector<std::string> header;
  {
    std::istringstream in(rows.front());
    for (std::string cell; std::getline(in, cell, ',');) header.push_back(cell);
  }
  const auto column = static_cast<std::size_t>(std::find(header.begin(), header.end(), "mode") - header.begin());
  EXPECT_LT(column, header.size()) << "no mode column";
  std::vector<int> modes;
  for (std::size_t r = 1; r < rows.size(); ++r) {
    std::istringstream in(rows[r]);
    std::string cell;
    for (std::size_t k = 0; k <= column && std::getline(in, cell, ','); ++k) {
    }
    modes.push_back(static_cast<int>(std::stod(cell)));
  }
  return modes;
}

// The plate of write_case under mixed, started implicit (mixed.start), checkpointed every 7 steps.
void write_mixed_implicit_case(const fs::path& dir) {
  write_case(dir, "mixed", false, R"(, "restart_every_steps": 7)");
  std::string text = slurp(dir / "case.json");
  replace(text, R"("time": {)", R"("mixed": {"start": "implicit", "unstable_rounds": 2}, "implicit": {"rho_infinity": 0.8},
    "time": {)");
  std::ofstream(dir / "case.json") << text;
}

}  // namespace

TEST(Checkpoint, MixedStartedImplicitShowsItsModesInHistoryAndRestartsBitwise) {
  // The pulled plate cracks: generalized-α steps (mode 2) first, Verlet (mode 0) once bonds keep
  // breaking; history.csv's mode column says so, run.log the switch; a run cut off after a periodic
  // checkpoint and restarted writes the uninterrupted run's frames and rows byte for byte.
  const fs::path whole = temp_dir("mixed_implicit_whole"), cut = temp_dir("mixed_implicit_cut");
  write_mixed_implicit_case(whole);
  write_mixed_implicit_case(cut);
  ASSERT_EQ(run(whole / "case.json"), pd::kOk) << slurp(whole / "out" / "run.log");
  const std::vector<int> modes = modes_of(whole / "out" / "history.csv");
  ASSERT_FALSE(modes.empty());
  EXPECT_EQ(modes.front(), 2);
  const auto first_explicit = std::find(modes.begin(), modes.end(), 0);
  ASSERT_NE(first_explicit, modes.end()) << "never explicit";
  EXPECT_TRUE(std::all_of(modes.begin(), first_explicit, [](int m) { return m == 2; }));
  EXPECT_EQ(std::count(modes.begin(), modes.end(), 1), 0);  // no quasi-static step
  EXPECT_GT(last_value(whole / "out" / "history.csv", "broken_bonds"), 0);
  const std::string log = slurp(whole / "out" / "run.log");
  EXPECT_NE(log.find("implicit → explicit"), std::string::npos) << log;
  EXPECT_NE(log.find("starts implicit (mixed.start)"), std::string::npos) << log;
  const std::int64_t steps = total_steps(whole / "out" / "history.csv");
  // Cut off in the implicit phase and in the explicit one.
  const std::int64_t implicit_rows = first_explicit - modes.begin();
  std::printf("mixed from implicit, plate: %lld steps, the first %lld rows implicit (history every 3 steps)\n",
              static_cast<long long>(steps), static_cast<long long>(implicit_rows));
  for (const std::int64_t stop : {std::int64_t{9}, steps * 2 / 3 + 1}) {
    fs::remove_all(cut / "out");
    ASSERT_EQ(run(cut / "case.json", {}, {}, stop), pd::kOk);
    const pd::Checkpoint ck = pd::read_checkpoint(cut / "out" / "checkpoint.bin");
    EXPECT_EQ(ck.loop.step, stop / 7 * 7);
    EXPECT_EQ(ck.integrator, "mixed");
    EXPECT_EQ(ck.linear_solver, "direct");  // implicit's, on one process (format version 4 on)
    ASSERT_EQ(run(cut / "case.json", {}, cut / "out" / "checkpoint.bin"), pd::kOk);
    expect_same_output(whole / "out", cut / "out");
  }
  fs::remove_all(whole);
  fs::remove_all(cut);
}
