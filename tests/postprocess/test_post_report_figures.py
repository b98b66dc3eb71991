"""Figures a user can put in a report (issue 16): what can be checked on the matplotlib objects.

Each figure is drawn with save_figure replaced by a spy that keeps the figure, then checked for:
axis labels with a unit in [...], no offset text ("1e-5", "+1.2e-3") on any linear axis, a legend
inside its axes over no data, a short title without the case's title nested in it; and the content:
the energy balance with every term (it closes to what validation reports), timestep.png per
integrator, no damage maps when nothing can break, the probe of figures.probe.
"""
import json
import re

import meshio
import numpy as np
import pytest
from matplotlib import pyplot as plt
from matplotlib.collections import LineCollection

import synthetic_output as synth
from postprocess import cli, energy_plot, maps, plotting, probe, timestep_plot
from postprocess.casefile import CaseSettings
from postprocess.plotting import TITLE_MAX, legend_covers, place_legend, si_scale
from postprocess.selection import probe_nodes

UNIT = re.compile(r"\[[^\]]+\]$")


@pytest.fixture
def keep(monkeypatch):
    """Figures drawn by the plotting modules, kept instead of saved: {file name: figure}."""
    kept = {}

    def spy(fig, path, dpi):
        assert dpi == 300, path   # figures.dpi's default reaches every figure
        fig.canvas.draw()
        kept[path.rsplit("/", 1)[-1]] = fig

    for module in (energy_plot, maps, probe, timestep_plot):
        monkeypatch.setattr(module, "save_figure", spy)
    yield kept
    for fig in kept.values():
        plt.close(fig)


def case(**kwargs):
    return CaseSettings(name="branching", dimension=2, title="Crack branching in soda-lime glass (docs/theory.md C7)",
                        **kwargs)


def check_readable(fig):
    """Every axes of a line figure: units in its labels, no offset text, short title, legend placed."""
    for ax in fig.axes:
        for axis, label in ((ax.xaxis, ax.get_xlabel()), (ax.yaxis, ax.get_ylabel())):
            if label and label != "step":
                assert UNIT.search(label), f"axis label without a unit: {label!r}"
            assert axis.get_offset_text().get_text() == "", f"offset text {axis.get_offset_text().get_text()!r}"
        for line in ax.get_title().splitlines():
            assert len(line) <= TITLE_MAX and "(" not in line.split(":")[0], ax.get_title()
        legend = ax.get_legend()
        if legend is not None:
            box = legend.get_window_extent(fig.canvas.get_renderer())
            frame = ax.get_window_extent(fig.canvas.get_renderer())
            assert frame.x0 <= box.x0 and box.x1 <= frame.x1 and frame.y0 <= box.y0 and box.y1 <= frame.y1
            assert legend_covers(ax) == 0


def fracture_history(rows=200, end=4.3e-5):
    """A run in µs with breaking: W = KE + U + E_broken + 1.2 % W (a known non-closure at the end)."""
    t = np.linspace(0.0, end, rows)
    work = 8e-3 * (t / end) ** 2
    kinetic, strain = 0.8 * work, 0.05 * work
    broken = 0.15 * work - 0.012 * work
    return {"step": np.arange(rows), "time": t, "dt": np.full(rows, end / rows), "iterations": np.ones(rows, int),
            "rejected": np.zeros(rows, int), "kinetic_energy": kinetic, "strain_energy": strain,
            "external_work": work, "damping_work": np.zeros(rows), "broken_bonds": np.arange(rows),
            "wall_time": np.linspace(0.0, 30.0, rows), "broken_bond_energy": broken}


