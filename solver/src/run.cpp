// One solver run as its phases (deal.II style): prepare → start or restore → loop → report, each in
// run/ (pipeline/formats.md §3–4).
#include "run.hpp"

#include "core/error.hpp"
#include "run/history_columns.hpp"
#include "run/loop.hpp"
#include "run/prepare.hpp"
#include "run/report.hpp"
#include "run/signals.hpp"
#include "run/start.hpp"

namespace pd {

int run(const RunOptions& opt) {
  const SignalGuard signals;  // from the start: a signal while reading is seen after the first step
  // Every input error is thrown by these two, before any output exists.
  const std::unique_ptr<Prepared> prepared = prepare(opt);
  Prepared& p = *prepared;
  Start s = start_or_restore(opt, p);

  // Output starts here.
  const HistoryColumns columns(p.model, p.c, p.integrator.get());
  // On a decomposed run rank 0 writes every file; the other ranks have no writer and a silent log.
  const std::unique_ptr<OutputWriter> out = open_output(opt, p, s, columns);
  // A checkpoint of an earlier run would not match the frames this run writes.
  if (!s.restarting && out) std::filesystem::remove(checkpoint_path(p.c));
  RunLog log(out ? p.c.output_dir / "run.log" : std::filesystem::path(), opt.quiet, s.restarting);
  log_title(log, opt, p);
  if (s.restarting) log.line(restart_line(opt, s));
  log_setup(log, p);

  // From here on output files exist: an error (a full disk, a failed rename) is a failed run, not
  // bad input (exit 3, --help), and it goes to run.log too; the frames written so far stay valid.
  try {
    const LoopEnd end = run_loop(opt, p, s, columns, out.get(), log);
    return report(opt, p, s.loop, end, out ? out->frames_written() : 0, log);
  } catch (const Error& e) {
    log.error(std::string("pdsolve: error during the run: ") + e.what() +
              "; the frames and history rows written before it are complete");
    return kRunFailed;
  }
}

}  // namespace pd
