"""Tolerance runs (driver/frictiondyn/tolerance.py): given a tolerance on the reported peaks, the
run chooses the technique and its steps, refines them until each estimated error is below the
tolerance, and reports the error it achieved; on the verification battery's short cases the
achieved error is within the tolerance against the exact answer and the estimate bounds it;
what it cannot meet is an error, never a run that returns; the executable refuses a
tolerance, which is a Python run, naming the command."""

from __future__ import annotations

import hashlib
import json
import math
import re
import warnings
from pathlib import Path

import frictiondyn as fd
import numpy as np
import pytest
from conftest import INPUTS, deck_text
from frictiondyn import tolerance as tolerance_module
from frictiondyn.cli import main as cli
from oracles import den_hartog
from test_verification import (
    AMP,
    F0,
    FF,
    FV_A,
    FV_K,
    FV_M,
    FV_U0,
    K,
    M,
    W,
    den_hartog_groups,
)


def quiet_run(text: str, **kw) -> fd.Result:
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", fd.FrictiondynWarning)
        return fd.run_text(text, **kw)


def den_hartog_amplitude() -> float:
    return float(den_hartog(np.array([0.0]), M, K, FF, F0, W)[2])


def check_bounds(summary: dict, key: str, exact: float, tol: float, index: int = 0) -> tuple[float, float]:
    """The run's value of ``key`` is within tol of ``exact`` and its estimated error is at least
    the true error; returns (true relative error, estimate / true)."""
    value = summary[key][index] if isinstance(summary[key], list) else summary[key]
    true = abs(value - exact)
    estimate = summary["estimated_error"][key][index]
    assert true <= tol * abs(exact), (key, value, exact, true / abs(exact))
    assert estimate >= true, (key, estimate, true)
    return true / abs(exact), estimate / true if true > 0 else np.inf


@pytest.mark.parametrize("tol", [1e-2, 1e-3])
def test_den_hartog_velocity_law_meets_its_tolerance(tol):
    """Den Hartog's steady state under the velocity law (eps = 1e-3 m/s, n1 = 20): the
    combined ladder (n1 = 1, 2, 4 with eps / 0.5, / 2, / 8: the model's period of 1 s and
    dt_record = 0.01 s need no finer step) meets both tolerances in its first round, three
    runs and the probe; the amplitude is then within the tolerance of the closed form
    (1.4e-6 of it, measured) and the estimate at least the true error (a plain difference of
    changes below the noise, 1.1e-4 of the amplitude)."""
    text = deck_text(den_hartog_groups("velocity", "newmark", 20, eps=1e-3))
    r = quiet_run(text, tolerance=tol)
    s = r.summary
    run = s["tolerance_run"]
    assert run["met"] and run["technique"] == "newmark" and run["tolerance"] == tol
    assert (run["n1"], run["law_divisor"], run["runs"], run["rounds"]) == (4, 8, 4, 1), run
    check_bounds(s, "peak_u_m", den_hartog_amplitude(), tol)
    assert s["estimated_error"]["peak_u_m"][0] <= tol * s["peak_u_m"][0]
    assert s["estimate_method"]["peak_u_m"][0].startswith(tolerance_module.COMBINED + ": ")


def free_vibration_text(technique: str) -> str:
    from test_verification import free_vibration  # noqa: F401  (the deck's definition)

    groups = {
        "model": {"n_dof": 1, "mass": [FV_M], "u0": [FV_U0]},
        "springs": {"n_springs": 1, "node_i": [1], "node_j": [0], "k": [FV_K]},
        "damping": {"damping_type": "none"},
        "friction": {"n_devices": 1, "node_i": 1, "node_j": 0, "law": "coulomb", "p": FV_K * FV_A, "mu": 1.0},
        "excitation": {"excitation_type": "none", "dt_record": 0.01, "duration": 4.0},
        "integration": {"technique": technique, "n1": 10, "tolerance": 1e-3},
        "output": {"output_every": 1},
    }
    return deck_text(groups)


