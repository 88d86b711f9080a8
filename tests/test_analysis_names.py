"""An Analysis names its own attributes in errors (not the deck it generates), and a Record
of an AT2 file needs no dt_record (the file gives it), as a deck does not."""

from __future__ import annotations

import pytest
from conftest import INPUTS

import frictiondyn as fd
from frictiondyn.model import python_place

AT2 = INPUTS / "synthetic_pga035.AT2"


def frame(**kw) -> fd.Analysis:
    args = dict(masses=[1000.0, 800.0], springs=[fd.Spring(1, 0, 4.0e5), fd.Spring(2, 1, 3.0e5)],
                excitation=fd.Harmonic(amplitude=0.01, frequency=2.0, dt_record=0.01, duration=0.5),
                damping=fd.Damping(type="none"),
                devices=[fd.Device(1, 0, p=1000.0, mu=0.1, law="velocity"),
                         fd.Device(2, 1, p=500.0, mu=0.1, law="velocity")])
    args.update(kw)
    return fd.Analysis(**args)


@pytest.mark.parametrize("change, place", [
    (lambda a: setattr(a.devices[1], "p", -5.0), "Analysis.devices[1].p: "),
    (lambda a: a.masses.__setitem__(1, -3.0), "Analysis.masses[1]: "),
    (lambda a: setattr(a.springs[0], "k", -1.0), "Analysis.springs[0].k: "),
    (lambda a: setattr(a.devices[0], "eps", 0.0), "Analysis.devices[0].eps: "),
    (lambda a: setattr(a.integration, "n1", 0), "Analysis.integration.n1: "),
    (lambda a: setattr(a.excitation, "frequency", -2.0), "Analysis.excitation.frequency: "),
])
def test_errors_name_the_attribute(change, place):
    a = frame()
    change(a)
    with pytest.raises(fd.DeckError) as err:
        a.run()
    text = str(err.value)
    assert text.startswith(place), text
    assert "analysis.nml" not in text


def test_place_of_deck_messages():
    assert python_place("x.nml, group &isolators: mu_table_v(:, 3) must increase") == \
        "isolators[2].mu_table"
    assert python_place("group &damping: damping_type = 'x' is invalid") == "damping.type"
    assert python_place("group &excitation: record_scale = 0 is invalid") == "excitation.scale"
    assert python_place("no group here") is None


def test_record_of_an_at2_file_needs_no_dt(tmp_path):
    a = frame(excitation=fd.Record(file=AT2, duration=0.5))
    r = a.run()
    assert r.summary["record"]["dt_s"] == 0.01  # the file's DT
    assert r.summary["record"]["units"] == "g"
    # a plain file without dt_record: the reader's own message, naming the Analysis
    plain = tmp_path / "rec.txt"
    plain.write_text("0.0\n0.1\n0.0\n")
    with pytest.raises(fd.DeckError) as err:
        frame(excitation=fd.Record(file=plain)).run()
    assert "dt_record" in str(err.value) and "analysis.nml" not in str(err.value)
    # values without dt_record: named by the attribute, before any file is written
    for attr in ("excitation", "excitation2"):
        kw = {"floors": fd.Floors([fd.Floor(1000.0, plan_x=2.0, plan_y=2.0)]),
              "frames": [fd.Frame(1, 0, 0, 0, 4.0e5), fd.Frame(1, 90, 0, 0, 4.0e5)],
              "masses": None, "springs": [], "devices": [],
              "excitation": fd.Record(file=AT2, duration=0.5)} if attr == "excitation2" else {}
        kw[attr] = fd.Record(values=[0.0, 0.1, 0.0])
        with pytest.raises(fd.DeckError) as err:
            frame(**kw).run()
        assert str(err.value) == (f"Analysis.{attr}.dt_record: a Record of values needs its step "
                                  "dt_record [s] (an AT2 file gives its own DT)")
    # format and units reach the reader: cm/s2 values a hundredth of m/s2
    b = frame(excitation=fd.Record(file=plain, dt_record=0.01, format="values", units="cm/s2"))
    assert b.run().summary["record"]["peak_acc_mps2"] == pytest.approx(0.001, rel=1e-12)


def test_warnings_name_the_analysis_at_the_callers_line():
    """A run's warning names the Analysis, not the deck it generates, and points at the
    line that called run()."""
    a = frame(integration=fd.Integration(n1=1, n2=2),
              excitation=fd.Harmonic(amplitude=0.05, frequency=8.0, dt_record=0.02, duration=1.0))
    with pytest.warns(fd.FrictiondynWarning) as caught:
        a.run()
    assert caught and all(str(w.message).startswith("Analysis: ") for w in caught), \
        [str(w.message) for w in caught]
    assert all(w.filename == __file__ for w in caught)
