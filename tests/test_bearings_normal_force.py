"""Planar bearings whose normal force varies with a vertical ground motion (&excitation3).

The vertical support is rigid: the ground's vertical acceleration a_z (upward positive) scales
each bearing's normal force, N = N0 (1 + a_z / g). The friction (P mu, the band's dashpot, the
sticking spring) takes N at each step's start, the friction pendulum's restoring force N / R s;
N <= 0 is uplift: no friction, no restoring force, reported (bearing_uplift_*, a warning).

- a_z = 0 is today's run to the bit; a constant a_z = c is the run with P scaled by (1 + c / g)
  to the bit (flat sliders, both laws);
- a friction pendulum under a constant a_z converges to the scaled run at first order (its
  restoring force N / R s takes s at the step's start);
- uplift in a violent vertical record: counted, timed, warned; no friction force while lifted;
- the energy balance closes to round-off with N varying (a sticking spring and a band's
  dashpot that change with N included);
- per bearing the extremes of N.
"""
from __future__ import annotations

import numpy as np
import pytest

import frictiondyn
from conftest import deck_text

G = 9.80665
M = 1000.0
DT = 0.01
DURATION = 4.0


def write_record(tmp_path, name: str, values) -> None:
    (tmp_path / name).write_text("".join(f"{v:.17e}\n" for v in values))


def vertical(name: str) -> dict:
    return {"excitation_type": "record", "record_file": name, "record_format": "values",
            "record_units": "m/s2", "dt_record": DT}


def groups(bearing: dict, p: float = M * G, az: str | None = None) -> dict:
    """A block (DOFs 1: x, 2: y) on one bearing to the table, a harmonic table motion along
    both DOFs, and the vertical record `az` if given."""
    g = {
        "model": {"n_dof": 2, "mass": [M, M]},
        "springs": {"n_springs": 2, "node_i": [1, 2], "node_j": [0, 0], "k": [2.0e4, 1.0e4]},
        "damping": {"damping_type": "none"},
        "bearings": {"n_bearings": 1, "dof_xi": 1, "dof_yi": 2, "dof_xj": 0, "dof_yj": 0,
                     "p": p, "mu": 0.1, **bearing},
        "excitation": {"excitation_type": "harmonic", "amplitude": 0.08, "frequency": 1.0,
                       "dt_record": DT, "duration": DURATION},
        "output": {"dir": "out", "output_every": 1},
    }
    if az is not None:
        g["excitation3"] = vertical(az)
    return g


LAWS = {
    "velocity": {"law": "velocity", "eps": 1.0e-3},
    "hysteretic": {"law": "hysteretic", "f": 2.0e-4, "eps1": 1.0e-3},
    "velocity mu(v)": {"law": "velocity", "eps": 1.0e-3, "mu_law": "exponential", "mu_max": 0.12,
                       "mu_min": 0.06, "mu_rate": 20.0},
}


def run(tmp_path, g: dict, name: str) -> frictiondyn.Result:
    if "mu_law" in g["bearings"]:
        g["bearings"].pop("mu")
    return frictiondyn.run_text(deck_text(g), name, tmp_path)


def same_run(a: frictiondyn.Result, b: frictiondyn.Result) -> None:
    assert a.names == b.names
    for col in a.names:
        assert np.array_equal(a[col], b[col]), col
    for key in ("peak_u_m", "peak_s_m", "peak_force_N", "bearing_peak_displacement_m", "energy_friction_J",
                "stick_to_slip", "steps_dt1", "steps_dt2"):
        assert a.summary[key] == b.summary[key], key


@pytest.mark.parametrize("law", list(LAWS))
def test_zero_vertical_component_is_the_run_without_it(tmp_path, law):
    """a_z = 0 everywhere: every history column and the summary's figures equal, to the bit, the
    run without &excitation3; N stays N0."""
    write_record(tmp_path, "az0.txt", np.zeros(int(DURATION / DT) + 1))
    a = run(tmp_path, groups(dict(LAWS[law])), "plain.nml")
    b = run(tmp_path, groups(dict(LAWS[law]), az="az0.txt"), "az0.nml")
    assert a.summary["slip_travel_m"][0] > 0.05
    same_run(a, b)
    assert b.summary["bearing_min_normal_force_N"] == [M * G]
    assert b.summary["bearing_max_normal_force_N"] == [M * G]
    assert b.summary["bearing_uplift_count"] == [0]


@pytest.mark.parametrize("law", list(LAWS))
@pytest.mark.parametrize("c", [-4.0, 2.0])
def test_constant_vertical_acceleration_scales_the_normal_force(tmp_path, law, c):
    """A constant a_z = c: the run equals, to the bit, the run with P = N0 (1 + c / g) (c a
    power of 2, which the record's linear interpolation returns exactly)."""
    write_record(tmp_path, "azc.txt", np.full(int(DURATION / DT) + 1, c))
    a = run(tmp_path, groups(dict(LAWS[law]), az="azc.txt"), "azc.nml")
    b = run(tmp_path, groups(dict(LAWS[law]), p=M * G * (1.0 + c / G)), "scaled.nml")
    assert b.summary["slip_travel_m"][0] > 0.05
    same_run(a, b)
    n = M * G * (1.0 + c / G)
    assert a.summary["bearing_min_normal_force_N"] == [n]
    assert a.summary["bearing_max_normal_force_N"] == [n]


