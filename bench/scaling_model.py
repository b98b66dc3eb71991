"""A model of strong and weak scaling of a decomposed Verlet run on a cluster (issue 15), from
per-step numbers measured on this machine (docs/notes/2026-12-03-scaling-model-largest-run.md says
which and how).

    /usr/bin/python3 -m bench.scaling_model [--nodes 1e8] [--rate 2.7e8] [--sums 2]

Per step and rank, with n owned nodes, g ghosts, R ranks, N = R·n nodes in all:
- compute: b·n / r, with b directed bonds per node and r directed bond updates per second per core;
- halo: one message to each of k neighbouring pieces (α each) and 24·g bytes (u, 3 doubles a
  ghost) at bandwidth β; not overlapped with the interior rows today;
- exact sums as built (core/exact_sum.hpp): s sums a step, each adds the rank's n terms into its
  accumulator (t_exact each, measured by pd_bench BM_ExactSum) and reduces the A = 560-byte
  accumulators with MPI_Allreduce (log₂R·(α + A/β));
- the ordered sums they replaced, for comparison: each gathered 8 bytes per node to rank 0 (rank 0
  receives 8·N bytes at β) and rank 0 added N terms one by one (t_add each), then a broadcast
  (log₂R·α).
Pieces are taken as cubes of side a = n^(1/3) node spacings (Morton pieces of R = 8^k ranks of a
cube are cubes; others are unions of octree cells with up to ~1.5× the surface), an interior
piece with ghosts g = (a + 2m)³ − a³ (m = 3 layers for δ = 3 dx) and k = 26 neighbours; a piece
can not be thinner than the horizon, so below a = m the model stops. At few ranks a piece has fewer
than 26 neighbours (at 8, each touches 7 across 3 faces), so the halo there is overestimated.
"""
import argparse
import math

BONDS_PER_NODE = 122      # directed bonds of an interior node, δ = 3.0002 dx (sphere of radius 3 on the lattice)
LAYERS = 3                # ghost layers: δ/dx rounded up
ALPHA = 2e-6              # network latency [s] (assumed)
BETA = 10e9               # network bandwidth [bytes/s] (assumed)
T_ADD = 1.0e-9            # rank 0's time per term of an ordered sum, one add in order [s] (a dependent add chain, ~4 cycles at ~4 GHz)
ACCUMULATOR_BYTES = 560   # core/exact_sum.hpp: 70 int64 (67 digit limbs, 3 counts of ±∞/NaN); asserted by tests/bench/test_mpi_halo.py
T_EXACT = 2.0e-9          # one term of an exact sum [s]: pd_bench BM_ExactSum (docs/performance.md §7), rounded up
BYTES_PER_NODE = 723.0    # peak memory per node of a serial run (docs/performance.md §3: 723 MB at 10⁶ nodes)


def piece(n):
    a = n ** (1.0 / 3.0)
    ghosts = (a + 2 * LAYERS) ** 3 - a ** 3
    return a, ghosts


def step_times(total, ranks, rate, sums):
    n = total / ranks
    a, g = piece(n)
    compute = BONDS_PER_NODE * n / rate
    if ranks == 1:
        return dict(n=n, a=a, ghosts=0.0, ratio=0.0, compute=compute, halo=0.0, sums_now=0.0, sums_exact=sums * n * T_EXACT)
    halo = 26 * ALPHA + 24 * g / BETA
    log_r = math.ceil(math.log2(ranks))
    sums_now = sums * (8 * total / BETA + total * T_ADD + log_r * ALPHA)
    sums_exact = sums * (n * T_EXACT + log_r * (ALPHA + ACCUMULATOR_BYTES / BETA))
    return dict(n=n, a=a, ghosts=g, ratio=g / n, compute=compute, halo=halo, sums_now=sums_now, sums_exact=sums_exact)


def table(title, rows, rate, sums, base_of):
    print(f"**{title}**\n")
    print("| ranks | nodes per rank | piece side a | ghosts per owned node | compute [ms] | halo [ms] | halo bytes per rank | "
          "ordered sums before [ms] | efficiency before | exact sums as built [ms] | efficiency as built |")
    print("|---|---|---|---|---|---|---|---|---|---|---|")
    for total, ranks in rows:
        t = step_times(total, ranks, rate, sums)
        now = t["compute"] + t["halo"] + t["sums_now"]
        exact = t["compute"] + t["halo"] + t["sums_exact"]
        base = base_of(total, ranks)
        print(f"| {ranks} | {t['n']:.3g} | {t['a']:.0f} | {t['ratio']:.3f} | {1e3 * t['compute']:.4g} | {1e3 * t['halo']:.3g} | "
              f"{24 * t['ghosts'] / 1e6:.3g} MB | {1e3 * t['sums_now']:.3g} | {base / now:.2f} | {1e3 * t['sums_exact']:.3g} | "
              f"{base / exact:.2f} |")
    print()


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--nodes", type=float, default=1e8)
    ap.add_argument("--rate", type=float, default=2.7e8, help="directed bond updates/s of one core")
    ap.add_argument("--sums", type=int, default=2, help="sums per step (2: the blow-up watch's energies)")
    args = ap.parse_args()
    ranks = [1, 8, 64, 128, 512, 1024]
    print(f"N = {args.nodes:.3g} nodes, {BONDS_PER_NODE} bonds per node, r = {args.rate:.3g} bond updates/s per core, "
          f"α = {ALPHA * 1e6:g} µs, β = {BETA / 1e9:g} GB/s, {args.sums} sums a step, exact sums {ACCUMULATOR_BYTES} B and {T_EXACT * 1e9:g} ns a term\n")
    serial = lambda total: BONDS_PER_NODE * total / args.rate  # noqa: E731
    table("Strong scaling (N fixed): efficiency = T(1) / (R·T(R))", [(args.nodes, r) for r in ranks], args.rate,
          args.sums, lambda total, r: serial(total) / r)
    per_rank = args.nodes / ranks[-1]
    table(f"Weak scaling ({per_rank:.3g} nodes per rank, {args.nodes:.3g} at {ranks[-1]} ranks): efficiency = T(1 rank, "
          f"n) / T(R)", [(per_rank * r, r) for r in ranks], args.rate, args.sums, lambda total, r: serial(per_rank))
    print(f"Memory: {BYTES_PER_NODE:.0f} B per node → {BYTES_PER_NODE * args.nodes / 1e9:.3g} GB for the whole model")


if __name__ == "__main__":
    main()