def test_energy_balance_counts_broken_bonds_and_closes_to_what_validation_reports(keep):
    h = fracture_history()
    # validation/branching.py: |KE + U + E_broken + D − W| / W at the end
    validation = abs(h["kinetic_energy"][-1] + h["strain_energy"][-1] + h["broken_bond_energy"][-1]
                     + h["damping_work"][-1] - h["external_work"][-1]) / h["external_work"][-1]
    assert validation == pytest.approx(0.012)
    drift, reference, _ = energy_plot.balance_error(h)
    assert abs(drift[-1]) == pytest.approx(validation, rel=1e-12) and reference == h["external_work"][-1]
    said = energy_plot.plot_energy(h, case(), "energy.png")
    assert "-1.2 %" in said
    fig = keep["energy.png"]
    top, bottom = fig.axes
    labels = [t.get_text() for t in top.get_legend().get_texts()]
    assert "broken bonds" in labels and "damping work" not in labels  # an all-zero term is not drawn
    assert top.get_ylabel() == "energy [mJ]" and bottom.get_xlabel() == "time t [µs]"
    assert np.allclose(bottom.get_lines()[0].get_ydata(), 100 * drift)
    assert top.get_title() == "branching: energy"
    check_readable(fig)


def test_with_load_steps_the_damping_work_is_labelled_with_what_they_give_up(keep):
    """A mixed run: the damping work holds what its quasi-static load steps gave up (the solver's
    run/loop.cpp), with or without damping, and the legend says so; a run without load steps keeps
    the plain label."""
    h = fracture_history()
    h["damping_work"] = 0.3 * h["external_work"]
    h["mode"] = np.where(np.arange(len(h["time"])) < 100, 1, 0)
    energy_plot.plot_energy(h, case(), "energy.png")
    labels = [t.get_text() for t in keep["energy.png"].axes[0].get_legend().get_texts()]
    assert "damping work + given up by load steps" in labels and "damping work" not in labels
    # The load steps' rows count no kinetic energy (their velocity is a mean rate); the others do.
    balance = energy_plot.energy_balance(h)
    with_kinetic = h["kinetic_energy"] + h["strain_energy"] + h["broken_bond_energy"] + h["damping_work"]
    without = 0.0 + h["strain_energy"] + h["broken_bond_energy"] + h["damping_work"]
    assert np.array_equal(balance[:100], (without - h["external_work"])[:100])
    assert np.array_equal(balance[100:], (with_kinetic - h["external_work"])[100:])
    h["mode"] = np.zeros(len(h["time"]), int)
    assert ("damping_work", "damping work") in energy_plot.balance_terms(h)


def test_every_stored_term_joins_the_balance():
    h = fracture_history()
    h["contact_energy"] = 0.1 * h["external_work"]
    h["indenter_energy"] = 0.2 * h["external_work"]
    h["damping_work"] = 0.3 * h["external_work"]
    expected = (h["kinetic_energy"] + h["strain_energy"] + h["contact_energy"] + h["indenter_energy"]
                + h["broken_bond_energy"] + h["damping_work"] - h["external_work"])
    assert np.array_equal(energy_plot.energy_balance(h), expected)


RUN_LOG = "dt 5.68539e-07 s (stable 7.10674e-07 s × safety factor 0.8), integrator verlet, damping 300 1/s\n"
RUN_LOG_EXACT = ("dt 9.6e-07 s (exact limit 1.2e-06 s = 1.7 × eq. 2.5, × safety factor 0.8), "
                 "integrator verlet, damping 0 1/s\n")


def test_verlet_timestep_shows_dt_against_its_stability_limit(tmp_path, keep):
    (tmp_path / "run.log").write_text("nodes 10\n" + RUN_LOG)
    h = fracture_history()
    h["dt"] = np.full(len(h["step"]), 5.68539e-07)
    said = timestep_plot.plot_timestep(h, case(integrator="verlet"), "timestep.png", run_log=str(tmp_path / "run.log"))
    assert "0.8 × eq. 2.5" in said
    fig = keep["timestep.png"]
    assert len(fig.axes) == 2  # not three panels of a constant
    a = fig.axes[0]
    assert a.get_ylabel() == "time step Δt [ns]"
    limit = [line for line in a.get_lines() if "stable limit" in line.get_label()]
    assert len(limit) == 1 and limit[0].get_ydata()[0] == pytest.approx(710.674)
    assert a.get_title() == "branching: Verlet, Δt = 0.8 × eq. 2.5"
    assert not [line for line in a.get_lines() if "shortened" in line.get_label()]  # none was
    check_readable(fig)


