"""postprocess.sizes: the line `make case=X` ends with, what a run left on disk by kind."""
import os

from postprocess import sizes


def write(path, size):
    os.makedirs(os.path.dirname(path), exist_ok=True)
    with open(path, "wb") as stream:
        stream.write(b"x" * size)


def test_each_file_counts_once_under_its_kind(tmp_path):
    write(tmp_path / "frames.pvd", 1_000)
    write(tmp_path / "frames" / "frame_000000.vtu", 2_000_000)
    write(tmp_path / "frames" / "frame_000001.vtu", 2_000_000)
    write(tmp_path / "gmsh" / "results.msh", 1_500_000)
    write(tmp_path / "figures" / "energy.png", 300_000)
    write(tmp_path / "history.csv", 40_000)
    write(tmp_path / "case.json", 3_000)
    write(tmp_path / "stray.txt", 7)
    write(tmp_path / ".lock", 20)                      # the folder's lock: not an output
    os.symlink(tmp_path / "gmsh" / "results.msh", tmp_path / "link.msh")   # not counted twice
    got = sizes.output_sizes(str(tmp_path))
    assert got == {"frames": (4_001_000, 3), "gmsh": (1_500_000, 1), "figures": (300_000, 1),
                   "history": (40_000, 1), "inputs": (3_000, 1), "other": (7, 1)}
    assert sizes.summary(str(tmp_path)) == (
        f"{tmp_path}: 5.8 MB: frames 4.0 MB (3 files), gmsh 1.5 MB, figures 0.3 MB (1 PNG), history 40 kB, "
        "inputs 3 kB, other 0 kB")


def test_an_empty_folder_says_so_and_a_bad_argument_is_a_usage_error(tmp_path, capsys):
    assert sizes.summary(str(tmp_path)) == f"{tmp_path}: 0 kB (empty)"
    assert sizes.main([str(tmp_path / "missing")]) == 2
    assert "usage: python3 -m postprocess.sizes OUT_DIR" in capsys.readouterr().err