# Free vibration's closed form: extremes u0 - 2 n a, the largest acceleration at the start
# (k u0 - F) / m = (k (u0 - 2 a) + F) / m, friction's work F times the path 53 a
FV_AABS = FV_K * (FV_U0 - FV_A) / FV_M
FV_ENERGY = FV_K * FV_A * 53 * FV_A


def test_coulomb_free_vibration_chooses_the_exact_technique():
    """One Coulomb device, deck asking Moreau-Jean, tolerance 1e-3 in the deck: the run
    chooses the exact technique (one run), says so, and its peaks are the closed form's to
    round-off, inside the estimate it reports (1e-9 of each quantity)."""
    r = quiet_run(free_vibration_text("moreau_jean"))
    s = r.summary
    run = s["tolerance_run"]
    assert run["technique"] == "event_driven" and run["runs"] == 1
    assert "exact event-driven" in run["why"]
    assert s["estimate_method"]["peak_u_m"] == ["exact: event-driven technique (round-off)"]
    check_bounds(s, "peak_aabs_mps2", FV_AABS, 1e-3)
    assert abs(s["energy_friction_J"] - FV_ENERGY) <= 1e-9 * FV_ENERGY
    assert s["estimated_error"]["energy_friction_J"][0] >= abs(s["energy_friction_J"] - FV_ENERGY)


def test_coulomb_free_vibration_by_moreau_jean_meets_its_tolerance(monkeypatch):
    """With the exact technique ruled out (as for a model of many devices), Moreau-Jean's n1
    is refined from its step levels until the estimate is below 1e-3: its peak acceleration
    and friction energy are then within 1e-3 of the closed form, inside their estimates."""
    monkeypatch.setattr(tolerance_module, "EXACT_DEVICES", 0)
    r = quiet_run(free_vibration_text("event_driven"))
    s = r.summary
    assert s["tolerance_run"]["technique"] == "moreau_jean" and s["technique"] == "moreau_jean"
    check_bounds(s, "peak_aabs_mps2", FV_AABS, 1e-3)
    true = abs(s["energy_friction_J"] - FV_ENERGY)
    assert true <= 1e-3 * FV_ENERGY and s["estimated_error"]["energy_friction_J"][0] >= true


def test_the_first_levels_come_from_the_model(monkeypatch):
    """Moreau-Jean on the free vibration (period 1 s, dt_record = 0.01 s) at 1e-3: the probe
    of one record step finds omega = 2 pi rad/s, (omega dt_record)^2 / 12 = 3.3e-4 is within
    the tolerance at n1 = 1, so the levels are n1 = 1, 2, 4 whatever the deck's n1 (10), and
    they meet it: 4 runs (the probe's one step and 400 + 800 + 1600 steps), not the deck's
    n1 = 12 and its coarser levels (8400 steps)."""
    monkeypatch.setattr(tolerance_module, "EXACT_DEVICES", 0)
    run = quiet_run(free_vibration_text("event_driven"))
    s = run.summary["tolerance_run"]
    assert s["n1"] == 4 and s["runs"] == 4, s
    assert "n1 = 1, 2, 4 first (omega = 6.283 rad/s, dt_record = 0.01 s" in s["why"], s["why"]
    assert s["steps"] == 1 + 400 + 800 + 1600, s["steps"]


def test_a_hysteretic_sticking_spring_does_not_set_the_first_levels():
    """Under the hysteretic law the stuck system holds the sticking spring, k = P mu / f
    (Den Hartog's at f = 1e-5 m: 76.4 rad/s), a numerical stiffness whose ringing the paper's
    dt2 steps resolve: the first levels follow the structure's period of 1 s (n1 = 1, 2, 4 at
    1e-3), not the spring's (n1 = 2, 4, 8)."""
    from frictiondyn._nml import read_namelist

    nml = read_namelist(hysteretic_den_hartog(), Path("dh.nml"))
    runner = tolerance_module._Runner(Path("dh.nml"), None)
    try:
        start, why = tolerance_module._probe_start(runner, nml, "newmark", 1e-3)
    finally:
        runner.close()
    assert start == 1 and "omega = 6.283 rad/s" in why, why
    assert runner.steps == 1


