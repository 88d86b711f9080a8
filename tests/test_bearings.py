"""Planar sliding bearings (&bearings): the paper's two laws carried to the plane under Newmark.

- Along one axis a bearing is today's one-dimensional device: the same run to 1e-12.
- A rigid block on a flat slider driven by a circular table motion reaches the steady circular
  orbit of the complex amplitude equation (friction of constant magnitude along the velocity);
  the velocity law approaches it as the step goes to 0 (in steady sliding the resultant never
  enters the disc, and the force takes the direction of the previous step), the hysteretic law
  as f goes to 0; the measured orders are asserted.
- A friction pendulum released from an offset along any direction decays as the closed-form 1D
  Coulomb oscillator (its turning points 2 mu R closer to the centre each half cycle) and stops
  inside the disc |s| <= mu R.
- The energy balance closes; event_driven refuses bearings (Moreau-Jean: test_bearings_moreau_jean.py).
"""
from __future__ import annotations

import math

import numpy as np
import pytest

import frictiondyn
from frictiondyn import FrictiondynError
from conftest import deck_text

G = 9.80665
MTX = "%%MatrixMarket matrix coordinate real symmetric\n2 2 2\n1 1 {a}\n2 2 {a}\n"


def matrices(tmp_path, k: float, m: float, influence2: bool) -> dict:
    """A point mass m in the plane (DOF 1: x, DOF 2: y) held by springs k along x and y."""
    (tmp_path / "K.mtx").write_text(MTX.format(a=k))
    (tmp_path / "M.mtx").write_text(MTX.format(a=m))
    g = {"k_file": "K.mtx", "m_file": "M.mtx", "influence": [1.0, 0.0]}
    if influence2:
        g["influence2"] = [0.0, 1.0]
    return g


# ---------------------------------------------------------------- motion along one axis

AXIS_CASES = {
    "velocity flat": {"law": "velocity", "eps": 1.0e-3},
    "velocity curved": {"law": "velocity", "eps": 1.0e-3, "radius": 2.0},
    "velocity mu(v)": {"law": "velocity", "eps": 1.0e-3, "radius": 2.0, "mu_law": "exponential",
                       "mu_max": 0.12, "mu_min": 0.06, "mu_rate": 20.0},
    "hysteretic flat": {"law": "hysteretic", "f": 2.0e-4, "eps1": 1.0e-3},
    "hysteretic curved": {"law": "hysteretic", "f": 2.0e-4, "eps1": 1.0e-3, "radius": 1.5},
}


@pytest.mark.parametrize("case", list(AXIS_CASES))
def test_motion_along_one_axis_is_the_one_dimensional_device(tmp_path, case):
    """A table motion along x: the bearing's x component equals an isolator of the same law on
    the x DOF (its displacement, force and the mass's motion, to 1e-12 of their peaks), and
    nothing moves along y."""
    settings = dict(AXIS_CASES[case])
    m = 1000.0
    common = {
        "damping": {"damping_type": "none"},
        "excitation": {"excitation_type": "harmonic", "amplitude": 0.06, "frequency": 1.0,
                       "dt_record": 0.01, "duration": 4.0},
        "output": {"dir": "out"},
    }
    mu = {} if "mu_law" in settings else {"mu": 0.1}
    planar = {"matrices": matrices(tmp_path, 1.0e4, m, False),
              "bearings": {"n_bearings": 1, "dof_xi": 1, "dof_yi": 2, "dof_xj": 0, "dof_yj": 0,
                           "p": m * G, **mu, **settings}, **common}
    oned = {"matrices": matrices(tmp_path, 1.0e4, m, False),
            "isolators": {"n_isolators": 1, "node_i": 1, "node_j": 0, "weight": m * G, **mu,
                          **settings}, **common}
    a = frictiondyn.run_text(deck_text(planar), "planar.nml", tmp_path)
    b = frictiondyn.run_text(deck_text(oned), "oned.nml", tmp_path)
    assert b.summary["slip_excursions"][0] >= 2  # it slides, both ways
    for col in ("u1", "v1", "s1", "F1"):
        scale = np.max(np.abs(b[col]))
        assert np.max(np.abs(a[col] - b[col])) <= 1.0e-12 * scale, col
    assert np.all(a["u2"] == 0.0) and np.all(a["F2"] == 0.0)
    assert a.summary["bearing_peak_displacement_m"][0] == pytest.approx(b.summary["peak_s_m"][0], rel=1e-12)
    assert a.summary["bearing_dissipated_energy_J"][0] == pytest.approx(b.summary["dissipated_energy_J"][0],
                                                                        rel=1e-12)


# ---------------------------------------------------------------- circular orbit

