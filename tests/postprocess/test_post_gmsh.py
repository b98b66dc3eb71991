"""Gmsh export: results.msh opens in gmsh's own API with a view per point array × N time steps, exact values."""
import meshio
import numpy as np

from postprocess import cli
from postprocess.gmsh_export import read_msh_node_data, write_results_msh
from postprocess.series import Frame, read_frame


def export(run):
    cli.run(str(run.out), only="gmsh", log=lambda *_: None)
    return run.out / "gmsh"


ARRAYS = ("displacement", "velocity", "damage", "block")  # every point array of the synthetic frames


def frame_arrays(run, k):
    """The point arrays of frame k as the synthetic output wrote them, (n, components) each."""
    frame = read_frame(str(run.out / "frames" / f"frame_{k:06d}.vtu"))
    assert tuple(frame.point_data) == ARRAYS
    return {name: np.asarray(v, dtype=np.float64).reshape(len(run.points), -1) for name, v in frame.point_data.items()}


def test_gmsh_opens_results_with_a_view_per_point_array_and_one_time_step_per_frame(run2d, gmsh_session):
    gmsh = gmsh_session
    gmsh_dir = export(run2d)
    assert sorted(p.name for p in gmsh_dir.iterdir()) == ["damage_final.pos", "results.msh", "results.msh.opt"]
    assert (gmsh_dir / "results.msh").read_bytes().startswith(b"$MeshFormat\n4.1 1 8\n")  # binary
    gmsh.open(str(gmsh_dir / "results.msh"))
    n_frames, n_nodes = len(run2d.times), len(run2d.points)
    tags = list(gmsh.view.getTags())
    names = [gmsh.option.getString(f"View[{gmsh.view.getIndex(t)}].Name") for t in tags]
    assert names == list(ARRAYS)
    expected = [frame_arrays(run2d, k) for k in range(n_frames)]
    assert np.array_equal(expected[-1]["displacement"], run2d.displacements[-1])
    for tag, name in zip(tags, names):
        assert gmsh.option.getNumber(f"View[{gmsh.view.getIndex(tag)}].NbTimeStep") == n_frames
        for k in range(n_frames):
            kind, node_tags, data, time, components = gmsh.view.getModelData(tag, k)
            assert kind == "NodeData"
            assert time == run2d.times[k]
            assert list(node_tags) == list(range(1, n_nodes + 1))
            assert components == expected[k][name].shape[1]
            assert np.array_equal(np.array(data), expected[k][name])  # exact: shortest round-trip repr
    # nodes at the reference positions, one point element each, tagged with the block
    node_tags, coords, _ = gmsh.model.mesh.getNodes()
    assert np.array_equal(np.asarray(coords).reshape(-1, 3)[np.argsort(node_tags)], run2d.points)
    types, elements, _ = gmsh.model.mesh.getElements(dim=0)
    assert list(types) == [15] and sum(len(e) for e in elements) == n_nodes
    assert sorted(gmsh.model.getPhysicalName(0, tag) for _, tag in gmsh.model.getPhysicalGroups(0)) == ["left", "right"]


def test_our_parser_and_meshio_read_the_values_back(run2d):
    path = export(run2d) / "results.msh"
    views = read_msh_node_data(str(path))
    assert sorted(views) == sorted(ARRAYS)
    for name in ARRAYS:
        blocks = views[name]
        assert [b[0] for b in blocks] == run2d.times.tolist()        # time of each block
        assert [b[1] for b in blocks] == list(range(len(run2d.times)))  # its time-step index
        for k, (_, _, tags, values) in enumerate(blocks):
            assert np.array_equal(tags, np.arange(1, len(run2d.points) + 1))
            assert np.array_equal(values, frame_arrays(run2d, k)[name])
    mesh = meshio.read(str(path))  # an independent reader of the mesh part (it keeps the last data block)
    assert np.array_equal(mesh.points, run2d.points)
    assert {c.type for c in mesh.cells} == {"vertex"}  # one cell block per run of nodes of one block
    assert np.array_equal(np.concatenate([c.data for c in mesh.cells]).ravel(), np.arange(len(run2d.points)))
    assert np.array_equal(mesh.point_data["displacement"], run2d.displacements[-1])


