"""damage_3d.png for 3D runs (postprocess/render3d.py): matplotlib always (the nodes it draws as
damaged are exactly those with φ > DAMAGED_SHOWN, the axes carry units, the title is short); with
ParaView's pvpython when it is installed (skipped otherwise); matplotlib again when pvpython fails;
never for 2D runs."""
import os
import shutil

import numpy as np
import pytest
from matplotlib import pyplot as plt

import synthetic_output as synth
from postprocess import cli, render3d
from postprocess.casefile import CaseSettings
from postprocess.plotting import TITLE_MAX
from test_post_figures import assert_real_png


@pytest.fixture
def no_pvpython(monkeypatch):
    monkeypatch.setattr(render3d.shutil, "which", lambda name: None)


def test_matplotlib_draws_exactly_the_damaged_nodes(monkeypatch, tmp_path, no_pvpython):
    kept = {}

    def spy(fig, path, dpi):
        fig.canvas.draw()
        kept["fig"] = fig

    monkeypatch.setattr(render3d, "save_figure", spy)
    points = synth.lattice((6, 5, 4), 3)
    damage = np.zeros(len(points))
    damage[[3, 17, 40]] = [0.05, 0.35, 0.9]   # 0.05 is below DAMAGED_SHOWN = 0.1
    case = CaseSettings(name="plate_3d", dimension=3, title="3D plate with a hole pulled to fracture")
    said = render3d.plot_damage_3d_matplotlib(points, damage, case, str(tmp_path / "d.png"), time=1.5e-4)
    fig = kept["fig"]
    try:
        ax = fig.axes[0]
        body, damaged = ax.collections
        assert np.allclose(np.asarray(damaged.get_array()), [0.35, 0.9])
        xs, ys, zs = damaged._offsets3d
        assert np.allclose(np.column_stack([xs, ys, zs]), points[[17, 40]] * 1e3)   # in mm
        assert [ax.get_xlabel(), ax.get_ylabel(), ax.get_zlabel()] == ["x [mm]", "y [mm]", "z [mm]"]
        assert ax.get_title() == "plate_3d: damage at t = 150 µs" and len(ax.get_title()) <= TITLE_MAX
        assert fig.axes[1].get_ylabel() == "damage φ [-]"
        assert "2 nodes with damage > 0.1 of 120" in said
    finally:
        plt.close(fig)


def test_a_3d_run_gets_damage_3d_png_and_a_2d_run_none(run3d, run2d, no_pvpython):
    written = cli.run(str(run3d.out), log=lambda *_: None)
    path = run3d.out / "figures" / "damage_3d.png"
    assert str(path) in written
    assert_real_png(path, min_width=600, min_height=400)
    cli.run(str(run2d.out), log=lambda *_: None)
    assert not (run2d.out / "figures" / "damage_3d.png").exists()


def test_a_failing_pvpython_falls_back_to_matplotlib(run3d, tmp_path, capsys, monkeypatch):
    fake = tmp_path / "bin" / "pvpython"
    fake.parent.mkdir()
    fake.write_text("#!/bin/sh\necho 'no display' >&2\nexit 3\n")
    fake.chmod(0o755)
    monkeypatch.setenv("PATH", f"{fake.parent}{os.pathsep}{os.environ['PATH']}")
    cli.run(str(run3d.out), log=lambda *_: None)
    err = capsys.readouterr().err
    assert "pvpython failed (exit 3): no display; drawing damage_3d.png with matplotlib" in err
    assert "damage_3d.png (matplotlib)" in err
    assert_real_png(run3d.out / "figures" / "damage_3d.png")
    assert not [p for p in os.listdir(run3d.out / "figures") if p.startswith(".tmp")]


@pytest.mark.skipif(shutil.which("pvpython") is None, reason="ParaView's pvpython is not installed (optional)")
def test_pvpython_renders_the_last_frame(run3d, capsys):
    cli.run(str(run3d.out), log=lambda *_: None)
    assert "damage_3d.png (ParaView, offscreen)" in capsys.readouterr().err
    path = run3d.out / "figures" / "damage_3d.png"
    assert synth.png_size(path) == (1200, 900)
    assert_real_png(path)