W = 2.0 * math.pi      # table circular frequency [rad/s]
MU = 0.1
M = 1000.0
K = 1.0e4              # a spring along x and y [N/m]: the orbit's centre settles fast
A0 = 1.0               # Rayleigh a0: C = a0 M [1/s], damps the start's transient
AMP = 2.0 * MU * G / W**2   # table orbit radius: |a_g| = 2 mu g


def orbit_radius(mu: float = MU) -> float:
    """The steady orbit of m z'' + c z' + k z = -m a_g - mu m g z'/|z'| with a_g the circular
    motion A w^2 (cos, sin): z = Z e^{iwt}, z'/|z'| = i Z/|Z|, so with Z = R e^{i phi}
    ((k - m w^2) R + i (c w R + mu m g)) e^{i phi} = m A w^2 e^{i psi}: the magnitudes give
    (k - m w^2)^2 R^2 + (c w R + mu m g)^2 = (m A w^2)^2, a quadratic in R."""
    c = A0 * M
    qa = (K - M * W**2) ** 2 + (c * W) ** 2
    qb = 2.0 * c * W * mu * M * G
    qc = (mu * M * G) ** 2 - (M * AMP * W**2) ** 2
    return (-qb + math.sqrt(qb * qb - 4.0 * qa * qc)) / (2.0 * qa)


def circular_run(tmp_path, bearing: dict, dt_record: float, n1: int) -> float:
    """The block's relative orbit radius, mean of |u| over the last two periods of 12 s."""
    t = np.arange(0.0, 12.0 + dt_record / 2, dt_record)
    ax = -AMP * W**2 * np.cos(W * t)
    ay = -AMP * W**2 * np.sin(W * t)
    (tmp_path / "ax.txt").write_text("".join(f"{v:.17e}\n" for v in ax))
    (tmp_path / "ay.txt").write_text("".join(f"{v:.17e}\n" for v in ay))
    rec = {"excitation_type": "record", "record_format": "values", "record_units": "m/s2",
           "dt_record": dt_record}
    groups = {
        "matrices": matrices(tmp_path, K, M, True),
        "damping": {"damping_type": "rayleigh", "rayleigh_a0": A0, "rayleigh_a1": 0.0},
        "bearings": {"n_bearings": 1, "dof_xi": 1, "dof_yi": 2, "dof_xj": 0, "dof_yj": 0,
                     "p": M * G, **({} if "mu_law" in bearing else {"mu": MU}), **bearing},
        "excitation": {**rec, "record_file": "ax.txt"},
        "excitation2": {**rec, "record_file": "ay.txt"},
        "integration": {"n1": n1},
        "output": {"dir": "out"},
    }
    res = frictiondyn.run_text(deck_text(groups), "orbit.nml", tmp_path)
    assert abs(res.summary["energy_residual_ratio"]) < 1.0e-6
    last = res["t"] >= 10.0 - 1e-9
    r = np.hypot(res["u1"][last], res["u2"][last])
    assert np.ptp(r) < 1.0e-4 * np.mean(r)   # a circle about the origin
    return float(np.mean(r))


def test_circular_orbit_velocity_law_converges_with_the_step(tmp_path):
    """Steady sliding never enters the disc (|v| = R w >> eps): the velocity law's error is the
    direction taken one step late, first order in dt1."""
    exact = orbit_radius()
    errors = [abs(circular_run(tmp_path, {"law": "velocity", "eps": 1.0e-4}, 0.004, n1) - exact) / exact
              for n1 in (2, 4, 8)]
    assert errors[-1] < 2.0e-3
    orders = [math.log2(errors[k] / errors[k + 1]) for k in range(2)]
    assert all(0.8 < q < 1.2 for q in orders), (errors, orders)


def test_circular_orbit_hysteretic_law_converges_with_f(tmp_path):
    """The hysteretic law's force trails the velocity by the sticking displacement f: its orbit
    tends to the closed form as f -> 0, first order in f / R."""
    exact = orbit_radius()
    errors = [abs(circular_run(tmp_path, {"law": "hysteretic", "f": f, "eps1": 1.0e-4}, 0.004, 8) - exact) / exact
              for f in (4.0e-3, 2.0e-3, 1.0e-3)]
    assert errors[-1] < 1.5e-2
    orders = [math.log2(errors[k] / errors[k + 1]) for k in range(2)]
    assert all(0.8 < q < 1.2 for q in orders), (errors, orders)


def test_circular_orbit_speed_dependent_mu_at_the_resultant_speed(tmp_path):
    """mu(|v|) = mu_max - (mu_max - mu_min) exp(-rate |v|) taken at the resultant speed: the
    steady orbit is the closed form's with mu = mu(R w), R and mu found together (a fixed
    point); the step's first-order error (8e-4 at n1 = 8, the test above) bounds the gap."""
    law = {"law": "velocity", "eps": 1.0e-4, "mu_law": "exponential", "mu_max": 0.1, "mu_min": 0.05,
           "mu_rate": 5.0}
    r = 0.05
    for _ in range(60):
        mu = 0.1 - 0.05 * math.exp(-5.0 * r * W)
        r = orbit_radius(mu)
    got = circular_run(tmp_path, law, 0.004, 8)
    assert abs(got - r) / r < 1.5e-3, (got, r)


