"""The isolation system's outputs of planar bearings (&bearings): each bearing's travel
(`bearing_slip_travel_m`) and reversals (`bearing_slip_reversals`), and the bearings' shear
along x, y and its resultant (`peak_isolation_shear_x_N`, `_y_N`, `peak_isolation_shear_N`).

- A friction pendulum released from 7.3 mu R decays along its line of release as the 1D
  Coulomb oscillator: it travels 12.6 + 8.6 + 4.6 + 0.6 = 26.4 mu R, never reverses while
  sliding (it stops at each turning point), and its shear peaks at the release, (P/R) 7.3 mu R.
- A block on a flat slider in a steady circular orbit: the travel is the orbit's radius times
  the angle swept, the resultant shear is mu P, and the sliding direction turns back twice a
  revolution; the travel and the reversals are the history's, step by step, exactly.
- Along one axis, the bearing's reversals are the 1D device's slip_reversals (a coarse run
  that reverses without sticking).
- A block of a rigid floor on four friction pendulums under two components: the isolation
  shear along x and y is the base shear along x and y (friction and restoring forces).
"""
from __future__ import annotations

import math

import numpy as np
import pytest

import frictiondyn
from conftest import deck_text

G = 9.80665
M = 1000.0


def mtx(diagonal) -> str:
    n = len(diagonal)
    return ("%%MatrixMarket matrix coordinate real symmetric\n" f"{n} {n} {n}\n"
            + "".join(f"{i + 1} {i + 1} {v!r}\n" for i, v in enumerate(diagonal)))


# ---------------------------------------------------------------- friction pendulum

MU_P, RADIUS, X0 = 0.05, 1.0, 7.3


@pytest.mark.parametrize("angle", [0.0, 30.0])
@pytest.mark.parametrize("law", [{"law": "hysteretic", "f": 1.0e-5, "eps1": 1.0e-4},
                                 {"law": "velocity", "eps": 1.0e-5}], ids=["hysteretic", "velocity"])
def test_friction_pendulum_travel_and_shear_are_the_closed_form(tmp_path, law, angle):
    """Released at rest from X0 mu R along `angle`: the turning points 7.3, -5.3, 3.3, -1.3 mu R
    and the stop at -0.7 mu R give a travel of 26.4 mu R (to the stop's 3e-3, tests/test_bearings.py);
    every turn is a stop (no reversal while sliding); the shear (P/R) s + F is largest at the
    release, where the friction force is 0: (P/R) X0 mu R = X0 mu P along the line of release."""
    c, s = math.cos(math.radians(angle)), math.sin(math.radians(angle))
    x0 = X0 * MU_P * RADIUS
    groups = {
        "model": {"n_dof": 2, "mass": [M, M], "u0": [x0 * c, x0 * s]},
        "springs": {"n_springs": 0},
        "damping": {"damping_type": "none"},
        "bearings": {"n_bearings": 1, "dof_xi": 1, "dof_yi": 2, "dof_xj": 0, "dof_yj": 0,
                     "p": M * G, "mu": MU_P, "radius": RADIUS, **law},
        "excitation": {"excitation_type": "none", "dt_record": 0.01, "duration": 6.0},
        "output": {"dir": "out"},
    }
    sm = frictiondyn.run_text(deck_text(groups), "pendulum.nml", tmp_path).summary
    assert sm["bearing_slip_travel_m"][0] == pytest.approx(26.4 * MU_P * RADIUS, rel=3e-4)
    assert sm["bearing_slip_reversals"] == [0]
    mup = MU_P * M * G
    assert sm["peak_isolation_shear_N"] == pytest.approx(X0 * mup, rel=1e-12)
    assert sm["peak_isolation_shear_time_s"] == 0.0
    assert sm["peak_isolation_shear_x_N"] == pytest.approx(X0 * mup * c, rel=1e-12)
    if s == 0.0:
        assert sm["peak_isolation_shear_y_N"] == 0.0 and sm["peak_isolation_shear_y_time_s"] is None
    else:
        assert sm["peak_isolation_shear_y_N"] == pytest.approx(X0 * mup * s, rel=1e-12)


# ---------------------------------------------------------------- circular orbit

W = 2.0 * math.pi   # table circular frequency [rad/s]
MU, K, A0 = 0.1, 1.0e4, 1.0
AMP = 2.0 * MU * G / W**2


def orbit_radius() -> float:
    """The steady orbit of m z'' + c z' + k z = -m a_g - mu m g z'/|z'| (tests/test_bearings.py)."""
    c = A0 * M
    qa = (K - M * W**2) ** 2 + (c * W) ** 2
    qb = 2.0 * c * W * MU * M * G
    qc = (MU * M * G) ** 2 - (M * AMP * W**2) ** 2
    return (-qb + math.sqrt(qb * qb - 4.0 * qa * qc)) / (2.0 * qa)


