"""timestep.png of the mixed scheme: Δt on a log scale, the quasi-static and explicit steps drawn
in their own colours with a legend (postprocess/timestep_plot.py)."""
import numpy as np
from matplotlib import pyplot as plt

from postprocess import timestep_plot


def test_mixed_history_draws_each_mode_on_a_log_scale(tmp_path, monkeypatch):
    step = np.arange(0, 12)
    mode = np.array([1, 1, 1, 1, 1, 0, 0, 0, 0, 0, 0, 1])
    dt = np.where(mode == 1, 1e-4, 1e-7)
    history = {"step": step, "time": np.cumsum(dt), "dt": dt, "iterations": np.where(mode == 1, 4, 1),
               "rejected": np.zeros_like(step), "mode": mode}
    saved = {}
    monkeypatch.setattr(timestep_plot, "save_figure", lambda fig, path, dpi: saved.update(fig=fig, path=path, dpi=dpi))

    class Case:
        heading = "mixed"
        dpi = 150

    timestep_plot.plot_timestep(history, Case(), str(tmp_path / "timestep.png"))
    assert saved["dpi"] == 150   # the case's figures.dpi
    axes = saved["fig"].axes
    assert axes[1].get_yscale() == "log" and axes[0].get_yscale() == "log"
    labels = [t.get_text() for t in axes[1].get_legend().get_texts()]
    assert labels == ["quasi-static load steps", "explicit (Verlet) steps"]
    # Every step after step 0 is drawn in exactly one of the two series.
    drawn = sum(len(line.get_xdata()) for line in axes[1].get_lines())
    assert drawn == len(step) - 1
    plt.close(saved["fig"])