def test_arrays_of_any_width_become_views_gmsh_can_hold(tmp_path, gmsh_session):
    """1, 3, 9 components as they are; 2 padded with z = 0; any other count one scalar per component."""
    gmsh = gmsh_session
    rng = np.random.default_rng(7)
    n = 5
    points = np.column_stack([np.arange(n) * 1e-3, np.zeros(n), np.zeros(n)])
    data = {"damage": rng.random(n), "velocity": rng.random((n, 3)), "stress": rng.random((n, 9)),
            "flat": rng.random((n, 2)), "strain6": rng.random((n, 6)), "block": np.arange(1, n + 1, dtype=np.int32)}
    frames = [(k, 0.5 * k, Frame(path=f"f{k}.vtu", points=points, point_data={name: v * (k + 1) for name, v in data.items()},
                                 broken_bonds=np.zeros((0, 2), np.int64)))
              for k in range(2)]
    path = tmp_path / "results.msh"
    assert write_results_msh(str(path), frames) == 2
    views = read_msh_node_data(str(path))
    want = {"damage": data["damage"][:, None], "velocity": data["velocity"], "stress": data["stress"],
            "flat": np.column_stack([data["flat"], np.zeros(n)]), "block": data["block"][:, None].astype(float)}
    want.update({f"strain6[{c}]": data["strain6"][:, c:c + 1] for c in range(6)})
    assert list(views) == ["damage", "velocity", "stress", "flat"] + [f"strain6[{c}]" for c in range(6)] + ["block"]
    for name, values in want.items():
        assert [b[0] for b in views[name]] == [0.0, 0.5]
        for k, (_, _, _, got) in enumerate(views[name]):
            assert np.array_equal(got, values * (k + 1))
    gmsh.open(str(path))
    tags = list(gmsh.view.getTags())
    names = [gmsh.option.getString(f"View[{gmsh.view.getIndex(t)}].Name") for t in tags]
    assert names == list(views)
    for tag, name in zip(tags, names):
        _, _, got, _, components = gmsh.view.getModelData(tag, 1)
        assert components == want[name].shape[1]
        assert np.array_equal(np.array(got), want[name] * 2)


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
    assert [gmsh.option.getNumber(f"View[{gmsh.view.getIndex(t)}].NbTimeStep") for t in tags] == [4] * len(ARRAYS)
    _, _, data, time, _ = gmsh.view.getModelData(tags[0], 3)
    assert time == run3d.times[3] and np.array_equal(np.array(data), run3d.displacements[3])


def _set_gmsh(run, value):
    import json
    case = json.loads(run.case_json.read_text())
    case["output"] = {"gmsh": value}
    run.case_json.write_text(json.dumps(case))


def test_output_gmsh_figures_copies_only_the_figure_frames_and_none_writes_no_gmsh_files(run2d):
    _set_gmsh(run2d, "figures")
    views = read_msh_node_data(str(export(run2d) / "results.msh"))
    wanted = [1, 2, 3, 5]  # the figures' frames (test_post_figures: default times of a run that breaks)
    assert sorted(wanted) != list(range(len(run2d.times)))  # the test would not tell the modes apart
    times = [run2d.times[k] for k in sorted(set(wanted))]
    for name in ARRAYS:
        # the figures' frames only, as time steps 0…n-1 with their own times (issue 39: tagged with
        # the frames' indices, Gmsh made a step for every index up to the largest, most of them empty)
        assert [b[1] for b in views[name]] == list(range(len(times)))
        assert [b[0] for b in views[name]] == times
    pos = (run2d.out / "gmsh" / "damage_final.pos").read_text()
    assert f"TIME{{{float(run2d.times[-1])!r}}}" in pos  # still the last frame
    _set_gmsh(run2d, "none")
    for name in ("results.msh", "damage_final.pos"):
        (run2d.out / "gmsh" / name).unlink()
    cli.run(str(run2d.out), log=lambda *_: None)
    assert not (run2d.out / "gmsh" / "results.msh").exists()
    assert (run2d.out / "figures" / "probe.png").exists()  # the frames were still read for the figures