# ---------------------------------------------------------------- friction pendulum

RADIUS = 1.0
MU_P = 0.05


def pendulum_run(tmp_path, law: dict, angle: float) -> frictiondyn.Result:
    """A block of two masses' DOFs (x: 1, y: 2) on a friction pendulum, released at rest from
    7.3 mu R along `angle`, with the table at rest."""
    x0 = 7.3 * MU_P * RADIUS
    groups = {
        "model": {"n_dof": 2, "mass": [M, M], "u0": [x0 * math.cos(math.radians(angle)),
                                                     x0 * math.sin(math.radians(angle))]},
        "springs": {"n_springs": 0},
        "damping": {"damping_type": "none"},
        "bearings": {"n_bearings": 1, "dof_xi": 1, "dof_yi": 2, "dof_xj": 0, "dof_yj": 0,
                     "p": M * G, "mu": MU_P, "radius": RADIUS, **law},
        "excitation": {"excitation_type": "none", "dt_record": 0.01, "duration": 6.0},
        "output": {"dir": "out"},
    }
    return frictiondyn.run_text(deck_text(groups), "pendulum.nml", tmp_path)


@pytest.mark.parametrize("angle", [0.0, 30.0, 135.0])
@pytest.mark.parametrize("law", [{"law": "hysteretic", "f": 1.0e-5, "eps1": 1.0e-4},
                                 {"law": "velocity", "eps": 1.0e-5}], ids=["hysteretic", "velocity"])
def test_friction_pendulum_decays_as_the_one_dimensional_oscillator(tmp_path, law, angle):
    """m x'' + (m g / R) x = -mu m g sgn(x'): each half cycle the turning point comes 2 mu R
    closer (7.3, -5.3, 3.3, -1.3 mu R), and from -1.3 mu R, about the centre -mu R, the block
    stops at -0.7 mu R, inside the disc mu R, on the line of release."""
    res = pendulum_run(tmp_path, law, angle)
    d = np.array([math.cos(math.radians(angle)), math.sin(math.radians(angle))])
    along = res["u1"] * d[0] + res["u2"] * d[1]
    across = -res["u1"] * d[1] + res["u2"] * d[0]
    mur = MU_P * RADIUS
    assert np.max(np.abs(across)) < 1.0e-9 * mur
    # the turning points: extrema of the motion along the line
    v = res["v1"] * d[0] + res["v2"] * d[1]
    turns = [along[k] for k in range(1, len(v)) if v[k - 1] * v[k] < 0.0 and abs(along[k]) > 1.05 * mur]
    assert np.allclose(np.array(turns[:3]) / mur, [-5.3, 3.3, -1.3], atol=2e-3), np.array(turns) / mur
    final = along[-1] / mur
    assert final == pytest.approx(-0.7, abs=2e-3)
    assert res.summary["bearing_residual_displacement_m"][0] == pytest.approx(0.7 * mur, rel=3e-3)
    assert res.summary["bearing_residual_displacement_m"][0] < mur
    assert res.summary["bearing_peak_displacement_m"][0] == pytest.approx(7.3 * mur, rel=1e-9)
    # the friction dissipated the strain energy lost: k (x0^2 - x_end^2) / 2
    k = M * G / RADIUS
    lost = 0.5 * k * ((7.3 * mur) ** 2 - (along[-1]) ** 2)
    assert res.summary["bearing_dissipated_energy_J"][0] == pytest.approx(lost, rel=2e-3)
    assert abs(res.summary["energy_residual_ratio"]) < 1.0e-6


# ---------------------------------------------------------------- refused

@pytest.mark.parametrize("technique", ["event_driven"])
def test_exact_techniques_refuse_bearings(tmp_path, technique):
    """The event-driven technique does not integrate planar bearings (docs/theory.md 5.6);
    Moreau-Jean does, with law = 'coulomb' (tests/test_bearings_moreau_jean.py)."""
    groups = {
        "model": {"n_dof": 2, "mass": [M, M]},
        "springs": {"n_springs": 0},
        "damping": {"damping_type": "none"},
        "bearings": {"n_bearings": 1, "dof_xi": 1, "dof_yi": 2, "dof_xj": 0, "dof_yj": 0,
                     "p": M * G, "mu": 0.1},
        "excitation": {"excitation_type": "harmonic", "amplitude": 0.05, "frequency": 1.0,
                       "dt_record": 0.01, "duration": 1.0},
        "integration": {"technique": technique},
        "output": {"dir": "out"},
    }
    with pytest.raises(FrictiondynError, match=r"&integration.*technique = '" + technique + r"'.*bearing 1"):
        frictiondyn.run_text(deck_text(groups), "refused.nml", tmp_path)


