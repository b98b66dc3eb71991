"""Bitwise regression check of the solver: run a fixed set of inputs, hash every result, compare.

For a refactor of solver/ that must not change one result bit. The inputs are made once (by the
pre-processor of one checkout, so that a change of the Python side cannot hide or fake a change of
the solver) and then every solver build runs exactly the same input files:

    /usr/bin/python3 bench/result_hashes.py prepare --repo /work/baseline --runs /work/hashruns
    /usr/bin/python3 bench/result_hashes.py run --solver build/solver/pdsolve --runs /work/hashruns \\
        --out /work/hashruns/new.json [--threads 2] [--ranks N [--frames gathered]] [--only NAME ...] [--keep DIR]
    /usr/bin/python3 bench/result_hashes.py compare /work/hashruns/baseline.json /work/hashruns/new.json

prepare: the runs are
  - every case and variant: for each cases/<case>/<config>.yaml of --repo, what
    `make case=<case> config=<config>` would feed the solver (the Makefile's stages,
    `python3 -m pipeline.run mesh` then `preprocess`, run in --repo; a case's own
    <case>.unv / .msh is used instead of meshing, as the Makefile does). Run name: <case>, or
    <case>-<config> for a variant (the Makefile's out/ folder name);
  - the runs of `make bench-accuracy` (bench/accuracy.py of --repo, run there, not copied): the
    wave and the fracture problem, each with its reference (Verlet at 0.05 × eq. 2.5) and every
    scheme of accuracy.schemes() (the full set by default, `--accuracy quick` for its --quick set,
    `none` for no such runs). Run name: accuracy-<problem>-<scheme>-<parameter>. The Δt_max =
    4 × eq. 2.5 of the "dtmax4" runs takes eq. 2.5 from `pdsolve --physics` on the problem
    (pipeline/solver_physics.py: $PDSOLVE, else --repo's build/solver/pdsolve, which the
    preprocess of the cases needs anyway) instead of a run's run.log, as bench-accuracy does; the
    number is stored in the run's case.json, so every solver compared gets the same one.
  Each run gets its folder <runs>/<run>/ holding case.json and the node file it names (copied in as
  nodes.vtu, the only file a case.json refers to); the copy of case.json has nodes_file
  "nodes.vtu" and output_dir "output", so that a run writes <runs>/<run>/output/ and nothing
  outside it (pdsolve refuses an output_dir outside the folder of case.json). The copy leaves out
  output.restart_every_wall when it is the default (600 s): a checkpoint changes no result, and
  without the key the inputs also run on a solver from before it (the baseline of a comparison). <runs>/manifest.json lists the runs and where they came from (repo, commit).

run: for each prepared run (in manifest order; --only / --skip to choose; --ranks N under mpiexec), empty
  <runs>/<run>/output/, run `SOLVER <run>/case.json --threads N --quiet` with OMP_WAIT_POLICY=passive
  (--frames gathered|pieces adds `--parallel-frames gathered|pieces`: on several ranks pdsolve writes its
  frames in pieces by default, and `--frames gathered` makes them the serial run's files, byte for
  byte comparable with a serial baseline. An option of pdsolve rather than an edited copy of
  case.json: the input files, their hashes and the paths relative to case.json stay as prepared)
  unless the environment sets it (much faster on a shared, loaded machine; no effect on results),
  stdout and stderr going to <runs>/<run>/solver.txt (not hashed), then record the SHA-256 of
  - "history.csv": the file with its wall_time column removed (found by name in the header; every
    other byte of every line, line ends included, exactly as written: no number is re-parsed);
  - "frames.pvd" and every "frames/frame_NNNNNN.vtu", byte for byte;
  - any other file the solver leaves in output/, byte for byte (today there is none; a new one
    shows up as a difference), except run.log (timings, paths), checkpoint.bin and the pieces in
    checkpoint.pieces/ (written
    on a signal, with output.restart_every_*, and every 600 s of wall time; it holds the wall time)
    and .lock (the folder's lock: the solver's pid and start time);
  - "input/case.json" and "input/nodes.vtu" (<run>/case.json and nodes.vtu), so that hashes of
    different input sets are not
    compared by mistake;
  - "exit": the solver's exit code (an integer, not a hash).
  --keep DIR copies each run's output/ to DIR/<run>/ for a closer look at a difference (the next
  `run` overwrites output/). The JSON is {run: {file: sha256 | exit code}}, plus an "_about" entry
  (solver, its --version, threads, seconds per run) that compare ignores.

compare: per run and per file, equal or different (or missing on one side); exit status 1 on any
  difference, 0 when every hash of every run is the same. --common: only the runs both files have
  (to check a `run --only` subset).

Stdlib only: the project's modules (numpy with them) run in processes started in --repo, in prepare.
"""
from __future__ import annotations

