"""A .geo that would run a command, write a file or read outside its case folder is refused before
gmsh starts (preprocess/geo_guard.py), with the file and the line; gmsh runs under a time limit."""
import glob
import os
import shutil
import subprocess

import pytest

from preprocess import PreprocessError
from preprocess.geo_guard import check_geo
from preprocess.gmsh_mesh import mesh_geo
from preprocess_testdata import ROOT
from common.paths import PYTHON

SQUARE = """DefineConstant[ a = {1.0, Name "a"} ];
Point(1) = {0, 0, 0, 0.5}; Point(2) = {a, 0, 0, 0.5}; Point(3) = {a, a, 0, 0.5}; Point(4) = {0, a, 0, 0.5};
Line(1) = {1, 2}; Line(2) = {2, 3}; Line(3) = {3, 4}; Line(4) = {4, 1};
Curve Loop(1) = {1, 2, 3, 4}; Plane Surface(1) = {1};
Physical Surface("square") = {1};
"""
LINE = SQUARE.count("\n") + 1   # the line an appended statement is on


def write(folder, name, text):
    path = folder / name
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(text)
    return path


@pytest.mark.parametrize("statement, fragment", [
    ('SystemCall "touch {marker}";', "'SystemCall' runs a shell command"),
    ('System "touch {marker}";', "'System' runs a shell command"),
    ('NonBlockingSystemCall "touch {marker}";', "'NonBlockingSystemCall' runs a shell command"),
    ('OnelabRun("x", "touch {marker}");', "'OnelabRun' runs an external program"),
    ('OnelabRun "touch {marker}";', "'OnelabRun' runs an external program"),
    ('CreateDir "{marker}";', "'CreateDir' creates a folder"),
    ('Printf("hello") > "{marker}";', 'Printf(…) > "file" writes a file'),
    ('Printf("%g", a) >> "{marker}";', 'Printf(…) > "file" writes a file'),
    ('Save "{marker}.msh";', "'Save' writes a file"),
    ('Print "{marker}.png";', "'Print' writes an image file"),
    ('Exit;', "'Exit' ends gmsh"),
    ('Sleep 100;', "'Sleep' pauses gmsh"),
    ('Plugin(Integrate).Run;', "'Plugin' runs a gmsh plugin"),
    # the command spelt in pieces: StringToName makes a command name from a string expression
    ('S2N[StrCat("Sys", "temCall")] "touch {marker}";', "'S2N' turns a string into a command"),
    ('StringToName[StrCat("Sys", "temCall")] "touch {marker}";', "'StringToName' turns a string"),
    ('Solver.Executable0 = "/bin/sh";', "the option Solver.Executable0 names a program"),
    ('General.OptionsFileName = "{marker}";', "the option General.OptionsFileName names a program to run or a file"),
    ('Include "/etc/passwd";', 'Include "/etc/passwd": a case reads only files inside its own folder'),
    ('Include "../other/x.geo";', 'Include "../other/x.geo": a case reads only files inside its own folder'),
    ('Merge "~/x.geo";', 'Merge "~/x.geo": a case reads only files inside its own folder'),
    ('Include StrCat("/etc/", "passwd");', "Include needs a plain \"file name\" (a string literal"),
    ('Include "missing.geo";', 'Include "missing.geo": no such file in the case folder'),
])
def test_forbidden_constructs_are_refused_with_file_and_line(tmp_path, statement, fragment):
    marker = tmp_path / "marker"
    geo = write(tmp_path / "case", "case.geo", SQUARE + statement.replace("{marker}", str(marker)) + "\n")
    out = tmp_path / "out" / "case.msh"
    with pytest.raises(PreprocessError) as err:
        mesh_geo(str(geo), str(out), 2, {})
    message = str(err.value)
    assert message.startswith(f"{geo}:{LINE}: "), message
    assert fragment in message, message
    assert not marker.exists() and not out.exists()


def test_mentions_in_comments_and_strings_are_fine(tmp_path):
    geo = write(tmp_path, "ok.geo", "// SystemCall \"rm -rf /\" would be refused\n/* Exit;\n Save \"x\"; */\n"
                + SQUARE + 'Printf("SystemCall > %g", a);\nPrintf("a > b");\n')
    out = tmp_path / "ok.msh"
    mesh_geo(str(geo), str(out), 2, {})
    assert out.read_text().startswith("$MeshFormat")


def test_unclosed_comment_and_string_are_refused(tmp_path):
    geo = write(tmp_path, "a.geo", SQUARE + "/* SystemCall \"x\";\n")
    with pytest.raises(PreprocessError, match=rf"a.geo:{LINE}: a /\* comment is never closed"):
        check_geo(str(geo))
    geo = write(tmp_path, "b.geo", SQUARE + 'Printf("x);\nx = 1;\n')
    with pytest.raises(PreprocessError, match=rf"b.geo:{LINE}: a string is never closed"):
        check_geo(str(geo))


