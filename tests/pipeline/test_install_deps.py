"""pipeline/install-deps.sh lists only packages that coexist with what users install beside the
project: ParaView (`apt-get install paraview python3-paraview`) must not remove any of them
(issue 16: Debian's python3-paraview conflicts with python3-vtk9, which the list used to require
although no Python file imported it)."""
import glob
import os
import re
import shutil
import subprocess

import pytest

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
SCRIPT = os.path.join(ROOT, "pipeline", "install-deps.sh")


def required_packages() -> set[str]:
    """The words of PACKAGES="…" in install-deps.sh (line continuations joined, `$*` left out)."""
    with open(SCRIPT, encoding="utf-8") as stream:
        text = stream.read().replace("\\\n", " ")
    match = re.search(r'^PACKAGES="([^"]*)"', text, re.MULTILINE)
    assert match, f"{SCRIPT}: no PACKAGES=\"…\" line"
    return {word for word in match.group(1).split() if not word.startswith("$")}


def removed_by(packages: list[str]) -> set[str]:
    """Packages apt-get would remove to install `packages`: its simulation's "Remv name [version]"
    lines. Skips when apt or its package lists are not available (nothing can be checked)."""
    if shutil.which("apt-get") is None:
        pytest.skip("no apt-get on this machine: cannot simulate the ParaView install")
    if not glob.glob("/var/lib/apt/lists/*_Packages*"):
        pytest.skip("apt's package lists are empty (run `apt-get update`): cannot simulate the install")
    result = subprocess.run(["apt-get", "install", "-s", *packages],
                            capture_output=True, text=True, env={**os.environ, "LC_ALL": "C"})
    if result.returncode != 0:
        if "Unable to locate package" in result.stderr:
            pytest.skip(f"apt's lists do not know {' '.join(packages)}: {result.stderr.strip()}")
        pytest.fail(f"apt-get install -s {' '.join(packages)} failed: {result.stderr.strip()}")
    return set(re.findall(r"^Remv (\S+)", result.stdout, re.MULTILINE))


def test_required_packages_parse():
    packages = required_packages()
    assert {"gmsh", "python3-gmsh", "python3-matplotlib", "python3-meshio"} <= packages
    assert "python3-vtk9" not in packages  # nothing imports it (grep 'import vtk' finds no file)


def test_no_python_file_imports_vtk():
    """python3-vtk9 was dropped because nothing uses it: keep it so, or restore the package."""
    pattern = re.compile(r"^\s*(import vtk|from vtk|import vtkmodules|from vtkmodules)", re.MULTILINE)
    users = []
    for path in glob.glob(os.path.join(ROOT, "**", "*.py"), recursive=True):
        if "/out/" in path or "/build/" in path:
            continue
        with open(path, encoding="utf-8", errors="replace") as stream:
            if pattern.search(stream.read()):
                users.append(os.path.relpath(path, ROOT))
    assert users == []


def test_paraview_removes_nothing_the_project_needs():
    removed = removed_by(["paraview", "python3-paraview"])
    assert removed & required_packages() == set(), (
        f"installing ParaView would remove {sorted(removed & required_packages())}, which "
        f"pipeline/install-deps.sh requires (all removals: {sorted(removed)})")
