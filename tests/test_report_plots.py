"""Plots for reports: the default time window, thinning that keeps the peaks,
units chosen by the user, names from the deck, the profiles over the height, titles,
resolution and figures composed of panels."""

from __future__ import annotations

from pathlib import Path

import frictiondyn as fd
import numpy as np
import pytest
from conftest import INPUTS
from frictiondyn import plots
from frictiondyn.paper import paper_analysis

G0 = 9.80665


@pytest.fixture(scope="module")
def damped() -> fd.Result:
    return fd.run(INPUTS / "building5_dampers.nml")


@pytest.fixture(scope="module")
def bare() -> fd.Result:
    return fd.run(INPUTS / "building5_bare.nml")


@pytest.fixture(scope="module")
def harmonic() -> fd.Result:
    return paper_analysis(4, "velocity", duration=5.0).run()


def test_default_window_is_the_last_cycles_of_a_harmonic_run(harmonic):
    f = harmonic.summary["excitation_frequency_Hz"]
    assert plots.auto_window(harmonic) == (5.0 - 5 / f, 5.0)
    fig = plots.plot_acceleration(harmonic, 1)
    x, _ = fig.axes[0].get_lines()[0].get_data()
    assert x[0] >= 5.0 - 5 / f - 1e-12 and x[-1] == 5.0
    fig = plots.plot_acceleration(harmonic, 1, t_range="all", max_points=0)
    assert np.array_equal(fig.axes[0].get_lines()[0].get_xdata(), harmonic.time)
    with pytest.raises(ValueError, match="'whole'"):
        plots.plot_acceleration(harmonic, 1, t_range="whole")


def test_a_record_run_is_plotted_whole_and_thinned_with_its_peaks(damped):
    assert plots.auto_window(damped) is None
    long = fd.Result(damped.names, damped.units, np.repeat(damped.data, 3, axis=0), damped.summary)
    long.data[:, 0] = np.arange(len(long.data)) * 1e-3  # a history of 9000 rows
    fig = plots.plot_acceleration(long, 5)
    x, y = fig.axes[0].get_lines()[0].get_data()
    assert len(y) <= 5002 and x[0] == 0.0 and x[-1] == long.time[-1]
    assert y.max() == long["aabs5"].max() and y.min() == long["aabs5"].min()
    assert np.all(np.diff(x) > 0)
    # thin keeps each interval's extremes
    t = np.linspace(0, 1, 100001)
    v = np.sin(40 * t) + (t == t[77777]) * 5.0
    xs, ys = plots.thin(t, v, 1000)
    assert len(xs) <= 1002 and ys.max() == v.max() and xs[np.argmax(ys)] == t[77777]


def test_units_and_names_from_the_deck(damped):
    fig = plots.plot_acceleration(damped, 5, units="mm,kN,g")
    ax = fig.axes[0]
    assert ax.get_title() == "roof: absolute acceleration"
    assert ax.get_ylabel() == "absolute acceleration [g]"
    np.testing.assert_allclose(ax.get_lines()[0].get_ydata().max(), damped["aabs5"].max() / G0)
    fig = plots.plot_hysteresis(damped, 2, units=plots.REPORT_UNITS)
    ax = fig.axes[0]
    assert ax.get_title() == "damper 2: force-displacement loop"
    assert (
        ax.get_xlabel() == "relative displacement [mm]" and ax.get_ylabel() == "friction force [kN]"
    )
    x, y = ax.get_lines()[0].get_data()
    np.testing.assert_allclose(np.abs(y).max(), 564075.0 / 1e3, rtol=1e-12)  # the slip load
    np.testing.assert_allclose(np.abs(x).max(), np.abs(damped["s2"]).max() * 1e3, rtol=1e-12)
    fig = plots.plot_storey_shear(damped, 1, units="kN", title="")
    assert fig.axes[0].get_title() == "" and fig.axes[0].get_ylabel() == "storey shear [kN]"
    with pytest.raises(ValueError, match="furlong"):
        plots.plot_acceleration(damped, 1, units="furlong")
    with pytest.raises(TypeError, match="t_rang"):  # a misspelt option is not ignored
        plots.plot_drift(damped, 1, t_rang=(0.0, 1.0))


