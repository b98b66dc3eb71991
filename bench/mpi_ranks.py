"""`make bench`, MPI rows (issue 15): pdsolve's Verlet loop on 1 and 2 ranks × 1 and 2 threads,
beside LAMMPS peri/pmb on 2 MPI ranks, on the same bricks in the same sitting.

Runs build/solver/pd_mpi_halo (solver/bench/mpi_halo.cpp) under `mpiexec --oversubscribe
--bind-to none -np R` with T OpenMP threads per rank: the velocity-Verlet loop of the `make bench`
brick with the two exact energy sums pdsolve's loop adds each step. Each rank reports, per
step, the halo messages and bytes it sent, the reductions (MPI_Allreduce) and their bytes,
its ghosts per owned node, the wall time in communication (every MPI call, the waits for the other
rank included), and its peak memory. The codes
alternate, `repeats` runs each, and the best run of each configuration counts (a busy neighbour
slows a run, nothing speeds it up). Writes out/bench/mpi.csv (one row per rank and configuration,
LAMMPS rows with its loop time) and prints a summary with the load average.

    /usr/bin/python3 -m bench.mpi_ranks [--build build/solver] [--sides 40 100] [--repeats 2]

2 ranks × 2 threads on a 2-core machine oversubscribe it (4 threads): that row shows the cost of
oversubscription, not of the decomposition, and says so. Such a row runs with OMP_WAIT_POLICY=passive
(unless the environment sets it): OpenMP's threads then sleep at the end of a loop instead of
spinning, and do not take the core from the other rank's threads or from its MPI wait
(docs/performance.md, MPI: 40³ at 2 × 2 went from 0.8–0.9e8 to 4.3–4.5e8 bond updates/s).
"""
import argparse
import csv
import os
import shutil
import subprocess
import sys
import tempfile

from common.output_lock import exit_code, output_lock

# 40³: 100 steps, a timed window of ~1.5 s on 2 ranks; at 40 steps (~0.6 s) one preemption by another
# process moved the 2-rank row by 10 % or more.
STEPS = {40: 100, 46: 30, 100: 10}
CONFIGURATIONS = [(1, 1), (1, 2), (2, 1), (2, 2)]  # (ranks, threads per rank)
MPI_ENV = dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1")


def oversubscribed(ranks, threads):
    """More threads in all than the machine has cores."""
    return ranks * threads > (os.cpu_count() or 1)


def run_ours(exe, side, steps, ranks, threads, extra=()):
    """The per-rank rows pd_mpi_halo prints, as dicts. extra: more of its options (--law lps,
    --alpha A, --blocking)."""
    command = ["mpiexec", "--oversubscribe", "--bind-to", "none", "-np", str(ranks), exe, "--side", str(side),
               "--steps", str(steps), "--threads", str(threads), *extra]
    env = dict(MPI_ENV, OMP_NUM_THREADS=str(threads))
    if oversubscribed(ranks, threads):
        env.setdefault("OMP_WAIT_POLICY", "passive")  # spinning threads would take the cores from the others
    out = subprocess.run(command, capture_output=True, text=True, env=env)
    if out.returncode != 0:
        raise RuntimeError(f"{' '.join(command)} failed (exit {out.returncode}):\n{out.stdout[-2000:]}{out.stderr[-2000:]}")
    lines = [line for line in out.stdout.splitlines() if line.strip()]
    header = lines[0].split(",")
    return [dict(zip(header, line.split(","))) for line in lines[1:]]


def waiting(row):
    """', halo X ms, of which Y ms waiting': the halo exchanges' time and their second halves' (a
    build before the overlap of the halo with the interior rows has no such columns)."""
    halo, wait = row.get("halo_s_per_step"), row.get("halo_wait_s_per_step")
    if not halo:
        return ""
    if not wait or wait == "nan":  # the exchange in one blocking piece
        return f"; halo {float(halo) * 1e3:.3f} ms"
    return f"; halo {float(halo) * 1e3:.3f} ms, of which {float(wait) * 1e3:.3f} ms waiting"


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--build", default="build/solver")
    ap.add_argument("--sides", type=int, nargs="+", default=[40, 100])
    ap.add_argument("--repeats", type=int, default=2)
    ap.add_argument("--out", default="out/bench/mpi.csv")
    args = ap.parse_args()
    # One writer per output folder, the lock make and peridyn take too (common/output_lock.py).
    with output_lock(os.path.dirname(args.out) or ".", "make bench (bench.mpi_ranks)"):
        return measure(args)


