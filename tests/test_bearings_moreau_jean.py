"""Planar bearings (&bearings, law = 'coulomb') under the Moreau-Jean technique: exact planar
Coulomb friction, the impulse of each step in the friction disc (docs/theory.md, 12.7).

- Along one axis a bearing is the one-dimensional Coulomb device of Moreau-Jean (&isolators):
  the same run to 1e-12.
- A rigid block on a flat slider under a circular table motion reaches the closed-form steady
  orbit (tests/test_bearings.py's complex amplitude equation), its error falling with the step
  at the measured order.
- A friction pendulum released from an offset along any direction decays as the closed-form
  1D Coulomb oscillator and stops inside the disc mu R.
- The energy balance closes to round-off (theta = 1/2), with several bearings and 1D devices
  coupled through the structure.
- What it cannot do is an error naming the group and the variable.
"""
from __future__ import annotations

import math

import numpy as np
import pytest

import frictiondyn
from frictiondyn import FrictiondynError
from conftest import deck_text
from test_bearings import AMP, A0, G, K, M, MU, MU_P, RADIUS, W, matrices, orbit_radius

MJ = {"technique": "moreau_jean"}


# ---------------------------------------------------------------- motion along one axis

@pytest.mark.parametrize("radius", [0.0, 2.0], ids=["flat", "curved"])
def test_motion_along_one_axis_is_the_one_dimensional_device(tmp_path, radius):
    """A table motion along x: the bearing's x component equals a Coulomb isolator on the x DOF
    under Moreau-Jean (displacement, velocity, force, to 1e-12 of their peaks), nothing moves
    along y, and the bearing's peak and dissipated energy are the isolator's."""
    common = {
        "damping": {"damping_type": "none"},
        "excitation": {"excitation_type": "harmonic", "amplitude": 0.06, "frequency": 1.0,
                       "dt_record": 0.01, "duration": 4.0},
        "integration": {**MJ, "n1": 2},
        "output": {"dir": "out"},
    }
    planar = {"matrices": matrices(tmp_path, 1.0e4, M, False),
              "bearings": {"n_bearings": 1, "dof_xi": 1, "dof_yi": 2, "dof_xj": 0, "dof_yj": 0,
                           "p": M * G, "mu": 0.1, "law": "coulomb", "radius": radius}, **common}
    oned = {"matrices": matrices(tmp_path, 1.0e4, M, False),
            "isolators": {"n_isolators": 1, "node_i": 1, "node_j": 0, "weight": M * G, "mu": 0.1,
                          "law": "coulomb", "radius": radius}, **common}
    a = frictiondyn.run_text(deck_text(planar), "planar.nml", tmp_path)
    b = frictiondyn.run_text(deck_text(oned), "oned.nml", tmp_path)
    pmu = 0.1 * M * G
    assert np.max(b["F1"]) == pytest.approx(pmu, rel=1e-12)   # it slides, both ways
    assert np.min(b["F1"]) == pytest.approx(-pmu, rel=1e-12)
    for col in ("u1", "v1", "s1", "F1", "aabs1"):
        scale = np.max(np.abs(b[col]))
        assert np.max(np.abs(a[col] - b[col])) <= 1.0e-12 * scale, col
    assert np.all(a["u2"] == 0.0) and np.all(a["F2"] == 0.0)
    assert a.summary["bearing_peak_displacement_m"][0] == pytest.approx(b.summary["peak_s_m"][0], rel=1e-12)
    assert a.summary["bearing_dissipated_energy_J"][0] == pytest.approx(b.summary["dissipated_energy_J"][0],
                                                                        rel=1e-12)
    assert abs(a.summary["energy_residual_ratio"]) < 1.0e-12


# ---------------------------------------------------------------- circular orbit

def circular_run(tmp_path, dt_record: float, n1: int) -> frictiondyn.Result:
    """The block on a flat Coulomb slider under the circular table motion of two components."""
    t = np.arange(0.0, 12.0 + dt_record / 2, dt_record)
    (tmp_path / "ax.txt").write_text("".join(f"{v:.17e}\n" for v in -AMP * W**2 * np.cos(W * t)))
    (tmp_path / "ay.txt").write_text("".join(f"{v:.17e}\n" for v in -AMP * W**2 * np.sin(W * t)))
    rec = {"excitation_type": "record", "record_format": "values", "record_units": "m/s2",
           "dt_record": dt_record}
    groups = {
        "matrices": matrices(tmp_path, K, M, True),
        "damping": {"damping_type": "rayleigh", "rayleigh_a0": A0, "rayleigh_a1": 0.0},
        "bearings": {"n_bearings": 1, "dof_xi": 1, "dof_yi": 2, "dof_xj": 0, "dof_yj": 0,
                     "p": M * G, "mu": MU, "law": "coulomb"},
        "excitation": {**rec, "record_file": "ax.txt"},
        "excitation2": {**rec, "record_file": "ay.txt"},
        "integration": {**MJ, "n1": n1},
        "output": {"dir": "out"},
    }
    return frictiondyn.run_text(deck_text(groups), "orbit.nml", tmp_path)


