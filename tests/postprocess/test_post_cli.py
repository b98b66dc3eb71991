"""The command line: outputs on success; a clear error, naming the file and what to do, otherwise."""
import json
import os
import subprocess

import pytest

from postprocess import cli
from common.paths import PYTHON as PY

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))


def python_m(*args, cwd=ROOT):
    """Run `python3 -m postprocess` as the Makefile does, with no display at all."""
    env = {k: v for k, v in os.environ.items() if k not in ("DISPLAY", "WAYLAND_DISPLAY", "MPLBACKEND")}
    env["PYTHONPATH"] = ROOT
    return subprocess.run([PY, "-m", "postprocess", *map(str, args)], cwd=cwd, env=env,
                          capture_output=True, text=True, timeout=120)


def test_python_m_writes_every_output_without_a_display(run2d):
    result = python_m(run2d.out)
    assert result.returncode == 0, result.stderr
    assert "plate: 6 frames" in result.stdout
    assert (run2d.out / "gmsh" / "results.msh").stat().st_size > 0
    assert len(list((run2d.out / "figures").glob("*.png"))) == 3 + 2 * 4


def test_python_m_missing_history_exits_non_zero_with_the_make_command(run2d):
    os.unlink(run2d.out / "history.csv")
    result = python_m(run2d.out)
    assert result.returncode == 1
    assert f"missing input: {run2d.out / 'history.csv'}" in result.stderr
    assert "run the solver first: make case=plate" in result.stderr
    assert not (run2d.out / "figures").exists() and not (run2d.out / "gmsh").exists()


def main(args, capsys):
    code = cli.main([str(a) for a in args])
    return code, capsys.readouterr().err


def test_missing_inputs(run2d, tmp_path, capsys):
    code, err = main([tmp_path / "out" / "nowhere"], capsys)
    assert code == 1 and "nowhere: no such directory; run the case first: make case=nowhere" in err
    os.unlink(run2d.out / "frames.pvd")
    code, err = main([run2d.out, "--only", "gmsh"], capsys)
    assert code == 1 and f"{run2d.out / 'frames.pvd'}" in err and "make case=plate" in err
    os.unlink(run2d.out / "case.json")
    code, err = main([run2d.out], capsys)
    assert code == 1
    assert str(run2d.out / "case.json") in err and "preprocess and solve first: make case=plate" in err


def test_history_is_not_needed_for_gmsh_only(run2d, capsys):
    os.unlink(run2d.out / "history.csv")
    code, err = main([run2d.out, "--only", "gmsh"], capsys)
    assert code == 0, err
    assert (run2d.out / "gmsh" / "results.msh").exists() and not (run2d.out / "figures").exists()


def test_case_json_from_elsewhere(run2d, tmp_path, capsys):
    moved = tmp_path / "elsewhere.json"
    os.replace(run2d.out / "case.json", moved)
    code, err = main([run2d.out, "--case-json", moved, "--only", "gmsh"], capsys)
    assert code == 0, err


def test_malformed_inputs_name_file_and_line(run2d, capsys):
    history = run2d.out / "history.csv"
    lines = history.read_text().splitlines()
    lines[2] = lines[2].replace(",", ";", 1)
    history.write_text("\n".join(lines) + "\n")
    code, err = main([run2d.out], capsys)
    assert code == 1 and f"{history}:3: 10 fields, the header has 11" in err

    case = json.loads((run2d.out / "case.json").read_text())
    case["figures"]["displacement_component"] = "z"
    (run2d.out / "case.json").write_text(json.dumps(case))
    code, err = main([run2d.out, "--only", "gmsh"], capsys)
    assert code == 1 and "figures.displacement_component: expected 0, 1 or 2 (x, y, z), got 'z'" in err

    (run2d.out / "case.json").write_text('{"case": "plate",\n "dimension": 2,,}')
    code, err = main([run2d.out, "--only", "gmsh"], capsys)
    assert code == 1 and f"{run2d.out / 'case.json'}:2:" in err and "not valid JSON" in err


def test_usage_error_exits_with_2(capsys):
    with pytest.raises(SystemExit) as stop:
        cli.main(["out", "--only", "everything"])
    assert stop.value.code == 2
