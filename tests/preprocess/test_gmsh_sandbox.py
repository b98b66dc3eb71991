"""Issue 36, item 1: no .geo runs a command or writes outside its output, even one whose trick the
guard (preprocess/geo_guard.py) does not know: the guard reads strings as gmsh 4.8.4's lexer does,
and every gmsh that reads a case's .geo runs in a sandbox (preprocess/sandbox.py)."""
import os
import shutil
import subprocess

import pytest

from preprocess import PreprocessError
from preprocess.geo_guard import check_geo
from preprocess.gmsh_mesh import mesh_geo
from preprocess_testdata import ROOT
from common.paths import PYTHON

SQUARE = """Point(1) = {0, 0, 0, 0.5}; Point(2) = {1, 0, 0, 0.5}; Point(3) = {1, 1, 0, 0.5}; Point(4) = {0, 1, 0, 0.5};
Line(1) = {1, 2}; Line(2) = {2, 3}; Line(3) = {3, 4}; Line(4) = {4, 1};
Curve Loop(1) = {1, 2, 3, 4}; Plane Surface(1) = {1};
Physical Surface("square") = {1};
"""


def split_string(marker) -> str:
    """The report's .geo: gmsh cuts the string at 1023 characters and runs what follows."""
    return ('If (General.Terminal)\nnote = "' + "A" * 1023 + f"'; SystemCall 'touch {marker}'; n2 = '\";\n"
            "EndIf\n")


def test_the_report_string_split_at_1023_characters_is_refused_by_check(tmp_path):
    """`make check` said ok and `make case=X` ran the command: now check refuses it at its line."""
    case = tmp_path / "evil"
    case.mkdir()
    shutil.copy(os.path.join(ROOT, "cases", "membrane", "membrane.yaml"), case / "evil.yaml")
    marker = tmp_path / "marker"
    geo = case / "evil.geo"
    text = open(os.path.join(ROOT, "cases", "membrane", "membrane.geo")).read()
    geo.write_text(text + split_string(marker))
    line = text.count("\n") + 2
    result = subprocess.run([PYTHON, "-m", "pipeline.run", "check", str(case / "evil.yaml")], cwd=ROOT,
                            capture_output=True, text=True, stdin=subprocess.DEVNULL)
    assert result.returncode == 2, result.stdout + result.stderr
    length = 1023 + len(f"'; SystemCall 'touch {marker}'; n2 = '")
    assert (f"error: {geo}:{line}: a string of {length} characters; gmsh cuts strings at 1023 characters and reads "
            "the rest as commands: keep it shorter") in result.stderr
    assert not marker.exists()


@pytest.mark.parametrize("text, line, message", [
    # gmsh keeps 1023 characters: that many pass, one more is refused
    ('s = "' + "B" * 1022 + '";\n', None, None),
    ('s = "' + "B" * 1023 + '";\n', 1, "a string of 1023 characters; gmsh cuts strings at 1023"),
    # the untaken branch of an If: gmsh ends it at an EndIf (or Else) inside a string, and runs the rest
    ("If (0)\ns = \"EndIf SystemCall 'touch M'; t = '\";\n'; EndIf\n// '\n", 2,
     "the string \"EndIf SystemCall 'touch M'; t = '\" holds 'EndIf'"),
    ("If (0)\ns = \"Else SystemCall 'touch M'; t = '\";\n'; EndIf\n// '\n", 2, "holds 'Else'"),
    # … and it honours comments there, but not strings: a // in a string hides the next line
    ('If (0)\ns = "//"; t = "\nEndIf\nSystemCall "touch M";\nu = "\nEndIf\n', 2, "the string \"//\" holds '//'"),
    ('s = "/* a comment for gmsh";\n', 1, "holds '/*'"),
    # a digit is a word boundary for that search: it would stop in the middle of the name
    ("If (0)\nx1EndIf = 1;\nEndIf\n", 2, "the name 'x1EndIf' holds If/Else/EndIf after a digit"),
    # skipping, gmsh drops the character after an E, I, F or R that is not its keyword (tried: each ran)
    ("If (0)\n E/* EndIf SystemCall 'touch M'; /* */\nEndIf\n", 2,
     "'E/': gmsh, skipping an If branch, a For loop or a Function body, would not see the '/' after the E, I, F "
     "or R before it and would read what follows differently: put a space between them"),
    ("Function f\n R\"Return SystemCall 'touch M'; a = '\";\n'; Return\nx = 1; // '\n", 2, "'R\"': gmsh, skipping"),
    ("For i In {1:0}\n E\"EndFor SystemCall 'touch M'; a = '\";\n'; EndFor\nx = 1; // '\n", 2, "'E\"': gmsh, skipping"),
    # … and after a nested If it drops four characters
    ("If (0)\nIf(1/* EndIf EndIf SystemCall 'touch M'; */\nEndIf\n", 2, "'If(1/': gmsh, skipping"),
    # after a dropped character gmsh's "previous character" is stale: an EndIf after a letter matches
    ("If (0)\ns = \" EaEndIf SystemCall 'touch M'; t = '\";\n'; EndIf\n// '\n", 2, "holds 'EndIf'"),
    ("If (0)\n EaEndIf2SystemCall = 1;\nEndIf\n", 2, "the name 'EaEndIf2SystemCall' holds 'SystemCall' after a digit"),
    # a NUL byte ends a string or a comment for gmsh
    ('s = "abc\0"; t = "";\n', 1, "a NUL byte, which ends a string or a comment early for gmsh"),
], ids=["1022-chars", "1023-chars", "EndIf-in-string", "Else-in-string", "line-comment-in-string",
        "block-comment-in-string", "digit-EndIf-name", "If-drops-comment", "Function-drops-quote", "For-drops-quote",
        "nested-If-drops-four", "stale-previous-in-string", "command-after-digits-in-name", "NUL"])