def test_pendulum_under_a_constant_vertical_acceleration_converges_to_the_scaled_run(tmp_path):
    """A friction pendulum: K holds N0 / R, the rest (N - N0) / R s acts as a force with s of
    the step's start, so the run tends to the scaled one at first order in the step."""
    c = -0.3 * G
    bearing = {"law": "velocity", "eps": 1.0e-3, "radius": 1.0}
    errors = []
    for n1 in (4, 8, 16):
        write_record(tmp_path, "azc.txt", np.full(int(DURATION / DT) + 1, c))
        ga = groups(dict(bearing), az="azc.txt")
        gb = groups(dict(bearing), p=M * G * (1.0 + c / G))
        for g in (ga, gb):
            g["integration"] = {"n1": n1}
            g["output"] = {"dir": "out"}
        a = run(tmp_path, ga, "azc.nml")
        b = run(tmp_path, gb, "scaled.nml")
        errors.append(float(np.max(np.abs(a["u1"] - b["u1"])) / np.max(np.abs(b["u1"]))))
    assert errors[0] > 0.0
    orders = [np.log2(errors[k] / errors[k + 1]) for k in range(2)]
    assert all(0.7 < q < 1.3 for q in orders), (errors, orders)
    assert errors[-1] < 5.0e-3, errors


def uplift_record(tmp_path) -> tuple[list[float], float]:
    """a_z: 0, then two pulses of -1.5 g lasting 0.3 s each (from 1.0 s and from 2.5 s; the
    record is interpolated linearly: N <= 0 from DT / 3 before each to DT / 3 after)."""
    t = np.arange(0.0, DURATION + DT / 2, DT)
    az = np.zeros_like(t)
    starts = [1.0, 2.5]
    width = 0.3
    for s in starts:
        az[(t >= s - 1e-9) & (t <= s + width + 1e-9)] = -1.5 * G
    write_record(tmp_path, "azu.txt", az)
    return starts, width


@pytest.mark.parametrize("law", ["velocity", "hysteretic"])
def test_uplift_is_counted_timed_and_warned_and_carries_no_friction(tmp_path, law):
    """N = N0 (1 - 1.5) < 0 in two pulses: two uplift episodes, the first at its start, the
    time lifted the pulses' length (steps of dt1 and the refinement's), N's minimum -N0 / 2; the
    warning names its docs/warnings.md section; the friction force is 0 while lifted."""
    starts, width = uplift_record(tmp_path)
    g = groups(dict(LAWS[law]), az="azu.txt")
    g["integration"] = {"n1": 10}
    dt1 = DT / 10
    with pytest.warns(frictiondyn.FrictiondynWarning, match="bearing-uplift"):
        r = run(tmp_path, g, "uplift.nml")
    s = r.summary
    assert s["bearing_uplift_count"] == [2]
    assert starts[0] - DT / 3 <= s["bearing_uplift_first_time_s"][0] <= starts[0] - DT / 3 + dt1
    assert s["bearing_uplift_duration_s"][0] == pytest.approx(2 * (width + 2 * DT / 3), abs=2 * dt1)
    assert s["bearing_min_normal_force_N"] == [pytest.approx(-0.5 * M * G, rel=1e-15)]
    assert s["bearing_max_normal_force_N"] == [pytest.approx(M * G, rel=1e-15)]
    warning = [w for w in s["warnings"] if "lifted off" in w]
    assert len(warning) == 1 and len(warning[0]) <= 220 and "docs/warnings.md#bearing-uplift" in warning[0]
    t = r["t"]
    for s0 in starts:
        lifted = (t > s0 + 1e-9) & (t <= s0 + width + 1e-9)
        assert np.all(r["F1"][lifted] == 0.0) and np.all(r["F2"][lifted] == 0.0)
        # the block slides freely under its springs: it moves while lifted
        assert np.ptp(r["u1"][lifted]) > 0.0


@pytest.mark.parametrize("law", ["velocity", "hysteretic"])
@pytest.mark.parametrize("radius", [0.0, 1.5])
def test_energy_balance_closes_with_a_varying_normal_force(tmp_path, law, radius):
    """A harmonic vertical motion of 0.5 g at 3 Hz: the friction's force and its stiffness or
    dashpot change every step; the device work is that of the forces the steps used, and the
    balance closes to round-off (average acceleration)."""
    t = np.arange(0.0, DURATION + DT / 2, DT)
    write_record(tmp_path, "azh.txt", 0.5 * G * np.sin(2 * np.pi * 3.0 * t))
    g = groups({**LAWS[law], "radius": radius}, az="azh.txt")
    r = run(tmp_path, g, "energy.nml")
    s = r.summary
    assert s["energy_balance"] == "closed"
    assert abs(s["energy_residual_ratio"]) < 1.0e-10
    assert s["bearing_min_normal_force_N"][0] == pytest.approx(0.5 * M * G, rel=1e-3)
    assert s["bearing_max_normal_force_N"][0] == pytest.approx(1.5 * M * G, rel=1e-3)
    assert s["energy_friction_J"] > 0.0