def test_sound_estimate_caps_the_order_and_takes_the_larger_change():
    """A measured order of 3.5 on a technique of order 1: the estimate of the finest level
    is Richardson's at order 1, 1.25 max(|d2|, |d1| / 2) / (2 - 1), not 1.25 |d2| / (2^3.5 - 1)
    (0.08 of it); an order below the cap is kept; without an order, 3 times the larger change.
    A coarser level's error is 1.25 times its distance to the finest plus the finest's."""
    from frictiondyn.convergence import method_text, methods_text, sound_estimate

    values = [1.0, 1.008, 1.008 + 0.008 / 2**3.5]
    e = sound_estimate(values, 2, 1.0, 1.0)
    assert e.method == "richardson" and e.order == 1.0 and e.measured == pytest.approx(3.5)
    assert e.errors[-1] == pytest.approx(1.25 * 0.008 / 2)
    assert e.errors[0] == pytest.approx(1.25 * (values[2] - values[0]) + e.errors[-1])
    assert methods_text(e, None) == "step: Richardson at order 1, the theoretical (3.50 measured)"
    values = [1.0, 1.008, 1.008 + 0.008 / 2**1.5]
    e = sound_estimate(values, 2, 1.0, 2.0)
    assert e.order == pytest.approx(1.5) and e.measured is None
    assert e.errors[-1] == pytest.approx(1.25 * 0.008 / 2**1.5 / (2**1.5 - 1))
    assert method_text(e) == "Richardson at order 1.50"
    values = [1.0, 1.008, 1.004]
    e = sound_estimate(values, 2, 1.0, 2.0)
    assert e.method == "difference" and e.errors[-1] == pytest.approx(3 * 0.008)
    assert method_text(e) == "difference (the changes between levels alternate in sign)"


def test_sound_estimate_over_every_other_level():
    """Five levels whose last three alternate (a sampled peak that moves by steps) but whose
    every other level converges at order 1 (a ratio of 4): Richardson's over levels 1, 3, 5,
    named as such; when every other level has no order either, the difference of the last
    three."""
    from frictiondyn.convergence import method_text, sound_estimate

    values = [1.0, 1.03, 1.012, 1.0135, 1.015]  # every other: 1.0, 1.012, 1.015 (order 1)
    e = sound_estimate(values, 2, 1.0, 2.0)
    assert e.method == "richardson" and e.order == pytest.approx(1.0)
    assert e.errors[-1] == pytest.approx(1.25 * max(0.003, 0.012 / 4) / 3)
    assert method_text(e) == "Richardson at order 1.00 (every other level)"
    values = [1.0, 1.03, 1.0, 1.0135, 1.03]
    e = sound_estimate(values, 2, 1.0, 2.0)
    assert e.method == "difference" and e.errors[-1] == pytest.approx(3 * 0.0165)


def test_moreau_jean_building_estimates_bound_the_true_errors(tmp_path, monkeypatch):
    """The 3-storey building with a damper in every storey by Moreau-Jean at 1e-2, against
    the exact technique: every estimated quantity is within the tolerance and every estimate
    is at least its true error (its peaks converge at measured orders of 2 to 4 by steps,
    which Richardson's at the measured order from the last change alone underestimated); the
    ladder n1 = 1, 2, 4, ... reuses each level: each run is made once."""
    from test_convergence import building

    exact_deck = building(tmp_path, "coulomb", "event_driven")
    exact = quiet_run(exact_deck.read_text(), base_dir=tmp_path).summary
    monkeypatch.setattr(tolerance_module, "EXACT_DEVICES", 0)
    deck = building(tmp_path, "coulomb", "moreau_jean")
    r, report, session = tolerance_module.tolerance_run(deck, 1e-2)
    session.close()
    s = r.summary
    assert s["technique"] == "moreau_jean"
    # the deck given, as sha256sum reads it, not the deck of the run chosen
    assert s["deck_sha256"] == hashlib.sha256(deck.read_bytes()).hexdigest()
    assert against_exact(report, exact) == (13, 13)
    n_levels = round(math.log2(report.n1)) + 1  # n1 = 1, 2, ..., report.n1
    assert report.runs == 1 + n_levels and report.rounds == n_levels - 2


