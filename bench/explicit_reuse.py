"""Reusing the explicit (Verlet) runs of an earlier bench/quasi_static_cases.py run (issue 13).

At dx × 2 and finer the explicit reference series (the loading rate halved until the peak settles,
at three damping levels) is most of the benchmark's time, and a change of the mixed integrator does
not touch it. Two ways to take those rows from an earlier run's --out folder DIR instead of running
them again; mixed, quasi_static and the paired reruns of mixed and its rival always run here, since
a speedup is a ratio measured side by side:

- `--reuse-explicit DIR`: a run is reused only when nothing that makes it differs: its case.json
  byte for byte as this run writes it (but its "source" line: see case_sha256), the lattice (nodes.vtu) byte for byte, the same number of
  threads, and a solver file with the same SHA-256 (recorded in DIR/<problem>/<run>/bench_run.json
  when that run was made). Anything else runs here again, and the output says why.
- `--explicit-from DIR`: the user names the run whose explicit rows to take, made by another solver
  (or by a version of this script that recorded no solver). The inputs must still be byte-identical;
  the solver need not be. To check that the solvers agree on explicit runs, the first explicit run
  of each problem is run here as well and its results (history.csv without the wall_time column and
  the energy sums the benchmark does not read, frames.pvd and every frame, byte for byte) compared with DIR's: any difference stops the
  benchmark. Times (wall and CPU) are DIR's, measured in its own sitting; the output says so per row.

Every explicit run made here writes bench_run.json next to its run.log: the solver's path and
SHA-256, the threads, the SHA-256 of case.json and nodes.vtu, and the counts and times of the run
(the CPU time is nowhere else). Runs made before that file existed are found through DIR/accuracy.csv
(its cpu_time column), by --explicit-from only.
"""
from __future__ import annotations

import csv
import hashlib
import json
import os
import re

from bench.result_hashes import history_without_wall_time
from bench.solver_runs import log_counts

RECORD = "bench_run.json"
_SHA_CACHE: dict[tuple, str] = {}


def file_sha256(path: str) -> str:
    """SHA-256 of a file's bytes (cached by path, size and mtime: a solver is hashed once a run)."""
    st = os.stat(path)
    key = (os.path.abspath(path), st.st_size, st.st_mtime_ns)
    if key not in _SHA_CACHE:
        digest = hashlib.sha256()
        with open(path, "rb") as stream:
            for block in iter(lambda: stream.read(1 << 20), b""):
                digest.update(block)
        _SHA_CACHE[key] = digest.hexdigest()
    return _SHA_CACHE[key]


def case_sha256(path: str) -> str:
    """SHA-256 of case.json's bytes but its `"source": ...` line: the path of the mixed.yaml it
    came from, which differs between checkouts and which the solver reads but never uses
    (solver/src/io/describe.cpp only lists it). In a Verlet run's case also but its
    `"quasi_static": {...}` block: the load-step settings of mixed.yaml, which the explicit cases
    inherit and a Verlet run never reads (so a change of mixed.yaml's load steps keeps the explicit
    rows reusable)."""
    with open(path, "rb") as stream:
        data = stream.read()
    data = re.sub(rb'(?m)^ *"source": "[^"\n]*",?\n', b"", data)
    if re.search(rb'(?m)^ *"integrator": "verlet",?$', data):
        data = re.sub(rb'(?ms)^ "quasi_static": \{\n.*?^ \},?\n', b"", data, count=1)
    return hashlib.sha256(data).hexdigest()


def write_record(run_dir: str, solver: str, threads: int, r: dict) -> None:
    """bench_run.json of a run made here (see the module docstring)."""
    record = {"solver": os.path.abspath(solver), "solver_sha256": file_sha256(solver), "threads": threads,
              "case_sha256": case_sha256(os.path.join(run_dir, "case.json")),
              "nodes_sha256": file_sha256(os.path.join(os.path.dirname(run_dir), "nodes.vtu")),
              **{key: r[key] for key in ("status", "steps", "wall", "cpu", "evaluations", "broken_bonds")}}
    with open(os.path.join(run_dir, RECORD), "w", encoding="utf-8") as stream:
        json.dump(record, stream, indent=1)


