"""Newmark's step checks of planar bearings at the normal forces the run had.

A hysteretic bearing's sticking spring N mu / f and a velocity-law bearing's band dashpot
N mu / eps grow with N. The stick-ringing and band-alternation checks take each bearing at the
largest N (and its margin, its floor, at the smallest) of the range predicted before the run
from the vertical motion joined with the N observed at the accepted states: the overturning's
dN is known only as the run goes (docs/theory.md 5.7, docs/warnings.md#stick-ringing).

- a tall block on four hysteretic bearings, overturning = .true., under a step of base
  acceleration: its overturning raises N by half on the leading row. At the deck's p the step's
  frequency error could not dephase the ringing within the run (drift x duration < 1 rad), at
  the observed N_max it does: stick_resolution is 'unresolved' and warned, and
  stick_frequency_error is the average acceleration rule's closed form at each bearing's
  observed N_max;
- the same block at n1 = 20: nothing reported, the figures the closed form's there;
- velocity-law bearings under a harmonic base motion: band_x is its closed form at the observed
  N_max of every bearing, not at p.
"""
from __future__ import annotations

import math

import numpy as np
import pytest

import frictiondyn
from conftest import deck_text
from test_bearings_overturning import DT, M, M0, X4, Y4, block, write_record

G = 9.80665
H = 6.0                                   # the block's height: dN up to half of p
P = (M0 + M) * G / 4                      # each bearing's p [N]
I0 = M0 * (10.0**2 + 8.0**2) / 12         # the base mat's rotational inertia [kg m2]
MU = 0.3
F = 1.0e-4                                # the hysteretic bearings' sticking displacement [m]
DURATION = 2.0


def tall_block(ax: str, n1: int, law: str, **bearing) -> dict:
    """The block of test_bearings_overturning at height H, undamped (the sticking springs'
    modes keep their ringing), on four bearings of `law`."""
    g = block(X4, Y4, ax, DURATION, mu=MU, integration={"n1": n1, "n2": 10}, law=[law] * 4, **bearing)
    if law != "velocity":
        g["bearings"].pop("eps")
    g["floors"]["height"] = [0.0, H]
    g["damping"] = {"damping_type": "none"}
    return g


def run(tmp_path, g: dict, name: str) -> frictiondyn.Result:
    return frictiondyn.run_text(deck_text(g), name, tmp_path)


def average_acceleration_error(x: float) -> float:
    """1 - omega~/omega of the average acceleration rule at omega dt = x."""
    return 1.0 - 2.0 * math.atan(x / 2.0) / x


def arms() -> list[float]:
    """|rz| term of each bearing component's direction on the base mat, in device order
    (x component: |y|, y component: |x|)."""
    return [a for x, y in zip(X4, Y4) for a in (abs(y), abs(x))]


def sticking_mode(n: float, arm: float, dt1: float) -> tuple[float, float]:
    """omega dt1 of a bearing component's sticking spring n mu / f on the base mat (its moved
    mass 1 / (1 / M0 + arm^2 / I0)), and the error there."""
    mr = 1.0 / (1.0 / M0 + arm**2 / I0)
    x = math.sqrt(n * MU / F / mr) * dt1
    return x, average_acceleration_error(x)


def step_record(tmp_path) -> str:
    t = np.arange(0.0, DURATION + DT / 2, DT)
    write_record(tmp_path, "step.txt", 0.2 * G * (t > 0))
    return "step.txt"


def test_overturning_rings_unresolved_at_the_observed_normal_force(tmp_path):
    """n1 = 11: at p no stick phase can be dephased by 1 rad within the run (the gate of the
    check), at the observed N_max they are, and the ringing is larger than the margin: the
    step is reported unresolved, its figures those of the observed N."""
    n1 = 11
    dt1 = DT / n1
    with pytest.warns(frictiondyn.FrictiondynWarning, match="stick-ringing"):
        r = run(tmp_path, tall_block(step_record(tmp_path), n1, "hysteretic", f=[F] * 4, eps1=[1.0e-3] * 4),
                "ring.nml")
    s = r.summary
    n_max = s["bearing_max_normal_force_N"]
    assert max(n_max) > 1.45 * P
    for d, arm in enumerate(arms()):
        x0, e0 = sticking_mode(P, arm, dt1)
        # at p the drift |error| omega cannot reach 1 rad within the whole run
        assert e0 * x0 / dt1 * DURATION < 1.0
        x1, e1 = sticking_mode(max(P, n_max[d // 2]), arm, dt1)
        assert s["stick_frequency_error"][d] == pytest.approx(e1, rel=1e-12)
    assert s["stick_resolution"] == "unresolved"
    assert max(s["stick_ringing_ratio"]) > 1.0
    [line] = [w for w in s["warnings"] if "stick-ringing" in w]
    assert "raise n1" in line and len(line) <= 220


def test_a_fine_enough_step_reports_nothing(tmp_path):
    """n1 = 20: no stick phase is dephased at the observed N either (the error falls as
    dt1^2); the figures are still the closed form's at the observed N_max."""
    n1 = 20
    dt1 = DT / n1
    r = run(tmp_path, tall_block(step_record(tmp_path), n1, "hysteretic", f=[F] * 4, eps1=[1.0e-3] * 4),
            "fine.nml")
    s = r.summary
    n_max = s["bearing_max_normal_force_N"]
    assert max(n_max) > 1.45 * P
    for d, arm in enumerate(arms()):
        assert s["stick_frequency_error"][d] == pytest.approx(sticking_mode(max(P, n_max[d // 2]), arm, dt1)[1],
                                                              rel=1e-12)
    assert s["stick_resolution"] == "resolved"
    assert s["stick_ringing_ratio"] == [0.0] * 8
    assert s["warnings"] == []


def test_band_x_is_taken_at_the_observed_normal_forces(tmp_path):
    """Velocity-law bearings (eps = 0.01 m/s) under a 0.4 g harmonic base motion: every band
    couples the base mat's ux, uy and rz, so a component's band_x = (1 - gamma) dt1 mu / eps
    sum_b N_b (1 / M0 + arm (|x_b| + |y_b|) / I0), N_b each bearing's largest N, the observed
    one where the overturning raised it above p."""
    eps = 0.01
    n1 = 4
    dt1 = DT / n1
    t = np.arange(0.0, DURATION + DT / 2, DT)
    write_record(tmp_path, "ax.txt", 0.4 * G * np.sin(2 * np.pi * t))
    r = run(tmp_path, tall_block("ax.txt", n1, "velocity", eps=[eps] * 4), "band.nml")
    s = r.summary
    n_max = [max(P, n) for n in s["bearing_max_normal_force_N"]]
    assert min(n_max) > 1.3 * P
    total = sum(n_max)
    for d, arm in enumerate(arms()):
        x = 0.5 * dt1 * MU / eps * total * (1.0 / M0 + arm * (abs(X4[0]) + abs(Y4[0])) / I0)
        x_p = 0.5 * dt1 * MU / eps * 4 * P * (1.0 / M0 + arm * (abs(X4[0]) + abs(Y4[0])) / I0)
        assert s["band_x"][d] == pytest.approx(x, rel=1e-12)
        assert s["band_x"][d] > 1.3 * x_p