def exact_test4() -> dict:
    return fd.run(INPUTS / "test4_coulomb.nml").summary


@pytest.mark.parametrize("tol", [1e-2, 1e-3])
def test_table1_test4_against_the_exact_technique(tol):
    """The paper's test 4 under the velocity law (40 s, eps = 1e-3 m/s, n1 = 20) against the
    exact technique's peaks: every estimated quantity (both DOFs' peak displacements and
    accelerations, the device force, the friction energy) is within the tolerance of the
    exact value. The combined ladder starts at n1 = 1 (the model's periods and dt_record =
    0.005 s) and reaches n1 = 4 with eps / 8 at 1e-2 and n1 = 8 with eps / 32 at 1e-3 (one
    level more, the one its measured order predicts); each estimate is at least the true
    error."""
    exact = exact_test4()
    s = quiet_run((INPUTS / "test4_velocity.nml").read_text(), name="test4_velocity.nml",
                  base_dir=INPUTS, tolerance=tol).summary
    bounded = total = 0
    for key in ("peak_u_m", "peak_aabs_mps2", "peak_force_N", "energy_friction_J"):
        values = s[key] if isinstance(s[key], list) else [s[key]]
        refs = exact[key] if isinstance(exact[key], list) else [exact[key]]
        for i, (v, ref) in enumerate(zip(values, refs)):
            true = abs(v - ref)
            assert true <= tol * abs(ref), (key, i, true / abs(ref))
            total += 1
            bounded += s["estimated_error"][key][i] >= true
    assert total == 6 and bounded == 6, bounded
    assert s["tolerance_run"]["n1"] == (4 if tol == 1e-2 else 8)
    # the probe and three combined levels (1e-2), and the one level more (1e-3); the separate
    # step and law ladders took 6 and 9 runs
    assert s["tolerance_run"]["runs"] <= (4 if tol == 1e-2 else 5), s["tolerance_run"]["runs"]
    assert s["tolerance_run"]["law_divisor"] == (8 if tol == 1e-2 else 32)


def hysteretic_den_hartog() -> str:
    return deck_text(den_hartog_groups("hysteretic", "newmark", 20, f=1e-5, eps1=1e-3))


def test_an_unmeetable_tolerance_is_an_error():
    """The hysteretic law's error falls at order 1/2 in f (Den Hartog's friction energy: 1.7 %
    at f = 4e-5 m, order 0.60 measured): 1e-3 would need f divided by far more than the cost
    limit allows. The run stops with ToleranceError naming the quantity, its estimate, the
    law's order and the way out; nothing is returned."""
    with pytest.raises(fd.ToleranceError) as info:
        quiet_run(hysteretic_den_hartog(), tolerance=1e-3)
    text = str(info.value)
    assert "tolerance 0.001 cannot be met: energy dissipated by friction" in text
    assert "the regularized law's error governs" in text and "law = 'coulomb'" in text
    assert f"eps and f / {tolerance_module.MAX_REFINEMENT}" in text


