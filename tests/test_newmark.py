"""The linear Newmark machinery against closed forms."""

from __future__ import annotations

import numpy as np
import pytest
from conftest import INPUTS, K1, K2, M1, M2, ok, run_deck_file, steady_amplitude
from oracles import chain_stiffness, steady_aabs


def free_vibration(omega: float, dt_r: float, n1: int, cycles: float = 20.0):
    period = 2 * np.pi / omega
    return {
        "model": {"n_dof": 1, "mass": [2.0], "u0": [0.01], "v0": [0.03]},
        "springs": {"n_springs": 1, "node_i": [1], "node_j": [0], "k": [2.0 * omega**2]},
        "damping": {"damping_type": "none"},
        "excitation": {"excitation_type": "none", "dt_record": dt_r, "duration": cycles * period},
        "integration": {"n1": n1},
        "output": {"output_every": 1},
    }


@pytest.mark.parametrize("w_dt", [0.05, 0.2, 0.6, 1.5])
def test_average_acceleration_period_elongation(run, w_dt):
    """T_num/T = (w dt/2)/atan(w dt/2) to 1e-12, and no amplitude decay (1e-11): measured
    3.6e-15 and 6.4e-13 (20 periods, the worst at w dt = 0.05)."""
    omega = 2 * np.pi / 0.7
    n1 = 4
    dt = w_dt / omega
    r = ok(run(free_vibration(omega, dt * n1, n1)))
    h = r.history()
    u, v = h["u1"], h["v1"]
    np.testing.assert_allclose(np.diff(h["t"]), dt, rtol=1e-11, atol=0)
    # A linear recurrence u[k+1] + u[k-1] = 2 cos(theta) u[k] holds exactly for the
    # discrete rotation; take cos(theta) where |u[k]| is largest.
    k = np.argsort(-np.abs(u[1:-1]))[:20] + 1
    cos_theta = np.median((u[k + 1] + u[k - 1]) / (2 * u[k]))
    t_ratio = (2 * np.pi / np.arccos(cos_theta) * dt) / (2 * np.pi / omega)
    expected = (w_dt / 2) / np.arctan(w_dt / 2)
    assert t_ratio == pytest.approx(expected, rel=1e-12)
    # the trapezoidal rule conserves the quadratic invariant w^2 u^2 + v^2
    inv = omega**2 * u**2 + v**2
    assert np.max(np.abs(inv / inv[0] - 1)) < 1e-11


def chain(n: int, masses, stiffnesses):
    return {
        "n_dof": n,
        "mass": list(masses),
    }, {
        "n_springs": n,
        "node_i": list(range(1, n + 1)),
        "node_j": list(range(0, n)),
        "k": list(stiffnesses),
    }


