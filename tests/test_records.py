"""Recorded table motion: PEER AT2 files, record_format and record_units, strict parsing
(every malformed record names the file, the line and what was expected) and the shipped
synthetic record."""

from __future__ import annotations

import numpy as np
import pytest
from conftest import INPUTS, deck_text, ok

from frictiondyn.synthetic import synthetic_record, write_at2

G = 9.80665


def oscillator(excitation: dict) -> dict:
    """A 1-DOF frame with a hysteretic friction damper (sticks and slips under 0.2 g)."""
    return {
        "model": {"n_dof": 1, "mass": [1000.0]},
        "springs": {"n_springs": 1, "node_i": [1], "node_j": [0], "k": [4.0e5]},
        "damping": {"damping_type": "rayleigh", "rayleigh_a0": 0.1},
        "friction": {"n_devices": 1, "node_i": 1, "node_j": 0, "law": "hysteretic",
                     "p": 2000.0, "mu": 0.3},
        "excitation": excitation,
        "integration": {"n1": 10},
        "output": {"name": "case"},
    }


def acc_g(n: int = 501, dt: float = 0.01) -> np.ndarray:
    t = np.arange(n) * dt
    return 0.2 * np.sin(2 * np.pi * 2.0 * t) * np.minimum(1.0, t)


def at2_text(values, dt="  .0100", npts=None, spelling="new", units="G",
             kind="ACCELERATION") -> str:
    n = len(values) if npts is None else npts
    line4 = {
        "new": f"NPTS=  {n}, DT= {dt} SEC",
        "old": f"  {n}   {dt}   NPTS, DT",
        "colon": f"NPTS, DT: {n} {dt} SEC",
    }[spelling]
    head = ["PEER NGA STRONG MOTION DATABASE RECORD", "TEST RECORD, 01/01/00, STATION X",
            f"{kind} TIME SERIES IN UNITS OF {units}", line4]
    vals = [v if isinstance(v, str) else f"{v:15.7E}" for v in values]
    rows = ["".join(vals[i:i + 5]) for i in range(0, len(vals), 5)]
    return "\n".join(head + rows) + "\n"


def record_excitation(file: str, **extra) -> dict:
    return {"excitation_type": "record", "record_file": file, **extra}


@pytest.mark.parametrize("spelling", ["new", "old", "colon"])
def test_at2_and_two_columns_give_the_same_response(run, spelling):
    """One record written as AT2 (values in g, five a line, DT from the header) and as
    time-value columns in g, and in m/s2: the same response."""
    a = acc_g()
    t = np.arange(a.size) * 0.01
    at2 = at2_text(a, spelling=spelling)
    a7 = np.array([float(f"{x:15.7E}") for x in a])  # the values the AT2 file holds
    cols_g = "".join(f"{ti:.2f} {float(x)!r}\n" for ti, x in zip(t, a7))
    cols_si = "".join(f"{ti:.2f} {float(x * G)!r}\n" for ti, x in zip(t, a7))
    r_at2 = ok(run(oscillator(record_excitation("rec.AT2")), files={"rec.AT2": at2}))
    r_g = ok(run(oscillator(record_excitation("rec.txt", dt_record=0.01, record_units="g")),
                 files={"rec.txt": cols_g}))
    r_si = ok(run(oscillator(record_excitation("rec.txt", dt_record=0.01)),
                  files={"rec.txt": cols_si}))
    h_at2, h_g, h_si = r_at2.history(), r_g.history(), r_si.history()
    assert h_at2.summary["stick_to_slip"][0] > 5  # the damper does stick and slip
    # same values, same arithmetic: identical
    assert np.array_equal(h_at2.data, h_g.data)
    # g * 9.80665 rounded once more: equal to round-off
    np.testing.assert_allclose(h_si.data, h_at2.data, rtol=0, atol=1e-12 * np.abs(h_at2.data).max())
    # the table acceleration is the record, in m/s2, at its samples
    np.testing.assert_allclose(h_at2["ag"][: a.size], a7 * G, rtol=1e-12, atol=1e-14)
    rec = r_at2.summary()["record"]
    assert rec["format"] == "at2" and rec["format_detected"] is True
    assert rec["units"] == "g" and rec["samples"] == a.size and rec["dt_s"] == 0.01
    assert "record rec.AT2 (at2, detected, g): 501 samples" in r_at2.stdout
    assert r_g.summary()["record"]["format"] == "time_value"