# history.csv's sums over nodes (energies and works): diagnostics this benchmark does not read, and
# whose last bits changed when every reduction became an exact sum (solver/src/core/exact_sum.hpp,
# 3 Dec 2026: rounded once instead of at each addition). The columns it reads (time, step, dt,
# broken_bonds, the reactions) and every frame are still compared byte for byte.
SUM_COLUMNS = (b"kinetic_energy", b"strain_energy", b"external_work", b"damping_work", b"contact_energy",
               b"indenter_energy", b"broken_bond_energy")


def is_sum_column(name: bytes) -> bool:
    """SUM_COLUMNS, and each indenter's reaction indenter_<name>_f{x,y,z} (an exact sum too)."""
    return name in SUM_COLUMNS or (name.startswith(b"indenter_") and name[-3:] in (b"_fx", b"_fy", b"_fz"))


def history_without_sums(data: bytes) -> bytes:
    """history.csv (wall_time already removed) without the sum columns; all else byte for byte."""
    lines = data.splitlines(keepends=True)
    if not lines:
        return data
    header = lines[0].rstrip(b"\r\n").split(b",")
    keep = [k for k, name in enumerate(header) if not is_sum_column(name)]
    out = []
    for line in lines:
        body = line.rstrip(b"\r\n")
        fields = body.split(b",")
        out.append(b",".join(fields[k] for k in keep if k < len(fields)) + line[len(body):])
    return b"".join(out)


def result_digests(run_dir: str) -> dict[str, str]:
    """{file: sha256} of a run's results: history.csv without wall_time and the SUM_COLUMNS,
    frames.pvd, frames/*."""
    out = {}
    names = ["history.csv", "frames.pvd"]
    frames = os.path.join(run_dir, "frames")
    if os.path.isdir(frames):
        names += [f"frames/{name}" for name in sorted(os.listdir(frames))]
    for name in names:
        path = os.path.join(run_dir, name)
        if not os.path.isfile(path):
            continue
        with open(path, "rb") as stream:
            data = stream.read()
        out[name] = hashlib.sha256(history_without_sums(history_without_wall_time(data)) if name == "history.csv"
                                   else data).hexdigest()
    return out


