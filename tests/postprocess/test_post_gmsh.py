"""Gmsh export: results.msh opens in gmsh's own API with 2 views × N time steps and exact values."""
import meshio
import numpy as np

from postprocess import cli
from postprocess.gmsh_export import read_msh_node_data


def export(run):
    cli.run(str(run.out), only="gmsh", log=lambda *_: None)
    return run.out / "gmsh"


def test_gmsh_opens_results_with_two_views_and_one_time_step_per_frame(run2d, gmsh_session):
    gmsh = gmsh_session
    gmsh_dir = export(run2d)
    assert sorted(p.name for p in gmsh_dir.iterdir()) == ["damage_final.pos", "results.msh"]
    gmsh.open(str(gmsh_dir / "results.msh"))
    n_frames, n_nodes = len(run2d.times), len(run2d.points)
    tags = list(gmsh.view.getTags())
    assert len(tags) == 2
    names = [gmsh.option.getString(f"View[{gmsh.view.getIndex(t)}].Name") for t in tags]
    assert names == ["displacement", "damage"]
    for tag, name in zip(tags, names):
        assert gmsh.option.getNumber(f"View[{gmsh.view.getIndex(tag)}].NbTimeStep") == n_frames
        for k in range(n_frames):
            kind, node_tags, data, time, components = gmsh.view.getModelData(tag, k)
            assert kind == "NodeData"
            assert time == run2d.times[k]
            assert list(node_tags) == list(range(1, n_nodes + 1))
            values = np.array(data)
            if name == "displacement":
                assert components == 3
                assert np.array_equal(values, run2d.displacements[k])  # exact: shortest round-trip repr
            else:
                assert components == 1
                assert np.array_equal(values[:, 0], run2d.damages[k])
    # nodes at the reference positions, one point element each, tagged with the block
    node_tags, coords, _ = gmsh.model.mesh.getNodes()
    assert np.array_equal(np.asarray(coords).reshape(-1, 3)[np.argsort(node_tags)], run2d.points)
    types, elements, _ = gmsh.model.mesh.getElements(dim=0)
    assert list(types) == [15] and sum(len(e) for e in elements) == n_nodes
    assert sorted(gmsh.model.getPhysicalName(0, tag) for _, tag in gmsh.model.getPhysicalGroups(0)) == ["left", "right"]


def test_our_parser_and_meshio_read_the_values_back(run2d):
    path = export(run2d) / "results.msh"
    views = read_msh_node_data(str(path))
    assert sorted(views) == ["damage", "displacement"]
    for name, expected in (("displacement", run2d.displacements), ("damage", run2d.damages)):
        blocks = views[name]
        assert [b[0] for b in blocks] == run2d.times.tolist()        # time of each block
        assert [b[1] for b in blocks] == list(range(len(run2d.times)))  # its time-step index
        for (_, _, tags, values), want in zip(blocks, expected):
            assert np.array_equal(tags, np.arange(1, len(run2d.points) + 1))
            assert np.array_equal(values.reshape(np.shape(want)), want)
    mesh = meshio.read(str(path))  # an independent reader of the mesh part (it keeps the last data block)
    assert np.array_equal(mesh.points, run2d.points)
    assert [c.type for c in mesh.cells] == ["vertex"] and len(mesh.cells[0].data) == len(run2d.points)
    assert np.array_equal(mesh.point_data["displacement"], run2d.displacements[-1])


def test_damage_pos_holds_the_last_frame_as_points_and_broken_bonds_as_lines(run2d, gmsh_session):
    gmsh = gmsh_session
    gmsh_dir = export(run2d)
    gmsh.merge(str(gmsh_dir / "damage_final.pos"))
    tags = list(gmsh.view.getTags())
    assert len(tags) == 2
    kinds, counts, data = gmsh.view.getListData(tags[0])
    assert list(kinds) == ["SP"] and list(counts) == [len(run2d.points)]
    points = np.asarray(data[0]).reshape(-1, 4)  # x, y, z, φ per point
    assert np.array_equal(points[:, :3], run2d.points)
    assert np.array_equal(points[:, 3], run2d.damages[-1])
    kinds, counts, data = gmsh.view.getListData(tags[1])
    assert list(kinds) == ["SL"] and list(counts) == [len(run2d.broken[-1])]
    lines = np.asarray(data[0]).reshape(-1, 8)  # x1 x2, y1 y2, z1 z2, then the two values
    bonds = run2d.broken[-1]
    assert np.array_equal(lines[:, [0, 2, 4]], run2d.points[bonds[:, 0]])
    assert np.array_equal(lines[:, [1, 3, 5]], run2d.points[bonds[:, 1]])


def test_3d_export_round_trips(run3d, gmsh_session):
    gmsh = gmsh_session
    gmsh.open(str(export(run3d) / "results.msh"))
    tags = list(gmsh.view.getTags())
    assert [gmsh.option.getNumber(f"View[{gmsh.view.getIndex(t)}].NbTimeStep") for t in tags] == [4, 4]
    _, _, data, time, _ = gmsh.view.getModelData(tags[0], 3)
    assert time == run3d.times[3] and np.array_equal(np.array(data), run3d.displacements[3])
