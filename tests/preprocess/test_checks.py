"""Checks on the mesh with clear errors, on small meshes built in memory; and the command line."""
import subprocess
import warnings

import numpy as np
import pytest

from preprocess_testdata import ROOT
from preprocess import Group, Mesh, PreprocessError, PreprocessWarning
from preprocess.discretize import discretize
from preprocess.node_file import read_node_file
from common.paths import PYTHON

# the unit square as two triangles, its left edge as a line
SQUARE = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]], float)
TRIS = np.array([[0, 1, 2], [0, 2, 3]])


def square(points=SQUARE, tris=TRIS, groups=None):
    cells = {"triangle": tris, "line": np.array([[3, 0]])}
    if groups is None:
        groups = {"sq": Group("sq", 2, {"triangle": np.arange(len(tris))}),
                  "left": Group("left", 1, {"line": np.array([0])})}
    return Mesh(path="sq.msh", points=points, cells=cells, groups=groups)


def run(mesh, method="mesh-nodes", blocks=("sq",), layers=None, dx=0.1):
    return discretize(mesh, dimension=2, thickness=0.5, method=method, dx=dx, block_names=list(blocks),
                      set_layers=layers or {})


def test_square_both_methods():
    c = run(square())
    assert c.volume.tolist() == [1 / 6 * 0.5 * 2, 1 / 6 * 0.5, 1 / 6 * 0.5 * 2, 1 / 6 * 0.5]
    assert c.sets["left"].tolist() == [True, False, False, True] and c.grid_spacing == 1.0
    c = run(square(), method="lattice")
    assert len(c.volume) == 100 and c.volume.sum() == pytest.approx(0.5)
    assert c.sets["left"].sum() == 10
    c = run(square(), layers={"left": 0.3})            # mesh-nodes with a layer: by distance
    assert c.sets["left"].tolist() == [True, False, False, True]
    c = run(square(), method="lattice", layers={"left": 0.3})
    assert c.sets["left"].sum() == 30


def test_no_groups_one_block_takes_everything():
    c = run(square(groups={}), blocks=["anything"], method="lattice")
    assert np.all(c.block == 1) and c.sets == {}


def test_empty_and_nan_and_off_plane():
    with pytest.raises(PreprocessError, match=r"^sq.msh: the mesh is empty"):
        run(Mesh("sq.msh", np.zeros((0, 3)), {}, {}))
    bad = SQUARE.copy()
    bad[2, 1] = np.nan
    with pytest.raises(PreprocessError, match=r"^sq.msh: 1 node\(s\) have NaN"):
        run(square(points=bad))
    bad = SQUARE.copy()
    bad[2, 2] = 1e-3
    with pytest.raises(PreprocessError, match=r"must lie in the plane z = 0; 1 node\(s\) do not, e.g. \(1, 1, 0.001\)"):
        run(square(points=bad))


def test_duplicate_nodes():
    pts = np.vstack([SQUARE, SQUARE[2]])
    tris = np.array([[0, 1, 2], [0, 4, 3]])
    with pytest.raises(PreprocessError, match=r"2 node\(s\) coincide with another node .* e.g. at \(1, 1, 0\)"):
        run(square(points=pts, tris=tris))


def test_degenerate_elements():
    tris = np.array([[0, 1, 2], [0, 2, 3], [0, 0, 2]])
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        c = run(square(tris=tris))
    assert any(issubclass(w.category, PreprocessWarning) and "1 degenerate 2D element" in str(w.message)
               for w in caught)
    assert c.volume.sum() == pytest.approx(0.5)
    with pytest.raises(PreprocessError, match="total area 0"):
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            run(square(points=SQUARE * [1, 0, 0]))


def test_group_names_and_empty_sets():
    groups = {"sq": Group("sq", 2, {"triangle": np.arange(2)}),
              "left edge": Group("left edge", 1, {"line": np.array([0])})}
    with pytest.raises(PreprocessError, match=r"physical group 'left edge' is not a valid node-set name"):
        run(square(groups=groups))
    groups = {"sq": Group("sq", 2, {"triangle": np.arange(2)}),
              "tiny": Group("tiny", 2, {"triangle": np.array([], np.int64)})}
    with pytest.raises(PreprocessError, match=r"physical group 'tiny' \(2D\) holds no node"):
        run(square(groups=groups), method="lattice")
    with pytest.raises(PreprocessError, match="a layer only applies to lower-dimension groups"):
        run(square(), layers={"sq": 0.1})


def test_command_line(meshes, tmp_path):
    out = tmp_path / "nodes.vtu"
    result = subprocess.run([PYTHON, "-m", "preprocess", meshes["plate.unv"], "-o", str(out),
                             "--dim", "2", "--thickness", "1e-3", "--method", "lattice", "--dx", "1e-3",
                             "--block", "main", "--block", "grip", "--layer", "left=2e-3"],
                            cwd=ROOT, capture_output=True, text=True)
    assert result.returncode == 0, result.stderr
    assert "warning:" in result.stderr and "'origin'" in result.stderr
    cloud = read_node_file(str(out))
    assert cloud.sets["left"].sum() == 2 * 50 and set(np.unique(cloud.block)) == {1, 2}
    assert f"{out}: {len(cloud.volume)} nodes" in result.stdout
    result = subprocess.run([PYTHON, "-m", "preprocess", meshes["plate"], "-o", str(out),
                             "--dim", "2", "--thickness", "1e-3", "--dx", "1e-3", "--block", "steel"],
                            cwd=ROOT, capture_output=True, text=True)
    assert result.returncode == 2
    assert result.stderr.startswith(f"error: {meshes['plate']}: block 'steel' is not a physical group")


@pytest.mark.parametrize("method", ["mesh-nodes", "lattice"])
def test_a_far_node_is_refused_naming_it(method):
    """A 1e300 coordinate ended in a numpy traceback (issue 17, item 9)."""
    points = SQUARE.copy()
    points[2] = [1e300, 1, 0]
    with pytest.raises(PreprocessError, match=r"^sq.msh: 1 node\(s\) lie beyond ±1e\+150 m \(first: node index 2 "):
        run(square(points), method=method)


def test_a_lattice_too_large_for_any_machine_is_refused():
    points = SQUARE * 1e6   # a 1000 km square at dx = 0.1 m: 10^14 cells
    with pytest.raises(PreprocessError, match=r"^sq.msh: the lattice with dx = 0.1 m over the mesh's bounding box "
                                              r".* would have 1e\+14 cells, more than 1e\+10; use a larger dx"):
        run(square(points), method="lattice")