@pytest.mark.parametrize("change, words", [
    ({"law": "coulomb"}, ["&bearings", "law(1)", "'coulomb'"]),
    ({"dof_yi": 1}, ["&bearings", "dof_xi(1)", "dof_yi(1)"]),
    ({"storey": 1}, ["&bearings", "storey", "&floors"]),
    ({"radius": -1.0}, ["&bearings", "radius(1)", "-1"]),
])
def test_bad_bearings_are_named(tmp_path, change, words):
    groups = {
        "model": {"n_dof": 2, "mass": [M, M]},
        "springs": {"n_springs": 0},
        "damping": {"damping_type": "none"},
        "bearings": {"n_bearings": 1, "dof_xi": 1, "dof_yi": 2, "dof_xj": 0, "dof_yj": 0,
                     "p": M * G, "mu": 0.1, **change},
        "excitation": {"excitation_type": "harmonic", "amplitude": 0.05, "frequency": 1.0,
                       "dt_record": 0.01, "duration": 1.0},
        "output": {"dir": "out"},
    }
    with pytest.raises(FrictiondynError) as info:
        frictiondyn.run_text(deck_text(groups), "bad.nml", tmp_path)
    for w in words:
        assert w in str(info.value), str(info.value)


# ---------------------------------------------------------------- rigid floors

def test_base_mat_on_four_bearings_of_rigid_floors(tmp_path):
    """A two-floor building on four hysteretic friction pendulums under its base mat, shaken
    along 30 degrees: each bearing's normal force defaults to its share of the weight (g 4e5 kg
    / 4), its resultant friction force never leaves the circle P mu and reaches it, and its peak
    lies along the shaking (30 or -150 degrees, the plan being symmetric)."""
    groups = {
        "floors": {"n_floors": 2, "mass": [2.0e5, 2.0e5], "plan_x": [20.0, 20.0], "plan_y": [12.0, 12.0],
                   "height": [1.0, 3.0], "excitation_angle": 30.0},
        "frames": {"n_frames": 4, "storey": [2, 2, 2, 2], "angle": [0.0, 0.0, 90.0, 90.0],
                   "x": [0.0, 0.0, -5.0, 5.0], "y": [-3.0, 3.0, 0.0, 0.0], "k": [1.0e8] * 4},
        "damping": {"damping_type": "rayleigh", "rayleigh_a0": 0.1, "rayleigh_a1": 0.001},
        "bearings": {"n_bearings": 4, "storey": [1] * 4, "x": [-10.0, 10.0, 10.0, -10.0],
                     "y": [-6.0, -6.0, 6.0, 6.0], "mu": [0.05] * 4, "radius": [2.0] * 4,
                     "law": ["hysteretic"] * 4, "f": [1.0e-4] * 4},
        "excitation": {"excitation_type": "harmonic", "amplitude": 0.1, "frequency": 0.5,
                       "dt_record": 0.01, "duration": 4.0},
        "output": {"dir": "out"},
    }
    res = frictiondyn.run_text(deck_text(groups), "mat.nml", tmp_path)
    pmu = 0.05 * G * 4.0e5 / 4
    assert res.summary["device_labels"][:2] == ["bearing 1 x", "bearing 1 y"]
    for b in range(4):
        f = np.hypot(res[f"F{2 * b + 1}"], res[f"F{2 * b + 2}"])
        assert np.max(f) <= pmu * (1.0 + 1e-12)
        assert np.max(f) >= pmu * (1.0 - 1e-12)
        angle = res.summary["bearing_peak_direction_deg"][b]
        assert min(abs(angle - 30.0), abs(angle + 150.0)) < 1.0
    assert abs(res.summary["energy_residual_ratio"]) < 1.0e-9


def test_a_bearing_on_one_dof_for_both_directions_is_refused(tmp_path):
    groups = {
        "model": {"n_dof": 3, "mass": [M, M, M]},
        "springs": {"n_springs": 1, "node_i": [3], "node_j": [0], "k": [1.0e5]},
        "damping": {"damping_type": "none"},
        "bearings": {"n_bearings": 1, "dof_xi": 1, "dof_yi": 2, "dof_xj": 3, "dof_yj": 3,
                     "p": M * G, "mu": 0.1},
        "excitation": {"excitation_type": "harmonic", "amplitude": 0.05, "frequency": 1.0,
                       "dt_record": 0.01, "duration": 1.0},
        "output": {"dir": "out"},
    }
    with pytest.raises(FrictiondynError, match=r"&bearings.*dof_yj\(1\) = 1, 2, 3, 3"):
        frictiondyn.run_text(deck_text(groups), "bad.nml", tmp_path)