def orbit_of(res: frictiondyn.Result) -> float:
    """The relative orbit's radius, mean of |u| over the last two seconds (two periods)."""
    last = res["t"] >= 10.0 - 1e-9
    r = np.hypot(res["u1"][last], res["u2"][last])
    assert np.ptp(r) < 1.0e-4 * np.mean(r)   # a circle about the origin
    return float(np.mean(r))


def test_circular_orbit_is_reached_at_the_measured_order(tmp_path):
    """Steady sliding along a circle: the friction impulse of each step lies on the disc's rim
    along the velocity at the step's end, a quarter of a step's turn ahead of the mean; the
    orbit tends to the closed form at first order in the step (measured 1.02 and 1.01; the
    record sampled at the step, n1 = 1, so that no interpolation of the table motion adds its
    own error), the resultant friction force is P mu throughout and the energy balance closes
    to round-off (theta = 1/2)."""
    exact = orbit_radius()
    errors = []
    for dt in (0.004, 0.002, 0.001):
        res = circular_run(tmp_path, dt, 1)
        errors.append(abs(orbit_of(res) - exact) / exact)
        assert abs(res.summary["energy_residual_ratio"]) < 1.0e-12
        last = res["t"] >= 10.0 - 1e-9
        f = np.hypot(res["F1"][last], res["F2"][last])
        assert np.max(np.abs(f - MU * M * G)) <= 1.0e-12 * MU * M * G
    assert errors[-1] < 2.0e-3
    orders = [math.log2(errors[k] / errors[k + 1]) for k in range(2)]
    assert all(0.9 < q < 1.1 for q in orders), (errors, orders)


# ---------------------------------------------------------------- friction pendulum

def pendulum_run(tmp_path, angle: float, n1: int) -> frictiondyn.Result:
    """The block (x: DOF 1, y: DOF 2) on a Coulomb friction pendulum released at rest from
    7.3 mu R along `angle`, the table at rest."""
    x0 = 7.3 * MU_P * RADIUS
    groups = {
        "model": {"n_dof": 2, "mass": [M, M], "u0": [x0 * math.cos(math.radians(angle)),
                                                     x0 * math.sin(math.radians(angle))]},
        "springs": {"n_springs": 0},
        "damping": {"damping_type": "none"},
        "bearings": {"n_bearings": 1, "dof_xi": 1, "dof_yi": 2, "dof_xj": 0, "dof_yj": 0,
                     "p": M * G, "mu": MU_P, "radius": RADIUS, "law": "coulomb"},
        "excitation": {"excitation_type": "none", "dt_record": 0.01, "duration": 6.0},
        "integration": {**MJ, "n1": n1},
        "output": {"dir": "out"},
    }
    return frictiondyn.run_text(deck_text(groups), "pendulum.nml", tmp_path)


