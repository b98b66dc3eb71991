"""Shared fixtures: gmsh meshes of the test geometries, made once per test session."""
import os
import subprocess

import pytest

from preprocess.gmsh_mesh import mesh_geo
from preprocess_testdata import BOX, DATA, PLATE


@pytest.fixture(scope="session")
def meshes(tmp_path_factory):
    """Paths of the plate-with-hole mesh (msh4, and converted by gmsh to msh2 and unv) and of the
    box-with-hole mesh (msh4)."""
    out = tmp_path_factory.mktemp("meshes")
    paths = {"plate": str(out / "plate.msh"), "box": str(out / "box.msh")}
    mesh_geo(os.path.join(DATA, "plate_hole.geo"), paths["plate"], 2, PLATE)
    # the same mesh in gmsh's other formats, converted from the msh4 file so the mesh is identical
    for fmt, name in (("msh2", "plate2.msh"), ("unv", "plate.unv")):
        subprocess.run(["gmsh", paths["plate"], "-0", "-format", fmt, "-o", str(out / name)],
                       check=True, capture_output=True, stdin=subprocess.DEVNULL)
        paths[name] = str(out / name)
    mesh_geo(os.path.join(DATA, "box_hole.geo"), paths["box"], 3, BOX)
    return paths