class ExplicitSource:
    """Where the explicit runs of one benchmark come from: run here (directory None), or reused
    from `directory` (mode "reuse": --reuse-explicit, "from": --explicit-from)."""

    def __init__(self, directory: str | None, mode: str, solver: str, threads: int):
        self.directory = os.path.abspath(directory) if directory else None
        self.mode, self.solver, self.threads = mode, solver, threads
        self.checked: set[str] = set()        # problems whose first explicit run was compared
        self.taken = self.ran = 0
        self._csv_rows = None

    def describe(self) -> str:
        if self.directory is None:
            return "explicit runs: all run here"
        if self.mode == "reuse":
            return (f"explicit runs: reused from {self.directory} where case.json, nodes.vtu, threads and the "
                    f"solver's SHA-256 ({file_sha256(self.solver)[:12]}) are the same; the others run here")
        return (f"explicit runs: taken from {self.directory} (--explicit-from: another sitting, maybe another "
                f"solver) where case.json and nodes.vtu are the same; the first of each problem rerun here and "
                f"compared; their times are {self.directory}'s")

    def _old_record(self, problem: str, run_name: str) -> tuple[dict | None, str]:
        """(record, why not) of DIR's run: bench_run.json, or (--explicit-from) its accuracy.csv row."""
        path = os.path.join(self.directory, problem, run_name, RECORD)
        if os.path.isfile(path):
            with open(path, encoding="utf-8") as stream:
                return json.load(stream), ""
        if self.mode == "reuse":
            return None, f"no {RECORD} there (made before runs recorded their solver)"
        if self._csv_rows is None:
            self._csv_rows = []
            table = os.path.join(self.directory, "accuracy.csv")
            if os.path.isfile(table):
                with open(table, newline="", encoding="utf-8") as stream:
                    self._csv_rows = list(csv.DictReader(stream))
        for row in self._csv_rows:
            if row.get("problem") == problem and os.path.basename(row.get("run_dir", "")) == run_name:
                return {"status": row["status"], "wall": float(row["wall_time"]), "cpu": float(row["cpu_time"]),
                        "solver": None, "solver_sha256": None, "threads": None}, ""
        return None, f"neither {RECORD} nor a row of {self.directory}/accuracy.csv"

    def find(self, problem: str, case_path: str) -> tuple[dict | None, str]:
        """(what to reuse, why not): the record, with "run_dir", of DIR's run of the same name when
        it may stand for the run of `case_path` (this benchmark's case.json, just written)."""
        run_dir = os.path.dirname(case_path)
        run_name = os.path.basename(run_dir)
        old_dir = os.path.join(self.directory, problem, run_name)
        old_case = os.path.join(old_dir, "case.json")
        if not os.path.isfile(old_case):
            return None, "not in it"
        if case_sha256(old_case) != case_sha256(case_path):
            return None, "its case.json differs (other than in its source line)"
        if file_sha256(os.path.join(self.directory, problem, "nodes.vtu")) != \
                file_sha256(os.path.join(os.path.dirname(run_dir), "nodes.vtu")):
            return None, "its nodes.vtu differs"
        record, why = self._old_record(problem, run_name)
        if record is None:
            return None, why
        if record["status"] != "ok":
            return None, f"it did not succeed there ({record['status']})"
        if self.mode == "reuse":
            if record["solver_sha256"] != file_sha256(self.solver):
                return None, f"another solver made it ({record['solver']}, SHA-256 {record['solver_sha256'][:12]})"
            if record["threads"] != self.threads:
                return None, f"it ran on {record['threads']} thread(s)"
        elif record["threads"] not in (None, self.threads):
            return None, f"it ran on {record['threads']} thread(s)"
        return dict(record, run_dir=old_dir), ""

    def run(self, problem: str, case_path: str, timed_run) -> tuple[dict, str, str]:
        """(result, run folder holding its outputs, note) of the explicit run of `case_path`:
        `timed_run(solver, case_path, threads)` here, or DIR's reused (see the module docstring)."""
        note = ""
        if self.directory is not None:
            old, why = self.find(problem, case_path)
            if old is not None and self.mode == "from" and problem not in self.checked:
                r = self._fresh(case_path, timed_run)
                if r["status"] == "ok":
                    here, there = result_digests(os.path.dirname(case_path)), result_digests(old["run_dir"])
                    if here != there:
                        differ = sorted(k for k in set(here) | set(there) if here.get(k) != there.get(k))
                        raise SystemExit(f"--explicit-from {self.directory}: {problem}'s "
                                         f"{os.path.basename(old['run_dir'])} gives other results with "
                                         f"{self.solver} ({', '.join(differ[:4])} differ): its explicit rows "
                                         f"cannot stand for this solver's; run without --explicit-from")
                    self.checked.add(problem)
                    return r, os.path.dirname(case_path), f"run here, the same results as {old['run_dir']}"
                return r, os.path.dirname(case_path), ""
            if old is not None:
                with open(os.path.join(old["run_dir"], "run.log"), encoding="utf-8") as stream:
                    log = stream.read()
                counts = log_counts(log)
                if counts is not None:
                    # The times are the record's: the paired reruns of a rival rewrite its run.log
                    # (with the same counts and results, which are deterministic).
                    self.taken += 1
                    r = dict(counts, status="ok", log=log, wall=old["wall"], cpu=old["cpu"])
                    return r, old["run_dir"], f"reused from {old['run_dir']}"
                why = "its run.log has no done: line"
            note = f"run here: {self.directory}'s run not reused, {why}"
        return self._fresh(case_path, timed_run), os.path.dirname(case_path), note

    def _fresh(self, case_path: str, timed_run) -> dict:
        self.ran += 1
        r = timed_run(self.solver, case_path, self.threads)
        if r["status"] == "ok":
            write_record(os.path.dirname(case_path), self.solver, self.threads, r)
        return r

    def summary(self) -> str:
        if self.directory is None:
            return ""
        return (f"explicit runs: {self.taken} taken from {self.directory} "
                f"({'same solver file' if self.mode == 'reuse' else '--explicit-from: their times measured there'}), "
                f"{self.ran} run here")