def test_verlet_steps_shortened_to_land_on_output_times_are_points_not_spikes(tmp_path, keep):
    # The loop cuts the step before each output time (run/schedule): 3 such steps of 4.4e-7 s among
    # 5.68539e-7 s ones. The line is the rule's step; the three are drawn and counted apart.
    (tmp_path / "run.log").write_text(RUN_LOG)
    h = fracture_history()
    h["dt"] = np.full(len(h["step"]), 5.68539e-07)
    cut = [3, 7, len(h["dt"]) - 1]
    h["dt"][cut] = 4.4e-07
    timestep_plot.plot_timestep(h, case(integrator="verlet"), "timestep.png", run_log=str(tmp_path / "run.log"))
    a = keep["timestep.png"].axes[0]
    step_line = [line for line in a.get_lines() if line.get_label() == "time step Δt"][0]
    assert np.all(step_line.get_ydata() == pytest.approx(568.539))
    points = [line for line in a.get_lines() if "shortened" in line.get_label()]
    assert len(points) == 1 and points[0].get_label() == "3 steps shortened to land on an output time"
    assert points[0].get_ydata() == pytest.approx([440.0] * 3)
    check_readable(keep["timestep.png"])


def test_run_log_limits_are_read_for_every_dt_rule(tmp_path):
    path = tmp_path / "run.log"
    path.write_text(RUN_LOG_EXACT)
    limits = timestep_plot.stability_limits(str(path))
    assert limits["exact 2/ω_max"] == 1.2e-06 and limits["eq. 2.5"] == pytest.approx(1.2e-06 / 1.7)
    path.write_text("dt 1e-08 s (fixed; stable 7.1e-07 s), integrator verlet, damping 0 1/s\n")
    assert timestep_plot.stability_limits(str(path)) == {"eq. 2.5": 7.1e-07}
    assert timestep_plot.stability_limits(str(tmp_path / "none.log")) == {}


def test_adaptive_timestep_keeps_dt_and_iterations(run2d, keep):
    h = synth.history_values()
    timestep_plot.plot_timestep(h, case(integrator="adaptive"), "timestep.png")
    fig = keep["timestep.png"]
    assert len(fig.axes) == 3 and fig.axes[2].get_ylabel() == "iterations K, rejections [–]"
    check_readable(fig)


def test_damage_map_colours_damage_and_draws_bonds_as_light_hairlines(run2d, keep):
    from postprocess.series import read_frame
    frame = read_frame(str(run2d.out / "frames/frame_000005.vtu"))
    assert len(frame.broken_bonds)
    settings = case(grid_spacing=synth.DX)
    maps.plot_map(frame, settings, "damage_0.png", quantity="damage", time=4.3e-5, index=5)
    fig = keep["damage_0.png"]
    ax = fig.axes[0]
    (bonds,) = [c for c in ax.collections if isinstance(c, LineCollection)]
    rgb = bonds.get_colors()[0][:3]
    assert min(rgb) >= 0.7 and bonds.get_linewidths()[0] <= 0.2  # light and thin, not black
    assert ax.get_title().splitlines()[0] == "branching: damage at t = 43 µs"
    assert ax.get_xlabel() == "x [mm]" and ax.get_ylabel() == "y [mm]"
    for axes in fig.axes:
        assert axes.xaxis.get_offset_text().get_text() == axes.yaxis.get_offset_text().get_text() == ""


def _set(run, **figures):
    data = json.loads(run.case_json.read_text())
    data["figures"].update(figures)
    run.case_json.write_text(json.dumps(data))
    return data