@pytest.mark.parametrize(
    "masses, stiffnesses, damping",
    [
        (
            [6.301, 2.530],
            [4000.0, 2895.0],
            {"damping_type": "rayleigh", "rayleigh_a0": 0.4, "rayleigh_a1": 0.002},
        ),
        (
            [3.0, 2.5, 2.0, 1.5, 1.0],
            [9000.0, 7000.0, 5000.0, 3000.0, 1500.0],
            {"damping_type": "rayleigh", "rayleigh_a0": 0.5, "rayleigh_a1": 0.001},
        ),
        (
            [3.0, 2.5, 2.0, 1.5, 1.0],
            [9000.0, 7000.0, 5000.0, 3000.0, 1500.0],
            {"damping_type": "stiffness", "xi": 0.05},
        ),
    ],
)
def test_chain_steady_state_matches_frequency_response(run, masses, stiffnesses, damping):
    """2- and 5-DOF damped chains in steady state: |aabs| equals the response of average-
    acceleration Newmark (the frequency response at the warped frequency (2/dt) tan(w dt/2))
    to 3e-10, measured 3e-11 (what is left of the transient after 60 s), and the exact
    frequency response (K - w^2 M + i w C)^-1 to 1e-4 at dt = dt_r/20 (measured 3.8e-5,
    the period error of the scheme)."""
    n = len(masses)
    freq, amp, dt_r = 3.3, 0.004, 0.005
    model, springs = chain(n, masses, stiffnesses)
    r = ok(
        run(
            {
                "model": model,
                "springs": springs,
                "damping": damping,
                "excitation": {
                    "excitation_type": "harmonic",
                    "amplitude": amp,
                    "frequency": freq,
                    "ramp_cycles": 3,
                    "dt_record": dt_r,
                    "duration": 60.0,
                },
                "integration": {"n1": 20},
            }
        )
    )
    h, s = r.history(), r.summary()
    if damping["damping_type"] == "rayleigh":

        def c(m, k):
            return damping["rayleigh_a0"] * m + damping["rayleigh_a1"] * k
    else:

        def c(m, k):
            return s["period_stuck_s"] * damping["xi"] / np.pi * k

    m, k = np.diag(masses), chain_stiffness(stiffnesses)
    exact = steady_aabs(m, k, c(m, k), amp, freq)
    newmark = steady_aabs(m, k, c(m, k), amp, freq, dt=s["dt1_s"])
    for i in range(n):
        got = steady_amplitude(h["t"], h[f"aabs{i + 1}"], freq, cycles=20)
        assert got == pytest.approx(newmark[i], rel=3e-10)
        assert got == pytest.approx(exact[i], rel=1e-4)
    # no phase change, one step size: the effective stiffness is factored once
    assert s["factorizations"] == 1
    assert s["steps_dt1"] == round(60.0 / (dt_r / 20))


def test_paper_stuck_period_and_damping(tmp_path):
    """T of m1 + m2 on k1 + k2 is the paper's 0.296 s; the stuck mode's damping ratio is xi."""
    r = run_deck_file(INPUTS / "test4_velocity.nml", tmp_path)
    assert r.returncode == 0, r.stderr
    s = r.summary()
    t_rigid = 2 * np.pi * np.sqrt((M1 + M2) / (K1 + K2))
    assert s["period_stuck_s"] == pytest.approx(t_rigid, rel=1e-12)
    assert s["period_stuck_s"] == pytest.approx(0.296, rel=1e-3)
    assert s["xi_stuck"] == pytest.approx(0.015, rel=1e-14)


@pytest.mark.parametrize(
    "table, linked",
    [("0.0, 1.0\n  mu_table_mu = 0.22, 0.0", True), ("0.5, 1.0\n  mu_table_mu = 0.0, 0.22", False)],
)
def test_the_stuck_system_links_a_device_by_its_band(run, table, linked):
    """A stuck velocity-law device holds its masses by its band's coupling P mu(eps) / eps.
    A table that falls to 0 at speed still holds in the band: the stuck system is m1 + m2 on
    k1 + k2, T = 2 pi sqrt((m1 + m2) / (k1 + k2)), as with the constant mu (not the table's
    last mu, whose 0 would give the bars apart). A table that is 0 in the band holds nothing: the
    bars apart, T = 2 pi sqrt(m1 / k1), the longer of the two."""
    text = (INPUTS / "test4_velocity.nml").read_text().replace("duration = 40.0", "duration = 0.1")
    text = text.replace("mu = 0.22", "mu_law = 'table'\n  mu_table_v = " + table)
    r = run(text)
    assert r.returncode == 0, r.stderr
    t = 2 * np.pi * np.sqrt((M1 + M2) / (K1 + K2) if linked else M1 / K1)
    assert r.summary()["period_stuck_s"] == pytest.approx(t, rel=1e-12)