def test_profiles_over_the_height_are_the_summary_peaks(damped, bare):
    fig = plots.plot_drift_profile([bare, damped], labels=["bare", "damped"])
    ax = fig.axes[0]
    assert ax.get_xlabel() == "drift ratio [%]" and ax.get_ylabel() == "height [m]"
    lines = [ln for ln in ax.get_lines() if ln.get_linestyle() == "-"]
    for ln, r in zip(lines, [bare, damped], strict=True):
        xs, ys = ln.get_data()
        np.testing.assert_allclose(xs[::2], 100 * np.array(r.summary["peak_drift_ratio"]))
        assert list(ys) == [0.0, 4.0, 4.0, 7.5, 7.5, 11.0, 11.0, 14.5, 14.5, 18.0]
    fig = plots.plot_drift_profile(damped, ratio=False, residual=True, units="mm")
    assert fig.axes[0].get_xlabel() == "drift [mm]"
    fig = plots.plot_acceleration_profile([bare, damped], units="g")
    ln = fig.axes[0].get_lines()[1]
    xs, ys = ln.get_data()
    assert list(ys) == [0.0, 4.0, 7.5, 11.0, 14.5, 18.0]
    np.testing.assert_allclose(xs[1:], np.array(damped.summary["peak_aabs_mps2"]) / G0)
    np.testing.assert_allclose(xs[0], np.abs(damped["ag"]).max() / G0)  # the table's
    with pytest.raises(ValueError, match="no storeys"):
        plots.plot_drift_profile(paper_analysis(4, "velocity", duration=0.1).run())


def test_figures_compose_as_panels_with_title_and_resolution(damped, bare, tmp_path):
    fig, axes = plots.figure(2, 2)
    assert axes.shape == (2, 2)
    plots.plot_drift_profile([bare, damped], ax=axes[0, 0])
    plots.plot_acceleration_profile([bare, damped], ax=axes[0, 1])
    got = plots.plot_storey_loop(damped, 1, ax=axes[1, 0])
    plots.plot_base_shear([bare, damped], ax=axes[1, 1], title="Vb")
    assert got is fig and all(len(a.get_lines()) > 0 for a in axes.flat)
    assert axes[1, 1].get_title() == "Vb"
    p1 = plots.save(fig, tmp_path / "a.png", dpi=60)
    p2 = plots.save(fig, tmp_path / "b.png", dpi=180)
    assert p2.stat().st_size > 2 * p1.stat().st_size
    from matplotlib.image import imread

    assert imread(p2).shape[1] == 3 * imread(p1).shape[1]  # the same figure, 3x the pixels
    fig = plots.plot_drift(damped, 3, path=tmp_path / "d.png", dpi=80)
    assert (tmp_path / "d.png").is_file() and fig.axes[0].get_title() == "storey 3: drift"


def test_plot_all_adds_the_storey_plots(damped, tmp_path):
    paths = plots.plot_all(damped, tmp_path, "b5", units="mm,kN,g", max_items=2)
    names = [p.name for p in paths]
    assert "b5_drift_profile.png" in names and "b5_acceleration_profile.png" in names
    assert "b5_storey_loop2.png" in names and "b5_storey_loop3.png" not in names
    assert all(p.stat().st_size > 5000 for p in paths)


def test_plot_all_titles_name_the_run(damped, tmp_path, monkeypatch):
    """Every figure plot_all writes (what run --plot and plot write) names the run in its
    title: the deck's name before the panel's own title."""
    titles = {}
    real_save = plots.save

    def save(fig, path, dpi=None):
        sup = fig._suptitle.get_text() if fig._suptitle is not None else ""
        titles[Path(path).name] = sup or next(a.get_title() for a in fig.axes if a.get_title())
        return real_save(fig, path, dpi)

    monkeypatch.setattr(plots, "save", save)
    paths = plots.plot_all(damped, tmp_path, "b5", kinds="key")
    assert sorted(titles) == sorted(p.name for p in paths) and len(paths) >= 4
    name = plots.default_label(damped, 0)
    assert name == "building5_dampers"
    assert titles["b5_drift_profile.png"] == f"{name}: peak inter-storey drift"
    assert all(t.startswith(f"{name}: ") for t in titles.values()), titles