def test_what_gmsh_lexes_differently_is_refused(tmp_path, text, line, message):
    geo = tmp_path / "case.geo"
    geo.write_text(SQUARE + text)
    if message is None:
        check_geo(str(geo))
        return
    with pytest.raises(PreprocessError) as err:
        check_geo(str(geo))
    assert str(err.value).startswith(f"{geo}:{SQUARE.count(chr(10)) + line}: "), str(err.value)
    assert message in str(err.value), str(err.value)


@pytest.fixture
def no_guard(monkeypatch):
    """A .geo the guard does not know about: what the sandbox alone must hold."""
    monkeypatch.setattr("preprocess.gmsh_mesh.check_geo", lambda *args, **kwargs: [])


def test_the_sandboxed_gmsh_runs_no_command_and_writes_nowhere_else(tmp_path, no_guard):
    case = tmp_path / "case"
    case.mkdir()
    outside = tmp_path / "outside"
    outside.mkdir()
    geo = case / "case.geo"
    geo.write_text(SQUARE + split_string(outside / "split") + f"""
SystemCall "touch {outside / 'called'}";
SystemCall "/usr/bin/touch {outside / 'direct'}";
Save "{outside / 'saved.msh'}";
Save "{case / 'saved.msh'}";
Print "{outside / 'printed.png'}";
Printf("x") > "{outside / 'printf.txt'}";
CreateDir "{outside / 'made'}";
""")
    out = tmp_path / "out" / "mesh.msh"
    with pytest.raises(PreprocessError) as err:
        mesh_geo(str(geo), str(out), 2, {})
    assert "Could not find /bin/sh: aborting system call" in str(err.value)
    assert os.listdir(outside) == [] and sorted(os.listdir(case)) == ["case.geo"]
    assert not out.exists() and os.listdir(out.parent) == []


def test_the_sandboxed_gmsh_cannot_read_outside_the_case_folder(tmp_path, no_guard):
    secret = tmp_path / "secret.geo"
    secret.write_text('Printf("SECRET-FIRST-LINE");\n')
    case = tmp_path / "case"
    case.mkdir()
    os.symlink(secret, case / "part.geo")
    geo = case / "case.geo"
    geo.write_text(SQUARE + 'Include "part.geo";\n' + f'Include "{secret}";\n')
    with pytest.raises(PreprocessError) as err:
        mesh_geo(str(geo), str(tmp_path / "mesh.msh"), 2, {})
    assert "SECRET-FIRST-LINE" not in str(err.value)
    assert "Unable to open file" in str(err.value)


def test_the_gmsh_api_probe_runs_no_command(tmp_path):
    """pipeline/body.py's probe opens the .geo with the gmsh API: a SystemCall there would run."""
    from pipeline.body import probe_geometry

    marker = tmp_path / "marker"
    case = tmp_path / "case"
    case.mkdir()
    geo = case / "case.geo"
    geo.write_text(SQUARE + f'SystemCall "touch {marker}";\nSave "{tmp_path / "saved.msh"}";\n')
    from pipeline.case import CaseError

    with pytest.raises(CaseError) as err:
        probe_geometry({"geometry": {"parameters": {}}, "dimension": 2, "_path": "x.yaml", "_lines": {}}, str(geo))
    assert "Could not find /bin/sh: aborting system call" in str(err.value)
    assert sorted(os.listdir(tmp_path)) == ["case"]


def test_a_sandbox_that_cannot_start_is_a_clear_error_and_can_be_switched_off(tmp_path, monkeypatch):
    from preprocess import sandbox

    geo = tmp_path / "case.geo"
    geo.write_text(SQUARE)
    out = tmp_path / "mesh.msh"
    monkeypatch.setattr(sandbox, "BWRAP", "bwrap-not-installed")
    sandbox._bwrap_works.cache_clear()
    try:
        with pytest.raises(PreprocessError) as err:
            mesh_geo(str(geo), str(out), 2, {})
        assert str(err.value) == (
            f"{geo}: gmsh runs in a sandbox, but bubblewrap (bwrap) is not installed. Install it (apt-get install "
            "bubblewrap, pipeline/install-deps.sh does) and, when not running as root, allow unprivileged user "
            "namespaces (sysctl kernel.unprivileged_userns_clone=1 on Debian); or, for a .geo you trust, run gmsh "
            "without the sandbox with PD_GMSH_SANDBOX=off")
        assert not out.exists()
        monkeypatch.setenv("PD_GMSH_SANDBOX", "off")
        mesh_geo(str(geo), str(out), 2, {})
        assert out.read_text().startswith("$MeshFormat")
    finally:
        sandbox._bwrap_works.cache_clear()