def turns(fx: np.ndarray, fy: np.ndarray) -> int:
    """Reversals of a direction sampled along one slide: each 180 degrees it turned."""
    turn = 0.0
    for k in range(1, len(fx)):
        turn += math.atan2(fx[k - 1] * fy[k] - fy[k - 1] * fx[k], fx[k - 1] * fx[k] + fy[k - 1] * fy[k])
    return int(abs(turn) // math.pi)


def orbit(tmp_path, duration: float) -> frictiondyn.Result:
    dt = 0.001
    t = np.arange(0.0, duration + dt / 2, dt)
    for name, a in (("ax.txt", -AMP * W**2 * np.cos(W * t)), ("ay.txt", -AMP * W**2 * np.sin(W * t))):
        (tmp_path / name).write_text("".join(f"{v:.17e}\n" for v in a))
    (tmp_path / "K.mtx").write_text(mtx([K, K]))
    (tmp_path / "M.mtx").write_text(mtx([M, M]))
    rec = {"excitation_type": "record", "record_format": "values", "record_units": "m/s2", "dt_record": dt}
    groups = {
        "matrices": {"k_file": "K.mtx", "m_file": "M.mtx", "influence": [1.0, 0.0], "influence2": [0.0, 1.0]},
        "damping": {"damping_type": "rayleigh", "rayleigh_a0": A0, "rayleigh_a1": 0.0},
        "bearings": {"n_bearings": 1, "dof_xi": 1, "dof_yi": 2, "dof_xj": 0, "dof_yj": 0, "p": M * G,
                     "mu": MU, "law": "velocity", "eps": 1.0e-4},
        "excitation": {**rec, "record_file": "ax.txt"},
        "excitation2": {**rec, "record_file": "ay.txt"},
        "integration": {"n1": 1},
        "output": {"dir": "out"},
    }
    return frictiondyn.run_text(deck_text(groups), "orbit.nml", tmp_path)


def test_circular_orbit_travel_shear_and_reversals(tmp_path):
    """The run to 8 s and the same run to 6 s: the travel between them is the steady orbit's
    radius times the two revolutions' 4 pi (the velocity law's first-order error in dt1,
    tests/test_bearings.py), and the history's path, row by row, to the chords of the steps
    between rows (each row a dt1 step; the refined steps' chords are shorter than the arc by
    (w h)^2 / 24)."""
    r = orbit(tmp_path, 8.0)
    sm = r.summary
    r6 = orbit(tmp_path, 6.0).summary
    travel = sm["bearing_slip_travel_m"][0] - r6["bearing_slip_travel_m"][0]
    assert travel == pytest.approx(orbit_radius() * 4.0 * math.pi, rel=2e-3)
    path = np.hypot(np.diff(r["s1"]), np.diff(r["s2"]))
    assert travel == pytest.approx(path[r["t"][1:] > 6.0 + 1e-9].sum(), rel=1e-6)
    # sliding outside the disc the force is mu P along the velocity: the resultant shear
    assert sm["peak_isolation_shear_N"] == pytest.approx(MU * M * G, rel=1e-12)
    assert max(sm["peak_isolation_shear_x_N"], sm["peak_isolation_shear_y_N"]) <= MU * M * G * (1 + 1e-12)
    # one slide from the first step that leaves the disc: its force turns back twice a revolution
    phase = r["phase1"]
    start = int(np.argmax(phase != 0))
    assert np.all(phase[start:] != 0)
    n = sm["bearing_slip_reversals"][0]
    assert n == turns(r["F1"][start:], r["F2"][start:])
    assert 2 * 8 - 2 <= n <= 2 * 8


# ---------------------------------------------------------------- along one axis


def test_reversals_along_one_axis_are_the_one_dimensional_devices(tmp_path):
    """The paper's Fig. 3 model (coarse steps, no correctness check: the device reverses
    without sticking) with the device a planar bearing between the two masses, moving along x:
    the bearing's reversals are the 1D device's."""
    m1, m2, k1, k2 = 6.301, 2.530, 1084.0, 2895.0
    (tmp_path / "K.mtx").write_text(mtx([k1, k1, k2, k2]))
    (tmp_path / "M.mtx").write_text(mtx([m1, m1, m2, m2]))
    fr = {"law": "hysteretic", "p": 61.81, "mu": 0.22, "f": 1.0e-5, "eps1": 1.0e-3}
    common = {"damping": {"damping_type": "stiffness", "xi": 0.015, "period": 0.296},
              "excitation": {"excitation_type": "harmonic", "amplitude": 0.004052, "frequency": 4.104,
                             "dt_record": 0.005, "duration": 10.0},
              "integration": {"n1": 2, "n2": 2, "n": 10, "check_correctness": False}, "output": {"dir": "out"}}
    oned = {"model": {"n_dof": 2, "mass": [m1, m2]},
            "springs": {"n_springs": 2, "node_i": [1, 2], "node_j": [0, 0], "k": [k1, k2]},
            "friction": {"n_devices": 1, "node_i": 1, "node_j": 2, **fr}, **common}
    planar = {"matrices": {"k_file": "K.mtx", "m_file": "M.mtx", "influence": [1.0, 0.0, 1.0, 0.0]},
              "bearings": {"n_bearings": 1, "dof_xi": 1, "dof_yi": 2, "dof_xj": 3, "dof_yj": 4, **fr}, **common}
    with pytest.warns(frictiondyn.FrictiondynWarning):
        a = frictiondyn.run_text(deck_text(oned), "oned.nml", tmp_path)
        b = frictiondyn.run_text(deck_text(planar), "planar.nml", tmp_path)
    assert np.max(np.abs(a["s1"] - b["s1"])) <= 1e-12 * np.max(np.abs(a["s1"]))
    assert a.summary["slip_reversals"][0] > 50
    assert b.summary["bearing_slip_reversals"] == a.summary["slip_reversals"]
    assert b.summary["peak_isolation_shear_N"] == a.summary["peak_force_N"][0]
    # the correctness condition is the bearing's, on its resultant: one (step, bearing) pair
    # per violation, as the 1D device's, not one per component
    assert a.summary["correctness_violations"] > 0
    assert b.summary["correctness_violations"] == a.summary["correctness_violations"]


# ---------------------------------------------------------------- a block on four pendulums


def test_isolation_shear_of_a_block_is_its_base_shear(tmp_path):
    """A rigid floor on four friction pendulums, nothing else below it and no damping: the
    bearings carry the whole base shear, along x and along y, friction and restoring force, and
    so does storey 1's shear."""
    dt, dur = 0.01, 4.0
    t = np.arange(0.0, dur + dt / 2, dt)
    for name, a in (("ax.txt", 2.0 * np.sin(2 * math.pi * 0.7 * t)), ("ay.txt", 1.5 * np.sin(2 * math.pi * 1.1 * t))):
        (tmp_path / name).write_text("".join(f"{v:.17e}\n" for v in a))
    rec = {"excitation_type": "record", "record_format": "values", "record_units": "m/s2", "dt_record": dt}
    groups = {
        "floors": {"n_floors": 1, "mass": 1.0e5, "plan_x": 10.0, "plan_y": 6.0},
        "frames": {"n_frames": 0},
        "damping": {"damping_type": "none"},
        "bearings": {"n_bearings": 4, "storey": [1, 1, 1, 1], "x": [-5.0, 5.0, 5.0, -5.0],
                     "y": [-3.0, -3.0, 3.0, 3.0], "law": ["hysteretic"] * 4, "mu": [0.06] * 4,
                     "f": [1.0e-4] * 4, "eps1": [1.0e-4] * 4, "radius": [2.0] * 4},
        "excitation": {**rec, "record_file": "ax.txt"},
        "excitation2": {**rec, "record_file": "ay.txt"},
        "integration": {"n1": 10},
        "output": {"dir": "out"},
    }
    sm = frictiondyn.run_text(deck_text(groups), "block.nml", tmp_path).summary
    assert min(sm["bearing_slip_travel_m"]) > 2 * max(sm["bearing_peak_displacement_m"])  # it slid to and fro
    assert sm["peak_isolation_shear_x_N"] == pytest.approx(sm["peak_base_shear_x_N"], rel=1e-9)
    assert sm["peak_isolation_shear_y_N"] == pytest.approx(sm["peak_base_shear_y_N"], rel=1e-9)
    assert sm["peak_isolation_shear_x_time_s"] == pytest.approx(sm["peak_base_shear_x_time_s"], abs=1e-12)
    # the storey of the bearings passes their friction and restoring forces alike
    assert sm["peak_storey_shear_N"] == pytest.approx([sm["peak_base_shear_x_N"], sm["peak_base_shear_y_N"]],
                                                      rel=1e-9)
    x, y = sm["peak_isolation_shear_x_N"], sm["peak_isolation_shear_y_N"]
    assert max(x, y) <= sm["peak_isolation_shear_N"] <= math.hypot(x, y)
