"""Plot helpers (Agg backend): they draw what the result holds."""
import math

import matplotlib
matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

import fesd  # noqa: E402
from fesd import plot, problems as P  # noqa: E402


def test_sliding_intervals():
    E = fesd.SwitchEvent
    evs = [E(1.0, 0, "sliding_entry", (0,), (0, 1)), E(2.0, 1, "crossing", (1,), (0,)),
           E(3.0, 0, "sliding_exit", (0, 1), (1,)), E(4.0, 1, "sliding_entry", (0,), (0, 1))]
    assert plot.sliding_intervals(evs, 5.0) == [(1.0, 3.0, 0), (4.0, 5.0, 1)]
    assert plot.sliding_intervals([E(1.0, 0, "sliding_exit", (0, 1), (0,))], 2.0) == [(-math.inf, 1.0, 0)]


def test_plots_write_png(tmp_path):
    res = fesd.solve_ivp(P.friction(), (0, 12), [5.5, 0.0], stages=3, h=0.1, dense_output=True,
                         record_elements=True)
    fig, ax = plot.plot_trajectory(res, labels=["x", "v"])
    assert len(ax.lines) >= 2 + 3  # two states (+ points) and three switches
    assert len(ax.patches) == 1  # the sliding arc from 3 pi
    fig.savefig(tmp_path / "traj.png")
    fig2, ax2 = plot.plot_elements(res)
    fig2.savefig(tmp_path / "elements.png")
    h = ax2.lines[0].get_ydata()
    # N_FE = 2: 0.05 each, but in the three switch steps the boundary moved onto the switch
    assert np.sum(~np.isclose(h, 0.05)) == 6 and np.isclose(h.sum(), 12.0)
    fig3, _ = plot.plot_work_precision({"a": ([1e-3, 1e-2], [1e-4, 1e-8])})
    fig3.savefig(tmp_path / "wp.png")
    for f in ("traj.png", "elements.png", "wp.png"):
        assert (tmp_path / f).stat().st_size > 5000
    plt.close("all")
