"""The overturning of rigid floors on planar bearings (&bearings overturning = .true.).

The floors a storey of bearings carries are one rigid body on the bearings' equal vertical
supports: the inertia forces m a (a the floor's absolute horizontal acceleration) at the
floors' heights above the bearing plane have the moments O = (sum m h a_x, sum m h a_y), which
the bearings share linearly in plan about their centroid, dN_b = -r'_b' S^-1 O (S = sum r' r'),
so that sum dN = 0 and sum r' dN = -O. N = p (1 + a_z / g) + dN, taken at each step's start
from the accelerations of the accepted state (docs/theory.md 5.7).

- a block at height h on four bearings in two rows d apart under a horizontal base
  acceleration a: dN = -+ m a h / (2 d) on the rows once the block moves with the ground, and
  sum dN = 0 at every step;
- a skewed layout under a diagonal acceleration: dN linear in plan, sum 0, moment balance
  (the general 2x2 form);
- the lag of the step's start: the error of N is first order in the step;
- overturning = .false. (and not given) is the run without it, to the bit;
- uplift on the lifted row, timed where the closed form puts it, warned;
- the energy balance closes; the history's N columns hold the summary's extremes.
"""
from __future__ import annotations

import numpy as np
import pytest

import frictiondyn
from conftest import deck_text

G = 9.80665
M0 = 5.0e4         # the base mat, in the bearing plane [kg]
M = 1.0e5          # the block on it, stiff frames between [kg]
H = 3.0            # the block's height above the bearing plane [m]
D = 6.0            # the rows' distance along x [m]
E = 4.0            # along y [m]
DT = 0.01
X4 = [-D / 2, D / 2, D / 2, -D / 2]
Y4 = [-E / 2, -E / 2, E / 2, E / 2]


def write_record(tmp_path, name: str, values) -> None:
    (tmp_path / name).write_text("".join(f"{v:.17e}\n" for v in values))


def record(name: str) -> dict:
    return {"excitation_type": "record", "record_file": name, "record_format": "values",
            "record_units": "m/s2", "dt_record": DT}


def block(x, y, ax: str, duration: float, ay: str | None = None, mu: float = 0.3, n1: int = 4,
          overturning: bool | None = True, integration: dict | None = None, **bearing) -> dict:
    """A block (floor 2, mass M, at height H above the bearing plane, on stiff damped frames)
    on a base mat (floor 1, mass M0, in the plane) on bearings at (x, y) of storey 1, under the
    x record `ax` (and the y record `ay`); velocity-law bearings under Newmark unless told
    (`integration`, the bearings' `law`: 'coulomb' takes no eps)."""
    n = len(x)
    b = {"n_bearings": n, "storey": [1] * n, "x": list(x), "y": list(y), "mu": [mu] * n,
         "law": ["velocity"] * n, "eps": [1.0e-3] * n, **bearing}
    if b["law"][0] == "coulomb":
        b.pop("eps")
    if overturning is not None:
        b["overturning"] = overturning
    g = {
        "floors": {"n_floors": 2, "mass": [M0, M], "plan_x": [10.0, 10.0], "plan_y": [8.0, 8.0],
                   "height": [0.0, H]},
        "frames": {"n_frames": 4, "storey": [2] * 4, "angle": [0.0, 0.0, 90.0, 90.0],
                   "x": [0.0, 0.0, -4.0, 4.0], "y": [-3.0, 3.0, 0.0, 0.0], "k": [1.0e9] * 4},
        "damping": {"damping_type": "rayleigh", "rayleigh_a0": 0.0, "rayleigh_a1": 0.002},
        "bearings": b,
        "excitation": {**record(ax), "duration": duration},
        "integration": integration if integration is not None else {"n1": n1, "n2": 10},
        "output": {"dir": "out", "output_every": 1},
    }
    if ay is not None:
        g["excitation2"] = {**record(ay), "duration": duration}
    return g


def run(tmp_path, g: dict, name: str) -> frictiondyn.Result:
    return frictiondyn.run_text(deck_text(g), name, tmp_path)


def normal_forces(r: frictiondyn.Result, n: int) -> np.ndarray:
    return np.array([r[f"N{b + 1}"] for b in range(n)])


def hold(tmp_path, name: str, a: float, duration: float = 1.0) -> None:
    """A base acceleration rising smoothly to a over 0.2 s, then held."""
    t = np.arange(0.0, duration + DT / 2, DT)
    write_record(tmp_path, name, a * np.where(t < 0.2, 0.5 - 0.5 * np.cos(np.pi * t / 0.2), 1.0))