def _cloud_box(points):
    return tuple(points.min(axis=0).tolist() + points.max(axis=0).tolist())


def test_results_msh_opens_framed_on_the_cloud_in_2d_and_3d_with_several_blocks(run2d, run3d, gmsh_session):
    """Gmsh frames a view on the model's bounding box (issue 16: it was a dot)."""
    gmsh = gmsh_session
    for run in (run2d, run3d):
        gmsh.clear()
        gmsh.open(str(export(run) / "results.msh"))
        assert gmsh.model.getBoundingBox(-1, -1) == _cloud_box(run.points)


def test_a_one_block_cloud_opens_framed_too(tmp_path, gmsh_session):
    """With one block every node lies on one point entity: only the corner entities give the box."""
    gmsh = gmsh_session
    rng = np.random.default_rng(3)
    points = rng.random((40, 3)) * [0.2, 0.05, 0.01] + [-0.1, 0.3, 0.0]
    frame = Frame(path="f.vtu", points=points, point_data={"damage": np.zeros(40)},
                  broken_bonds=np.zeros((0, 2), np.int64))
    path = tmp_path / "results.msh"
    write_results_msh(str(path), [(0, 0.0, frame)], block_names={1: "plate"})
    gmsh.open(str(path))
    assert gmsh.model.getBoundingBox(-1, -1) == _cloud_box(points)
    assert [gmsh.model.getPhysicalName(0, tag) for _, tag in gmsh.model.getPhysicalGroups(0)] == ["plate"]
    node_tags, coords, _ = gmsh.model.mesh.getNodes()
    assert np.array_equal(np.asarray(coords).reshape(-1, 3)[np.argsort(node_tags)], points)


def test_damage_pos_fixes_the_damage_range_and_hides_the_constant_legend_of_broken_bonds(run2d, gmsh_session):
    gmsh = gmsh_session
    gmsh.merge(str(export(run2d) / "damage_final.pos"))
    damage, bonds = (gmsh.view.getIndex(t) for t in gmsh.view.getTags())
    assert gmsh.option.getString(f"View[{damage}].Name") == "damage"
    assert gmsh.option.getNumber(f"View[{damage}].RangeType") == 2  # custom: 0…1
    assert (gmsh.option.getNumber(f"View[{damage}].CustomMin"),
            gmsh.option.getNumber(f"View[{damage}].CustomMax")) == (0.0, 1.0)
    assert gmsh.option.getNumber(f"View[{damage}].ShowScale") == 1
    assert gmsh.option.getString(f"View[{bonds}].Name") == "broken bonds"
    assert gmsh.option.getNumber(f"View[{bonds}].ShowScale") == 0  # its legend read "1 1 1"


def test_a_subset_of_frames_opens_in_gmsh_with_no_empty_step_and_no_stray_points(run2d, gmsh_session):
    """Issue 39, item 1: output.gmsh: figures wrote frames 0, 15, 30, 43 tagged so, and Gmsh made 44
    time steps of which 40 were empty; the corner entities showed as two dots."""
    gmsh = gmsh_session
    _set_gmsh(run2d, "figures")
    path = export(run2d) / "results.msh"
    gmsh.open(str(path))
    assert gmsh.option.getNumber("Geometry.Points") == 0     # results.msh.opt, merged by Gmsh itself
    views = read_msh_node_data(str(path))
    steps = len(views["damage"])
    assert 1 < steps < len(run2d.times)
    for tag in gmsh.view.getTags():
        index = gmsh.view.getIndex(tag)
        assert gmsh.option.getNumber(f"View[{index}].NbTimeStep") == steps
        for k in range(steps):
            _, node_tags, data, _, _ = gmsh.view.getModelData(tag, k)
            assert len(node_tags) == len(run2d.points) and len(data) == len(run2d.points)
