"""The figures: every PNG is written, valid and non-trivial, and the maps show the nearest frames."""
import json
import os

import matplotlib.image
import numpy as np
import pytest

import synthetic_output as synth
from postprocess import cli, maps
from common.atomic import atomic_path
from postprocess.errors import PostprocessError
from postprocess.energy_plot import energy_balance
from postprocess.history import read_history

FIXED = ["energy.png", "probe.png", "timestep.png"]


def run_quietly(out, **kwargs):
    return cli.run(str(out), log=lambda *_: None, **kwargs)


def assert_real_png(path, min_width=600, min_height=400):
    width, height = synth.png_size(path)
    assert width >= min_width and height >= min_height, (path, width, height)
    assert os.path.getsize(path) > 15000, path
    image = matplotlib.image.imread(path)
    assert image.shape[:2] == (height, width)
    rgb = (image[..., :3] * 255).astype(np.uint32)
    colours = np.unique(rgb[..., 0] << 16 | rgb[..., 1] << 8 | rgb[..., 2])
    assert len(colours) > 50, f"{path}: only {len(colours)} colours, an empty plot?"


@pytest.fixture
def map_calls(monkeypatch):
    """Record what the CLI asks each map to draw, then draw it."""
    calls = []
    real = maps.plot_map

    def spy(frame, case, path, **kwargs):
        calls.append((os.path.basename(path), os.path.basename(frame.path), kwargs["time"], kwargs["requested"]))
        return real(frame, case, path, **kwargs)

    monkeypatch.setattr(maps, "plot_map", spy)
    return calls


def test_every_figure_is_a_real_png(run2d, map_calls):
    synth.set_figures(run2d, times=[0.0, 1.4e-4, 2.6e-4, 1.0])
    written = run_quietly(run2d.out)
    figures = run2d.out / "figures"
    maps_expected = [f"{q}_{i}.png" for i in range(4) for q in ("damage", "displacement")]
    assert synth.file_names(figures) == sorted(FIXED + maps_expected)
    assert sorted(os.path.basename(p) for p in written if "/figures/" in p) == sorted(FIXED + maps_expected)
    for name in FIXED + maps_expected:
        assert_real_png(figures / name)
    # each requested time got the nearest frame; 1.0 s lies after the run: its last frame
    frames = {name: (frame, time, requested) for name, frame, time, requested in map_calls}
    expected = {0: ("frame_000000.vtu", 0.0), 1: ("frame_000001.vtu", 1e-4), 2: ("frame_000003.vtu", 3e-4),
                3: ("frame_000005.vtu", 5e-4)}
    requested = [0.0, 1.4e-4, 2.6e-4, 1.0]
    for i, (frame, time) in expected.items():
        for quantity in ("damage", "displacement"):
            assert frames[f"{quantity}_{i}.png"] == (frame, pytest.approx(time, abs=1e-15), requested[i])
    assert not [n for n in os.listdir(figures) if n.startswith(".tmp")]


def test_default_times_of_a_run_that_breaks_follow_its_broken_bonds(run2d, map_calls):
    """The synthetic history breaks 1 bond per 10 of its 40 steps (4 at 0.5 ms): 10 % of them are
    broken at 0.125 ms, 50 % at 0.25 ms, 90 % at 0.5 ms, so the frames at or after (every 0.1 ms) are
    2, 3 and 5, and the frame before the first break, 1, makes the fourth (selection.event_times)."""
    synth.set_figures(run2d, times=None)
    run_quietly(run2d.out, only="figures")
    drawn = sorted({(name.split("_")[1], frame) for name, frame, _, _ in map_calls})
    assert drawn == [("0.png", "frame_000001.vtu"), ("1.png", "frame_000002.vtu"),
                     ("2.png", "frame_000003.vtu"), ("3.png", "frame_000005.vtu")]
    assert not (run2d.out / "gmsh").exists()


def test_maps_left_from_a_longer_time_list_are_removed(run2d):
    synth.set_figures(run2d, times=[0.0, 1e-4, 2e-4, 3e-4, 4e-4])
    run_quietly(run2d.out, only="figures")
    assert (run2d.out / "figures" / "damage_4.png").exists()
    synth.set_figures(run2d, times=[5e-4])
    (run2d.out / "figures" / "notes.png").write_bytes(b"not ours")
    run_quietly(run2d.out, only="figures")
    names = synth.file_names(run2d.out / "figures")
    assert names == sorted(FIXED + ["damage_0.png", "displacement_0.png", "notes.png"])