@pytest.mark.parametrize(
    "line3, units, factor",
    [
        ("ACCELERATION TIME SERIES IN UNITS OF G", "g", G),
        ("ACCELERATION TIME SERIES IN UNITS OF G.", "g", G),
        ("ACCELERATION TIME SERIES UNITS: CM/S/S", "cm/s2", 0.01),
        ("ACCELERATION TIME SERIES (CM/S2)", "cm/s2", 0.01),
        ("ACCELERATION TIME SERIES IN UNITS OF CM/SEC**2", "cm/s2", 0.01),
        ("ACCELERATION TIME SERIES, UNITS = M/S^2", "m/s2", 1.0),
        ("ACCELERATION TIME SERIES, M 6.7", "g", G),  # no unit named: PEER's g
    ],
)
def test_at2_units_as_line_3_writes_them(run, line3, units, factor):
    """Line 3's units in the spellings real files use: the table acceleration is the value
    times the factor of the units the line names (a unit misread as g is a factor of 981)."""
    a = [0.0, 50.0, -120.0, 30.0, 0.0, 10.0]
    text = at2_text(a).replace("ACCELERATION TIME SERIES IN UNITS OF G", line3)
    r = ok(run(oscillator(record_excitation("rec.AT2")), files={"rec.AT2": text}))
    assert r.summary()["record"]["units"] == units
    np.testing.assert_allclose(r.history()["ag"][:6], np.array(a) * factor, rtol=1e-12)


def test_at2_units_gal_are_cm_s2(run):
    """record_units = 'gal' agrees with a header in cm/s2 (the same unit)."""
    text = at2_text([0.0, 50.0, -120.0, 30.0, 0.0, 10.0], units="CM/S/S")
    r = ok(run(oscillator(record_excitation("rec.AT2", record_units="gal")), files={"rec.AT2": text}))
    np.testing.assert_allclose(r.history()["ag"][:3], [0.0, 0.5, -1.2], rtol=1e-12)


def test_at2_with_a_byte_order_mark(run):
    """An AT2 file saved by an editor that writes a UTF-8 byte order mark reads as without."""
    a = [0.0, 0.1, -0.2, 0.05, 0.0, 0.02]
    plain = ok(run(oscillator(record_excitation("rec.AT2")), files={"rec.AT2": at2_text(a)}))
    marked = ok(run(oscillator(record_excitation("rec.AT2")), files={"rec.AT2": "\ufeff" + at2_text(a)}))
    assert np.array_equal(plain.history().data, marked.history().data)


def test_commented_plain_record_is_not_taken_for_at2(run):
    """A one-value-a-line file whose '#' comments name NPTS and DT on its fourth line is
    read as 'values' (m/s2), not as an AT2 file in g."""
    text = "# synthetic\n# generated\n# seed 1\n# NPTS = 5, DT = 0.01 s\n0.0\n0.5\n-1.0\n2.0\n0.0\n"
    r = ok(run(oscillator(record_excitation("rec.txt", dt_record=0.01)), files={"rec.txt": text}))
    rec = r.summary()["record"]
    assert rec["format"] == "values" and rec["units"] == "m/s2"
    assert rec["peak_acc_mps2"] == pytest.approx(2.0, rel=1e-15)


def test_record_units_and_scale_compose(run):
    """cm/s2 values with record_scale 2: the table acceleration is value * 0.01 * 2."""
    a = np.array([0.0, 50.0, -120.0, 30.0, 0.0])
    r = ok(run(oscillator(record_excitation("rec.txt", dt_record=0.01, record_units="cm/s2",
                                            record_scale=2.0, record_format="values")),
               files={"rec.txt": "".join(f"{x}\n" for x in a)}))
    h = r.history()
    np.testing.assert_allclose(h["ag"][:5], a * 0.02, rtol=1e-15)
    rec = r.summary()["record"]
    assert rec["format_detected"] is False and rec["peak_acc_mps2"] == pytest.approx(2.4)


