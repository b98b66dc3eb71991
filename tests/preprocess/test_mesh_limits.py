"""Issue 36, item 12 (the mesh parts): gmsh runs under a memory cap; a given mesh file has a size cap,
checked before it is read; an element naming a node the mesh does not define is refused."""
import os
import time

import pytest

from preprocess import PreprocessError, read_mesh
from preprocess.gmsh_mesh import mesh_geo

FINE_SQUARE = """Point(1) = {0, 0, 0, 0.0005}; Point(2) = {1, 0, 0, 0.0005}; Point(3) = {1, 1, 0, 0.0005};
Point(4) = {0, 1, 0, 0.0005}; Line(1) = {1, 2}; Line(2) = {2, 3}; Line(3) = {3, 4}; Line(4) = {4, 1};
Curve Loop(1) = {1, 2, 3, 4}; Plane Surface(1) = {1};
"""


def test_gmsh_stops_at_its_memory_cap_with_a_clear_error(tmp_path, monkeypatch):
    """4 million nodes need about 5 GB; with the cap at 200 MB gmsh's allocation fails within seconds."""
    from preprocess import sandbox

    monkeypatch.setattr(sandbox, "memory_cap", lambda: 200 * 1024 * 1024)
    geo = tmp_path / "fine.geo"
    geo.write_text(FINE_SQUARE)
    out = tmp_path / "out" / "fine.msh"
    with pytest.raises(PreprocessError) as err:
        mesh_geo(str(geo), str(out), 2, {}, timeout=60)
    assert str(err.value).startswith(f"{geo}: gmsh ran out of the memory it may use (210 MB: half of the memory "
                                     "available, all of it with FORCE=1) or was killed (exit code 134)")
    assert not out.exists() and os.listdir(out.parent) == []


def test_the_memory_cap_is_half_of_the_available_memory(monkeypatch):
    from preprocess import sandbox

    monkeypatch.setattr("common.memory.available_memory", lambda: 16e9)
    monkeypatch.delenv("FORCE", raising=False)
    assert sandbox.memory_cap() == 8_000_000_000
    monkeypatch.setenv("FORCE", "1")
    assert sandbox.memory_cap() == 16_000_000_000
    monkeypatch.setattr("common.memory.available_memory", lambda: 1e9)
    assert sandbox.memory_cap() == 2 * 1024 ** 3   # Python with numpy maps more than it uses


def big_sparse_file(path, size):
    """A file of `size` bytes that takes no disk: a valid start, then a hole."""
    with open(path, "wb") as stream:
        stream.write(b"$MeshFormat\n4.1 0 8\n$EndMeshFormat\n$Nodes\n" if path.suffix == ".msh" else b"    -1\n  2411\n")
        stream.truncate(size)


@pytest.mark.parametrize("name", ["big.msh", "big.unv"])
def test_a_mesh_file_above_the_size_cap_is_refused_before_it_is_read(tmp_path, monkeypatch, name):
    """A 3 GB .msh was read for 61 s before failing with an empty reason."""
    monkeypatch.delenv("FORCE", raising=False)
    monkeypatch.setattr("common.memory.available_memory", lambda: 64e9)
    path = tmp_path / name
    big_sparse_file(path, 3 * 10 ** 9)
    start = time.monotonic()
    with pytest.raises(PreprocessError) as err:
        read_mesh(str(path))
    assert time.monotonic() - start < 1.0
    assert str(err.value) == (f"{path}: 3000 MB, more than the 1074 MB a mesh file may have (about 10 million "
                              "nodes); use a coarser mesh, or read it anyway with FORCE=1 (make FORCE=1 case=...)")


def test_a_mesh_file_that_would_not_fit_in_memory_is_refused_even_with_force(tmp_path, monkeypatch):
    monkeypatch.setenv("FORCE", "1")
    monkeypatch.setattr("common.memory.available_memory", lambda: 1e9)
    path = tmp_path / "big.msh"
    big_sparse_file(path, 100 * 10 ** 6)
    with pytest.raises(PreprocessError) as err:
        read_mesh(str(path))
    assert str(err.value) == (f"{path}: 100 MB; reading it takes up to 8x that, more than half of the 1000 MB of "
                              "memory available: use a coarser mesh or a machine with more memory")


MSH2 = """$MeshFormat
2.2 0 8
$EndMeshFormat
$PhysicalNames
1
2 1 "plate"
$EndPhysicalNames
$Nodes
3
1 0 0 0
2 1 0 0
{third} 0 1 0
$EndNodes
$Elements
1
7 2 2 1 1 1 2 {node}
$EndElements
"""

MSH4 = """$MeshFormat
4.1 0 8
$EndMeshFormat
$PhysicalNames
1
2 1 "plate"
$EndPhysicalNames
$Entities
0 0 1 0
1 0 0 0 1 1 0 1 1 0
$EndEntities
$Nodes
1 3 1 {third}
2 1 0 3
1
2
{third}
0 0 0
1 0 0
0 1 0
$EndNodes
$Elements
1 1 7 7
2 1 2 1
7 1 2 {node}
$EndElements
"""


@pytest.mark.parametrize("template, line", [(MSH2, 16), (MSH4, 25)], ids=["msh2", "msh4"])
@pytest.mark.parametrize("third, node", [(4, 3), (3, 0), (3, 99)], ids=["gap", "zero", "beyond"])
def test_an_element_naming_a_missing_node_is_refused(tmp_path, template, line, third, node):
    """meshio turned a missing node tag into -1, and tag 0 into the last node, without a word."""
    path = tmp_path / "bad.msh"
    path.write_text(template.format(third=third, node=node))
    with pytest.raises(PreprocessError) as err:
        read_mesh(str(path))
    assert str(err.value) == (f"{path}:{line}: element 7 names node {node}, which $Nodes does not define; fix the "
                              "mesh (export it again)")


def test_a_unv_element_naming_a_missing_node_is_refused(tmp_path):
    path = tmp_path / "bad.unv"
    path.write_text("    -1\n  2411\n         1         1         1        11\n"
                    "   0.0000000000000000D+00   0.0000000000000000D+00   0.0000000000000000D+00\n"
                    "         2         1         1        11\n"
                    "   1.0000000000000000D+00   0.0000000000000000D+00   0.0000000000000000D+00\n"
                    "    -1\n    -1\n  2412\n         5        41         2         1         7         3\n"
                    "         1         2         9\n    -1\n")
    with pytest.raises(PreprocessError) as err:
        read_mesh(str(path))
    assert str(err.value) == f"{path}:10: element 5 refers to node 9, which dataset 2411 does not define"
