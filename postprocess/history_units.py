"""history.json: the unit and meaning of every column of a run's history.csv, for people and programs.

Written by postprocess beside history.csv from its header (the solver's columns are not touched):
{"format_version": 2, "file": "history.csv", "fixed_columns": [names every history.csv has],
 "columns": {"<name>": {"unit": "J", "description": "…"}, …}}   (header order)
Units are SI symbols; "1" marks a count or a ratio (formats.md §4 writes it "–"). The table below
is formats.md §4's; tests/postprocess/test_post_history_json.py checks the two agree.
"""
from __future__ import annotations

import json
import re

from common.atomic import atomic_path

FORMAT_VERSION = 2  # 2: fixed_columns (issue 16)

# The columns every history.csv has since issue 16, whatever the case (formats.md §4): the solver's
# base columns, then the terms a case may lack, written as 0 (solver/src/run/history_columns.cpp).
FIXED_COLUMNS = ("step", "time", "dt", "iterations", "rejected", "kinetic_energy", "strain_energy", "external_work",
                 "damping_work", "broken_bonds", "wall_time", "contact_energy", "indenter_energy",
                 "broken_bond_energy", "contact_rebuilds", "mode")

# name → (unit, description), formats.md §4 in its order.
COLUMNS = {
    "step": ("1", "completed steps"),
    "time": ("s", "simulated time after the step"),
    "dt": ("s", "the step just taken"),
    "iterations": ("1", "fixed-point or Newton iterations K of the step (1 for Verlet)"),
    "rejected": ("1", "rejected attempts before the step was accepted (0 for Verlet)"),
    "kinetic_energy": ("J", "kinetic energy, sum of 1/2 rho V |v|^2"),
    "strain_energy": ("J", "strain energy of the intact bonds, sum of 1/4 c s^2 |xi| V_i V_j"),
    "external_work": ("J", "work of body forces, of the reactions at prescribed nodes and of moving indenters"),
    "damping_work": ("J", "energy removed by damping, integral of sum rho alpha V |v|^2 dt, plus what "
                     "quasi-static load steps gave up on their jumps to equilibrium"),
    "broken_bonds": ("1", "broken bonds, each counted once"),
    "wall_time": ("s", "wall-clock seconds since the time loop started"),
    "contact_energy": ("J", "potential of the short-range contact pairs (0 without contact)"),
    "indenter_energy": ("J", "potential of the rigid indenters, sum of V K h^3/3 (0 without indenters)"),
    "broken_bond_energy": ("J", "energy the broken bonds held when they broke, sum of 1/2 c s0^2 |xi| nu V_i V_j "
                                "at the critical stretch s0 each crossed (0 when nothing can break)"),
    "contact_rebuilds": ("1", "Verlet-list builds of the contact search so far (0 without contact)"),
    "mode": ("1", "kind of step: 1 quasi-static load step, 2 implicit step of mixed (mixed.start: implicit), "
                   "0 any other dynamic (explicit or implicit) step"),
}
# Families of columns, one triple per indenter, reaction set or probe quantity: (pattern, unit, description template).
FAMILIES = (
    (re.compile(r"^indenter_(?P<name>.+)_f(?P<axis>[xyz])$"), "N",
     "reaction force on indenter '{name}' along {axis} (minus its force on the body)"),
    (re.compile(r"^reaction_(?P<name>.+)_f(?P<axis>[xyz])$"), "N",
     "force the prescribed displacement or velocity applies to node set '{name}' along {axis}"),
    (re.compile(r"^probe_(?P<name>.+)_u(?P<axis>[xyz])$"), "m",
     "volume-weighted mean displacement of node set '{name}' along {axis} (output.probes)"),
    (re.compile(r"^probe_(?P<name>.+)_v(?P<axis>[xyz])$"), "m/s",
     "volume-weighted mean velocity of node set '{name}' along {axis} (output.probes)"),
)


def describe_column(name: str) -> tuple[str | None, str]:
    """(unit, description) of a history.csv column; (None, …) for a column formats.md does not know."""
    if name in COLUMNS:
        return COLUMNS[name]
    for pattern, unit, template in FAMILIES:
        match = pattern.match(name)
        if match:
            return unit, template.format(**match.groupdict())
    return None, "not documented in pipeline/formats.md §4 (a newer solver?)"


def header_of(history_csv: str) -> list[str]:
    """The column names of history.csv's header line (the first non-blank line)."""
    with open(history_csv, encoding="utf-8") as stream:
        for line in stream:
            if line.strip():
                return [name.strip() for name in line.split(",")]
    return []


def write_history_json(history_csv: str, path: str) -> dict:
    """Write the sidecar of history_csv to path; returns its content."""
    columns = {}
    for name in header_of(history_csv):
        unit, description = describe_column(name)
        columns[name] = {"unit": unit, "description": description}
    content = {"format_version": FORMAT_VERSION, "file": "history.csv", "fixed_columns": list(FIXED_COLUMNS),
               "columns": columns}
    with atomic_path(path) as tmp, open(tmp, "w", encoding="utf-8") as stream:
        json.dump(content, stream, indent=1, ensure_ascii=False)
        stream.write("\n")
    return content
