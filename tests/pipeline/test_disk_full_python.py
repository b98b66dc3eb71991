"""A full disk during a Python stage: one line naming the file and the free space, exit code 3
(as the solver's), no OSError traceback, no temporary file left (issue 17, item 6)."""
import os
import shutil
import subprocess

from tests.disk_full import run_on_small_disk
from common.paths import PYTHON as PY

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))


def test_preprocess_on_a_full_disk(tmp_path):
    case = tmp_path / "membrane"
    case.mkdir()
    shutil.copy(os.path.join(ROOT, "cases", "membrane", "membrane.yaml"), case)
    shutil.copy(os.path.join(ROOT, "cases", "membrane", "membrane.geo"), case)
    mesh = tmp_path / "mesh.msh"
    env = dict(os.environ, PYTHONPATH=ROOT)
    made = subprocess.run([PY, "-m", "pipeline.run", "mesh", str(case / "membrane.yaml"), str(case / "membrane.geo"),
                           str(mesh)], cwd=ROOT, env=env, capture_output=True, text=True, timeout=300)
    assert made.returncode == 0, made.stderr
    out = tmp_path / "out"
    out.mkdir()
    command = [PY, "-m", "pipeline.run", "preprocess", str(case / "membrane.yaml"), str(mesh), str(out)]
    # The work plan sees the disk is too small for the run's frames and stops before writing ...
    code, _, err, left = run_on_small_disk(out, command, size_kb=16, cwd=ROOT, env=env)
    assert code == 2 and "Traceback" not in err, err
    assert f"MB of disk, " in err and f"; it writes about 6 MB, more than half of the 0 MB free in {out}" in err
    assert left in ([], [".lock"])   # at most the folder's lock (common/output_lock.py)
    # ... and with FORCE=1 the node file itself does not fit.
    code, _, err, left = run_on_small_disk(out, command, size_kb=16, cwd=ROOT, env=dict(env, FORCE="1"))
    assert "Traceback" not in err, err
    assert code == 3, err
    assert f"error: disk full writing {out}/nodes.vtu: 0 MB free in {out}; free some space and run make again" in err
    assert left in ([], [".lock"])   # at most the folder's lock (common/output_lock.py)


def test_gmsh_on_a_full_disk_keeps_no_truncated_mesh(tmp_path):
    """gmsh itself exits 0 with a cut .msh; the mesh stage checks the file's last section."""
    case = os.path.join(ROOT, "cases", "membrane")
    out = tmp_path / "out"
    out.mkdir()
    # FORCE=1: the estimate before meshing (pipeline/body.py) would refuse a 70 kB mesh on a 24 kB
    # disk before gmsh starts; this test is about gmsh's own truncated file.
    env = dict(os.environ, PYTHONPATH=ROOT, FORCE="1")
    code, _, err, left = run_on_small_disk(
        out, [PY, "-m", "pipeline.run", "mesh", os.path.join(case, "membrane.yaml"),
              os.path.join(case, "membrane.geo"), str(out / "mesh.msh")], size_kb=24, cwd=ROOT, env=env)
    assert "Traceback" not in err, err
    assert code == 3, err
    assert f"error: disk full writing {out}/mesh.msh: 0 MB free in {out}; free some space and run make again" in err
    assert left in ([], [".lock"])   # at most the folder's lock (common/output_lock.py)


def test_a_cut_mesh_file_is_refused(tmp_path):
    from preprocess.errors import PreprocessError
    from preprocess.gmsh_mesh import check_complete_msh
    import pytest
    whole = tmp_path / "whole.msh"
    whole.write_text("$MeshFormat\n4.1 0 8\n$EndMeshFormat\n$Nodes\n1 2 3\n$EndNodes\n")
    check_complete_msh(str(whole), str(whole))
    cut = tmp_path / "cut.msh"
    cut.write_text("$MeshFormat\n4.1 0 8\n$EndMeshFormat\n$Nodes\n1 2 3\n0.5 0.2")
    with pytest.raises(PreprocessError, match=r"cut\.msh: gmsh wrote an incomplete mesh \(it ends with '0\.5 0\.2'"):
        check_complete_msh(str(cut), str(cut))
