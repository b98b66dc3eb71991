"""history.json beside history.csv: a unit and a meaning for every column, the same as formats.md §4."""
import json
import os
import re

import synthetic_output as synth
from postprocess import cli
from postprocess.history_units import COLUMNS, FIXED_COLUMNS, describe_column, write_history_json

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))


def formats_md_units() -> dict[str, str]:
    """column → unit of every '| column | unit | meaning |' table of formats.md §4."""
    with open(os.path.join(ROOT, "pipeline", "formats.md"), encoding="utf-8") as stream:
        text = stream.read()
    section = text[text.index("## 4. Solver output"):text.index("## 5.")]
    units = {}
    for match in re.finditer(r"^\s*\| ([^|]+?) \| (\S+) \| .* \|$", section, re.MULTILINE):
        name, unit = match.group(1), match.group(2)
        if name not in ("column", "---|---|---"):
            units[name.replace("\\<", "<").replace("\\>", ">")] = unit
    return units


def test_the_table_is_formats_md():
    documented = formats_md_units()
    assert len(documented) >= 17
    for name, unit in documented.items():
        if "<" in name:  # indenter_<name>_fx, _fy, _fz: one family
            example = name.replace("<name>", "ball").replace("<set>", "left").split(",")[0]
            got, _ = describe_column(example)
        else:
            got, _ = describe_column(name)
        assert got == ("1" if unit == "–" else unit), name
    # every column the table knows is documented
    assert set(COLUMNS) <= set(documented)


def test_fixed_columns_are_formats_md_tables_before_the_named_ones():
    """history.json's fixed_columns: the names of formats.md §4's tables up to the first family
    (indenter_<name>_…), in order: what every history.csv has since issue 16."""
    with open(os.path.join(ROOT, "pipeline", "formats.md"), encoding="utf-8") as stream:
        text = stream.read()
    section = text[text.index("## 4. Solver output"):text.index("## 5.")]
    names = [m.group(1) for m in re.finditer(r"^\s*\| ([^|]+?) \| \S+ \| .* \|$", section, re.MULTILINE)
             if m.group(1) not in ("column",)]
    fixed = names[:names.index("indenter_\\<name\\>_fx, _fy, _fz")]
    assert fixed == list(FIXED_COLUMNS)
    assert FIXED_COLUMNS[-5:] == ("contact_energy", "indenter_energy", "broken_bond_energy", "contact_rebuilds", "mode")


def test_history_json_lists_every_column_in_header_order(run2d):
    header = synth.HISTORY_HEADER.split(",") + ["broken_bond_energy", "indenter_ball_fx", "reaction_left_fz", "novel"]
    path = run2d.out / "h.csv"
    path.write_text(",".join(header) + "\n" + ",".join("0" for _ in header) + "\n")
    content = write_history_json(str(path), str(run2d.out / "h.json"))
    assert json.loads((run2d.out / "h.json").read_text()) == content
    assert list(content["columns"]) == header
    assert content["columns"]["time"] == {"unit": "s", "description": "simulated time after the step"}
    assert content["columns"]["broken_bond_energy"]["unit"] == "J"
    assert content["columns"]["indenter_ball_fx"] == {
        "unit": "N", "description": "reaction force on indenter 'ball' along x (minus its force on the body)"}
    assert content["columns"]["reaction_left_fz"]["unit"] == "N"
    assert content["columns"]["novel"]["unit"] is None


def test_postprocess_writes_it_beside_history_csv(run2d):
    cli.run(str(run2d.out), only="figures", log=lambda *_: None)
    content = json.loads((run2d.out / "history.json").read_text())
    assert list(content["columns"]) == synth.HISTORY_HEADER.split(",")
    assert content["format_version"] == 2 and content["fixed_columns"] == list(FIXED_COLUMNS)
    assert all(column["unit"] for column in content["columns"].values())