def measure(args):
    """The MPI rows of main(), with the output folder locked."""
    exe = os.path.join(args.build, "pd_mpi_halo")
    if not os.path.exists(exe) or shutil.which("mpiexec") is None:
        print(f"MPI rows skipped: {exe} or mpiexec missing (pdsolve built without PD_MPI, or no openmpi-bin)")
        return
    from . import lammps_brick
    lammps = lammps_brick.available() is None
    os.makedirs(os.path.dirname(args.out) or ".", exist_ok=True)
    rows = []
    print(f"MPI rows: load average before {os.getloadavg()[0]:.2f} (on {os.cpu_count()} cores)", flush=True)
    with tempfile.TemporaryDirectory() as workdir:
        for side in args.sides:
            steps = STEPS.get(side, 10)
            best, best_lammps, atoms = {}, None, None
            for _ in range(args.repeats):
                for ranks, threads in CONFIGURATIONS:
                    run = run_ours(exe, side, steps, ranks, threads)
                    if (ranks, threads) not in best or float(run[0]["loop_s"]) < float(best[(ranks, threads)][0]["loop_s"]):
                        best[(ranks, threads)] = run
                if lammps:
                    loop, atoms = lammps_brick.run_lammps(side, steps, 2, workdir, "pmb")
                    best_lammps = loop if best_lammps is None else min(best_lammps, loop)
            load = f"{os.getloadavg()[0]:.2f}"
            for (ranks, threads), run in best.items():
                for r in run:
                    rows.append(dict(code="pdsolve", load_average=load, oversubscribed=int(oversubscribed(ranks, threads)), **r))
            directed = float(best[(1, 1)][0]["directed_bonds"])
            nodes = int(best[(1, 1)][0]["nodes"])
            if best_lammps is not None:
                if atoms != nodes:
                    raise RuntimeError(f"LAMMPS made {atoms} atoms, pd_mpi_halo {nodes} nodes: not the same brick")
                rows.append(dict(code="lammps peri/pmb", rank="all", side=side, nodes=nodes, ranks=2, threads=1, steps=steps,
                                 directed_bonds=f"{directed:.0f}", loop_s=f"{best_lammps:.4f}",
                                 bond_updates_per_s=f"{directed * steps / best_lammps:.4e}", load_average=load))
            rate = {k: float(v[0]["bond_updates_per_s"]) for k, v in best.items()}
            for (ranks, threads), run in best.items():
                r0 = run[0]
                crowded = (f" [oversubscribed: {ranks * threads} threads on {os.cpu_count()} cores, "
                           f"OMP_WAIT_POLICY={os.environ.get('OMP_WAIT_POLICY', 'passive')}]") if oversubscribed(ranks, threads) else ""
                print(f"  {side}³ = {nodes} nodes, {ranks} rank(s) × {threads} thread(s){crowded}: {rate[(ranks, threads)]:.3e} "
                      f"directed bond updates/s; per rank and step: {r0['halo_messages_per_step']} messages, "
                      f"{r0['halo_bytes_per_step']} halo bytes, {r0['reductions_per_step']} reductions (MPI_Allreduce) "
                      f"of {r0['reduction_bytes_per_step']} bytes, "
                      f"{r0['ghosts_per_owned']} ghosts per owned node, {float(r0['communication_s_per_step']) * 1e3:.3f} ms "
                      f"in communication ({100 * float(r0['communication_share']):.1f} %{waiting(r0)}), "
                      f"peak {r0['peak_rss_mb']} MB "
                      f"(load {load})", flush=True)
            print(f"  2-rank efficiency against 2 threads (1 thread each): {rate[(2, 1)] / rate[(1, 2)]:.2f}", flush=True)
            if best_lammps is not None:
                lammps_rate = directed * steps / best_lammps
                print(f"  LAMMPS peri/pmb, 2 MPI ranks: {lammps_rate:.3e}; ours on 2 ranks is "
                      f"{rate[(2, 1)] / lammps_rate:.2f}× that (target ≥ 3.5×)", flush=True)
    fields = ["code", "rank", "side", "nodes", "ranks", "threads", "steps", "directed_bonds", "loop_s",
              "bond_updates_per_s", "owned", "ghosts", "ghosts_per_owned", "halo_messages_per_step",
              "halo_bytes_per_step", "reductions_per_step", "reduction_bytes_per_step", "communication_s_per_step",
              "communication_share", "peak_rss_mb", "halo_s_per_step", "halo_wait_s_per_step", "oversubscribed", "load_average"]
    with open(args.out, "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=fields)
        w.writeheader()
        w.writerows(rows)
    print(f"wrote {args.out}")


if __name__ == "__main__":
    sys.exit(exit_code(main))
