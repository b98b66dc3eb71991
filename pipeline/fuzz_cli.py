"""A fuzzer for pdsolve's command line: random argument lists from the options, their edge values
and the files a user might give by mistake; each run must end with one of the documented exit codes
(0, 1 bad input, 2 bad command line, 3 failed run) within PER_RUN_SECONDS, never with a signal
(`--threads 100000` segfaulted, issue 17 item 9) or an "internal error".

    /usr/bin/python3 -m pipeline.fuzz_cli --seconds 60 [--seed N] [--solver build/solver/pdsolve]

A valid case is made first (a 2D plate of 64 nodes, written by the node-file writer of preprocess),
so that the arguments reach the run and not only the parser.
"""
from __future__ import annotations

import argparse
import json
import os
import random
import subprocess
import sys
import tempfile
import time

import numpy as np

from common.memory import limit_address_space
from common.paths import pdsolve

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
PER_RUN_SECONDS = 20
# Set by main() on itself and inherited by every pdsolve it starts: the 64-node runs need some
# 100 MB; OpenMP threads and glibc's per-thread arenas reserve address space beyond that.
MEMORY_LIMIT_MB = 4096
DOCUMENTED = {0, 1, 2, 3}


def make_case(folder: str) -> str:
    """A small valid case.json + nodes.vtu in folder; returns the case.json path."""
    from preprocess.cloud import NodeCloud
    from preprocess.node_file import write_node_file
    dx = 1e-3
    pts = np.array([[i * dx, j * dx, 0.0] for j in range(8) for i in range(8)])
    left = pts[:, 0] < 1.5 * dx
    write_node_file(os.path.join(folder, "nodes.vtu"),
                    NodeCloud(points=pts, volume=np.full(len(pts), dx * dx * 1e-3), block=np.ones(len(pts), np.int32),
                              sets={"left": left}, grid_spacing=dx, dimension=2))
    case = {"format_version": 1, "case": "fuzz", "title": "", "source": "fuzz.yaml", "nodes_file": "nodes.vtu",
            "output_dir": "out", "dimension": 2, "analysis": "plane_stress", "thickness": 0.001,
            "grid_spacing": dx, "horizon": 3.015 * dx,
            "blocks": [{"id": 1, "name": "plate", "model": "pmb", "density": 2440.0, "youngs_modulus": 7.2e10}],
            "node_sets": ["left"],
            "boundary_conditions": [{"set": "left", "kind": "displacement", "component": 0, "times": [0.0],
                                     "values": [0.0]}],
            "time": {"end": 2e-6, "integrator": "verlet", "dt": "stable", "safety_factor": 0.8},
            "output": {"every_time": 1e-6}}
    path = os.path.join(folder, "case.json")
    with open(path, "w", encoding="utf-8") as stream:
        json.dump(case, stream)
    return path


def arguments(rng: random.Random, case: str, folder: str) -> list[str]:
    options = ["--restart", "--threads", "--end-time", "--max-steps", "--quiet", "--help", "--version",
               "--describe", "--stable-dt", "--exact", "--bogus", "-", "--"]
    values = ["0", "1", "2", "-1", "100000", "1e300", "-1e-300", "nan", "inf", "1e-12", "9223372036854775808",
              "", "abc", "3.5", case, folder, "/dev/zero", "/dev/null", os.path.join(folder, "missing"),
              os.path.join(folder, "nodes.vtu"), os.path.join(folder, "out", "checkpoint.bin")]
    argv = [case] if rng.random() < 0.8 else []
    for _ in range(rng.choice((0, 1, 1, 1, 2, 3))):
        option = rng.choice(options)
        argv.append(option)
        if option in ("--restart", "--threads", "--end-time", "--max-steps") and rng.random() < 0.95:
            argv.append(rng.choice(values))
        elif rng.random() < 0.2:
            argv.append(rng.choice(values))
    if rng.random() < 0.2:
        rng.shuffle(argv)
    # A long --end-time is a long run, not a finding: bound it. 2000 steps write at most ~290 frames
    # of the 64-node plate (about 1 s); 20 000 steps wrote ~2 900 frames and passed PER_RUN_SECONDS
    # on a loaded machine (17 of 2 742 runs of the 10-minute run, all exit 0 when rerun by hand).
    if "--max-steps" not in argv:
        argv += ["--max-steps", "2000"]
    return argv


def fuzz(solver: str, seconds: float, seed: int, max_runs: int | None = None) -> dict:
    rng = random.Random(seed)
    findings, runs, codes = [], 0, {}
    start = time.monotonic()
    # Passive OpenMP waiting unless the caller chose: on a loaded machine, spinning threads made a
    # 2000-step run of the 64-node plate take 5–8 s instead of 0.3 s (measured beside a CI run),
    # which is load, not a finding. Results do not depend on it.
    env = dict(os.environ, OMP_WAIT_POLICY=os.environ.get("OMP_WAIT_POLICY", "passive"))
    with tempfile.TemporaryDirectory(prefix="pd-fuzz-cli-") as folder:
        case = make_case(folder)
        while time.monotonic() - start < seconds and (max_runs is None or runs < max_runs):
            argv = arguments(rng, case, folder)
            runs += 1
            try:
                result = subprocess.run([solver, *argv], capture_output=True, text=True, timeout=PER_RUN_SECONDS,
                                        stdin=subprocess.DEVNULL, cwd=folder, env=env)
            except subprocess.TimeoutExpired:
                findings.append((argv, f"no answer within {PER_RUN_SECONDS} s"))
                continue
            codes[result.returncode] = codes.get(result.returncode, 0) + 1
            if result.returncode not in DOCUMENTED and result.returncode not in (130, 143):
                findings.append((argv, f"exit code {result.returncode}: {result.stderr[-300:]}"))
            elif "internal error" in result.stderr:
                findings.append((argv, result.stderr[-300:]))
    return {"runs": runs, "codes": codes, "findings": findings, "seconds": time.monotonic() - start}


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(prog="pipeline.fuzz_cli", description=__doc__,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--seconds", type=float, default=60.0)
    parser.add_argument("--seed", type=int, default=None)
    parser.add_argument("--solver", default=pdsolve())
    args = parser.parse_args(argv)
    seed = args.seed if args.seed is not None else int(time.time())
    limit_address_space(MEMORY_LIMIT_MB)  # bounds make fuzz's memory, pdsolve's runs included
    result = fuzz(args.solver, args.seconds, seed)
    codes = ", ".join(f"{k}: {v}" for k, v in sorted(result["codes"].items()))
    print(f"pdsolve command line: seed {seed}: {result['runs']} runs in {result['seconds']:.0f} s (exit codes "
          f"{codes}); {len(result['findings'])} finding(s)")
    for arguments_, what in result["findings"][:5]:
        print(f"--- pdsolve {' '.join(arguments_)}\n{what}", file=sys.stderr)
    return 1 if result["findings"] else 0


if __name__ == "__main__":
    sys.exit(main())
