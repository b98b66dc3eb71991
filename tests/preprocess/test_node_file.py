"""The node file of pipeline/formats.md §1-2: round trip through our reader and meshio, and errors."""
import struct

import meshio
import numpy as np
import pytest

from preprocess import NodeCloud, PreprocessError
from preprocess.node_file import read_node_file, write_node_file


@pytest.fixture
def cloud():
    rng = np.random.default_rng(1)
    n = 57
    pts = rng.random((n, 3))
    return NodeCloud(points=pts, volume=rng.random(n) + 0.1, block=rng.integers(1, 4, n).astype(np.int32),
                     sets={"left": pts[:, 0] < 0.3, "top_edge": pts[:, 1] > 0.5, "_x9": np.ones(n, bool)},
                     grid_spacing=0.125, dimension=3)


def test_round_trip_own_reader_and_meshio(cloud, tmp_path):
    path = str(tmp_path / "nodes.vtu")
    write_node_file(path, cloud)
    back = read_node_file(path)
    assert np.array_equal(back.points, cloud.points)
    assert np.array_equal(back.volume, cloud.volume)
    assert np.array_equal(back.block, cloud.block) and back.block.dtype == np.int32
    assert list(back.sets) == ["left", "top_edge", "_x9"]
    for name, mask in cloud.sets.items():
        assert np.array_equal(back.sets[name], mask)
    assert back.grid_spacing == 0.125 and back.dimension == 3
    m = meshio.read(path)
    assert np.array_equal(m.points, cloud.points)
    assert len(m.cells) == 1 and m.cells[0].type == "vertex"
    assert np.array_equal(m.cells[0].data.ravel(), np.arange(len(cloud.volume)))
    assert np.array_equal(m.point_data["volume"], cloud.volume)
    assert np.array_equal(m.point_data["block"], cloud.block) and m.point_data["block"].dtype == np.int32
    assert m.point_data["set_left"].dtype == np.uint8
    assert np.array_equal(m.point_data["set_top_edge"], cloud.sets["top_edge"].astype(np.uint8))
    assert m.field_data["pd_node_file_version"].tolist() == [1]
    assert m.field_data["dimension"].tolist() == [3]
    assert m.field_data["grid_spacing"].tolist() == [0.125]


def test_encoding_matches_formats_md(cloud, tmp_path):
    path = tmp_path / "nodes.vtu"
    write_node_file(str(path), cloud)
    data = path.read_bytes()
    assert b'<VTKFile type="UnstructuredGrid" version="1.0" byte_order="LittleEndian" header_type="UInt64">' in data
    assert b"compressor" not in data
    start = data.index(b'<AppendedData encoding="raw">')
    head = data[:start].decode()
    assert head.count("<DataArray") == head.count('format="appended"') == 3 + 1 + 3 + 2 + 3
    assert data.endswith(b"\n  </AppendedData>\n</VTKFile>\n")
    base = data.index(b"_", start) + 1
    # the first array: the version, a UInt64 byte count 4 then Int32 1
    assert struct.unpack_from("<Qi", data, base) == (4, 1)
    # the last array (set__x9) ends right before "\n  </AppendedData>"
    n = len(cloud.volume)
    assert struct.unpack_from("<Q", data, len(data) - len(b"\n  </AppendedData>\n</VTKFile>\n") - n - 8)[0] == n


def test_no_temporary_file_left_and_overwrite(cloud, tmp_path):
    path = tmp_path / "nodes.vtu"
    write_node_file(str(path), cloud)
    write_node_file(str(path), cloud)
    assert [p.name for p in tmp_path.iterdir()] == ["nodes.vtu"]


def test_invalid_cloud_is_not_written(cloud, tmp_path):
    cloud.volume[3] = 0.0
    with pytest.raises(PreprocessError, match="volume that is not > 0"):
        write_node_file(str(tmp_path / "nodes.vtu"), cloud)
    assert not (tmp_path / "nodes.vtu").exists()


def _corrupt(cloud, tmp_path, change):
    path = tmp_path / "nodes.vtu"
    write_node_file(str(path), cloud)
    path.write_bytes(change(path.read_bytes()))
    with pytest.raises(PreprocessError) as err:
        read_node_file(str(path))
    msg = str(err.value)
    assert msg.startswith(str(path) + ": not a valid node file")
    return msg


def test_wrong_header(cloud, tmp_path):
    assert 'header_type="UInt32", expected "UInt64"' in _corrupt(
        cloud, tmp_path, lambda d: d.replace(b'header_type="UInt64"', b'header_type="UInt32"', 1))
    assert "byte_order" in _corrupt(cloud, tmp_path, lambda d: d.replace(b"LittleEndian", b"BigEndian", 1))
    assert "PointData volume has type Float32" in _corrupt(
        cloud, tmp_path, lambda d: d.replace(b'type="Float64" Name="volume"', b'type="Float32" Name="volume"'))
    assert "missing PointData block" in _corrupt(
        cloud, tmp_path, lambda d: d.replace(b'Name="block"', b'Name="blocc"'))


def test_wrong_version(cloud, tmp_path):
    def version_2(d):
        base = d.index(b"_", d.index(b"<AppendedData")) + 1
        return d[:base + 8] + struct.pack("<i", 2) + d[base + 12:]
    assert "pd_node_file_version = 2" in _corrupt(cloud, tmp_path, version_2)


def test_truncated_file(cloud, tmp_path):
    assert "truncated" in _corrupt(cloud, tmp_path, lambda d: d[:len(d) - 200])
    assert "truncated" in _corrupt(cloud, tmp_path, lambda d: d[:len(d) - 20])
    assert "truncated" in _corrupt(cloud, tmp_path, lambda d: d[:d.index(b"<AppendedData") + 10])
    assert "truncated" in _corrupt(cloud, tmp_path, lambda d: d[:300])
    assert "XML header" in _corrupt(cloud, tmp_path, lambda d: d.replace(b"</Points>", b"</Pts>", 1))