@pytest.mark.parametrize("angle", [0.0, 30.0, 135.0])
def test_friction_pendulum_decays_as_the_one_dimensional_oscillator(tmp_path, angle):
    """m x'' + (m g / R) x = -mu m g sgn(x'): the turning points come 2 mu R closer each half
    cycle (7.3, -5.3, 3.3, -1.3 mu R) and the block stops at -0.7 mu R, inside the disc mu R,
    on the line of release, exactly at rest (v = 0) from then on; the friction dissipated the
    strain energy lost."""
    res = pendulum_run(tmp_path, angle, 10)
    d = np.array([math.cos(math.radians(angle)), math.sin(math.radians(angle))])
    along = res["u1"] * d[0] + res["u2"] * d[1]
    across = -res["u1"] * d[1] + res["u2"] * d[0]
    mur = MU_P * RADIUS
    assert np.max(np.abs(across)) < 1.0e-12 * mur
    v = res["v1"] * d[0] + res["v2"] * d[1]
    # the turning points: the extreme positions of each half cycle
    turns = []
    k0 = 1
    for k in range(1, len(v)):
        if v[k - 1] * v[k] < 0.0 or (v[k] == 0.0 and v[k - 1] != 0.0):
            seg = along[k0:k + 1]
            turns.append(seg[np.argmax(np.abs(seg))])
            k0 = k
    assert np.allclose(np.array(turns[1:4]) / mur, [-5.3, 3.3, -1.3], atol=2e-3), np.array(turns) / mur
    final = along[-1] / mur
    assert final == pytest.approx(-0.7, abs=2e-3)
    # it stops at the fourth turning point, four half periods pi sqrt(R / g) after release,
    # and stays at rest: v = 0 exactly in every later sample
    stop = res["t"][np.flatnonzero((res["v1"] != 0.0) | (res["v2"] != 0.0))[-1] + 1]
    assert stop == pytest.approx(4.0 * math.pi * math.sqrt(RADIUS / G), abs=0.02)
    assert res.summary["bearing_residual_displacement_m"][0] < mur
    assert res.summary["bearing_peak_displacement_m"][0] == pytest.approx(7.3 * mur, rel=1e-12)
    k = M * G / RADIUS
    lost = 0.5 * k * ((7.3 * mur) ** 2 - (along[-1]) ** 2)
    assert res.summary["bearing_dissipated_energy_J"][0] == pytest.approx(lost, rel=1e-9)
    assert abs(res.summary["energy_residual_ratio"]) < 1.0e-12


# ---------------------------------------------------------------- several bearings, 1D devices

def two_bodies(tmp_path, technique: str = "moreau_jean", law: str = "coulomb", n1: int = 4) -> dict:
    """Two bodies in the plane (DOFs 1, 2 and 3, 4) on springs: body 1 on a Coulomb friction
    pendulum on the table, body 2 on a flat slider on body 1, and a 1D Coulomb isolator from
    body 2's x DOF to the table, under a table motion along both axes (r = 1)."""
    return {
        "model": {"n_dof": 4, "mass": [2.0 * M, 2.0 * M, M, M]},
        "springs": {"n_springs": 2, "node_i": [3, 4], "node_j": [1, 2], "k": [4.0e4, 2.5e4]},
        "damping": {"damping_type": "none"},
        "bearings": {"n_bearings": 2, "dof_xi": [1, 3], "dof_yi": [2, 4], "dof_xj": [0, 1],
                     "dof_yj": [0, 2], "p": [3.0 * M * G, M * G], "mu": [0.05, 0.08],
                     "radius": [2.5, 0.0], "law": [law, law]},
        "isolators": {"n_isolators": 1, "node_i": 3, "node_j": 0, "weight": 0.2 * M * G, "mu": 0.1,
                      "law": law},
        "excitation": {"excitation_type": "harmonic", "amplitude": 0.12, "frequency": 0.8,
                       "dt_record": 0.01, "duration": 6.0},
        "integration": {"technique": technique, "n1": n1},
        "output": {"dir": "out"},
    }


def test_several_bearings_and_a_one_dimensional_device_together(tmp_path):
    """Block Gauss-Seidel over two coupled bearings and a 1D device (device 1, the isolator;
    the bearings' components after it): every bearing's resultant force stays in its disc
    P mu and reaches it, the 1D device's reaches +-P mu, the energy balance closes to
    round-off, and the run converges with the step (against n1 = 64, the error of body 2's x
    halves from n1 = 8 to 16: measured 2.09e-4 and 9.1e-5)."""
    runs = {n1: frictiondyn.run_text(deck_text(two_bodies(tmp_path, n1=n1)), f"two{n1}.nml", tmp_path)
            for n1 in (8, 16, 64)}
    res = runs[8]
    assert res.summary["device_labels"][:3] == ["isolator 1", "bearing 1 x", "bearing 1 y"]
    for b, pmu in enumerate([0.05 * 3.0 * M * G, 0.08 * M * G]):
        f = np.hypot(res[f"F{2 * b + 2}"], res[f"F{2 * b + 3}"])
        assert np.max(f) <= pmu * (1.0 + 1e-12)
        assert np.max(f) >= pmu * (1.0 - 1e-12)
        assert np.min(np.abs(res[f"F{2 * b + 2}"])) < 0.5 * pmu   # a diagonal force, not along x only
        assert res.summary["bearing_dissipated_energy_J"][b] > 0.0
    assert np.max(np.abs(res["F1"])) == pytest.approx(0.1 * 0.2 * M * G, rel=1e-12)
    assert abs(res.summary["energy_residual_ratio"]) < 1.0e-12
    e8 = np.max(np.abs(runs[8]["u3"] - runs[64]["u3"]))
    e16 = np.max(np.abs(runs[16]["u3"] - runs[64]["u3"]))
    assert 1.5 * e16 < e8 < 4.0 * e16, (e8, e16)