def test_block_on_two_rows_takes_m_a_h_over_2d(tmp_path):
    """A base acceleration held at a = 0.1 g along x (mu = 0.3: the block follows the ground,
    creeping in the velocity law's band): the row at -d/2 takes + m a h / (2 d) each bearing,
    the row at +d/2 loses as much; sum dN = 0 at every step."""
    a = 0.1 * G
    hold(tmp_path, "ax.txt", a)
    r = run(tmp_path, block(X4, Y4, "ax.txt", 1.0, eps=[0.05] * 4), "rows.nml")
    n = normal_forces(r, 4)
    p = (M0 + M) * G / 4
    dn = M * a * H / (2 * D)
    steady = r["t"] > 0.6
    expected = np.array([p + dn, p - dn, p - dn, p + dn])
    for b in range(4):
        assert np.allclose(n[b][steady], expected[b], rtol=1e-9, atol=0.0), b
    # the rows share the moment and nothing else, at every state
    assert np.allclose(n.sum(axis=0), 4 * p, rtol=1e-13, atol=0.0)
    assert r.summary["bearing_max_normal_force_N"][0] == pytest.approx(p + dn, rel=1e-6)
    assert r.summary["bearing_min_normal_force_N"][1] == pytest.approx(p - dn, rel=1e-6)
    assert r.summary["bearing_uplift_count"] == [0] * 4


def test_skewed_layout_under_diagonal_motion_takes_the_2x2_form(tmp_path):
    """Three bearings at the corners of a skewed triangle (S not diagonal) under a constant base
    acceleration along x and y: dN is linear in plan, sums to 0 and balances the moment
    (sum r' dN = -m h a), the general 2x2 form."""
    ax, ay = 0.08 * G, -0.05 * G
    hold(tmp_path, "ax.txt", ax)
    hold(tmp_path, "ay.txt", ay)
    x = np.array([-3.0, 4.0, 1.5])
    y = np.array([-2.0, -1.0, 3.5])
    r = run(tmp_path, block(x.tolist(), y.tolist(), "ax.txt", 1.0, ay="ay.txt", eps=[0.05] * 3), "skew.nml")
    n = normal_forces(r, 3)
    p = (M0 + M) * G / 3
    xr, yr = x - x.mean(), y - y.mean()
    s = np.array([[xr @ xr, xr @ yr], [xr @ yr, yr @ yr]])
    assert abs(s[0, 1]) > 0.1 * s[0, 0]
    arm = np.linalg.solve(s, np.array([xr, yr]))
    expected = p - arm.T @ np.array([M * H * ax, M * H * ay])
    steady = r["t"] > 0.6
    for b in range(3):
        assert np.allclose(n[b][steady], expected[b], rtol=1e-9, atol=0.0), b
    dn = n[:, -1] - p
    assert abs(dn.sum()) < 1e-9 * p
    assert xr @ dn == pytest.approx(-M * H * ax, rel=1e-9)
    assert yr @ dn == pytest.approx(-M * H * ay, rel=1e-9)


def test_overturning_off_is_the_run_without_it_to_the_bit(tmp_path):
    """overturning = .false. given is the deck without it; the N columns hold p."""
    t = np.arange(0.0, 2.0 + DT / 2, DT)
    write_record(tmp_path, "ax.txt", 2.0 * np.sin(2 * np.pi * 1.5 * t))
    a = run(tmp_path, block(X4, Y4, "ax.txt", 2.0, mu=0.1, overturning=False), "off.nml")
    b = run(tmp_path, block(X4, Y4, "ax.txt", 2.0, mu=0.1, overturning=None), "none.nml")
    assert a.names == b.names
    for col in a.names:
        assert np.array_equal(a[col], b[col]), col
    assert np.all(normal_forces(a, 4) == (M0 + M) * G / 4)
    on = run(tmp_path, block(X4, Y4, "ax.txt", 2.0, mu=0.1), "on.nml")
    assert not np.array_equal(on["u1"], a["u1"])


def ramp(tmp_path, t_end: float, a_end: float) -> None:
    t = np.arange(0.0, t_end + DT / 2, DT)
    write_record(tmp_path, "ramp.txt", a_end * t / t_end)


def test_uplift_from_overturning_is_counted_timed_and_warned(tmp_path):
    """A base acceleration ramping to 0.5 g on a block twice as high as its rows are apart: the
    row at +d/2 lifts off where m a h / (2 d) reaches its share (m0 + m) g / 4 (within the steps
    the lag and the transient take); the other row never does."""
    t_end, a_end, h = 2.0, 0.5 * G, 2.0 * D
    ramp(tmp_path, t_end, a_end)
    g = block(X4, Y4, "ramp.txt", t_end, mu=0.6)
    g["floors"]["height"] = [0.0, h]
    with pytest.warns(frictiondyn.FrictiondynWarning, match="bearing-uplift"):
        r = run(tmp_path, g, "lift.nml")
    s = r.summary
    t_lift = t_end * ((M0 + M) * G * D / (2 * M * h)) / a_end
    assert s["bearing_uplift_count"] == [0, 1, 1, 0]
    for b in (1, 2):
        assert s["bearing_uplift_first_time_s"][b] == pytest.approx(t_lift, abs=2 * DT)
        assert s["bearing_min_normal_force_N"][b] < 0.0
    warning = [w for w in s["warnings"] if "lifted off" in w]
    assert len(warning) == 1 and "docs/warnings.md#bearing-uplift" in warning[0]