def test_no_damage_maps_when_nothing_can_break(run2d, capsys):
    for k in range(6):  # an unbreakable body: no damage, no broken bonds in any frame
        path = run2d.out / f"frames/frame_{k:06d}.vtu"
        synth.write_vtu(path, run2d.points, {"displacement": run2d.displacements[k], "velocity": run2d.displacements[k],
                                             "damage": np.zeros(len(run2d.points)), "block": np.ones(len(run2d.points), np.int32)},
                        {"TIME": float(run2d.times[k]), "step": np.int64(8 * k)}, np.zeros((0, 2), np.int64))
    (run2d.out / "figures").mkdir()
    (run2d.out / "figures" / "damage_0.png").write_bytes(b"left from a run that could break")
    cli.run(str(run2d.out), only="figures", log=lambda *_: None)
    names = sorted(p.name for p in (run2d.out / "figures").iterdir())
    assert not [n for n in names if n.startswith("damage_")]
    assert [n for n in names if n.startswith("displacement_")] == [f"displacement_{i}.png" for i in range(4)]
    assert "no damage maps: nothing can break" in capsys.readouterr().err
    # the same frames with a fracture_energy: the maps are drawn (all zero is then a result)
    data = json.loads(run2d.case_json.read_text())
    data["blocks"][0]["fracture_energy"] = 3.8
    run2d.case_json.write_text(json.dumps(data))
    cli.run(str(run2d.out), only="figures", log=lambda *_: None)
    assert (run2d.out / "figures" / "damage_3.png").exists()


def test_postprocess_says_what_it_draws_one_line_per_figure(run2d, capsys):
    written = cli.run(str(run2d.out), log=lambda *_: None)
    err = capsys.readouterr().err.splitlines()
    assert all(line.startswith("postprocess: ") for line in err)
    for name in ("gmsh/results.msh", "gmsh/damage_final.pos", "energy.png", "timestep.png",
                 "damage_<i>.png and displacement_<i>.png", "probe.png"):
        assert sum(line.startswith(f"postprocess: {name}:") for line in err) == 1, (name, err)
    assert len(written) == 1 + 2 + 3 + 8  # history.json, gmsh files, energy/timestep/probe, 4 × 2 maps
    assert sum(line.startswith("postprocess: history.json:") for line in err) == 1


def test_probe_is_the_node_nearest_a_point_or_the_mean_of_a_node_set(run2d, keep):
    points = run2d.points
    nodes, where = probe_nodes(points, None)
    assert list(nodes) == [run2d.centre] and "centre" in where
    nodes, _ = probe_nodes(points, [0.0021, 0.0049, 0.0])
    assert list(nodes) == [int(np.argmin(np.linalg.norm(points - [0.002, 0.005, 0.0], axis=1)))]
    # a node set from nodes.vtu (formats.md §1: one uint8 set_<name> array per node set)
    member = (points[:, 0] <= 1.5e-3).astype(np.uint8)
    meshio.write_points_cells(str(run2d.out / "nodes.vtu"), points, [("vertex", np.arange(len(points))[:, None])],
                              point_data={"volume": np.ones(len(points)), "set_left_edge": member})
    nodes, where = probe_nodes(points, "left_edge", str(run2d.out / "nodes.vtu"))
    assert list(nodes) == list(np.flatnonzero(member)) and f"the {member.sum()} nodes of 'left_edge'" in where
    with pytest.raises(Exception, match="no node set 'nope'.*its sets are: left_edge"):
        probe_nodes(points, "nope", str(run2d.out / "nodes.vtu"))
    _set(run2d, probe="left_edge")
    cli.run(str(run2d.out), only="figures", log=lambda *_: None)
    line = keep["probe.png"].axes[0].get_lines()[0]
    expected = [np.mean(u[member == 1, 2]) for u in run2d.displacements]
    factor, _ = si_scale(expected, "m")
    assert np.allclose(line.get_ydata(), np.array(expected) * factor, rtol=1e-6)  # frames hold float32
    check_readable(keep["probe.png"])