import argparse
import hashlib
import json
import os
import shutil
import subprocess
import sys
import tempfile
import time

EXCLUDED = {"run.log", "checkpoint.bin", ".lock"}  # output files not hashed (see the module docstring)
CHECKPOINT_PIECES = "checkpoint.pieces/"  # a checkpoint's pieces (pipeline/formats.md §5), not hashed either
HISTORY = "history.csv"
DROPPED_COLUMN = b"wall_time"


# ---------------------------------------------------------------- prepare

INPUTS = ("case.json", "nodes.vtu")   # in <run>/, hashed as input/<name>
DEFAULT_RESTART_EVERY_WALL = 600.0   # pipeline/schema.py's default of output.restart_every_wall


def install_input(case_path: str, run_dir: str) -> None:
    """Copy case.json and the node file it names into run_dir/, pointing the copy's nodes_file at
    the copied node file and its output_dir at run_dir/output/."""
    with open(case_path, encoding="utf-8") as stream:
        case = json.load(stream)
    if os.path.isdir(run_dir):
        shutil.rmtree(run_dir)
    os.makedirs(run_dir)
    nodes = os.path.join(os.path.dirname(os.path.abspath(case_path)), case["nodes_file"])
    shutil.copyfile(nodes, os.path.join(run_dir, "nodes.vtu"))
    case["nodes_file"] = "nodes.vtu"
    case["output_dir"] = "output"   # relative to the folder of case.json, and inside it (formats.md §3)
    if case["output"].get("restart_every_wall") == DEFAULT_RESTART_EVERY_WALL:
        del case["output"]["restart_every_wall"]   # see the module docstring
    # json reads and writes floats as the shortest repr, so every number keeps its exact value.
    with open(os.path.join(run_dir, "case.json"), "w", encoding="utf-8") as stream:
        stream.write(json.dumps(case, indent=1) + "\n")


def prepare_cases(repo: str, runs: str, scratch: str, manifest: dict) -> None:
    """Every cases/<case>/<config>.yaml through the Makefile's mesh and preprocess stages."""
    cases_dir = os.path.join(repo, "cases")
    for case in sorted(os.listdir(cases_dir)):
        case_dir = os.path.join(cases_dir, case)
        if not os.path.isdir(case_dir):
            continue
        for yaml in sorted(f for f in os.listdir(case_dir) if f.endswith(".yaml")):
            config = yaml[:-len(".yaml")]
            name = case if config == case else f"{case}-{config}"
            out = os.path.join(scratch, name)
            os.makedirs(out)
            yaml_rel = os.path.join("cases", case, yaml)
            given = [os.path.join("cases", case, case + ext) for ext in (".unv", ".msh")
                     if os.path.isfile(os.path.join(case_dir, case + ext))]
            if given:
                mesh = given[0]
            else:
                mesh = os.path.join(out, "mesh.msh")
                stage(repo, ["mesh", yaml_rel, os.path.join("cases", case, case + ".geo"), mesh])
            if not stage(repo, ["preprocess", yaml_rel, mesh, out]):
                manifest.setdefault("_skipped", {})[name] = "over the work plan's limits (FORCE=1 prepares it)"
                print(f"skipped {name}: over the work plan's limits; FORCE=1 in the environment prepares it", flush=True)
                continue
            install_input(os.path.join(out, "case.json"), os.path.join(runs, name))
            manifest[name] = {"from": yaml_rel}
            print(f"prepared {name}", flush=True)


def stage(repo: str, args: list[str]) -> bool:
    """One `python3 -m pipeline.run ...` stage, run in repo (the Makefile's command lines). False when
    preprocess's work plan refuses the run (the full beam_3d: hours), which `make` would refuse too;
    any other failure stops prepare."""
    command = [sys.executable, "-m", "pipeline.run", *args]
    result = subprocess.run(command, cwd=repo, stderr=subprocess.PIPE, text=True)
    sys.stderr.write(result.stderr)
    if result.returncode != 0 and "FORCE=1" in result.stderr and "work plan" in result.stderr:
        return False
    if result.returncode != 0:
        raise SystemExit(f"failed ({result.returncode}) in {repo}: {' '.join(command)}")
    return True


