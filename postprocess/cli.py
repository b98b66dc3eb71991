"""The command line: read a case's solver output and write its figures and Gmsh views.

    /usr/bin/python3 -m postprocess OUT_DIR [--case-json PATH] [--only figures|gmsh]

Reads OUT_DIR/case.json (or PATH), OUT_DIR/history.csv and OUT_DIR/frames.pvd with its frames;
writes OUT_DIR/figures/{energy,timestep,probe,damage_<i>,displacement_<i>}.png,
OUT_DIR/gmsh/{results.msh,damage_final.pos} and OUT_DIR/history.json (units of history.csv), and
says on stderr, one line each, what it draws. Every frame is read once, in order.
Exit status 0 on success, 1 with a message naming the file on an error, 2 on a usage error.
"""
from __future__ import annotations

import argparse
import contextlib
import glob
import os
import re
import sys

import numpy as np

from common.atomic import DISK_FULL_EXIT, WriteError

from .casefile import load_case_settings
from .errors import PostprocessError
from .crack_tip import DAMAGED
from .history import read_history
from .series import read_frame, read_series
from .plotting import say
from .selection import default_times, event_times, probe_nodes, select_frames

MAP_NAME = re.compile(r"(damage|displacement)_(\d+)\.png$")


def _parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="python3 -m postprocess",
        description="Figures (PNG) and Gmsh views of a solver run (pipeline/formats.md §4).")
    parser.add_argument("out_dir", metavar="OUT_DIR", help="the case's output directory, e.g. out/membrane")
    parser.add_argument("--case-json", metavar="PATH",
                        help="the resolved case (default: OUT_DIR/case.json)")
    parser.add_argument("--only", choices=("figures", "gmsh"), help="write only the figures or only the Gmsh files")
    return parser


def _check_inputs(out_dir: str, case_json: str, need_history: bool):
    """Every input present, or one error listing what is missing and how to make it."""
    if not os.path.isdir(out_dir):
        raise PostprocessError(f"{out_dir}: no such directory; run the case first: "
                               f"make case={os.path.basename(os.path.normpath(out_dir))}")
    needed = [case_json, os.path.join(out_dir, "frames.pvd")]
    if need_history:
        needed.append(os.path.join(out_dir, "history.csv"))
    missing = [path for path in needed if not os.path.isfile(path)]
    if missing:
        name = os.path.basename(os.path.normpath(out_dir))
        if os.path.isfile(case_json):
            try:
                name = load_case_settings(case_json).name
            except PostprocessError:
                pass
        stage = "preprocess and solve" if case_json in missing else "run the solver"
        raise PostprocessError("missing input: " + ", ".join(missing) +
                               f"; {stage} first: make case={name}")


def _remove_stale_maps(directory: str, count: int, keep_damage: bool = True):
    """Maps numbered ≥ count are left from an earlier run with more `figures.times`, and damage
    maps from a run that could break: remove them."""
    for path in glob.glob(os.path.join(directory, "*.png")):
        match = MAP_NAME.search(os.path.basename(path))
        if match and (int(match.group(2)) >= count or (match.group(1) == "damage" and not keep_damage)):
            os.unlink(path)


def _crack_outputs(out_dir, fig_dir, case, times, points, crack_masks) -> list[str]:
    """crack_path.png and crack_tips.csv when bonds can break and a crack grew; else none (and
    those of an earlier run removed)."""
    from .crack_plot import plot_crack_path, tip_table, unresolved_growth, write_tip_csv
    from .crack_tip import plan_tracks

    paths = [os.path.join(fig_dir, "crack_path.png"), os.path.join(out_dir, "crack_tips.csv")]
    tracks = plan_tracks(points, crack_masks, case.cracks) if case.breakable and points is not None else []
    if not tracks:
        for stale in paths:
            if os.path.exists(stale):
                os.unlink(stale)
        if case.breakable:
            say("crack_path.png: none, no crack grew (no node's damage passed "
                f"{DAMAGED:g} beyond the pre-cracks)")
        return []
    unresolved = unresolved_growth(times, points, crack_masks, tracks)  # once, for the table and the figure
    write_tip_csv(paths[1], tip_table(times, points, crack_masks, tracks, unresolved))
    say(plot_crack_path(times, points, crack_masks, tracks, case, paths[0], unresolved))
    return paths


def _default_times(out_dir: str, times: list, history) -> list:
    """figures.times: null → the crack's growth when bonds break (selection.event_times), else
    times evenly spread over the run."""
    path = os.path.join(out_dir, "history.csv")
    if history is None and os.path.isfile(path):
        history = read_history(path)
    event = event_times(times, history["time"], history["broken_bonds"]) if history is not None else None
    return event or default_times(times)


