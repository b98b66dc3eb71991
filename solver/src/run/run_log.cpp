// run.log's lines (run/run_log.hpp): the file itself, then the header, the loop's notes and the
// closing lines, in the order a run writes them.
#include "run/run_log.hpp"

#include <cmath>
#include <fstream>
#include <iostream>
#include <iterator>
#include <vector>

#include "core/work_plan.hpp"
#include "forces/indenter.hpp"
#include "io/atomic_file.hpp"
#include "parallel/local_model.hpp"
#include "run/loop.hpp"
#include "run/prepare.hpp"
#include "run/signals.hpp"
#include "run/start.hpp"
#include "run/text.hpp"

namespace pd {

RunLog::RunLog(std::filesystem::path path, bool quiet, bool append) : path_(std::move(path)), quiet_(quiet) {
  if (!append) return;
  std::ifstream in(path_, std::ios::binary);
  text_.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

void RunLog::line(const std::string& text) {
  if (path_.empty()) return;  // a rank other than 0 of a decomposed run: rank 0 writes the log
  if (!quiet_) std::cout << text << std::endl;
  text_ += text + "\n";
  write_file_atomically(path_, text_);
}

void RunLog::note(const std::string& text) {
  if (path_.empty()) return;
  text_ += text + "\n";
  write_file_atomically(path_, text_);
}

void RunLog::error(const std::string& text) {
  if (path_.empty()) return;
  std::cerr << text << std::endl;
  text_ += text + "\n";
  write_file_atomically(path_, text_);
}

void RunLog::title(const RunOptions& opt, const Prepared& p) {
  line("pdsolve " PD_VERSION ": case " + (p.c.name.empty() ? opt.case_file.string() : p.c.name) + " (" +
           opt.case_file.string() + ")");
}

void RunLog::restarted(const RunOptions& opt, const Start& s) {
  line("restart from " + opt.restart.string() + ": step " + std::to_string(s.loop.step) + ", t = " +
       format("%.6g", s.loop.t) + " s, " + std::to_string(s.resume.frame_times.size()) +
       " frames kept (frames after it, history.csv rows after it: dropped)");
}

void RunLog::setup(const Prepared& p) {
  const Case& c = p.c;
  const Model& model = p.model;
  const auto n = static_cast<std::size_t>(p.nodes);
  line("nodes " + std::to_string(n) + ", bonds " + std::to_string(p.directed_bonds() / 2) + " (" +
           format("%.1f", static_cast<double>(p.directed_bonds()) / static_cast<double>(n)) +
           " per node), built in " + format("%.3f", p.build_seconds) + " s");
  line("analysis " + c.analysis + ", horizon " + format("%.6g", c.horizon) + " m = " +
           format("%.4g", c.horizon / c.grid_spacing) + " dx");
  for (std::size_t b = 0; b < model.material.block.size(); ++b)
    line("block " + std::to_string(b + 1) + " '" + c.blocks[b].name + "': c " +
             format("%.6g", model.material.block[b].micromodulus) + ", s0 " +
             (std::isinf(model.material.block[b].critical_stretch) ? std::string("none (unbreakable)")
                                                                   : format("%.6g", model.material.block[b].critical_stretch)));
  line("dt " + format("%.6g", p.dt) + " s (" +
           (c.time.dt_rule == "stable" ? "stable " + format("%.6g", p.dt_stable) + " s × safety factor " + format("%g", c.time.safety_factor)
            : c.time.dt_rule == "exact" ? "exact limit " + format("%.6g", p.dt_exact) + " s = " + format("%.4g", p.dt_exact / p.dt_stable) +
                                              " × eq. 2.5, × safety factor " + format("%g", c.time.safety_factor)
                                        : "fixed; stable " + format("%.6g", p.dt_stable) + " s") +
           (p.integrator->controls_step() ? ", the initial step" : "") +
           "), integrator " + p.integrator->name() + ", damping " + format("%g", c.damping) + " 1/s");
  if (p.isolated > 0 && p.writes_output())  // node_text reads the whole positions, which rank 0 keeps
    line("warning: " + std::to_string(p.isolated) + " of " + std::to_string(n) +
             " nodes have no bond within the horizon (isolated: only loads and contact act on them); the first is " +
             node_text(model, p.first_isolated));
  for (const auto& text : p.step_warnings) line(text);
  for (const auto& text : work_summary(*p.op, c)) line(text);
  if (p.decomposed) {
    const Decomposed& d = *p.decomposed;
    const std::int64_t ghosts = d.total(static_cast<std::int64_t>(d.piece().ghost_local.size()));
    line("decomposed over " + std::to_string(d.ranks()) + " MPI ranks (Morton pieces balanced by bond count): " +
             std::to_string(ghosts) + " ghosts in all, " +
             format("%.3f", static_cast<double>(ghosts) / static_cast<double>(n)) + " per owned node; " +
             "frames, history and run.log from rank 0");
    // What each rank holds of the bonds: its piece's rows, and the whole list too if it kept it.
    const std::vector<double> held = d.per_rank(static_cast<double>(d.piece().model.bonds.directed() + model.bonds.directed()));
    std::string text = "directed bonds held per rank (of " + std::to_string(p.directed_bonds()) + "):";
    for (std::size_t r = 0; r < held.size(); ++r) text += " rank " + std::to_string(r) + " " + format("%.0f", held[r]) + (r + 1 < held.size() ? "," : "");
    line(text + (p.whole_bonds ? "; every rank holds the whole bond list too, for " + whole_bonds_reason(c)
                                   : "; each rank built only the rows of its own nodes"));
    // What each rank holds of the per-node data after set-up: the whole cloud's arrays (rank 0, which
    // writes the output, and every rank that keeps the whole bond list) and its piece's.
    const std::vector<double> whole = d.per_rank(static_cast<double>(node_data_bytes(model)));
    const std::vector<double> own = d.per_rank(static_cast<double>(node_data_bytes(d.piece().model)));
    text = "node data held per rank after set-up (bytes: the whole cloud's arrays + the piece's):";
    for (std::size_t r = 0; r < whole.size(); ++r)
      text += " rank " + std::to_string(r) + " " + format("%.0f", whole[r]) + " + " + format("%.0f", own[r]) + (r + 1 < whole.size() ? "," : "");
    line(text);
  }
  if (p.indenter_watch)
    for (std::size_t k = 0; k < model.indenters.size(); ++k) {
      const IndenterSettings& ind = model.indenters[k];
      const double depth = p.indenter_depths[k];
      const std::string basis = std::string("its stiffness 2K·h with ") + (p.omega2_exact > 0.0 ? "the exact limit" : "eq. 2.5");
      // A sphere or a disk cannot push a node deeper than its radius: a bound past it (1.007 m for a
      // 1.5 mm disk, issue 16) says only that the stiffness never limits the step.
      if (ind.shape != "plane" && depth >= ind.radius)
        line("indenter '" + ind.name + "': dt stays stable at any depth (" + basis + " allows " +
                 format("%.4g", depth) + " m, more than its radius " + format("%.4g", ind.radius) + " m)");
      else
        line("indenter '" + ind.name + "': dt stays stable while no node is deeper than " + format("%.4g", depth) +
                 " m (" + basis + "; a bound, the step may hold deeper)");
    }
  for (const auto& text : p.integrator->describe(p.dt_exact_configured)) line(text);
  line("end time " + format("%.6g", c.time.end) + " s, steps expected " + std::to_string(p.steps_expected) +
           (p.integrator->controls_step() ? " at the initial step (the integrator sets its own)" : "") +
           (p.steps_for_end > p.max_steps ? " (capped by max_steps)" : "") + ", threads " + std::to_string(p.threads));
}

void RunLog::checkpoint_written(const Prepared& p, const LoopState& loop, double seconds) {
  note("checkpoint: " + checkpoint_path(p.c).string() + " at step " + std::to_string(loop.step) + ", t = " +
       format("%.6g", loop.t) + " s (output.restart_every_wall " + format("%g", p.c.output.restart_every_wall) +
       " s), written in " + format("%.3g", seconds) + " s wall");
}

void RunLog::frames_dropped(int dropped, std::int64_t from_step, const std::string& while_what, double kept_until) {
  line("removed " + std::to_string(dropped) + " frame(s) written from step " + std::to_string(from_step) + " on, " +
       while_what + "; the last frame kept, at t = " + format("%.6g", kept_until) + " s, is the last before the growth");
}

void RunLog::summary(const Prepared& p, const LoopState& loop, const LoopEnd& end, std::int64_t frames_written) {
  const Model& model = p.model;
  const double wall = end.wall;
  // The rate of this run: its steps over its wall time (a restart's wall time starts at the restart).
  const double updates = static_cast<double>(p.directed_bonds()) * static_cast<double>(end.steps);
  line(std::string(end.interrupted ? "interrupted" : end.status == kOk ? "done" : "stopped") + ": " +
       std::to_string(loop.step) + " steps to t = " + format("%.6g", loop.t) + " s in " + format("%.3f", wall) +
       " s wall (" + format("%.3g", wall > 0 ? updates / wall : 0.0) + " bond updates/s), " +
       std::to_string(frames_written) + " frames, " + std::to_string(loop.broken) + " broken bonds, " +
       std::to_string(loop.force_evaluations) + " force evaluations" +
       (p.integrator->linear_algebra_summary().empty() ? "" : ", " + p.integrator->linear_algebra_summary()));
  line("output: frames and history.csv took " + format("%.3f", end.output_seconds) + " s wall, " +
       format("%.1f", wall > 0 ? 100.0 * end.output_seconds / wall : 0.0) + " % of the time loop");
  if (model.contact.pairs) {
    // The operator's list: on a decomposed run the piece's, whose owned rows the ranks add up (collective).
    const NeighbourList& list = p.op->model().contact_list;
    auto directed = static_cast<std::int64_t>(list.pairs().directed());
    if (p.decomposed) directed = p.decomposed->total(directed);
    line("contact: " + std::to_string(list.rebuilds()) + " Verlet-list builds in " + std::to_string(loop.step) +
         " steps, " + format("%.3f", list.seconds()) + " s searching" + (p.decomposed ? " (on rank 0)" : "") + ", " +
         std::to_string(directed / 2) + " pairs in the last list");
  }
}

void RunLog::interrupted(const RunOptions& opt, const Prepared& p, const LoopState& loop, int signal) {
  // A checkpoint of a decomposed run holds the whole model in node order: any rank count R continues it.
  const std::string checkpoint_file = checkpoint_path(p.c).string();
  error("pdsolve: interrupted by " + std::string(signal_name(signal)) + " after step " + std::to_string(loop.step) +
        " (t = " + format("%.6g", loop.t) + " s); checkpoint written to " + checkpoint_file + "; continue with: " +
        (p.decomposed ? "mpiexec -np R pdsolve " : "pdsolve ") + opt.case_file.string() + " --restart " + checkpoint_file);
}

void RunLog::stopped_at_max_steps(std::int64_t max_steps) {
  line("note: stopped at max_steps " + std::to_string(max_steps) + " before the end time");
}

}  // namespace pd