# prepare_accuracy's part that runs in --repo, on that checkout's own bench/accuracy.py, pipeline and
# preprocess: a Python started in the folder finds them first (its sys.path begins with it). It
# writes each problem's cases under the scratch folder and prints where, as JSON.
ACCURACY_INPUTS = r"""
import json, os, sys
from bench import accuracy
from pipeline.solver_physics import physics
repo, scratch, quick = sys.argv[1], sys.argv[2], sys.argv[3] == "quick"
if os.path.dirname(os.path.abspath(accuracy.__file__)) != os.path.join(repo, "bench"):
    raise SystemExit(f"imported {accuracy.__file__}, not the one of {repo}")
problems = []
for problem_name, make in (("wave", accuracy.strip_problem), ("fracture", accuracy.hole_problem)):
    directory = os.path.join(scratch, "accuracy", problem_name)
    os.makedirs(directory)
    problem = make(directory)
    # eq. 2.5 of the problem, the solver's (pdsolve --physics: $PDSOLVE, else this checkout's
    # build/solver/pdsolve, common/paths.py), asked on a case of it that is never run
    probe = accuracy.write_case(directory, problem, "physics", {"integrator": "verlet", "dt": "stable",
                                                                "safety_factor": 1.0}, None)
    dt_stable = physics(probe)["stable"]
    # The reference run of accuracy.main(), then every scheme it sweeps.
    runs = [("reference", 0.05, {"integrator": "verlet", "dt": "stable", "safety_factor": 0.05}, None)]
    runs += list(accuracy.schemes(quick, dt_stable))
    cases = []
    for scheme, parameter, time_section, adaptive in runs:
        label = "reference" if scheme == "reference" else f"{scheme}-{parameter:g}"
        cases.append([label, accuracy.write_case(directory, problem, label, time_section, adaptive)])
    problems.append({"problem": problem_name, "dt_stable": repr(dt_stable), "cases": cases})
json.dump(problems, sys.stdout)
"""


def prepare_accuracy(repo: str, runs: str, scratch: str, manifest: dict, quick: bool) -> None:
    """The runs of bench/accuracy.py (make bench-accuracy), with its own problem and case writers."""
    made = subprocess.run([sys.executable, "-c", ACCURACY_INPUTS, repo, scratch, "quick" if quick else "full"],
                          cwd=repo, stdout=subprocess.PIPE, text=True)
    if made.returncode != 0:
        raise SystemExit(f"failed ({made.returncode}) in {repo}: the inputs of bench/accuracy.py")
    for problem in json.loads(made.stdout):
        for label, case_path in problem["cases"]:
            name = f"accuracy-{problem['problem']}-{label}"
            install_input(case_path, os.path.join(runs, name))
            manifest[name] = {"from": f"bench/accuracy.py {problem['problem']} {label}" + (" (quick)" if quick else "")}
        print(f"prepared accuracy-{problem['problem']}-* ({len(problem['cases'])} runs; eq. 2.5 = {problem['dt_stable']} s)",
              flush=True)


def git(repo: str, *args: str) -> str:
    result = subprocess.run(["git", "-C", repo, *args], capture_output=True, text=True)
    return result.stdout.strip() if result.returncode == 0 else "?"


def cmd_prepare(args) -> int:
    repo, runs = os.path.abspath(args.repo), os.path.abspath(args.runs)
    manifest_path = os.path.join(runs, "manifest.json")
    if os.path.exists(manifest_path) and not args.force:
        raise SystemExit(f"{manifest_path} exists: these inputs are prepared already (--force to make them again)")
    os.makedirs(runs, exist_ok=True)
    entries: dict = {}
    with tempfile.TemporaryDirectory(prefix="result-hashes-") as scratch:
        prepare_cases(repo, runs, scratch, entries)
        if args.accuracy != "none":
            prepare_accuracy(repo, runs, scratch, entries, quick=args.accuracy == "quick")
    skipped = entries.pop("_skipped", {})
    manifest = {"repo": repo, "commit": git(repo, "rev-parse", "HEAD"),
                "uncommitted_changes": bool(git(repo, "status", "--porcelain")), "python": sys.executable,
                "runs": entries, "skipped": skipped}
    with open(manifest_path, "w", encoding="utf-8") as stream:
        json.dump(manifest, stream, indent=1)
        stream.write("\n")
    print(f"{len(entries)} runs prepared in {runs} (manifest.json)"
          + (f"; skipped: {', '.join(skipped)}" if skipped else ""))
    return 0


# ---------------------------------------------------------------- run

def sha256(data: bytes) -> str:
    return hashlib.sha256(data).hexdigest()