def test_command_line_tolerance_run(tmp_path, capsys):
    """``python -m frictiondyn run DECK --tolerance T``: the history and the summary of the
    chosen run, the summary with estimated_error, estimate_method and tolerance_run; an
    unmeetable tolerance exits 1 with the message and writes nothing."""
    deck = tmp_path / "dh.nml"
    deck.write_text(deck_text(den_hartog_groups("velocity", "newmark", 20, eps=1e-3)))
    assert cli(["run", str(deck), "--tolerance", "0.01", "--out", str(tmp_path / "out")]) == 0
    printed = capsys.readouterr().out
    assert "tolerance run: 0.01 (floor 0.01): newmark, n1 = 4, eps and f / 8 (4 runs, 1 round)" in printed
    summary = json.loads((tmp_path / "out" / "dh.summary.json").read_text())
    assert summary["tolerance_run"]["met"] and summary["estimated_error"]["peak_u_m"][0] > 0
    assert summary["estimated_error"]["peak_u_m"][0] <= 0.01 * summary["peak_u_m"][0]
    assert (tmp_path / "out" / "dh.csv").is_file()
    assert sorted(p.name for p in (tmp_path / "out").iterdir()) == ["dh.csv", "dh.summary.json"]
    bad = tmp_path / "bad.nml"
    bad.write_text(hysteretic_den_hartog().replace("&integration", "&integration\n  tolerance = 1e-3"))
    assert cli(["run", str(bad), "--out", str(tmp_path / "none")]) == 1
    assert "tolerance 0.001 cannot be met" in capsys.readouterr().err
    assert not (tmp_path / "none").exists()


def test_the_executable_refuses_a_tolerance_naming_the_python_command(tmp_path):
    """The executable runs one setting: a deck with &integration tolerance is refused with a
    message naming the Python command; a tolerance out of (0, 1) is refused as invalid."""
    deck = tmp_path / "dh.nml"
    text = deck_text(den_hartog_groups("velocity", "newmark", 20, eps=1e-3))
    deck.write_text(text.replace("&integration", "&integration\n  tolerance = 0.01"))
    with pytest.raises(fd.RunFailed) as info:
        fd.run_executable(deck, cwd=tmp_path)
    assert "group &integration: tolerance = 0.01 is a tolerance run, made by Python: python -m frictiondyn run DECK" \
        in info.value.stderr
    deck.write_text(text.replace("&integration", "&integration\n  tolerance = 1.5"))
    with pytest.raises(fd.RunFailed) as info:
        fd.run_executable(deck, cwd=tmp_path)
    assert "group &integration: tolerance = 1.5 is invalid: must be in (0, 1" in info.value.stderr
    with pytest.raises(fd.DeckError, match=r"tolerance = 1.5 is invalid"):
        fd.run(deck)
    assert not (tmp_path / "out").exists()


def test_analysis_tolerance():
    """``Analysis(..., tolerance=)`` is a tolerance run (the deck's &integration carries it)."""
    a = fd.Analysis(
        masses=[FV_M], springs=[fd.Spring(1, 0, FV_K)], u0=[FV_U0],
        excitation=fd.FreeVibration(dt_record=0.01, duration=4.0),
        damping=fd.Damping("none"),
        devices=[fd.Device(1, 0, p=FV_K * FV_A, mu=1.0, law="coulomb")],
        integration=fd.Integration(technique="moreau_jean", n1=10),
        tolerance=1e-3,
    )
    s = a.run().summary
    assert s["tolerance_run"]["technique"] == "event_driven"
    assert abs(s["energy_friction_J"] - FV_ENERGY) <= 1e-9 * FV_ENERGY


def test_a_peak_at_the_first_instant_of_a_regularized_law_is_refused():
    """Free vibration under the velocity law: released from rest at u0, the device starts
    unloaded (no force at rest, whatever eps), so the peak acceleration is k u0 / m at t = 0,
    10 % above Coulomb's k (u0 - a) / m, and no level changes it (its estimate would be
    round-off). The run refuses it rather than return it."""
    text = free_vibration_text("event_driven").replace("'event_driven'", "'newmark'").replace(
        "'coulomb'", "'velocity'")
    with pytest.raises(fd.ToleranceError, match=r"peak \|a_abs\| DOF 1 = 0.406628 m/s2 is reached at t = 0"):
        quiet_run(text)