def run(out_dir: str, case_json: str | None = None, only: str | None = None, log=print) -> list[str]:
    """Write the outputs of one case; returns the paths written."""
    case_json = case_json or os.path.join(out_dir, "case.json")
    do_figures, do_gmsh = only in (None, "figures"), only in (None, "gmsh")
    _check_inputs(out_dir, case_json, need_history=do_figures)
    case = load_case_settings(case_json)
    series = read_series(os.path.join(out_dir, "frames.pvd"))
    times = [t for t, _ in series]
    history = read_history(os.path.join(out_dir, "history.csv")) if do_figures else None

    # output.gmsh: every frame into results.msh, only the frames of the figures (the default: a
    # copy of all 55 frames of plate_with_hole was 533 MB), or no Gmsh files at all.
    do_gmsh = do_gmsh and case.gmsh != "none"
    requested = case.times if case.times is not None else _default_times(out_dir, times, history)
    selected = select_frames(times, requested)
    if do_figures:
        # A relative slack of 1e-9: the last frame's time is the sum of the steps, which may land
        # an ulp below the end time the user wrote (4.3e-05 against 4.2999999999999995e-05).
        slack = 1e-9 * max(abs(times[0]), abs(times[-1]), 1e-300)
        for t in requested:
            if t < times[0] - slack or t > times[-1] + slack:
                print(f"postprocess: note: figures.times {t:g} s is outside the run "
                      f"[{times[0]:g}, {times[-1]:g}] s; drawing the nearest frame", file=sys.stderr)

    say(f"reading {len(series)} frames of {out_dir} (frames.pvd)"
        + (f"; Gmsh copy of {'all of them' if case.gmsh == 'all' else 'those of the figures'}" if do_gmsh else ""))
    kept: dict = {}
    probe: dict = {"values": [], "nodes": None, "where": "", "position": None}
    # A probe the solver recorded at every history row (output.probes) needs nothing from the frames.
    from .probe import probe_from_history
    recorded = probe_from_history(history, case) if do_figures else None
    nodes_file = os.path.join(out_dir, "nodes.vtu")
    state: dict = {"last": None, "count": None}
    # crack nodes (φ > DAMAGED) of every frame, for the crack-tip tracks: a bool per node and frame
    # (plate_with_hole: 55 × 78 760 bytes), only when something can break
    crack_masks: list = []

    def frames():
        """Each frame once: feeds the probe, keeps the frames the maps need, and yields for Gmsh."""
        for index, (t, path) in enumerate(series):
            frame = read_frame(path)
            if state["count"] is None:
                state["count"] = len(frame.points)
                if recorded is None:
                    probe["nodes"], probe["where"] = probe_nodes(frame.points, case.probe, nodes_file)
                    if len(probe["nodes"]) == 1:
                        probe["position"] = frame.points[probe["nodes"][0]]
            elif len(frame.points) != state["count"]:
                raise PostprocessError(f"{path}: {len(frame.points)} points, the first frame "
                                       f"{series[0][1]} has {state['count']}")
            if recorded is None:
                probe["values"].append(float(np.mean(frame.displacement[probe["nodes"], case.component])))
            if case.breakable:
                crack_masks.append(frame.damage > DAMAGED)
            if index in selected:
                kept[index] = frame
            state["last"] = (index, t, frame)
            yield index, t, frame

    written = []
    history_csv = os.path.join(out_dir, "history.csv")
    if os.path.isfile(history_csv):
        # history.json: each column's unit and meaning, from the header (formats.md §4)
        from .history_units import write_history_json

        path = os.path.join(out_dir, "history.json")
        content = write_history_json(history_csv, path)
        written.append(path)
        unknown = [name for name, column in content["columns"].items() if column["unit"] is None]
        say(f"history.json: unit and meaning of the {len(content['columns'])} columns of history.csv"
            + (f" ({', '.join(unknown)} not documented in formats.md §4)" if unknown else ""))
    if do_gmsh:
        from .gmsh_export import write_damage_pos, write_results_msh

        gmsh_dir = os.path.join(out_dir, "gmsh")
        path = os.path.join(gmsh_dir, "results.msh")
        chosen = frames() if case.gmsh == "all" else (f for f in frames() if f[0] in selected)
        count = write_results_msh(path, chosen, block_names=case.block_names or None)
        written.append(path)
        say(f"gmsh/results.msh: {count} of {len(series)} frames as Gmsh views"
            + (" (output.gmsh: all)" if case.gmsh == "all" else " (those of the figures; output.gmsh: all for every one)"))
        index, t, frame = state["last"]
        path = os.path.join(gmsh_dir, "damage_final.pos")
        write_damage_pos(path, frame, time=t, title=f"{case.name}, frame {index}")
        written.append(path)
        say(f"gmsh/damage_final.pos: damage and {len(frame.broken_bonds)} broken bonds of frame {index}")
    else:
        for _ in frames():
            pass

    if do_figures:
        from .energy_plot import plot_energy
        from .indenter_plot import indenter_names, plot_indenter_forces
        from .maps import displacement_range, plot_map
        from .probe import plot_probe
        from .timestep_plot import plot_timestep

        fig_dir = os.path.join(out_dir, "figures")
        path = os.path.join(fig_dir, "energy.png")
        say(plot_energy(history, case, path))
        written.append(path)
        path = os.path.join(fig_dir, "timestep.png")
        say(plot_timestep(history, case, path, run_log=os.path.join(out_dir, "run.log")))
        written.append(path)
        if indenter_names(history):  # only when the case has indenters (formats.md §4)
            path = os.path.join(fig_dir, "indenter_force.png")
            say(plot_indenter_forces(history, case, path))
            written.append(path)
        from .reaction_plot import plot_reactions, reaction_sets
        if reaction_sets(history):  # only when the case lists output.reactions (formats.md §4)
            path = os.path.join(fig_dir, "reaction_force.png")
            say(plot_reactions(history, case, case_json, path))
            written.append(path)
        shared = displacement_range([kept[i] for i in selected], case.component)
        # Damage maps only where something can break or a pre-crack shows: an unbreakable
        # membrane got four all-zero maps.
        damaged = case.breakable or any(np.any(kept[i].damage != 0.0) for i in selected)
        quantities = ("damage", "displacement") if damaged else ("displacement",)
        for number, (t_requested, index) in enumerate(zip(requested, selected)):
            for quantity in quantities:
                path = os.path.join(fig_dir, f"{quantity}_{number}.png")
                plot_map(kept[index], case, path, quantity=quantity, time=times[index], index=index,
                         requested=t_requested, vrange=shared if quantity == "displacement" else None)
                written.append(path)
        say(f"{' and '.join(q + '_<i>.png' for q in quantities)}: frames "
            f"{', '.join(str(i) for i in selected)} (figures.times)"
            + ("" if damaged else "; no damage maps: nothing can break (no fracture_energy) and no damage"))
        _remove_stale_maps(fig_dir, len(selected), keep_damage=damaged)
        path = os.path.join(fig_dir, "probe.png")
        if recorded is not None:  # every history row (output.probes): not aliased by the frame interval
            rows, values, where = recorded
            say(plot_probe(rows, values, case, path, where=where, samples="history rows"))
        else:
            say(plot_probe(times, probe["values"], case, path, where=probe["where"], position=probe["position"]))
        written.append(path)
        path = os.path.join(fig_dir, "damage_3d.png")
        if case.dimension == 3 and damaged:  # a rendered view of where the damage is inside the body
            from .render3d import render_damage_3d
            index, t, frame = state["last"]
            say(render_damage_3d(series[index][1], frame, case, path, time=t))
            written.append(path)
        elif os.path.exists(path):  # left from an earlier run of a case that could break
            os.unlink(path)
        written += _crack_outputs(out_dir, fig_dir, case, times, state["last"][2].points,
                                  crack_masks)
    log(f"postprocess: {case.name}: {len(series)} frames → " +
        ", ".join(os.path.relpath(p, out_dir) for p in written) + f" in {out_dir}")
    return written


def main(argv=None) -> int:
    args = _parser().parse_args(argv)
    from common.output_lock import FolderInUse, output_lock

    try:
        # The run folder's lock (make's, handed down as PD_LOCK_FD, or our own): figures drawn by
        # hand while a run writes the frames read frames half the run had written (issue 36 probe).
        with output_lock(args.out_dir, "python3 -m postprocess") if os.path.isdir(args.out_dir) \
                else contextlib.nullcontext():
            run(args.out_dir, args.case_json, args.only)
    except FolderInUse as error:
        print(f"postprocess: {error}", file=sys.stderr)
        return 75
    except PostprocessError as error:
        print(f"postprocess: error: {error}", file=sys.stderr)
        return 1
    except WriteError as error:  # a full disk: its own exit code, as in the solver
        print(f"postprocess: error: {error}", file=sys.stderr)
        return DISK_FULL_EXIT
    return 0