def test_3d_case_draws_the_body_and_its_mid_plane(run3d):
    run_quietly(run3d.out)
    for i in range(4):
        assert_real_png(run3d.out / "figures" / f"damage_{i}.png", min_width=1200)
        assert_real_png(run3d.out / "figures" / f"displacement_{i}.png", min_width=1200)


def test_energy_balance_is_kinetic_plus_strain_plus_damping_minus_external(run2d):
    history = read_history(str(run2d.out / "history.csv"))
    t, end = history["time"], history["time"][-1]
    # synthetic terms: cos² e^{-λt} + sin² e^{-λt} + (1 − e^{-λt}) − t/(2 t_end) = 1 − t/(2 t_end)
    assert np.allclose(energy_balance(history), 1.0 - 0.5 * t / end, rtol=0, atol=1e-15)


def test_displacement_maps_share_a_symmetric_colour_range(run2d):
    from postprocess.series import read_frame
    frames = [read_frame(str(run2d.out / f"frames/frame_{k:06d}.vtu")) for k in (1, 4)]
    lo, hi = maps.displacement_range(frames, 2)
    largest = max(np.max(np.abs(u[:, 2])) for u in (run2d.displacements[1], run2d.displacements[4]))
    assert (lo, hi) == (-largest, largest)
    still = read_frame(str(run2d.out / "frames/frame_000000.vtu"))  # u_z = 0 everywhere at t = 0
    assert maps.displacement_range([still], 2) == (-1.0, 1.0)  # never an empty colour range


def test_marker_size_follows_the_node_spacing(run2d):
    points = run2d.points
    assert maps.node_spacing(points, 2, 2.5e-3) == 2.5e-3
    # without grid_spacing: a uniform cloud filling the bounding box, here 8 mm × 6 mm / 63 nodes
    assert maps.node_spacing(points, 2, None) == pytest.approx(np.sqrt(48e-6 / 63))


def test_an_interrupted_write_leaves_the_old_file_and_no_temporary(tmp_path):
    target = tmp_path / "figure.png"
    target.write_bytes(b"old")
    with pytest.raises(RuntimeError):
        with atomic_path(str(target)) as tmp:
            with open(tmp, "wb") as stream:
                stream.write(b"half")
            raise RuntimeError("interrupted")
    assert target.read_bytes() == b"old"
    assert os.listdir(tmp_path) == ["figure.png"]


def test_figures_dpi_scales_the_pixels_not_the_layout(run2d):
    """figures.dpi (default 300, fit for print): the same figure at 150 dpi has half the pixels
    each way, within the one pixel that the tight bounding box rounds."""
    case = json.loads(run2d.case_json.read_text())
    assert "dpi" not in case["figures"]   # a case.json from before the key: the default applies
    run_quietly(run2d.out, only="figures")
    at_300 = synth.png_size(run2d.out / "figures" / "energy.png")
    case["figures"]["dpi"] = 150
    run2d.case_json.write_text(json.dumps(case))
    run_quietly(run2d.out, only="figures")
    at_150 = synth.png_size(run2d.out / "figures" / "energy.png")
    assert at_300[0] == pytest.approx(2 * at_150[0], abs=2) and at_300[1] == pytest.approx(2 * at_150[1], abs=2)
    assert at_150[0] > 600   # 7 in wide at 150 dpi, less what tight cropping removes


@pytest.mark.parametrize("dpi", [49, 1201, 300.0, True, "300"])
def test_figures_dpi_out_of_range_names_the_key(run2d, dpi):
    case = json.loads(run2d.case_json.read_text())
    case["figures"]["dpi"] = dpi
    run2d.case_json.write_text(json.dumps(case))
    with pytest.raises(PostprocessError, match=r"case\.json: figures\.dpi: expected a whole number of dots per "
                                               r"inch in \[50, 1200\], got"):
        run_quietly(run2d.out, only="figures")