def history_without_wall_time(data: bytes) -> bytes:
    """history.csv with its wall_time field removed from every line; all else byte for byte."""
    lines = data.splitlines(keepends=True)
    if not lines:
        return data
    header = lines[0].rstrip(b"\r\n").split(b",")
    if DROPPED_COLUMN not in header:
        return data
    column = header.index(DROPPED_COLUMN)
    out = []
    for line in lines:
        body = line.rstrip(b"\r\n")
        end = line[len(body):]
        fields = body.split(b",")
        if len(fields) > column:   # a short line (there should be none) is hashed as it is
            del fields[column]
        out.append(b",".join(fields) + end)
    return b"".join(out)


def hash_run(run_dir: str) -> dict:
    """{file: sha256} of a run's inputs and of every result file but the EXCLUDED ones."""
    hashes = {}
    for name in INPUTS:
        with open(os.path.join(run_dir, name), "rb") as stream:
            hashes[f"input/{name}"] = sha256(stream.read())
    output = os.path.join(run_dir, "output")
    for folder, _dirs, files in os.walk(output):
        for file in files:
            path = os.path.join(folder, file)
            rel = os.path.relpath(path, output).replace(os.sep, "/")
            if rel in EXCLUDED or rel.startswith(CHECKPOINT_PIECES):
                continue
            with open(path, "rb") as stream:
                data = stream.read()
            hashes[rel] = sha256(history_without_wall_time(data) if rel == HISTORY else data)
    return dict(sorted(hashes.items()))


def cmd_run(args) -> int:
    runs, solver = os.path.abspath(args.runs), os.path.abspath(args.solver)
    with open(os.path.join(runs, "manifest.json"), encoding="utf-8") as stream:
        names = list(json.load(stream)["runs"])
    if args.only:
        unknown = sorted(set(args.only) - set(names))
        if unknown:
            raise SystemExit(f"not prepared in {runs}: {', '.join(unknown)}")
        names = [n for n in names if n in args.only]
    if args.skip:
        names = [n for n in names if n not in args.skip]
    # Idle OpenMP threads sleep instead of spinning: on a shared machine, spinning threads of a
    # 2-thread run fight the other jobs for the cores (plate_with_hole took 2.4 times as long).
    # It changes how threads wait, not what they compute. A value already set is kept.
    env = dict(os.environ)
    env.setdefault("OMP_WAIT_POLICY", "passive")
    version = subprocess.run([solver, "--version"], capture_output=True, text=True).stdout.strip()
    # --ranks N: the same runs decomposed over N MPI ranks. Results are bitwise the same for any rank
    # count, so these hashes compare equal to a serial run's (the rank-local-model issue checks both).
    launcher = []
    if args.ranks > 1:
        env.setdefault("OMPI_MCA_rmaps_base_oversubscribe", "1")
        # OpenMPI refuses to start as root without these (bench/mpi_ranks.py sets them too).
        env.setdefault("OMPI_ALLOW_RUN_AS_ROOT", "1")
        env.setdefault("OMPI_ALLOW_RUN_AS_ROOT_CONFIRM", "1")
        launcher = ["mpiexec", "-n", str(args.ranks)]
    results: dict = {}
    seconds = {}
    start = time.monotonic()
    for name in names:
        run_dir = os.path.join(runs, name)
        if os.path.isfile(os.path.join(run_dir, "input", "case.json")):
            raise SystemExit(f"{run_dir} was prepared by an older bench/result_hashes.py (input/case.json with "
                             "output_dir ../output, which pdsolve refuses now): prepare again with --force")
        output = os.path.join(run_dir, "output")
        if os.path.isdir(output):
            shutil.rmtree(output)
        os.makedirs(output)
        begin = time.monotonic()
        with open(os.path.join(run_dir, "solver.txt"), "wb") as log:
            frames = ["--parallel-frames", args.frames] if args.frames else []
            code = subprocess.run([*launcher, solver, os.path.join(run_dir, "case.json"), "--threads",
                                   str(args.threads), "--quiet", *frames], stdout=log, stderr=subprocess.STDOUT,
                                  env=env).returncode
        seconds[name] = round(time.monotonic() - begin, 3)
        results[name] = dict(hash_run(run_dir), exit=code)
        if args.keep:
            kept = os.path.join(os.path.abspath(args.keep), name)
            if os.path.isdir(kept):
                shutil.rmtree(kept)
            shutil.copytree(output, kept)
        files = sum(1 for key in results[name] if not key.startswith("input/")) - 1
        print(f"{name:44s} exit {code:3d}  {files:4d} files  {seconds[name]:8.2f} s", flush=True)
    total = time.monotonic() - start
    results["_about"] = {"solver": solver, "version": version, "threads": args.threads, "ranks": args.ranks,
                         "frames": args.frames, "OMP_WAIT_POLICY": env["OMP_WAIT_POLICY"], "runs": runs,
                         "seconds": seconds, "total_seconds": round(total, 1)}
    with open(args.out, "w", encoding="utf-8") as stream:
        json.dump(results, stream, indent=1)
        stream.write("\n")
    failed = [n for n in names if results[n]["exit"] != 0]
    print(f"{len(names)} runs in {total:.0f} s, {len(failed)} with a nonzero exit code"
          f"{': ' + ', '.join(failed) if failed else ''}; hashes in {args.out}")
    return 0


