"""A parameter study with peridyn (docs/python-api.md): the branching case, coarsened to dx = δ/3 =
0.67 mm (150 × 60 nodes) so each run takes seconds, at three fracture energies G0. Draws the
broken bonds and the crack tip's position against time, one curve per G0, into
docs/examples/fracture_energy_study.png.

    /usr/bin/python3 docs/examples/fracture_energy_study.py [OUT_DIR]     (from the repository root)

peridyn installed as docs/python-api.md says; without the install, PYTHONPATH=. in front does it.
"""
import os
import sys

import numpy as np

import peridyn
from postprocess.plotting import new_figure, save_figure

OUT = sys.argv[1] if len(sys.argv) > 1 else "out/study"
ENERGIES = (2.0, 3.8, 8.0)  # J/m²; 3.8 is soda-lime glass (docs/theory.md C7)

base = peridyn.load("cases/branching/branching.yaml")
base["discretization.dx"] = 6.666666666666667e-4   # δ/3 with δ = 2 mm
base["discretization.horizon"] = 2.0e-3
base["node_sets.top_band.layer"] = 2.0e-3          # the no-fail bands stay one horizon wide
base["node_sets.bottom_band.layer"] = 2.0e-3
base["boundary_conditions.0.body_force.y"] = 3.0e9   # 2 MPa over one row of nodes: σ/dx
base["boundary_conditions.1.body_force.y"] = -3.0e9
base["output.every_time"] = 1.0e-6

fig, axes = new_figure(2, 1, size=(7.0, 6.5), sharex=True)
for energy in ENERGIES:
    case = base.copy()
    case["materials.glass.fracture_energy"] = energy
    run = case.run(os.path.join(OUT, f"G{energy:g}"), figures=False)
    h = run.history
    axes[0, 0].plot(h["time"] * 1e6, h["broken_bonds"], label=f"G0 = {energy:g} J/m²")
    # the crack tip: the largest x of the nodes with damage above 0.3 in each frame
    tips = [f.points[f.damage > 0.3, 0].max() * 1e3 if np.any(f.damage > 0.3) else np.nan for f in run.frames()]
    axes[1, 0].plot(run.times * 1e6, tips, marker=".")
axes[0, 0].set_ylabel("broken bonds [–]")
axes[0, 0].set_title("branching, dx = 0.67 mm: crack growth against fracture energy")
axes[0, 0].legend(loc="upper left", fontsize="small")
axes[1, 0].set_ylabel("crack tip x [mm]")
axes[1, 0].set_xlabel("time t [µs]")
for ax in axes[:, 0]:
    ax.grid(alpha=0.3)
fig.tight_layout()
save_figure(fig, "docs/examples/fracture_energy_study.png")
print("wrote docs/examples/fracture_energy_study.png")
