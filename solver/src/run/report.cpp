// The closing lines of a run and its exit status (run/report.hpp).
#include "run/report.hpp"

#include "run/schedule.hpp"
#include "run/signals.hpp"
#include "run/text.hpp"

namespace pd {

int report(const RunOptions& opt, const Prepared& p, const LoopState& loop, const LoopEnd& end, std::int64_t frames_written,
           RunLog& log) {
  const Model& model = p.model;
  const double wall = end.wall;
  // The rate of this run: its steps over its wall time (a restart's wall time starts at the restart).
  const double updates = static_cast<double>(p.directed_bonds()) * static_cast<double>(end.steps);
  log.line(std::string(end.interrupted ? "interrupted" : end.status == kOk ? "done" : "stopped") + ": " +
           std::to_string(loop.step) + " steps to t = " + format("%.6g", loop.t) + " s in " + format("%.3f", wall) +
           " s wall (" + format("%.3g", wall > 0 ? updates / wall : 0.0) + " bond updates/s), " +
           std::to_string(frames_written) + " frames, " + std::to_string(loop.broken) + " broken bonds, " +
           std::to_string(loop.force_evaluations) + " force evaluations" +
           (p.integrator->linear_algebra_summary().empty() ? "" : ", " + p.integrator->linear_algebra_summary()));
  log.line("output: frames and history.csv took " + format("%.3f", end.output_seconds) + " s wall, " +
           format("%.1f", wall > 0 ? 100.0 * end.output_seconds / wall : 0.0) + " % of the time loop");
  if (model.contact.pairs) {
    // The operator's list: on a decomposed run the piece's, whose owned rows the ranks add up (collective).
    const NeighbourList& list = p.op->model().contact_list;
    auto directed = static_cast<std::int64_t>(list.pairs().directed());
    if (p.decomposed) directed = p.decomposed->total(directed);
    log.line("contact: " + std::to_string(list.rebuilds()) + " Verlet-list builds in " +
             std::to_string(loop.step) + " steps, " + format("%.3f", list.seconds()) + " s searching" +
             (p.decomposed ? " (on rank 0)" : "") + ", " + std::to_string(directed / 2) + " pairs in the last list");
  }
  // A checkpoint of a decomposed run holds the whole model in node order: any rank count R continues it.
  if (end.interrupted) {
    const std::string checkpoint_file = checkpoint_path(p.c).string();
    log.error("pdsolve: interrupted by " + std::string(signal_name(end.interrupted)) + " after step " +
              std::to_string(loop.step) + " (t = " + format("%.6g", loop.t) + " s); checkpoint written to " +
              checkpoint_file + "; continue with: " +
              (p.decomposed ? "mpiexec -np R pdsolve " : "pdsolve ") + opt.case_file.string() + " --restart " + checkpoint_file);
    return kInterruptedBase + end.interrupted;
  }
  if (end.status == kOk && loop.step >= p.max_steps && Schedule(p.c.output, p.c.time.end).before_end(loop.t))
    log.line("note: stopped at max_steps " + std::to_string(p.max_steps) + " before the end time");
  return end.status;
}

}  // namespace pd
