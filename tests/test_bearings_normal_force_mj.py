"""Planar Coulomb bearings whose normal force varies with a vertical ground motion (&excitation3)
under the Moreau-Jean technique, and the step checks of Newmark's bearings with N(t).

Moreau-Jean takes each step's friction disc h mu N and pendulum excess (N - N0) / R at the
step's theta point, N = N0 (1 + a_z / g), the excess as a force with s of the step's start (K
holds N0 / R); N <= 0 is uplift: no friction, no restoring force, reported as Newmark reports it
(docs/theory.md 5.7 and 12.7).

- a_z = 0 is the run without &excitation3 to the bit; a constant a_z = c is the run with P scaled
  by (1 + c / g) (flat slider);
- uplift pulses: counted, timed as the closed form says, warned; no friction while lifted;
- the energy balance closes to round-off under a 0.5 g vertical motion (theta = 1/2);
- a block on a friction pendulum under horizontal and vertical motion: Moreau-Jean tends to
  Newmark's velocity law (small eps, fine step) at first order in h.
- Newmark's stick-ringing and band-alternation checks take a bearing's sticking spring and band
  dashpot at the largest N of the run, where the step resolves them worst.
"""
from __future__ import annotations

import math

import numpy as np
import pytest

import frictiondyn
from conftest import deck_text

G = 9.80665
M = 1000.0
DT = 0.01
DURATION = 4.0
MU = 0.1
MJ = {"technique": "moreau_jean"}


def write_record(tmp_path, name: str, values) -> None:
    (tmp_path / name).write_text("".join(f"{v:.17e}\n" for v in values))


def times() -> np.ndarray:
    return np.arange(0.0, DURATION + DT / 2, DT)


def groups(radius: float = 0.0, p: float = M * G, az: str | None = None, n1: int = 4,
           bearing: dict | None = None, integration: dict | None = None) -> dict:
    """A block (DOFs 1: x, 2: y) on one Coulomb bearing to the table, springs along x and y, a
    harmonic table motion along both DOFs, and the vertical record `az` if given."""
    g = {
        "model": {"n_dof": 2, "mass": [M, M]},
        "springs": {"n_springs": 2, "node_i": [1, 2], "node_j": [0, 0], "k": [2.0e4, 1.0e4]},
        "damping": {"damping_type": "none"},
        "bearings": {"n_bearings": 1, "dof_xi": 1, "dof_yi": 2, "dof_xj": 0, "dof_yj": 0,
                     "p": p, "mu": MU, "law": "coulomb", "radius": radius, **(bearing or {})},
        "excitation": {"excitation_type": "harmonic", "amplitude": 0.08, "frequency": 1.0,
                       "dt_record": DT, "duration": DURATION},
        "integration": integration if integration is not None else {**MJ, "n1": n1},
        "output": {"dir": "out", "output_every": 1},
    }
    if az is not None:
        g["excitation3"] = {"excitation_type": "record", "record_file": az, "record_format": "values",
                            "record_units": "m/s2", "dt_record": DT}
    return g


def run(tmp_path, g: dict, name: str) -> frictiondyn.Result:
    return frictiondyn.run_text(deck_text(g), name, tmp_path)


SUMMARY = ("peak_u_m", "peak_s_m", "peak_force_N", "bearing_peak_displacement_m", "energy_friction_J",
           "energy_residual_ratio", "stick_to_slip", "slip_reversals", "bearing_dissipated_energy_J")


# ---------------------------------------------------------------- a_z = 0, a constant a_z

@pytest.mark.parametrize("radius", [0.0, 1.5], ids=["flat", "curved"])
def test_zero_vertical_component_is_the_run_without_it(tmp_path, radius):
    """a_z = 0 everywhere: every history column and the summary's figures equal, to the bit, the
    Moreau-Jean run without &excitation3; N stays N0, no uplift."""
    write_record(tmp_path, "az0.txt", np.zeros(times().size))
    a = run(tmp_path, groups(radius), "plain.nml")
    b = run(tmp_path, groups(radius, az="az0.txt"), "az0.nml")
    assert a.summary["bearing_slip_travel_m"][0] > 0.05
    assert a.names == b.names
    for col in a.names:
        assert np.array_equal(a[col], b[col]), col
    for key in SUMMARY:
        assert a.summary[key] == b.summary[key], key
    assert b.summary["bearing_min_normal_force_N"] == [M * G]
    assert b.summary["bearing_max_normal_force_N"] == [M * G]
    assert b.summary["bearing_uplift_count"] == [0]