def converge_on_the_same_levels(tmp_path, text: str, report) -> dict:
    """``converge`` (its JSON report) of ``text`` on the step levels a tolerance run's last
    round stood on: the last (at most) five of n1 = ..., report.n1 / 2, report.n1."""
    from frictiondyn.convergence import step_convergence

    ladder = min(5, 2 + report.rounds)
    deck = tmp_path / "levels.nml"
    first = report.n1 // 2 ** (ladder - 1)
    stripped = text.replace("  tolerance = 0.001\n", "")
    deck.write_text(re.sub(r"n1 = \d+", f"n1 = {first}", stripped))
    study = step_convergence(deck, levels=ladder - 1)
    assert study.n1 == [first * 2**k for k in range(ladder)] and study.n1[-1] == report.n1
    return {(q["key"], q["item"]): q for q in study.to_dict()["quantities"]}


@pytest.mark.parametrize("case", ["moreau_jean", "newmark"])
def test_converge_reports_the_tolerance_runs_estimates(tmp_path, monkeypatch, case):
    """``frictiondyn converge`` on the levels a tolerance run stood on reports, for every
    estimated quantity, the estimate of the finest level and its method exactly as the
    tolerance run does (one estimator: the order capped at the technique's, 1 for
    Moreau-Jean and 2 for Newmark, from the larger of the last two changes): Moreau-Jean on the
    free vibration (the exact technique ruled out) at 1e-3, whose peaks measure orders above 1,
    and Newmark on the resonant oscillator of test_convergence at 1e-2."""
    from test_convergence import OSCILLATOR

    if case == "moreau_jean":
        monkeypatch.setattr(tolerance_module, "EXACT_DEVICES", 0)
        text, tol = free_vibration_text("event_driven").replace("'event_driven'", "'moreau_jean'"), 1e-3
    else:
        text, tol = OSCILLATOR.replace("N1", "20"), 1e-2
    r, report, session = tolerance_module.tolerance_run(text=text, tolerance=tol, name="case.nml",
                                                        base_dir=tmp_path)
    session.close()
    assert report.technique == case
    study = converge_on_the_same_levels(tmp_path, text, report)
    capped = 0
    for row in report.quantities:
        q = study[(row["key"], row["item"])]
        finest = q["step"]["errors"][-1]
        assert row["estimated_error"] == max(finest, tolerance_module.ROUND_OFF * q["scale"]), row
        assert row["method"] == q["estimate_method"], (row, q["estimate_method"])
        capped += "the theoretical" in row["method"]
    assert capped >= 1  # a measured order above the technique's: both cap it