def test_base_mat_on_four_bearings_under_two_components(tmp_path):
    """A two-floor building of rigid floors on four Coulomb friction pendulums under its base
    mat, under two table components: the eight components act on the mat's three DOFs (a
    Delassus operator of rank 3, the bearings redundant), and still every bearing's
    resultant force stays in its disc P mu and reaches it, and the energy balance, with the
    work of both components, closes to round-off."""
    groups = {
        "floors": {"n_floors": 2, "mass": [2.0e5, 2.0e5], "plan_x": [20.0, 20.0], "plan_y": [12.0, 12.0],
                   "height": [1.0, 3.0], "excitation_angle": 30.0},
        "frames": {"n_frames": 4, "storey": [2, 2, 2, 2], "angle": [0.0, 0.0, 90.0, 90.0],
                   "x": [0.0, 0.0, -5.0, 5.0], "y": [-3.0, 3.0, 0.0, 0.0], "k": [1.0e8] * 4},
        "damping": {"damping_type": "rayleigh", "rayleigh_a0": 0.1, "rayleigh_a1": 0.001},
        "bearings": {"n_bearings": 4, "storey": [1] * 4, "x": [-10.0, 10.0, 10.0, -10.0],
                     "y": [-6.0, -6.0, 6.0, 6.0], "mu": [0.05] * 4, "radius": [2.0] * 4,
                     "law": ["coulomb"] * 4},
        "excitation": {"excitation_type": "harmonic", "amplitude": 0.1, "frequency": 0.5,
                       "dt_record": 0.01, "duration": 4.0},
        "excitation2": {"excitation_type": "harmonic", "amplitude": 0.07, "frequency": 0.7,
                        "dt_record": 0.01, "duration": 4.0},
        "integration": {**MJ, "n1": 4},
        "output": {"dir": "out"},
    }
    res = frictiondyn.run_text(deck_text(groups), "mat.nml", tmp_path)
    pmu = 0.05 * G * 4.0e5 / 4
    for b in range(4):
        f = np.hypot(res[f"F{2 * b + 1}"], res[f"F{2 * b + 2}"])
        assert np.max(f) <= pmu * (1.0 + 1e-12)
        assert np.max(f) >= pmu * (1.0 - 1e-12)
    assert res.summary["bearing_peak_displacement_m"][0] > 0.05
    assert res.summary["patterns_solved"] > 0
    assert abs(res.summary["energy_residual_ratio"]) < 1.0e-12


# ---------------------------------------------------------------- refused

def test_speed_dependent_mu_is_refused_for_a_coulomb_bearing(tmp_path):
    """Moreau-Jean takes Coulomb friction of a constant mu, in 1D as in the plane: mu_law with a
    'coulomb' bearing is an error naming &bearings and mu_law(1)."""
    deck = two_bodies(tmp_path)
    deck["bearings"] = {"n_bearings": 1, "dof_xi": 1, "dof_yi": 2, "dof_xj": 0, "dof_yj": 0, "p": M * G,
                        "law": "coulomb", "mu_law": "exponential", "mu_max": 0.1, "mu_min": 0.05,
                        "mu_rate": 20.0}
    with pytest.raises(FrictiondynError) as info:
        frictiondyn.run_text(deck_text(deck), "mu.nml", tmp_path)
    for w in ("&bearings", "mu_law(1)", "'exponential'", "law(1) = 'coulomb'"):
        assert w in str(info.value), str(info.value)


@pytest.mark.parametrize("technique, law, words", [
    ("moreau_jean", "velocity", ["&bearings", "law(1) = 'velocity'", "'moreau_jean'", "'coulomb'"]),
    ("newmark", "coulomb", ["&bearings", "law(1) = 'coulomb'", "'newmark'", "'moreau_jean'"]),
])
def test_a_bearing_law_the_technique_does_not_integrate_is_named(tmp_path, technique, law, words):
    deck = two_bodies(tmp_path, technique, law)
    deck["isolators"]["law"] = "coulomb" if technique == "moreau_jean" else "velocity"
    with pytest.raises(FrictiondynError) as info:
        frictiondyn.run_text(deck_text(deck), "law.nml", tmp_path)
    for w in words:
        assert w in str(info.value), str(info.value)