@pytest.mark.parametrize("c", [-4.0, 2.0])
def test_constant_vertical_acceleration_scales_the_normal_force(tmp_path, c):
    """A constant a_z = c on a flat slider: the run equals the one with P = N0 (1 + c / g) (each
    step's disc h mu N, the end's bounds mu N) to 1e-12 of every column's peak."""
    write_record(tmp_path, "azc.txt", np.full(times().size, c))
    a = run(tmp_path, groups(az="azc.txt"), "azc.nml")
    b = run(tmp_path, groups(p=M * G * (1.0 + c / G)), "scaled.nml")
    assert b.summary["bearing_slip_travel_m"][0] > 0.05
    for col in b.names:
        scale = max(np.max(np.abs(b[col])), 1e-300)
        assert np.max(np.abs(a[col] - b[col])) <= 1.0e-12 * scale, col
    n = M * G * (1.0 + c / G)
    assert a.summary["bearing_min_normal_force_N"] == [pytest.approx(n, rel=1e-15)]
    assert a.summary["bearing_max_normal_force_N"] == [pytest.approx(n, rel=1e-15)]
    assert a.summary["energy_friction_J"] == pytest.approx(b.summary["energy_friction_J"], rel=1e-12)


# ---------------------------------------------------------------- uplift

def test_uplift_is_counted_timed_and_warned_and_carries_no_friction(tmp_path):
    """a_z = -1.5 g in two pulses of 0.3 s (from 1.0 s and 2.5 s; the record interpolated
    linearly, N <= 0 from DT / 3 before each to DT / 3 after): two episodes, the first at the
    first step's end at or after 1.0 - DT / 3, lifted for 2 (0.3 + 2 DT / 3) to a step, N's
    minimum -N0 / 2, the warning with its anchor, and no friction force while lifted."""
    t = times()
    az = np.zeros_like(t)
    starts, width = [1.0, 2.5], 0.3
    for s in starts:
        az[(t >= s - 1e-9) & (t <= s + width + 1e-9)] = -1.5 * G
    write_record(tmp_path, "azu.txt", az)
    dt1 = DT / 10
    with pytest.warns(frictiondyn.FrictiondynWarning, match="bearing-uplift"):
        r = run(tmp_path, groups(az="azu.txt", n1=10), "uplift.nml")
    s = r.summary
    assert s["bearing_uplift_count"] == [2]
    assert starts[0] - DT / 3 <= s["bearing_uplift_first_time_s"][0] <= starts[0] - DT / 3 + dt1
    assert s["bearing_uplift_duration_s"][0] == pytest.approx(2 * (width + 2 * DT / 3), abs=2 * dt1)
    assert s["bearing_min_normal_force_N"] == [pytest.approx(-0.5 * M * G, rel=1e-15)]
    assert s["bearing_max_normal_force_N"] == [pytest.approx(M * G, rel=1e-15)]
    warning = [w for w in s["warnings"] if "lifted off" in w]
    assert len(warning) == 1 and len(warning[0]) <= 220 and "docs/warnings.md#bearing-uplift" in warning[0]
    tt = r["t"]
    for s0 in starts:
        lifted = (tt > s0 + 1e-9) & (tt <= s0 + width + 1e-9)
        assert np.all(r["F1"][lifted] == 0.0) and np.all(r["F2"][lifted] == 0.0)
        assert np.ptp(r["u1"][lifted]) > 0.0   # it moves under its springs alone
    # loaded again, it has its friction back: a slide at mu N0 somewhere after the pulses
    after = tt > starts[1] + width + DT
    assert np.max(np.hypot(r["F1"][after], r["F2"][after])) == pytest.approx(MU * M * G, rel=1e-12)


# ---------------------------------------------------------------- energy

@pytest.mark.parametrize("radius", [0.0, 1.5], ids=["flat", "curved"])
def test_energy_balance_closes_with_a_varying_normal_force(tmp_path, radius):
    """A vertical motion of 0.5 g at 3 Hz: each step's disc and the pendulum's excess change;
    the friction term holds the impulses' work and the excess's, and the balance closes to
    round-off (theta = 1/2)."""
    write_record(tmp_path, "azh.txt", 0.5 * G * np.sin(2 * np.pi * 3.0 * times()))
    r = run(tmp_path, groups(radius, az="azh.txt"), "energy.nml")
    s = r.summary
    assert s["energy_balance"] == "closed"
    assert abs(s["energy_residual_ratio"]) < 1.0e-10
    assert s["bearing_min_normal_force_N"][0] == pytest.approx(0.5 * M * G, rel=1e-3)
    assert s["bearing_max_normal_force_N"][0] == pytest.approx(1.5 * M * G, rel=1e-3)
    assert s["energy_friction_J"] > 0.0
    assert s["bearing_uplift_count"] == [0]