def test_displacement_at2_in_cm(run):
    """A .DT2-style file (displacement in cm) read as a displacement record: x(t) = X t^3
    has the exact second difference 6 X t inside the record."""
    dt, x0 = 0.01, 2.0  # cm/s^3
    t = np.arange(11) * dt
    text = at2_text(list(x0 * t**3), kind="DISPLACEMENT", units="CM")
    r = ok(run(oscillator(record_excitation("rec.dt2", record_kind="displacement")),
               files={"rec.dt2": text}))
    ag = r.history()["ag"][1:10]
    np.testing.assert_allclose(ag, 6 * x0 * 0.01 * t[1:10], rtol=1e-6)
    assert r.summary()["record"]["units"] == "cm"


def assert_rejected(r, words):
    assert r.returncode == 1, r.stdout
    for w in words:
        assert w in r.stderr, f"{w!r} not in {r.stderr!r}"
    assert not (r.workdir / "out").exists() or not any((r.workdir / "out").iterdir())


AT2_BAD = [
    ("NPTS larger than the data", at2_text([0.1] * 6, npts=7),
     ["line 4 declares NPTS = 7", "6 values after the header"]),
    ("NPTS smaller than the data", at2_text([0.1] * 6, npts=5),
     ["line 6", "beyond the NPTS = 5"]),
    ("DT zero", at2_text([0.1] * 6, dt="0.0"), ["line 4", "DT = 0.0 s must be > 0"]),
    ("DT negative", at2_text([0.1] * 6, dt="-.005", spelling="old"), ["line 4", "must be > 0"]),
    ("DT missing", at2_text([0.1] * 6).replace(", DT=   .0100 SEC", ""),
     ["line 4", "DT is missing", "expected NPTS and DT"]),
    ("DT without value", at2_text([0.1] * 6).replace("  .0100", ""), ["line 4", "DT has no value"]),
    ("NPTS not whole", at2_text([0.1] * 6).replace("NPTS=  6", "NPTS=  6.5"),
     ["line 4", "not a whole number"]),
    ("NaN", at2_text([0.1, 0.2, "    NaN", 0.3, 0.4, 0.5]), ["line 5", "'NaN' is NaN"]),
    ("not a number", at2_text([0.1, 0.2, "   0.3x", 0.3, 0.4, 0.5]),
     ["line 5", "'0.3x' is not a number"]),
    ("repeat count", at2_text([0.1, 0.2, "    3*", 0.4, 0.5, 0.6]),
     ["line 5", "'3*'", "list-directed"]),
    ("slash", at2_text([0.1] * 5 + ["  /"]), ["line 6", "'/'", "list-directed"]),
    ("star", at2_text([0.1] * 5 + ["  *"]), ["line 6", "'*'", "list-directed"]),
    ("tab line", at2_text([0.1] * 6).replace("\n  1.0", "\n\t\n  1.0", 1) + "\t\n",
     ["no value"]),
    ("velocity file", at2_text([0.1] * 6, kind="VELOCITY", units="CM/S"),
     ["line 3", "velocity time series"]),
    ("units contradict", at2_text([0.1] * 6, units="CM/S/S"),
     ["line 3", "units of 'cm/s2'", "record_units = 'g'"]),
    ("DT in milliseconds", at2_text([0.1] * 6, dt="5 MSEC").replace(" SEC\n", "\n", 1),
     ["line 4", "DT is followed by 'MSEC'", "seconds"]),
    ("units unknown", at2_text([0.1] * 6, units="FT/S2"),
     ["line 3", "units of 'ft/s2'", "convert the record"]),
    ("three header lines", "H1\nH2\nACCELERATION TIME SERIES IN UNITS OF G\n",
     ["ends at line 3", "four header lines"]),
    ("NPTS twice", at2_text([0.1] * 6).replace("NPTS=  6,", "NPTS=  6, NPTS=  7,"),
     ["line 4", "NPTS is given twice", "once each"]),
    ("DT twice", at2_text([0.1] * 6, spelling="old").replace("NPTS, DT", "NPTS, DT, DT"),
     ["line 4", "DT is given twice"]),
    ("a value after the header", at2_text([0.1] * 6).replace(" SEC\n", " SEC  1.0000000E-01\n", 1),
     ["line 4", "'1.0000000E-01' after NPTS and DT", "the values start on line 5"]),
    ("a third number (old spelling)", at2_text([0.1] * 6, spelling="old").replace("NPTS, DT", "NPTS, DT  7"),
     ["line 4", "'7' after NPTS and DT"]),
    # a file cut inside its last number: 1.4126416E-01 read as 1.4126416 would be 10x too large
    ("last number cut before its exponent", at2_text([0.1] * 5 + [0.14126416]).rstrip("\n")[:-4],
     ["line 6", "value '1.4126416' ends at column 11", "fixed-width fields of 15 characters",
      "values of line 5"]),
    ("last number cut inside its exponent", at2_text([0.1] * 5 + [0.14126416]).rstrip("\n")[:-1],
     ["line 6", "value '1.4126416E-0' ends at column 14", "fixed-width fields of 15"]),
    ("a tab among fixed-width fields", at2_text([0.1] * 7).replace("\n  1.0000000E-01  1.0000000E-01\n",
                                                                  "\n  1.0000000E-01\t1.0000000E-01\n"),
     ["line 6", "a tab or a comma", "fixed-width fields of 15"]),
]


