"""Issue 36, item 2: every input of a case is a regular file inside its case folder, refused before
any stage reads it (pipeline/inputs.py). `ln -s /etc/shadow cases/leak/leak.geo; make case=leak`
had gmsh print the file's first line in its syntax error."""
import os
import subprocess
import sys

import pytest

from minimal_case import MINIMAL

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
SECRET = "SECRET-FIRST-LINE of a file outside the case"
SQUARE = """Point(1) = {0, 0, 0, 0.01}; Point(2) = {0.02, 0, 0, 0.01}; Point(3) = {0.02, 0.02, 0, 0.01};
Point(4) = {0, 0.02, 0, 0.01}; Line(1) = {1, 2}; Line(2) = {2, 3}; Line(3) = {3, 4}; Line(4) = {4, 1};
Curve Loop(1) = {1, 2, 3, 4}; Plane Surface(1) = {1}; Physical Surface("plate") = {1};
"""


def run(*args):
    return subprocess.run([sys.executable, "-m", "pipeline.run", *map(str, args)], cwd=ROOT, capture_output=True,
                          text=True, stdin=subprocess.DEVNULL, timeout=120)


def leak_case(tmp_path, linked: str):
    """cases-like folder leak/ with leak.yaml and leak.geo, `linked` (one of them, or leak.msh,
    leak.unv, leak.geo.opt) a symbolic link to a file outside the folder."""
    outside = tmp_path / "outside.txt"
    outside.write_text(SECRET + "\n")
    case = tmp_path / "leak"
    case.mkdir()
    (case / "leak.yaml").write_text(MINIMAL)
    (case / "leak.geo").write_text(SQUARE)
    (case / linked).unlink(missing_ok=True)
    os.symlink(outside, case / linked)
    return case


STAGES = {
    "check": lambda case, out: ["check", case / "leak.yaml"],
    "mesh-parameters": lambda case, out: ["mesh-parameters", case / "leak.yaml", out / "mesh-parameters.json"],
    "mesh": lambda case, out: ["mesh", case / "leak.yaml", case / "leak.geo", out / "mesh.msh"],
    "preprocess": lambda case, out: ["preprocess", case / "leak.yaml", case / "leak.msh", out],
}


# Every stage with the linked .geo; every kind of input with `check` (all go through one function).
@pytest.mark.parametrize("stage, linked", [(stage, "leak.geo") for stage in sorted(STAGES)]
                         + [("check", name) for name in ("leak.yaml", "leak.msh", "leak.unv", "leak.geo.opt")])
def test_a_link_out_of_the_case_folder_is_refused_before_any_stage_reads(tmp_path, stage, linked):
    case = leak_case(tmp_path, linked)
    out = tmp_path / "out"
    result = run(*STAGES[stage](case, out))
    assert result.returncode == 2, result.stdout + result.stderr
    assert result.stderr == (f"error: {case / linked}: leads outside the case folder {case} (a symbolic link to "
                             f"{tmp_path / 'outside.txt'}); a case reads only its own files: copy the file into "
                             "the case folder\n")
    assert not out.exists()


def test_a_folder_or_a_fifo_named_as_an_input_is_refused(tmp_path):
    case = tmp_path / "leak"
    case.mkdir()
    (case / "leak.yaml").write_text(MINIMAL)
    os.mkfifo(case / "leak.geo")   # gmsh would wait on it for ever
    result = run("check", case / "leak.yaml")
    assert result.returncode == 2
    assert f"error: {case / 'leak.geo'}: a FIFO (named pipe), not a regular file; a case input must be a regular " \
        f"file in {case}" \
        in result.stderr


def test_a_link_that_stays_in_the_case_folder_is_fine(tmp_path):
    case = tmp_path / "leak"
    case.mkdir()
    (case / "leak.yaml").write_text(MINIMAL)
    (case / "square.geo").write_text(SQUARE)
    os.symlink("square.geo", case / "leak.geo")
    result = run("check", case / "leak.yaml")
    assert result.returncode == 0, result.stderr
    assert "the body of leak.geo is sound" in result.stdout