# ---------------------------------------------------------------- against Newmark's velocity law

def test_moreau_jean_tends_to_newmarks_velocity_law_at_first_order(tmp_path):
    """A block on a friction pendulum (R = 1.5 m) under the horizontal harmonic along x and y and
    a vertical motion of 0.4 g at 2.5 Hz: Moreau-Jean's displacements tend to those of Newmark's
    velocity law with a small eps at a fine step, the error halving with h (orders near 1)."""
    write_record(tmp_path, "azh.txt", 0.4 * G * np.sin(2 * np.pi * 2.5 * times()))
    ref = run(tmp_path, groups(1.5, az="azh.txt", bearing={"law": "velocity", "eps": 1.0e-5},
                               integration={"n1": 40}), "newmark.nml")
    assert ref.summary["energy_balance"] == "closed"
    scale = max(np.max(np.abs(ref["u1"])), np.max(np.abs(ref["u2"])))
    assert ref.summary["bearing_slip_travel_m"][0] > 0.1
    errors = []
    for n1 in (2, 4, 8):
        r = run(tmp_path, groups(1.5, az="azh.txt", n1=n1), f"mj{n1}.nml")
        # the reference's samples at the record's steps
        assert np.array_equal(r["t"][::n1], ref["t"][::40])
        err = max(np.max(np.abs(r[c][::n1] - ref[c][::40])) for c in ("u1", "u2"))
        errors.append(err / scale)
    orders = [math.log2(errors[k] / errors[k + 1]) for k in range(2)]
    assert all(0.7 < q < 1.4 for q in orders), (errors, orders)
    assert errors[-1] < 1.0e-2, errors


# ---------------------------------------------------------------- Newmark's step checks with N(t)

def newmark_frequency_error(x: float) -> float:
    """Average acceleration's relative frequency error at omega dt = x: 1 - 2 atan(x / 2) / x."""
    return 1.0 - 2.0 * math.atan(x / 2.0) / x


def test_step_checks_take_the_largest_normal_force(tmp_path):
    """A velocity-law bearing's band dashpot N mu / eps and a hysteretic bearing's sticking
    spring N mu / f grow with N: under a vertical motion that lifts N to 1.5 N0 the checks take
    them at the largest N of the run. band_x at N0 is 0.8 (the step damps the band) and 1.2 at
    1.5 N0 (it alternates); the sticking mode's frequency error is that of omega at 1.5 N0."""
    t = times()
    az = 0.5 * G * np.sin(2 * np.pi * 1.5 * t)
    write_record(tmp_path, "azh.txt", az)
    n_max = M * G * (1.0 + az.max() / G)
    n1 = 2
    dt1 = DT / n1
    # band_x = (1 - gamma) dt1 N mu / (eps m) = 0.8 at N0
    eps = 0.5 * dt1 * M * G * MU / (0.8 * M)
    vel = {"law": "velocity", "eps": eps}
    integ = {"n1": n1}
    plain = run(tmp_path, groups(0.0, bearing=vel, integration=integ), "vplain.nml")
    varied = run(tmp_path, groups(0.0, az="azh.txt", bearing=vel, integration=integ), "vvaried.nml")
    assert plain.summary["band_x"][0] == pytest.approx(0.8, rel=1e-12)
    x = 0.5 * dt1 * n_max * MU / (eps * M)
    assert x == pytest.approx(0.8 * 1.5, rel=1e-3)
    assert varied.summary["band_x"] == [pytest.approx(x, rel=1e-12)] * 2
    # the hysteretic bearing's sticking spring
    f = 2.0e-4
    hys = {"law": "hysteretic", "f": f, "eps1": 1.0e-3}
    plain = run(tmp_path, groups(0.0, bearing=hys, integration=integ), "hplain.nml")
    varied = run(tmp_path, groups(0.0, az="azh.txt", bearing=hys, integration=integ), "hvaried.nml")
    x0 = math.sqrt(M * G * MU / f / M) * dt1
    x1 = math.sqrt(n_max * MU / f / M) * dt1
    assert plain.summary["stick_frequency_error"][0] == pytest.approx(newmark_frequency_error(x0), rel=1e-9)
    assert varied.summary["stick_frequency_error"] == [pytest.approx(newmark_frequency_error(x1), rel=1e-9)] * 2
    assert varied.summary["stick_frequency_error"][0] > 1.4 * plain.summary["stick_frequency_error"][0]