def test_at2_line_4_with_tabs_reads_as_with_blanks(run):
    """Tabs between the words of line 4 ('NPTS=<tab>501,<tab>DT=<tab>.0100 SEC') separate
    them as blanks do: the same record, the same run."""
    a = list(acc_g())
    plain = ok(run(oscillator(record_excitation("rec.AT2")), files={"rec.AT2": at2_text(a)}))
    text = at2_text(a).replace("NPTS=  501, DT=   .0100 SEC", "NPTS=\t501,\tDT=\t.0100\tSEC")
    assert "\t" in text
    tabs = ok(run(oscillator(record_excitation("rec.AT2")), files={"rec.AT2": text}))
    assert np.array_equal(tabs.history().data, plain.history().data)
    assert tabs.summary()["record"]["samples"] == 501


def test_at2_free_format_body_is_not_held_to_fields(run):
    """A body whose values are separated freely (widths vary, as a script writes them) is
    read as it is: the fixed-width rule applies only to a file whose first body line has
    the fields."""
    head = at2_text([0.1] * 6).splitlines()[:4]
    body = ["0.1 -0.25 0.003", "1e-2 -0.5", "0.125"]
    r = ok(run(oscillator(record_excitation("rec.AT2")), files={"rec.AT2": "\n".join(head + body)}))
    assert r.history()["ag"][:6] == pytest.approx(np.array([0.1, -0.25, 0.003, 0.01, -0.5, 0.125]) * G,
                                                  rel=1e-15)


@pytest.mark.parametrize("text, words", [c[1:] for c in AT2_BAD], ids=[c[0] for c in AT2_BAD])
def test_malformed_at2(run, text, words):
    exc = record_excitation("rec.AT2")
    if "contradict" in " ".join(words) or "record_units = 'g'" in words:
        exc["record_units"] = "g"
    r = run(oscillator(exc), files={"rec.AT2": text})
    assert_rejected(r, ["&excitation", "record_file = 'rec.AT2'", "rec.AT2"] + words)


