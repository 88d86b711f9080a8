"""Implausible models and records: a first period beyond 0.01-10 s or a record's peak
acceleration beyond 0.005-3 g (the likely unit mistake named in one line, the run done), and
the same decks with the right units silent."""

from __future__ import annotations

import warnings

import pytest
from conftest import INPUTS, ok

import frictiondyn

G0 = 9.80665


def _bare(k_scale: float = 1.0, duration: float = 1.0) -> str:
    """inputs/building5_bare.nml (T1 = 0.633 s) for `duration` seconds of its record, its
    storey stiffnesses times k_scale."""
    text = (INPUTS / "building5_bare.nml").read_text()
    ks = "400.0e6, 360.0e6, 320.0e6, 260.0e6, 200.0e6"
    assert ks in text
    text = text.replace(ks, ", ".join(f"{k * k_scale!r}" for k in (400e6, 360e6, 320e6, 260e6, 200e6)))
    text = text.replace("record_file = 'synthetic_pga035.AT2'", f"record_file = '{INPUTS / 'synthetic_pga035.AT2'}'")
    assert "duration = 30.0" in text
    return text.replace("duration = 30.0", f"duration = {duration}")


def _period_warnings(r) -> list[str]:
    return [w for w in r.stderr.splitlines() if "implausible" in w]


def test_a_storey_stiffness_in_kn_per_m_warns(run):
    """The storey stiffnesses typed in kN/m (400e3 for 400 MN/m): T1 = 0.633 s x sqrt(1000)
    = 20.0 s, and the executable warns once, naming the likely mistake; the run is done."""
    r = ok(run(_bare(1e-3)))
    lines = _period_warnings(r)
    assert lines == ["frictiondyn: warning: the first period T1 = 20.0 s (period_stuck_s) is beyond 10 s, "
                     "longer than structures have: a stiffness in kN/m typed as N/m?; "
                     "see docs/warnings.md#implausible-period"]
    assert len(lines[0]) - len("frictiondyn: warning: ") <= 220
    s = r.summary()
    assert s["period_plausibility"] == "warns" and s["record_plausibility"] == "passed"
    assert s["period_stuck_s"] == pytest.approx(0.6332451357043677 * 1000**0.5, rel=1e-9)


def test_the_same_deck_in_n_per_m_is_silent(run):
    r = ok(run(_bare()))
    assert r.stderr == ""
    s = r.summary()
    assert s["warnings"] == [] and s["period_plausibility"] == "passed"


def test_a_friction_damped_building_in_kn_per_m_warns_by_its_free_period():
    """inputs/building5_friction.nml has a damper in every storey: its stuck system (every
    device a rigid link) has no period, so the free system's (the bare frame's) is judged,
    20.0 s with the stiffnesses in kN/m. Python issues it as a FrictiondynWarning."""
    text = (INPUTS / "building5_friction.nml").read_text()
    text = text.replace("400.0e6, 360.0e6, 320.0e6, 260.0e6, 200.0e6", "400.0e3, 360.0e3, 320.0e3, 260.0e3, 200.0e3")
    text = text.replace("record_file = 'synthetic_pga035.AT2'",
                        f"record_file = '{INPUTS / 'synthetic_pga035.AT2'}'\n  duration = 1.0")
    with pytest.warns(frictiondyn.FrictiondynWarning, match=r"T1 = 20\.0 s \(periods_free_s\(1\)\).*kN/m"):
        r = frictiondyn.run_text(text)
    assert r.summary["period_stuck_s"] is None and r.summary["period_plausibility"] == "warns"


def _record_deck(units: str, values: list[float]) -> tuple[dict, dict]:
    """A 0.63 s oscillator (100 kg, 1e4 N/m) under a record of plain values in `units`."""
    deck = {
        "model": {"n_dof": 1, "mass": [100.0]},
        "springs": {"n_springs": 1, "node_i": [1], "node_j": [0], "k": [1.0e4]},
        "damping": {"damping_type": "stiffness", "xi": 0.02},
        "excitation": {"excitation_type": "record", "record_file": "rec.txt", "record_format": "values",
                       "record_units": units, "dt_record": 0.01},
        "integration": {"n1": 4},
    }
    return deck, {"rec.txt": "\n".join(repr(v) for v in values) + "\n"}


# the same record, peak 0.35 g, in a file of cm/s2 and in a file of g
RECORD_CM = [0.0, 120.0, -343.0, 250.0, -80.0, 30.0, 0.0]
RECORD_G = [0.0, 0.12, -0.35, 0.25, -0.08, 0.03, 0.0]


@pytest.mark.parametrize("values, units, verdict, words", [
    (RECORD_CM, "cm/s2", "passed", None),
    (RECORD_G, "g", "passed", None),
    (RECORD_CM, "g", "warns", "the record peaks at 343.0 g (record.peak_acc_mps2 = 3.364E+03), beyond 3 g, "
                              "more than earthquakes have: a record in cm/s2 read as g or m/s2? set record_units"),
    (RECORD_CM, "m/s2", "warns", "the record peaks at 35.0 g (record.peak_acc_mps2 = 3.430E+02), beyond 3 g"),
    (RECORD_G, "cm/s2", "warns", "the record peaks at 3.57E-04 g (record.peak_acc_mps2 = 3.500E-03), below "
                                 "0.005 g, less than earthquakes have: a record in g or m/s2 read as cm/s2? "
                                 "set record_units, record_scale"),
])
def test_a_record_read_in_the_wrong_units_warns(run, values, units, verdict, words):
    """A record of 0.35 g read in its units is silent; its file of cm/s2 read as g (343 g) or
    as m/s2 (35 g), and its file of g read as cm/s2 (3.6e-4 g), warn once, naming the likely
    mistake."""
    deck, files = _record_deck(units, values)
    r = ok(run(deck, files=files))
    s = r.summary()
    assert s["record_plausibility"] == verdict and s["period_plausibility"] == "passed"
    lines = [w for w in r.stderr.splitlines() if "record peaks" in w]
    if words is None:
        assert lines == [] and s["warnings"] == []
    else:
        assert len(lines) == 1 and words in lines[0] and lines[0].endswith("#implausible-record")
        assert len(lines[0]) - len("frictiondyn: warning: ") <= 220


def test_a_record_of_zeros_is_not_judged(run):
    """Free vibration from u0 under a record of zeros: no peak to judge, no warning."""
    deck, files = _record_deck("m/s2", [0.0] * 20)
    deck["model"]["u0"] = [0.01]
    r = ok(run(deck, files=files))
    s = r.summary()
    assert s["record_plausibility"] == "not applicable" and s["warnings"] == []


def test_no_warning_from_python_for_a_sane_deck():
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        r = frictiondyn.run_text(_bare(duration=0.5))
    assert r.summary["warnings"] == []
