"""The indenter-force figure: drawn from the indenter_<name>_f{x,y,z} columns only when they exist,
and the contact energy joins the energy balance when history.csv has it (formats.md §4)."""
import os

import numpy as np

import synthetic_output as synth
from postprocess import cli
from postprocess.energy_plot import energy_balance
from postprocess.history import read_history
from postprocess.indenter_plot import indenter_names
from test_post_figures import assert_real_png


def add_columns(run, extra: dict):
    history = synth.history_values()
    names = synth.HISTORY_HEADER.split(",") + list(extra)
    history.update(extra)
    with open(run.out / "history.csv", "w") as stream:
        stream.write(",".join(names) + "\n")
        for i in range(len(history["step"])):
            stream.write(",".join(repr(float(history[k][i])) for k in names) + "\n")


def test_no_indenter_no_figure(run2d):
    written = cli.run(str(run2d.out), log=lambda *_: None)
    assert not any(p.endswith("indenter_force.png") for p in written)


def test_indenter_columns_give_the_figure_and_contact_energy_joins_the_balance(run2d):
    t = synth.history_values()["time"]
    force = 1.0e3 * (t / t[-1]) ** 2  # grows like K·h² for h ∝ t
    contact = 0.25 * (t / t[-1]) ** 3
    add_columns(run2d, {"contact_energy": contact, "indenter_punch_fx": 0 * t,
                        "indenter_punch_fy": force, "indenter_punch_fz": 0 * t})
    history = read_history(str(run2d.out / "history.csv"))
    assert indenter_names(history) == ["punch"]
    base = history["kinetic_energy"] + history["strain_energy"] + history["damping_work"] - history["external_work"]
    assert np.allclose(energy_balance(history) - base, contact, rtol=0, atol=1e-15)
    written = cli.run(str(run2d.out), log=lambda *_: None)
    path = str(run2d.out / "figures" / "indenter_force.png")
    assert path in written and os.path.isfile(path)
    assert_real_png(path)