def test_si_scale_picks_the_prefix_that_reads_1_to_1000():
    assert si_scale([0.0, 4.3e-5], "s") == (1e6, "µs")
    assert si_scale([0.0, 0.003], "s") == (1e3, "ms")
    assert si_scale([0.001 * (1 - 1e-12)], "s") == (1e3, "ms")
    assert si_scale([0.0, 0.0], "m") == (1.0, "m")
    assert si_scale([-2.5e3], "N") == (1e-3, "kN")


def test_a_legend_that_would_cover_every_place_moves_above_the_data():
    fig, axes = plotting.new_figure()
    ax = axes[0, 0]
    x = np.linspace(0.0, 1.0, 400)
    for k in range(6):  # curves through every corner and the middle
        ax.plot(x, np.sin(2 * np.pi * (x + k / 6.0)), label=f"curve {k}")
    place_legend(ax)
    assert legend_covers(ax) == 0
    check_readable(fig)
    plt.close(fig)


def test_a_run_crack_s_many_bonds_are_not_drawn_over_the_damage_colours(run2d, keep):
    """A dozen broken bonds per node along a crack would cover its colours: the map says how many."""
    from postprocess.series import Frame
    points = run2d.points
    pairs = np.array([(i, j) for i in range(len(points)) for j in range(i + 1, min(i + 4, len(points)))])
    frame = Frame(path="f.vtu", points=points, point_data={"displacement": np.zeros((len(points), 3)),
                                                           "damage": np.full(len(points), 0.5)},
                  broken_bonds=pairs)
    maps.plot_map(frame, case(grid_spacing=synth.DX), "damage_0.png", quantity="damage", time=1e-5, index=3)
    ax = keep["damage_0.png"].axes[0]
    assert not [c for c in ax.collections if isinstance(c, LineCollection)]
    assert f"{len(pairs)} broken bonds (not drawn)" in ax.get_title()


def test_a_probe_the_solver_recorded_is_drawn_from_every_history_row(run2d, keep):
    """output.probes puts probe_<set>_u<axis> in every history row (formats.md §4): probe.png draws those
    rows, not the frames (which alias a motion faster than their interval), for figures.probe naming the
    set, or by default the first recorded set; a set the solver did not record still comes from the frames."""
    path = run2d.out / "history.csv"
    lines = path.read_text().splitlines()
    time = lines[0].split(",").index("time")
    rows = [float(line.split(",")[time]) for line in lines[1:]]
    wiggle = [np.sin(9.0e5 * t) * 1e-6 for t in rows]  # a motion the frames cannot follow
    header = lines[0] + "," + ",".join(f"probe_tip_{q}" for q in ("ux", "uy", "uz", "vx", "vy", "vz"))
    body = [line + "," + ",".join(repr(w * (k + 1)) for k in range(6)) for line, w in zip(lines[1:], wiggle)]
    path.write_text("\n".join([header] + body) + "\n")
    for chosen in (None, "tip"):
        _set(run2d, probe=chosen)
        cli.run(str(run2d.out), only="figures", log=lambda *_: None)
        line = keep["probe.png"].axes[0].get_lines()[0]
        assert len(line.get_ydata()) == len(rows) > len(run2d.times)
        factor, _ = si_scale([w * 3 for w in wiggle], "m")  # u_z: the column's third value (component 2)
        assert np.allclose(line.get_ydata(), np.array(wiggle) * 3 * factor, rtol=1e-12)
        assert "'tip'" in line.get_label()
    case = probe.CaseSettings(name="x", dimension=2, title="x", probe="elsewhere")
    assert probe.probe_from_history({"time": np.zeros(2), "probe_tip_ux": np.zeros(2)}, case) is None