def test_included_files_are_scanned_recursively(tmp_path):
    case = tmp_path / "case"
    write(case, "parts/deep.geo", "x = 1;\nSystemCall \"touch marker\";\n")
    write(case, "parts/mid.geo", 'Include "deep.geo";\n')     # relative to the including file
    geo = write(case, "case.geo", SQUARE + 'Include "parts/mid.geo";\n')
    with pytest.raises(PreprocessError) as err:
        check_geo(str(geo))
    assert str(err.value).startswith(f"{case / 'parts' / 'deep.geo'}:2: 'SystemCall' runs a shell command")


def test_an_include_cycle_ends_and_a_clean_include_passes(tmp_path):
    write(tmp_path, "b.geo", 'Include "a.geo";\ny = 2;\n')
    geo = write(tmp_path, "a.geo", 'Include "b.geo";\nx = 1;\n')
    assert check_geo(str(geo)) == [str(geo), str(tmp_path / "b.geo")]


def test_the_opt_file_gmsh_merges_by_itself_is_scanned(tmp_path):
    geo = write(tmp_path, "case.geo", SQUARE)
    write(tmp_path, "case.geo.opt", "Mesh.Algorithm = 6;\nSystemCall \"touch marker\";\n")
    with pytest.raises(PreprocessError, match=r"case.geo.opt:2: 'SystemCall' runs a shell command"):
        check_geo(str(geo))


def test_a_symbolic_link_out_of_the_case_folder_is_refused(tmp_path):
    outside = write(tmp_path, "elsewhere/secret.geo", "x = 1;\n")
    case = tmp_path / "case"
    case.mkdir()
    os.symlink(outside, case / "link.geo")
    geo = write(case, "case.geo", SQUARE + 'Include "link.geo";\n')
    with pytest.raises(PreprocessError, match="leads outside the case folder"):
        check_geo(str(geo))


@pytest.mark.parametrize("geo", sorted(glob.glob(os.path.join(ROOT, "cases", "*", "*.geo"))
                                       + glob.glob(os.path.join(ROOT, "validation", "models", "*.geo"))))
def test_every_shipped_geo_is_accepted(geo):
    assert check_geo(geo) == [os.path.realpath(geo)]


def test_gmsh_is_stopped_at_the_time_limit(tmp_path):
    # 10¹⁰ empty iterations: gmsh would run for hours
    geo = write(tmp_path, "slow.geo", "For i In {1:100000}\n For j In {1:100000}\n EndFor\nEndFor\n" + SQUARE)
    out = tmp_path / "slow.msh"
    with pytest.raises(PreprocessError) as err:
        mesh_geo(str(geo), str(out), 2, {}, timeout=1.0)
    assert "gmsh did not finish within 1 s and was stopped" in str(err.value)
    assert "PD_GMSH_TIMEOUT" in str(err.value)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["slow.geo"]


def test_a_bad_timeout_setting_is_named(tmp_path, monkeypatch):
    geo = write(tmp_path, "a.geo", SQUARE)
    monkeypatch.setenv("PD_GMSH_TIMEOUT", "soon")
    with pytest.raises(PreprocessError, match="PD_GMSH_TIMEOUT='soon': expected a number of seconds > 0"):
        mesh_geo(str(geo), str(tmp_path / "a.msh"), 2, {})


def test_the_mesh_stage_on_a_malicious_case_runs_nothing(tmp_path):
    """The stage `make case=X` runs first, on a shipped case with one line added."""
    case = tmp_path / "evil"
    case.mkdir()
    shutil.copy(os.path.join(ROOT, "cases", "membrane", "membrane.yaml"), case / "evil.yaml")
    marker = tmp_path / "marker"
    geo = case / "evil.geo"
    geo.write_text(open(os.path.join(ROOT, "cases", "membrane", "membrane.geo")).read()
                   + f'SystemCall "touch {marker}";\n')
    line = geo.read_text().count("\n")
    out = tmp_path / "out" / "mesh.msh"
    result = subprocess.run([PYTHON, "-m", "pipeline.run", "mesh", str(case / "evil.yaml"), str(geo),
                             str(out)], cwd=ROOT, capture_output=True, text=True, stdin=subprocess.DEVNULL)
    assert result.returncode == 2
    assert f"error: {geo}:{line}: 'SystemCall' runs a shell command" in result.stderr, result.stderr
    assert "Traceback" not in result.stderr
    assert not marker.exists() and not out.exists()