PLAIN_BAD = [
    ("only commas", "0.1\n,,\n0.2\n", ["line 2", "no value"]),
    ("only a tab", "0.1\n\t\n0.2\n", ["line 2", "no value"]),
    ("empty field", "0.0, 0.1\n0.01,,0.2\n", ["line 2", "empty field"]),
    ("trailing comma", "0.1,\n0.2\n", ["line 1", "empty field"]),
    ("slash", "0.1\n/\n0.2\n", ["line 2", "'/'", "list-directed"]),
    ("repeat count", "0.1\n2*0.5\n0.2\n", ["line 2", "'2*0.5'", "list-directed"]),
    ("infinite", "0.1\n1e999\n0.2\n", ["line 2", "'1e999' is not finite"]),
    ("Fortran exponent without letter", "0.1\n1.5-3\n0.2\n", ["line 2", "'1.5-3' is not a number"]),
    ("columns change", "0.1\n0.2 0.3\n", ["line 2", "one column", "found 2"]),
    ("off the time grid", "0.00 0.0\n0.01 0.1\n0.03 0.2\n", ["line 3", "0.03", "dt_record",
                                                              "expected 0.02"]),
]


@pytest.mark.parametrize("text, words", [c[1:] for c in PLAIN_BAD], ids=[c[0] for c in PLAIN_BAD])
def test_malformed_plain_record(run, text, words):
    r = run(oscillator(record_excitation("rec.txt", dt_record=0.01)), files={"rec.txt": text})
    assert_rejected(r, ["&excitation", "rec.txt"] + words)


@pytest.mark.parametrize(
    "extra, words",
    [
        ({"record_format": "csv"}, ["record_format = 'csv'", "'at2'"]),
        ({"record_units": "ft/s2"}, ["record_units = 'ft/s2'", "'cm/s2'"]),
        ({"record_units": "cm", "record_format": "values"}, ["record_units = 'cm'"]),
        ({"record_format": "values"}, ["dt_record must be given"]),
        ({"dt_record": 0.02}, ["DT = 0.01 s differs from dt_record = 0.02 s"]),
    ],
)
def test_bad_record_settings(run, extra, words):
    text = at2_text(list(acc_g(20)))
    r = run(oscillator(record_excitation("rec.AT2", **extra)), files={"rec.AT2": text})
    assert_rejected(r, ["&excitation"] + words)


def test_synthetic_record_has_the_pga_asked_for(run, tmp_path):
    """The generator's record, read back by the Fortran reader: max |ag| = PGA g (the
    AT2 file's 8 significant digits), and the record is labelled synthetic."""
    for pga, seed in ((0.35, 2024), (0.12, 7)):
        path = write_at2(synthetic_record(duration=8.0, dt=0.005, pga_g=pga, seed=seed),
                         tmp_path / f"syn{seed}.AT2")
        text = path.read_text()
        assert "SYNTHETIC" in text.splitlines()[0] and "NOT A RECORDED" in text.splitlines()[0]
        r = ok(run(oscillator(record_excitation(str(path))), files={}))
        assert r.summary()["record"]["peak_acc_mps2"] == pytest.approx(pga * G, rel=1e-12)
        assert np.abs(r.history()["ag"]).max() == pytest.approx(pga * G, rel=1e-12)
        assert r.summary()["record"]["samples"] == 1601


def test_shipped_synthetic_record():
    """inputs/synthetic_pga035.AT2 is what the generator makes with its defaults."""
    rec = synthetic_record()
    shipped = (INPUTS / "synthetic_pga035.AT2").read_text().splitlines()
    assert "SYNTHETIC" in shipped[0] and "NOT A RECORDED" in shipped[0]
    vals = np.array([float(v) for line in shipped[4:] for v in line.split()])
    assert vals.size == rec.acc_g.size == 2001
    np.testing.assert_allclose(vals, rec.acc_g, rtol=0, atol=1e-7 * 0.35)
    assert np.abs(vals).max() == 0.35


def test_record_deck_without_dt_record_runs_from_python(tmp_path):
    """The extension reads AT2 records too (the same reader): the same numbers."""
    import frictiondyn

    (tmp_path / "rec.AT2").write_text(at2_text(list(acc_g())))
    deck = tmp_path / "case.nml"
    deck.write_text(deck_text(oscillator(record_excitation("rec.AT2"))))
    res = frictiondyn.run(deck)
    exe = frictiondyn.run_executable(deck, cwd=tmp_path)
    assert np.array_equal(res.data, exe.history().data)
    assert res.summary["record"] == exe.summary()["record"]