def test_stuck_period_with_a_device_to_the_table(run):
    """A device locking DOF 3 to the table removes it; two devices joining 1-2 merge them."""
    m = [2.0, 1.0, 1.5, 0.5]
    k = [800.0, 600.0, 400.0, 300.0]
    model, springs = chain(4, m, k)
    r = ok(
        run(
            {
                "model": model,
                "springs": springs,
                "damping": {"damping_type": "stiffness", "xi": 0.02},
                "friction": {
                    "n_devices": 2,
                    "node_i": [3, 2],
                    "node_j": [0, 1],
                    "law": ["velocity"] * 2,
                    "p": [10.0, 10.0],
                    "mu": [0.2, 0.2],
                },
                "excitation": {"excitation_type": "none", "dt_record": 0.01, "duration": 0.1},
            }
        )
    )
    # independent: generalized DOFs q = (u1 = u2, u4), u3 = 0
    t = np.array([[1, 0], [1, 0], [0, 0], [0, 1]], float)
    kq = t.T @ chain_stiffness(k) @ t
    mq = t.T @ np.diag(m) @ t
    w2 = np.min(np.linalg.eigvals(np.linalg.solve(mq, kq)).real)
    assert r.summary()["period_stuck_s"] == pytest.approx(2 * np.pi / np.sqrt(w2), rel=1e-12)
    assert r.summary()["xi_stuck"] == pytest.approx(0.02, rel=1e-14)


def harmonic_record_decks(dt_r: float, kind: str, columns: int):
    freq, amp = 3.102, 0.004062
    w = 2 * np.pi * freq
    duration = 6.0
    tk = np.arange(0.0, duration + 0.5 * dt_r, dt_r)
    if kind == "acceleration":
        values = -amp * w**2 * np.sin(w * tk)
    else:
        values = amp * np.sin(w * tk)
    if columns == 1:
        text = "# harmonic table motion\n" + "\n".join(f"{x:.17e}" for x in values) + "\n"
    else:
        text = "\n".join(f"{t:.10f} {x:.17e}" for t, x in zip(tk, values)) + "\n"
    base = {
        "model": {"n_dof": 2, "mass": [M1, M2]},
        "springs": {"n_springs": 2, "node_i": [1, 2], "node_j": [0, 0], "k": [K1, K2]},
        "damping": {"damping_type": "rayleigh", "rayleigh_a0": 0.3, "rayleigh_a1": 0.001},
        "integration": {"n1": 20},
    }
    harm = dict(
        base,
        excitation={
            "excitation_type": "harmonic",
            "amplitude": amp,
            "frequency": freq,
            "dt_record": dt_r,
            "duration": duration,
        },
    )
    rec = dict(
        base,
        excitation={
            "excitation_type": "record",
            "record_file": "table.txt",
            "record_kind": kind,
            "dt_record": dt_r,
            "duration": duration,
        },
    )
    return harm, rec, text


@pytest.mark.parametrize(
    "kind, columns", [("acceleration", 1), ("acceleration", 2), ("displacement", 1)]
)
def test_record_reproduces_harmonic_within_interpolation_error(run, kind, columns):
    """A record of the harmonic motion gives the harmonic run's response, with the error of
    the linear interpolation (or second differences) of the record: second order in dt_r.
    Measured at dt_r = 4 ms: 5.05e-4 (acceleration), 1.005e-3 (displacement), and error
    ratios 3.98 to 4.00 per halving of dt_r."""
    errors = []
    for dt_r in (0.004, 0.002, 0.001):
        harm, rec, text = harmonic_record_decks(dt_r, kind, columns)
        h1 = ok(run(harm)).history()
        h2 = ok(run(rec, files={"table.txt": text})).history()
        assert np.array_equal(h1["t"], h2["t"])
        # the relative equations of motion see only the table acceleration
        scale = np.max(np.abs(h1["aabs1"]))
        errors.append(np.max(np.abs(h1["aabs1"] - h2["aabs1"])) / scale)
    assert errors[0] < (6e-4 if kind == "acceleration" else 1.2e-3)
    # linear interpolation (and second differences): error ~ dt_r^2
    assert errors[0] / errors[1] == pytest.approx(4.0, rel=0.01)
    assert errors[1] / errors[2] == pytest.approx(4.0, rel=0.01)
