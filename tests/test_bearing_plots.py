"""The planar bearings' plots are made of the run's own data: each orbit's largest radius is
the summary's peak resultant displacement, the resultant force never exceeds P mu, and run
--plot writes the figure for a deck with &bearings (checked on the plotted data, not pixels)."""

from __future__ import annotations

import numpy as np
import pytest
from conftest import deck_text
from matplotlib.figure import Figure

import frictiondyn
from frictiondyn import plots

M, MU, G = 2.0e4, 0.08, 9.80665


def block(tmp_path) -> frictiondyn.Result:
    t = np.arange(0, 3.0 + 1e-9, 0.01)
    (tmp_path / "x.txt").write_text("\n".join(repr(float(v)) for v in 3.0 * np.sin(2 * np.pi * t)))
    (tmp_path / "y.txt").write_text("\n".join(repr(float(v)) for v in 2.0 * np.cos(2 * np.pi * 0.7 * t)))
    rec = {"excitation_type": "record", "record_format": "values", "record_units": "m/s2",
           "dt_record": 0.01, "duration": 3.0}
    groups = {
        "floors": {"n_floors": 1, "mass": M, "plan_x": 4.0, "plan_y": 4.0},
        "frames": {"n_frames": 0},
        "damping": {"damping_type": "none"},
        # one bearing under the centre of mass carrying the floor's weight (p by default)
        "bearings": {"n_bearings": 1, "storey": 1, "x": 0.0, "y": 0.0, "mu": MU,
                     "law": "hysteretic", "f": 1e-4, "eps1": 1e-5},
        "excitation": {**rec, "record_file": "x.txt"},
        "excitation2": {**rec, "record_file": "y.txt"},
        "integration": {"n1": 10},
    }
    text = deck_text(groups)
    return frictiondyn.run_text(text, "b.nml", tmp_path)


def test_bearing_plot_is_the_runs_orbit_and_force(tmp_path, monkeypatch):
    r = block(tmp_path)
    drawn = []
    monkeypatch.setattr(Figure, "savefig", lambda fig, *a, **k: drawn.append(fig))
    plots.plot_bearings(r, tmp_path / "b.png")
    ax_o, ax_f = drawn[0].axes
    (orbit,), (loop,) = ax_o.lines[:1], ax_f.lines[:1]
    x, y = orbit.get_xdata(), orbit.get_ydata()
    # the history's rows are samples: their largest radius is at most the summary's peak
    # over every step, and within the step's motion of it
    peak = r.summary["bearing_peak_displacement_m"][0]
    assert np.hypot(x, y).max() <= peak * (1 + 1e-12)
    assert np.hypot(x, y).max() == pytest.approx(peak, rel=2e-2)
    np.testing.assert_array_equal(loop.get_xdata(), np.hypot(x, y))
    assert loop.get_ydata().max() <= M * G * MU * (1 + 1e-12)
    assert loop.get_ydata().max() == pytest.approx(M * G * MU, rel=1e-9)  # it slid


def test_run_plot_writes_the_bearings(tmp_path):
    r = block(tmp_path)
    written = plots.plot_all(r, tmp_path, "b", kinds="key")
    assert tmp_path / "b_bearings.png" in written


def test_bearing_plot_needs_bearings(tmp_path):
    from conftest import INPUTS

    r = frictiondyn.run(INPUTS / "test4_hysteretic.nml")
    with pytest.raises(ValueError, match="no planar bearing"):
        plots.plot_all(r, tmp_path, "t", kinds=("bearings",))