def test_the_lag_is_first_order_in_the_step(tmp_path):
    """N takes the accelerations of the step's start, an error first order in the step. Skewed
    friction pendulums whose band holds the whole motion (eps = 2 m/s: linear dashpots P mu / eps,
    no phase change) twist the block as their N differ: the floor's rotation converges at second
    order without the overturning (Newmark's average acceleration), and the overturning's own
    effect on it (the run with it less the run without) at first order."""
    t = np.arange(0.0, 2.0 + DT / 2, DT)
    write_record(tmp_path, "ax.txt", 3.0 * np.sin(2 * np.pi * t))
    x, y = [-3.0, 4.0, 1.5], [-2.0, -1.0, 3.5]
    rz = {}
    for on in (True, False):
        for n1 in (4, 8, 16, 512):
            g = block(x, y, "ax.txt", 2.0, n1=n1, mu=0.05, overturning=on, radius=[2.0] * 3, eps=[2.0] * 3)
            rz[on, n1] = run(tmp_path, g, f"twist{n1}{on}.nml")["u3"][::n1]
    steps = (4, 8, 16)

    def orders(series):
        e = np.array([np.max(np.abs(series(n) - series(512))) for n in steps])
        return np.log2(e[:-1] / e[1:])

    assert np.all(np.abs(orders(lambda n: rz[False, n]) - 2.0) < 0.05)
    assert np.all(np.abs(orders(lambda n: rz[True, n] - rz[False, n]) - 1.0) < 0.1)
    assert np.max(np.abs(rz[True, 512] - rz[False, 512])) > 0.005 * np.max(np.abs(rz[True, 512]))


@pytest.mark.parametrize("law", ["velocity", "hysteretic"])
def test_energy_balance_closes_and_history_holds_the_extremes(tmp_path, law):
    """A harmonic base motion along x and y with the overturning on (a pendulum, sliding): the
    balance closes to round-off; each bearing's N column's extremes are the summary's (one
    history row a step, no refined steps: n2 = 1)."""
    t = np.arange(0.0, 2.0 + DT / 2, DT)
    write_record(tmp_path, "ax.txt", 3.0 * np.sin(2 * np.pi * 1.5 * t))
    write_record(tmp_path, "ay.txt", 2.0 * np.cos(2 * np.pi * 1.1 * t))
    extra = {"law": [law] * 4, "radius": [2.0] * 4}
    if law == "hysteretic":
        extra["f"] = [2.0e-4] * 4
        extra.pop("law")
        extra["law"] = ["hysteretic"] * 4
    g = block(X4, Y4, "ax.txt", 2.0, ay="ay.txt", mu=0.1, **extra)
    if law == "hysteretic":
        g["bearings"].pop("eps")
    g["integration"]["n2"] = 1
    r = run(tmp_path, g, "energy.nml")
    s = r.summary
    assert s["energy_balance"] == "closed"
    assert abs(s["energy_residual_ratio"]) < 1.0e-10
    n = normal_forces(r, 4)
    assert list(n.min(axis=1)) == s["bearing_min_normal_force_N"]
    assert list(n.max(axis=1)) == s["bearing_max_normal_force_N"]
    assert np.ptp(n[0]) > 0.05 * (M0 + M) * G / 4


@pytest.mark.parametrize("change, words", [
    ({"floors": {"height": [0.0, 0.0]}}, ["&bearings", "overturning", "height(2)"]),
    ({"bearings": {"x": [-3.0, 0.0, 3.0, 6.0], "y": [1.0, 1.0, 1.0, 1.0]}}, ["&bearings", "overturning",
                                                                              "storey = 1", "line"]),
    ({"integration": {"technique": "event_driven"}, "bearings": {"law": ["coulomb"] * 4}},
     ["technique = 'event_driven' does not integrate planar bearings", "'moreau_jean'"]),
])
def test_what_the_overturning_cannot_take_is_refused(tmp_path, change, words):
    write_record(tmp_path, "ax.txt", [1.0] * 101)
    g = block(X4, Y4, "ax.txt", 1.0)
    for group, values in change.items():
        g[group].update(values)
    if "law" in change.get("bearings", {}) and change["bearings"]["law"][0] == "coulomb":
        g["bearings"].pop("eps")
    with pytest.raises(frictiondyn.FrictiondynError) as err:
        run(tmp_path, g, "bad.nml")
    # The folder's name holds the test's name ("overturning"): only the message itself counts.
    message = str(err.value).replace(str(tmp_path), "<dir>")
    for w in words:
        assert w in message, (w, message)
