"""The reference code on the bench's brick: LAMMPS's PERI package (pair_style peri/pmb, or peri/lps
for the linear peridynamic solid with the same K and ν = 1/4, G = 3K/5) on the same
side³ simple cubic lattice as pd_speed (dx = 1 mm, δ = 3.0002·dx, free faces, the top three layers
moving down at 0.1 m/s, the same glass-like material), serial and with 2 MPI ranks.

    /usr/bin/python3 -m bench.lammps_brick [--side 40] [--steps 40] [--ranks 1 2]

Needs Debian's `lammps` package (lmp, built with PERI) and `mpirun` (openmpi-bin); `make bench`
installs both. The rate is counted as pd_speed counts it: directed bonds × steps / LAMMPS's own
"Loop time", with the directed bond count of our bond list on the same lattice (each bond from both
ends). LAMMPS's peri/pmb also computes its short-range repulsion over every neighbour-list pair in
the same loop; pd_speed has no contact on this brick. That is the work each code does by default on
this problem, and it is what a user switching codes would see.
"""
import argparse
import os
import re
import shutil
import subprocess
import sys
import tempfile

import numpy as np

from pipeline.solver_physics import physics_of_cloud  # pdsolve --physics: the solver's own numbers
from preprocess.cloud import NodeCloud

# The material of pd_speed (solver/bench/speed.cpp): E = 72 GPa, ν = 1/4, ρ = 2440 kg/m³, G0 = 4 J/m².
DX = 1e-3
HORIZON = 3.0002 * DX
YOUNG, DENSITY, FRACTURE_ENERGY = 72e9, 2440.0, 4.0
BULK = YOUNG / (3.0 * (1.0 - 2.0 * 0.25))                          # k = E/(3(1−2ν)), ν = 1/4
SHEAR = YOUNG / (2.0 * (1.0 + 0.25))                               # G = E/(2(1+ν)): peri/lps


def lattice_physics():
    """pdsolve --physics on a 9³ piece of the brick's lattice with its material: PMB's c = 18k/(πδ⁴)
    (docs/theory.md T2) and s0 = √(5G0/(9kδ)) from E and G0, and thesis eq. 2.5's step, whose minimum
    is at an interior node, so that the piece (an interior node with its whole family) gives the
    brick's. 0.8 of the step is the one pd_speed takes (0.8 · stable_time_step of the model).
    Returns (c, s0, the step × 0.8)."""
    side = 2 * (int(HORIZON / DX) + 1) + 1
    k, j, i = np.meshgrid(np.arange(side), np.arange(side), np.arange(side), indexing="ij")
    points = np.column_stack([i.ravel(), j.ravel(), k.ravel()]).astype(float) * DX
    n = len(points)
    cloud = NodeCloud(points=points, volume=np.full(n, DX ** 3), block=np.ones(n, np.int32),
                      sets={"brick": np.ones(n, bool)}, grid_spacing=DX, dimension=3)
    case = {"format_version": 1, "case": "lammps_brick", "dimension": 3, "analysis": "3d", "thickness": None,
            "grid_spacing": DX, "horizon": HORIZON,
            "blocks": [{"id": 1, "name": "brick", "model": "pmb", "density": DENSITY, "youngs_modulus": YOUNG,
                        "fracture_energy": FRACTURE_ENERGY}],
            "no_fail_sets": [], "node_sets": ["brick"], "boundary_conditions": [], "initial_conditions": [],
            "damping": 0.0, "time": {"integrator": "verlet", "dt": "stable", "safety_factor": 0.8, "end": 1e-6},
            "output": {"every_time": 1e-6, "every_steps": None, "history_every": 1}}
    answer = physics_of_cloud(case, cloud)
    (block,) = answer["blocks"]
    return block["micromodulus"], block["critical_stretch"], answer["safety_factor"] * answer["stable"]


MICROMODULUS, CRITICAL_STRETCH, TIME_STEP = lattice_physics()


def lammps_input(side, steps, model="pmb"):
    """A LAMMPS input for the side³ brick (lattice units of dx, nodes at 0 … side−1). peri/lps takes
    K, G, δ, s00, α (its own influence function 1/|ξ|; s0 as PMB's, which LPS's formula gives for
    ω = 1/|ξ|: materials/lps/lps.hpp)."""
    hi = side - 0.5
    if model == "lps":
        pair = (f"pair_style peri/lps\npair_coeff * * {BULK:.10e} {SHEAR:.10e} {HORIZON:.10e} "
                f"{CRITICAL_STRETCH:.10e} 0.0")
    else:
        pair = f"pair_style peri/pmb\npair_coeff * * {MICROMODULUS:.10e} {HORIZON:.10e} {CRITICAL_STRETCH:.10e} 0.0"
    return f"""# written by bench/lammps_brick.py
units si
boundary s s s
atom_style peri
atom_modify map array
lattice sc {DX}
region box block -0.5 {hi} -0.5 {hi} -0.5 {hi}
create_box 1 box
create_atoms 1 region box
{pair}
set group all density {DENSITY}
set group all volume {DX ** 3:.10e}
region top block INF INF INF INF {side - 3.5} INF
group top region top
velocity top set 0.0 0.0 -0.1 units box
neighbor {0.1 * DX} bin
neigh_modify every 100000 delay 100000 check no
fix 1 all nve
timestep {TIME_STEP:.10e}
thermo 100000
run {steps}
"""


def run_lammps(side, steps, ranks, workdir, model="pmb"):
    """Loop time [s] and atom count LAMMPS reports for the brick with `ranks` MPI ranks."""
    path = os.path.abspath(os.path.join(workdir, f"in.brick-{side}-{model}"))
    with open(path, "w") as f:
        f.write(lammps_input(side, steps, model))
    cmd = ["lmp", "-in", path, "-log", "none"]
    if ranks > 1:
        cmd = ["mpirun", "--allow-run-as-root", "--oversubscribe", "-np", str(ranks)] + cmd
    out = subprocess.run(cmd, capture_output=True, text=True, cwd=workdir)
    m = re.search(r"Loop time of ([0-9.eE+-]+) on (\d+) procs for (\d+) steps with (\d+) atoms", out.stdout)
    if out.returncode != 0 or not m:
        raise RuntimeError(f"{' '.join(cmd)} failed (exit {out.returncode}):\n{out.stdout[-2000:]}{out.stderr[-2000:]}")
    return float(m.group(1)), int(m.group(4))


def available():
    """None if lmp and mpirun are on PATH, else what is missing."""
    missing = [p for p in ("lmp", "mpirun") if shutil.which(p) is None]
    return None if not missing else " and ".join(missing)


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--side", type=int, default=40)
    ap.add_argument("--steps", type=int, default=40)
    ap.add_argument("--ranks", type=int, nargs="+", default=[1, 2])
    ap.add_argument("--model", choices=("pmb", "lps"), default="pmb")
    args = ap.parse_args()
    if available():
        sys.exit(f"lammps_brick.py: {available()} not found: apt-get install lammps openmpi-bin (make bench does)")
    with tempfile.TemporaryDirectory(prefix="pd-lammps-") as tmp:
        for ranks in args.ranks:
            loop, atoms = run_lammps(args.side, args.steps, ranks, tmp, args.model)
            print(f"LAMMPS peri/{args.model}, {atoms} atoms, {ranks} rank(s): loop {loop:.3f} s for {args.steps} steps")


if __name__ == "__main__":
    main()
