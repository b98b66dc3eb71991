"""Mesh readers: .msh (msh4 and msh2 through meshio) and our own .unv reader agree on the same mesh."""
import warnings

import numpy as np
import pytest

from preprocess import PreprocessError, PreprocessWarning, read_mesh


def canonical(mesh):
    """Nodes sorted by coordinates, and per type the sorted elements / group members as node tuples
    in that sorted numbering, so that meshes with different node numbering compare equal."""
    order = np.lexsort(mesh.points.T[::-1])
    rank = np.empty(len(order), np.int64)
    rank[order] = np.arange(len(order))
    cells = {t: rank[c] for t, c in mesh.cells.items()}

    def rows(a):
        return sorted(map(tuple, np.sort(a, axis=1).tolist()))

    groups = {name: (g.dim, {t: rows(cells[t][idx]) for t, idx in g.cells.items() if len(idx)},
                     sorted(rank[g.explicit_nodes].tolist()))
              for name, g in mesh.groups.items()}
    return mesh.points[order], {t: rows(c) for t, c in cells.items()}, groups


def read_quietly(path):
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        mesh = read_mesh(path)
    return mesh, [str(w.message) for w in caught if issubclass(w.category, PreprocessWarning)]


def test_msh4_groups(meshes):
    mesh = read_mesh(meshes["plate"])
    assert {n: g.dim for n, g in mesh.groups.items()} == {
        "plate": 2, "main": 2, "grip": 2, "left": 1, "right": 1, "hole": 1, "origin": 0}
    assert set(mesh.cells) == {"vertex", "line", "triangle"}
    plate = mesh.groups["plate"].cells["triangle"]
    main, grip = mesh.groups["main"].cells["triangle"], mesh.groups["grip"].cells["triangle"]
    assert len(plate) == len(mesh.cells["triangle"]) == len(main) + len(grip)
    assert np.array_equal(np.sort(np.concatenate([main, grip])), plate)
    x = mesh.points[mesh.group_nodes("left"), 0]
    assert np.all(x == 0.0) and len(x) == np.sum(mesh.points[:, 0] == 0.0)


def test_msh2_equals_msh4(meshes):
    # msh2 writes an element once per physical group; the reader drops the copies
    a, b = canonical(read_mesh(meshes["plate"])), canonical(read_mesh(meshes["plate2.msh"]))
    assert np.array_equal(a[0], b[0])
    assert a[1] == b[1]
    assert a[2] == b[2]


def test_unv_written_by_gmsh_equals_msh(meshes):
    msh = read_mesh(meshes["plate"])
    unv, warned = read_quietly(meshes["plate.unv"])
    # gmsh lists the point element of 'origin' in its group but does not write it to dataset 2412
    assert len(warned) == 1 and "group 'origin'" in warned[0] and "dropped" in warned[0]
    a, b = canonical(msh), canonical(unv)
    assert np.array_equal(a[0], b[0])                   # same nodes ('D' exponents parsed exactly)
    assert {t: len(c) for t, c in a[1].items() if t != "vertex"} == {t: len(c) for t, c in b[1].items()}
    assert a[1]["triangle"] == b[1]["triangle"] and a[1]["line"] == b[1]["line"]
    expected = {name: value for name, value in a[2].items() if name != "origin"}
    assert b[2] == expected


def test_unv_hand_made_groups(meshes, tmp_path):
    """Append a dataset 2467 with a node group and an element group (odd counts: the last entity
    line holds one entity) and a dataset 2477, and read them back exactly."""
    text = open(meshes["plate.unv"]).read()
    unv = read_quietly(meshes["plate.unv"])[0]
    tri_labels = _element_labels(text, "91")[:5]        # first five triangles, by label
    node_labels = [3, 7, 11]
    lines = ["    -1", "  2467",
             f"{1:10d}{0:10d}{0:10d}{0:10d}{0:10d}{0:10d}{0:10d}{len(node_labels):10d}", "my_nodes"]
    lines += _entities(7, node_labels)
    lines += [f"{2:10d}{0:10d}{0:10d}{0:10d}{0:10d}{0:10d}{0:10d}{len(tri_labels):10d}", "some_tris"]
    lines += _entities(8, tri_labels)
    lines += ["    -1", "    -1", "  2477",
              f"{3:10d}{0:10d}{0:10d}{0:10d}{0:10d}{0:10d}{0:10d}{2:10d}", "mixed"]
    lines += [f"{7:10d}{1:10d}{0:10d}{0:10d}{8:10d}{tri_labels[0]:10d}{0:10d}{0:10d}"]   # node + element
    lines += ["    -1"]
    path = tmp_path / "groups.unv"
    path.write_text(text.rstrip("\n") + "\n" + "\n".join(lines) + "\n")
    mesh = read_quietly(str(path))[0]
    assert mesh.groups["my_nodes"].dim == 0
    assert np.array_equal(mesh.groups["my_nodes"].explicit_nodes, np.array(node_labels) - 1)
    tris = mesh.groups["some_tris"].cells
    assert list(tris) == ["triangle"] and len(tris["triangle"]) == 5
    assert np.array_equal(mesh.cells["triangle"][tris["triangle"]], unv.cells["triangle"][:5])
    mixed = mesh.groups["mixed"]
    assert mixed.dim == 2 and mixed.explicit_nodes.tolist() == [0] and len(mixed.cells["triangle"]) == 1


