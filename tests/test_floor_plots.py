"""The plots of a building of rigid floors, checked on the data they draw: the roof's
orbit (its extent is the summary's peak displacements) and the plan of the braces (each at
its plan position along its angle, coloured by its peak force)."""

import numpy as np
import pytest

from conftest import ok
from test_floor_outputs import building

import frictiondyn as fd
from frictiondyn import plots


@pytest.fixture(scope="module")
def b3d():
    return fd.run("inputs/building3d.nml")


def test_orbit_spans_the_peaks(run):
    """A history at every step of a run without refinement (its braces stay stuck): the
    centre of mass's orbit reaches the summary's peak |ux| and |uy| of the top floor, and the
    corner's is ux - rz dy, uy + rz dx at a plan corner, the one that goes farthest out."""
    r = ok(run(building(), name="b")).history()
    s = r.summary
    fig = plots.plot_orbit(r)
    cm, corner = fig.axes[0].get_lines()[:2]
    assert np.abs(cm.get_xdata()).max() == pytest.approx(s["peak_u_m"][3], rel=1e-12)
    assert np.abs(cm.get_ydata()).max() == pytest.approx(s["peak_u_m"][4], rel=1e-12)
    ux, uy, rz = (np.asarray(r[f"u{i}"]) for i in (4, 5, 6))
    reach = {(dx, dy): np.hypot(ux - rz * dy, uy + rz * dx).max() for dx in (-10.0, 10.0) for dy in (-6.0, 6.0)}
    dx, dy = max(reach, key=reach.get)
    assert np.array_equal(corner.get_xdata(), ux - rz * dy)
    assert np.array_equal(corner.get_ydata(), uy + rz * dx)
    assert f"({dx:+g}, {dy:+g})" in corner.get_label()


def test_orbit_in_units(b3d):
    fig = plots.plot_orbit(b3d, units="mm")
    cm = fig.axes[0].get_lines()[0]
    assert np.abs(cm.get_xdata()).max() == pytest.approx(1000 * np.abs(b3d["u7"]).max(), rel=1e-12)
    assert fig.axes[0].get_xlabel() == "ux [mm]"


def test_device_plan_draws_each_brace_where_it_is_with_its_peak_force(b3d):
    s = b3d.summary
    fig = plots.plot_device_plan(b3d)
    panels = [ax for ax in fig.axes if ax.get_title().startswith("storey")]
    assert [ax.get_title() for ax in panels] == ["storey 1", "storey 2", "storey 3"]
    for st, ax in enumerate(panels, start=1):
        (lc,) = ax.collections
        devices = [d for d in range(6) if s["device_storey"][d] == st]
        assert np.array_equal(lc.get_array(), [s["peak_force_N"][d] for d in devices])
        for seg, d in zip(lc.get_segments(), devices, strict=True):
            mid = np.asarray(seg).mean(axis=0)
            assert mid == pytest.approx([s["device_plan_x_m"][d], s["device_plan_y_m"][d]], abs=1e-12)
            direction = np.diff(np.asarray(seg), axis=0)[0]
            angle = np.degrees(np.arctan2(direction[1], direction[0]))
            assert angle == pytest.approx(s["device_angle_deg"][d], abs=1e-9)
    # the braces along x at y = -6 m and along y at x = 8 m
    assert s["device_plan_y_m"][0::2] == [-6.0] * 3 and s["device_plan_x_m"][1::2] == [8.0] * 3


def test_plots_need_rigid_floors():
    r = fd.run("inputs/test4_velocity.nml")
    with pytest.raises(ValueError, match="not a building of rigid floors"):
        plots.plot_orbit(r)
    with pytest.raises(ValueError, match="not a building of rigid floors"):
        plots.plot_device_plan(r)


def test_run_plot_writes_the_orbit_and_the_plan(b3d, tmp_path):
    written = plots.plot_all(b3d, tmp_path, "b3d", kinds="key")
    names = {p.name for p in written}
    assert {"b3d_orbit.png", "b3d_device_plan.png", "b3d_drift_profile.png"} <= names
    assert all(p.stat().st_size > 0 for p in written)