def bench_module():
    """bench/tolerance.py, whose battery builds the shear buildings."""
    import importlib.util

    path = Path(__file__).resolve().parent.parent / "bench" / "tolerance.py"
    spec = importlib.util.spec_from_file_location("bench_tolerance", path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_the_run_stops_as_soon_as_every_estimate_is_within_the_tolerance():
    """The battery's 3-storey building under the velocity law at 1e-3: the run is returned at
    the first level of the combined ladder whose every estimate is within its allowed error,
    with no margin beyond the estimate's own safety factors: n1 = 2, 4, 8 (eps / 0.5, / 2,
    / 8), then n1 = 16 with eps / 32, in 5 runs (the separate ladders took 7, and 1.4 times
    the steps). Every estimated quantity is within the tolerance of the exact technique's
    peaks and each estimate is at least its true error."""
    bench = bench_module()
    exact = quiet_run(bench.building_text(3, "coulomb", "event_driven")).summary
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", fd.FrictiondynWarning)
        r, report, session = tolerance_module.tolerance_run(
            text=bench.building_text(3, "velocity", "newmark"), tolerance=1e-3, name="b3.nml")
    session.close()
    assert (report.n1, report.law_divisor, report.runs) == (16, 32, 5), report
    assert report.steps < 70_000, report.steps
    worst = max(row["estimated_error"] / row["allowed"] for row in report.quantities)
    assert worst <= 1.0, worst
    for row in report.quantities:
        ref = exact[row["key"]]
        true = abs(row["value"] - (ref[row["index"]] if isinstance(ref, list) else ref))
        assert true <= row["allowed"] and row["estimated_error"] >= true, row


def test_ladder_estimate_measures_the_order_across_a_jump():
    """A ladder at h, h/2 and then h/16 (ratios 2 and 8): values q* + C h^1.5 give back order
    1.5 and the limit q*, the finest level's error 1.25 times its distance to it; capped at 1,
    the d2 that d1 predicts at order 1 (8 times the true one's share) governs; a jump whose
    change comes back with the other sign has no order, a difference with its reason."""
    from frictiondyn.convergence import ladder_estimate, method_text

    h = [1.0, 0.5, 0.5 / 8]
    values = [2.0 + 0.3 * x**1.5 for x in h]
    e = ladder_estimate(values, [2, 8], 1.0, 2.0)
    assert e.method == "richardson" and e.order == pytest.approx(1.5, rel=1e-9)
    assert e.extrapolated == pytest.approx(2.0, rel=1e-12)
    assert e.errors[-1] == pytest.approx(1.25 * 0.3 * h[-1]**1.5, rel=1e-9)
    assert method_text(e) == "Richardson at order 1.50 (ratios 2 and 8)"
    capped = ladder_estimate(values, [2, 8], 1.0, 1.0)
    d1 = values[1] - values[0]
    assert capped.order == 1.0 and capped.measured == pytest.approx(1.5, rel=1e-9)
    assert capped.errors[-1] == pytest.approx(1.25 * abs(d1) / 8)
    bad = ladder_estimate([values[0], values[1], values[1] + 0.01], [2, 8], 1.0, 2.0)
    assert bad.method == "difference" and bad.errors[-1] == pytest.approx(3 * abs(d1))
    assert "alternate in sign" in method_text(bad)
    same = ladder_estimate([1.0, 1.008, 1.004], [2, 2], 1.0, 2.0)
    assert same.method == "difference" and same.errors[-1] == pytest.approx(3 * 0.008)


def exact_den_hartog() -> dict:
    return quiet_run(deck_text(den_hartog_groups("coulomb", "event_driven", 20))).summary


def against_exact(report, exact: dict) -> tuple[int, int]:
    """Every estimated quantity of ``report`` within its allowed error of ``exact``; returns
    (quantities, estimates at least the true error)."""
    total = bounded = 0
    for row in report.quantities:
        ref = exact[row["key"]]
        ref = ref[row["index"]] if isinstance(ref, list) else ref
        true = abs(row["value"] - ref)
        assert true <= row["allowed"], row
        total += 1
        bounded += row["estimated_error"] >= true
    return total, bounded


def test_the_combined_ladder_jumps_to_the_level_its_order_predicts():
    """Den Hartog under the hysteretic law at 2e-3: the combined ladder's first three levels
    (n1 = 1, 2, 4 with f and eps1 / 0.5, / 2, / 8) measure one order for the step and the law
    together; the next level is the one that order predicts, n1 = 16 with f / 128 (a jump of
    4, not two levels of 2), whose estimate stands on the ladder 2, 4, 16 and confirms the
    order across the jump: 4 runs and the probe, each made once. Every estimated quantity is
    within the tolerance of the exact technique's and each estimate at least its true
    error."""
    text = deck_text(den_hartog_groups("hysteretic", "newmark", 20, f=1e-5, eps1=1e-3))
    r, report, session = tolerance_module.tolerance_run(text=text, tolerance=2e-3, name="dh.nml")
    session.close()
    assert [label for label, _ in report.made] == ["probe"] + [
        f"combined level: n1 = {n}, eps and f / {d:g}" for n, d in
        ((1, 0.5), (2, 2), (4, 8), (16, 128))]
    assert (report.n1, report.law_divisor, report.runs, report.rounds) == (16, 128, 5, 2)
    assert any("(ratios 2 and 4)" in row["method"] for row in report.quantities)
    assert against_exact(report, exact_den_hartog()) == (4, 4)


def test_a_combined_order_not_measured_falls_back_to_the_separate_ladders(monkeypatch):
    """The battery's 3-storey building under the velocity law at 1e-2, the combined ladder
    held to its first three levels: floor 2's peak acceleration changes sign between them
    (+0.09 % to -0.04 % to -0.01 % of exact, above the noise), so no combined order is
    measured; the run says so and takes the separate law and step ladders, which reuse the
    combined level they share (n1 = 4 with eps / 8), and each quantity's method is then the
    step's and the law's. Every estimated quantity is within the tolerance of the exact
    technique's."""
    monkeypatch.setattr(tolerance_module, "COMBINED_EXTRA", 0)
    bench = bench_module()
    exact = quiet_run(bench.building_text(3, "coulomb", "event_driven")).summary
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", fd.FrictiondynWarning)
        r, report, session = tolerance_module.tolerance_run(
            text=bench.building_text(3, "velocity", "newmark"), tolerance=1e-2, name="b3.nml")
    session.close()
    assert ("the combined ladder (eps and f tied to the step) measured no order (peak |a_abs| "
            "DOF 2: the combined levels n1 = 1, 2, 4 give difference (the changes between levels "
            "alternate in sign)): the separate step and law ladders") in report.why
    labels = [label for label, _ in report.made]
    assert labels.count("combined level: n1 = 4, eps and f / 8") == 1
    assert "law level: n1 = 4, eps and f / 8" not in labels
    assert all(row["method"].startswith("step: ") and "; law: " in row["method"]
               for row in report.quantities)
    total, bounded = against_exact(report, exact)
    assert total == 13


def test_moreau_jean_jumps_to_the_level_its_order_predicts(monkeypatch):
    """Den Hartog by Moreau-Jean (the exact technique ruled out) at 1e-3: from n1 = 1, 2, 4 the
    estimate at Moreau-Jean's order 1 (3.5 times the allowed error) predicts a step 1.5 x 3.5
    = 5.2 times finer: n1 = 24, the smallest integer multiple (a power of 2 would be 32), run
    next; the changes across that jump show no order, so n1 = 8, twice the level it jumped
    from, is filled in and the estimate of n1 = 24 stands on the ladder 4, 8, 24: 5 levels and
    the probe, 22 286 steps (the jump to 32 with 16 filled in took 31 430, the ladder 1, 2,
    ..., 32 36 001). Every estimated quantity is within the tolerance of the exact technique's
    and each estimate at least its true error."""
    monkeypatch.setattr(tolerance_module, "EXACT_DEVICES", 0)
    text = deck_text(den_hartog_groups("coulomb", "moreau_jean", 20))
    r, report, session = tolerance_module.tolerance_run(text=text, tolerance=1e-3, name="dh.nml")
    session.close()
    assert [label for label, _ in report.made] == ["probe"] + [
        f"step level: n1 = {n}" for n in (1, 2, 4, 24, 8)]
    assert (report.technique, report.n1, report.runs) == ("moreau_jean", 24, 6)
    assert report.steps == 22_286, report.steps
    assert against_exact(report, exact_den_hartog()) == (4, 4)


def test_a_jump_is_the_smallest_integer_multiple_the_order_asks():
    """An error 3.5 times the allowed at order 1 asks a step 1.5 x 3.5 = 5.25 times finer: the
    jump is 6 (not 8, the next power of 2); at order 2, sqrt(5.25) = 2.29: 3; within the
    allowed error with its margin, still 2 (a jump refines)."""
    assert tolerance_module._multiple(3.5, 1.0, 1.0) == 6
    assert tolerance_module._multiple(3.5, 1.0, 2.0) == 3
    assert tolerance_module._multiple(0.5, 1.0, 1.0) == 2
    assert tolerance_module._multiple(4.0, 1.0, 1.0) == 6
    assert tolerance_module._multiple(2.0, 1.0, 1.0) == 3