def _entities(code, labels):
    out = []
    for i in range(0, len(labels), 2):
        out.append("".join(f"{code:10d}{label:10d}{0:10d}{0:10d}" for label in labels[i:i + 2]))
    return out


def _element_labels(text, fe_id):
    lines = text.splitlines()
    start = next(i for i in range(len(lines) - 1) if lines[i].strip() == "-1" and lines[i + 1].strip() == "2412")
    labels = []
    for line in lines[start + 2:]:
        f = line.split()
        if len(f) == 6 and f[1] == fe_id:
            labels.append(int(f[0]))
        if line.strip() == "-1":
            break
    return labels


SMALL = """\
    -1
   164
         1  SI - mks (Newton)  2
  1.0000000000000000D+00  1.0000000000000000D+00  1.0000000000000000D+00
  2.7314999999999998D+02
    -1
    -1
  2411
        10         1         1        11
   0.0000000000000000D+00   0.0000000000000000D+00   0.0000000000000000D+00
        20         1         1        11
   1.0000000000000000D+00   0.0000000000000000D+00   0.0000000000000000D+00
        30         1         1        11
   1.0000000000000000D+00   2.5000000000000000D-01   0.0000000000000000D+00
        40         1         1        11
  -5.0000000000000000d-01   1.2500000000000000D+00   0.0000000000000000E+00
    -1
    -1
  2412
         1        21         1         1         7         2
         0         0         0
        10        20
         2        91         1         1         7         3
        10        20        30
         3        44         1         1         7         4
        10        20        30        40
         4        24         1         1         7         3
         0         0         0
        10        40        20
    -1
    -1
  2477
         1         0         0         0         0         0         0         3
bottom_and_quad
         8         1         0         0         8         3         0         0
         7        40         0         0
    -1
"""


def test_small_unv_d_exponents_beams_quadratic_and_unknown_datasets(tmp_path):
    path = tmp_path / "small.unv"
    path.write_text(SMALL)
    mesh = read_mesh(str(path))
    assert np.array_equal(mesh.points, [[0, 0, 0], [1, 0, 0], [1, 0.25, 0], [-0.5, 1.25, 0]])
    assert mesh.cells["line"].tolist() == [[0, 1]]
    assert mesh.cells["triangle"].tolist() == [[0, 1, 2]]
    assert mesh.cells["quad"].tolist() == [[0, 1, 2, 3]]
    assert mesh.cells["line3"].tolist() == [[0, 1, 3]]     # UNV end, mid, end → corners first
    g = mesh.groups["bottom_and_quad"]
    assert g.dim == 2 and g.cells["line"].tolist() == [0] and g.cells["quad"].tolist() == [0]
    assert g.explicit_nodes.tolist() == [3]


def unv_error(tmp_path, text):
    path = tmp_path / "bad.unv"
    path.write_text(text)
    with pytest.raises(PreprocessError) as err:
        read_mesh(str(path))
    return str(path), str(err.value)


def test_truncated_unv_names_file_and_line(tmp_path):
    lines = SMALL.splitlines()
    cut = lines.index("         3        44         1         1         7         4") + 1
    path, msg = unv_error(tmp_path, "\n".join(lines[:cut]) + "\n")
    assert msg.startswith(f"{path}:{cut}: truncated file") and "element 3" in msg
    path, msg = unv_error(tmp_path, "\n".join(lines[:12]) + "\n")     # inside 2411
    assert msg.startswith(f"{path}:12: ") and "truncated" in msg


def test_bad_records_name_file_and_line(tmp_path):
    lines = SMALL.splitlines()
    bad = list(lines)
    i = bad.index("   1.0000000000000000D+00   0.0000000000000000D+00   0.0000000000000000D+00")
    bad[i] = "   1.0000000000000000D+00   oops   0.0"
    path, msg = unv_error(tmp_path, "\n".join(bad) + "\n")
    assert msg.startswith(f"{path}:{i + 1}: bad record") and "node 20" in msg
    bad = list(lines)
    i = bad.index("         1         0         0         0         0         0         0         3")
    bad[i] = "         1         0         0         0         0         0         0         4"
    path, msg = unv_error(tmp_path, "\n".join(bad) + "\n")
    assert msg.startswith(f"{path}:") and "dataset 2477" in msg        # runs into the closing -1
    bad = list(lines)
    i = bad.index("         2        91         1         1         7         3")
    bad[i] = "         2        91         1         1         7         4"
    path, msg = unv_error(tmp_path, "\n".join(bad) + "\n")
    assert msg.startswith(f"{path}:{i + 2}: bad record for the nodes of element 2 (4 declared on line {i + 1})")
    bad[i] = "         2        91         1         1         7         4"
    bad[i + 1] = "        10        20        30        40"
    path, msg = unv_error(tmp_path, "\n".join(bad) + "\n")
    assert msg.startswith(f"{path}:{i + 1}: element 2: FE descriptor id 91 (triangle) has 3 nodes")
    bad = list(lines)
    i = bad.index("        10        20        30")
    bad[i] = "        10        20        99"
    path, msg = unv_error(tmp_path, "\n".join(bad) + "\n")
    assert "element 2 refers to node 99" in msg