# ---------------------------------------------------------------- compare

def cmd_compare(args) -> int:
    with open(args.a, encoding="utf-8") as stream:
        a = json.load(stream)
    with open(args.b, encoding="utf-8") as stream:
        b = json.load(stream)
    names = [n for n in dict.fromkeys([*a, *b]) if not n.startswith("_")]
    if args.common:   # e.g. a `run --only` subset against a full set
        names = [n for n in names if n in a and n in b]
    different = 0
    for name in names:
        if name not in a or name not in b:
            print(f"{name}: DIFFERENT (run only in {args.a if name in a else args.b})")
            different += 1
            continue
        problems = []
        for file in dict.fromkeys([*a[name], *b[name]]):
            if file not in a[name]:
                problems.append(f"{file} only in {args.b}")
            elif file not in b[name]:
                problems.append(f"{file} only in {args.a}")
            elif a[name][file] != b[name][file]:
                problems.append(f"exit {a[name][file]} vs {b[name][file]}" if file == "exit" else f"{file} differs")
        if problems:
            different += 1
            shown = problems if args.verbose or len(problems) <= 8 else problems[:8] + [f"... {len(problems) - 8} more"]
            print(f"{name}: DIFFERENT: " + "; ".join(shown))
        else:
            print(f"{name}: equal ({len(a[name]) - 1} hashes, exit {a[name]['exit']})")
    print(f"{len(names) - different} of {len(names)} runs equal" + (f", {different} different" if different else ""))
    return 1 if different else 0


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    sub = parser.add_subparsers(dest="command", required=True)
    p = sub.add_parser("prepare", help="mesh and preprocess every case and variant, write the bench-accuracy cases")
    p.add_argument("--repo", required=True, help="checkout whose cases and pre-processor make the inputs")
    p.add_argument("--runs", required=True, help="folder of the prepared runs")
    p.add_argument("--accuracy", choices=("full", "quick", "none"), default="full",
                   help="which bench-accuracy runs (default: full, as `make bench-accuracy`)")
    p.add_argument("--force", action="store_true", help="prepare again over an existing manifest.json")
    p.set_defaults(func=cmd_prepare)
    p = sub.add_parser("run", help="run a solver on every prepared input and hash the results")
    p.add_argument("--solver", required=True, help="the pdsolve to run")
    p.add_argument("--runs", required=True, help="folder of the prepared runs")
    p.add_argument("--out", required=True, help="JSON file of the hashes")
    p.add_argument("--threads", type=int, default=2, help="OpenMP threads of every run (default 2)")
    p.add_argument("--ranks", type=int, default=1, help="MPI ranks of every run, under mpiexec when above 1 (default 1)")
    p.add_argument("--frames", choices=("gathered", "pieces"),
                   help="pdsolve --parallel-frames: gathered makes a run on several ranks write the serial "
                        "run's frames (default: the case's output.parallel_frames, pieces if it has none)")
    p.add_argument("--only", nargs="+", metavar="NAME", help="only these runs")
    p.add_argument("--skip", nargs="+", metavar="NAME", help="all runs but these")
    p.add_argument("--keep", metavar="DIR", help="also copy each run's output/ to DIR/<run>/")
    p.set_defaults(func=cmd_run)
    p = sub.add_parser("compare", help="compare two hash files; exit 1 on any difference")
    p.add_argument("a")
    p.add_argument("b")
    p.add_argument("-v", "--verbose", action="store_true", help="list every differing file")
    p.add_argument("--common", action="store_true", help="only the runs present in both files")
    p.set_defaults(func=cmd_compare)
    args = parser.parse_args(argv)
    return args.func(args)


if __name__ == "__main__":
    sys.exit(main())
