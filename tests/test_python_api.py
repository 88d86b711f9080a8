"""The Python API through the f2py extension: the same numbers as the executable, Python-built
decks, clean exceptions for bad input, no hidden state (repeat, threads), exact round trips
of the result files, and the accessors."""

from __future__ import annotations

import copy
import dataclasses
import io
import shutil
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

import frictiondyn
import numpy as np
import pytest
from conftest import FIG3_REVERSALS, FIG3_VIOLATIONS, INPUTS, K1, K2, M1, M2, MU, TABLE1, P
from frictiondyn import (
    Analysis,
    Damping,
    DeckError,
    Device,
    Harmonic,
    Integration,
    Output,
    Record,
    Result,
    Spring,
)
from frictiondyn.paper import deck_name, paper_analysis

PMU = P * MU


def same_summary(a: dict, b: dict) -> None:
    """Summaries equal in every key except the wall-clock time, the deck's path and the hash
    of its text (an equal analysis may be written differently)."""
    skip = {"run_time_s", "deck", "deck_sha256"}
    assert {k: v for k, v in a.items() if k not in skip} == {
        k: v for k, v in b.items() if k not in skip
    }
    assert set(a) == set(b)


def short_analysis(law: str = "velocity", duration: float = 3.0, **kw) -> Analysis:
    """The paper's test 4 model for a few seconds (Table 1 values)."""
    freq, amp, dtr = TABLE1[4]
    return Analysis(
        masses=[M1, M2],
        springs=[Spring(1, 0, K1), Spring(2, 0, K2)],
        damping=Damping.stiffness(0.015),
        devices=[Device(1, 2, p=P, mu=MU, law=law)],
        excitation=Harmonic(amp, freq, dtr, duration),
        **kw,
    )


# --- extension vs executable --------------------------------------------------------------


@pytest.mark.parametrize("deck", ["test4_velocity", "fig3_coarse"])
def test_extension_and_executable_give_identical_histories(deck, tmp_path):
    path = INPUTS / f"{deck}.nml"
    ext = frictiondyn.run(path)
    exe_run = frictiondyn.run_executable(path, cwd=tmp_path)
    exe = Result.from_files(exe_run.history_path)
    assert exe.names == ext.names and exe.units == ext.units
    assert ext.data.shape == (8001, 12)  # 40 s written every dt_r = 5 ms
    assert np.array_equal(ext.data, exe.data)  # 17 digits in the CSV: exact round trip
    same_summary(ext.summary, exe.summary)
    assert exe.summary["deck"] == str(path) and ext.summary["deck"] == str(path)
    # and what they say is the paper's: the coarse deck violates eq. 12, the fine one not
    if deck == "fig3_coarse":
        assert ext.summary["correctness_violations"] == FIG3_VIOLATIONS
        assert ext.summary["slip_reversals"] == [FIG3_REVERSALS]
    else:  # two slides in each of the 164 whole cycles
        assert ext.summary["correctness_violations"] == 0
        assert ext.summary["stick_to_slip"] == [2 * 164]


@pytest.mark.parametrize(
    "test,law,coarse",
    [(t, law, False) for t in TABLE1 for law in ("velocity", "hysteretic")]
    + [(4, "hysteretic", True)],
)
def test_paper_decks_built_in_python_equal_the_bundled_decks(test, law, coarse):
    """frictiondyn.paper embeds the decks' values: identical runs to inputs/*.nml."""
    bundled = frictiondyn.run(INPUTS / f"{deck_name(test, law, coarse)}.nml")
    built = paper_analysis(test, law, coarse=coarse).run()
    assert np.array_equal(built.data, bundled.data)
    same_summary(built.summary, bundled.summary)


def _record_analysis() -> Analysis:
    """Test 4's table acceleration given as a record (values), ramped over 2 cycles."""
    freq, amp, dtr = TABLE1[4]
    t = np.arange(0, 2.0 + dtr / 2, dtr)
    w = 2 * np.pi * freq
    ramp = np.minimum(t * freq / 2, 1.0)
    acc = -amp * w**2 * np.sin(w * t) * ramp
    return Analysis(
        masses=[M1, M2],
        springs=[Spring(1, 0, K1), Spring(2, 0, K2)],
        damping=Damping.rayleigh(0.1, 1e-4),
        devices=[Device(1, 2, p=P, mu=MU, law="hysteretic", f=2e-5, eps1=2e-3)],
        excitation=Record(dt_record=dtr, file="table.txt", values=acc),
        integration=Integration(n1=10, n2=20, n=5.0),
        output=Output(dir="results", name="rec"),
        u0=[1e-3, 0.0],
        v0=[0.0, 0.05],
    )


@pytest.mark.parametrize("case", ["harmonic", "record"])
def test_deck_written_from_python_is_run_identically_by_the_executable(case, tmp_path):
    a = (
        short_analysis("hysteretic", output=Output(dir="results", name="harm"))
        if case == "harmonic"
        else _record_analysis()
    )
    deck = a.write_deck(tmp_path / "deck.nml")
    exe_run = frictiondyn.run_executable(deck, cwd=tmp_path)
    assert exe_run.history_path == tmp_path / "results" / f"{a.output.name}.csv"
    exe = Result.from_files(exe_run.history_path)
    mine = a.run()
    assert np.array_equal(mine.data, exe.data)
    same_summary(mine.summary, exe.summary)
    if case == "record":
        # the table acceleration at the record's sample times is the record itself,
        # and the initial conditions are the deck's
        values = np.loadtxt(tmp_path / "table.txt")
        np.testing.assert_allclose(mine["ag"], values[: len(mine["ag"])], rtol=0, atol=1e-12)
        assert mine["u1"][0] == 1e-3 and mine["v2"][0] == 0.05
        assert mine.summary["stick_to_slip"][0] > 0


# --- bad input ----------------------------------------------------------------------------


def _text(a: Analysis, directory: Path | None = None) -> str:
    return a.deck_text(directory)


def _without_group(group: str):
    def make(tmp: Path) -> str:
        nml = short_analysis().namelist()
        del nml[group]
        buf = io.StringIO()
        nml.write(buf)
        return buf.getvalue()

    return make


def _modified(change):
    def make(tmp: Path) -> str:
        a = copy.deepcopy(short_analysis())
        change(a)
        return _text(a, tmp)

    return make


def _set_device(**kw):
    def change(a: Analysis) -> None:
        for k, v in kw.items():
            setattr(a.devices[0], k, v)

    return change


def _record(file: str, text: str | None):
    def make(tmp: Path) -> str:
        if text is not None:
            (tmp / file).write_text(text)
        a = short_analysis()
        a.excitation = Record(dt_record=0.005, file=file)
        return _text(a, tmp)

    return make


BAD = [
    # (id, deck text maker, words the message must contain)
    ("missing group", _without_group("damping"), ["&damping", "missing"]),
    (
        "misspelled variable",
        lambda tmp: _text(short_analysis()).replace("n_dof", "n_dofs"),
        ["&model", "n_dofs"],
    ),
    (
        "negative mass",
        _modified(lambda a: setattr(a, "masses", [M1, -2.53])),
        ["&model", "mass(2)", "-2.53", "> 0"],
    ),
    ("eps = 0", _modified(_set_device(eps=0.0)), ["&friction", "eps(1)", "= 0", "> 0"]),
    ("eps < 0", _modified(_set_device(eps=-1e-3)), ["&friction", "eps(1)", "-0.001"]),
    (
        "eps1 = 0",
        _modified(_set_device(eps1=0.0, law="hysteretic")),
        ["&friction", "eps1(1)", "= 0"],
    ),
    (
        "n = 1",
        _modified(lambda a: setattr(a.integration, "n", 1.0)),
        ["&integration", "n = 1", "> 1"],
    ),
    ("n < 1", _modified(lambda a: setattr(a.integration, "n", 0.5)), ["&integration", "n = 0.5"]),
    (
        "missing record file",
        _record("nosuch.txt", None),
        ["&excitation", "record_file", "nosuch.txt", "does not exist"],
    ),
    (
        "record with NaN",
        _record("nan.txt", "0.0\n0.1\nnan\n0.2\n"),
        ["&excitation", "nan.txt", "line 3", "nan", "not finite"],
    ),
]


@pytest.fixture(scope="module")
def reference() -> Result:
    return short_analysis().run()


@pytest.mark.parametrize("make,words", [b[1:] for b in BAD], ids=[b[0] for b in BAD])
def test_bad_input_raises_deck_error_and_the_process_still_runs_good_decks(
    make, words, tmp_path, reference
):
    text = make(tmp_path)
    with pytest.raises(DeckError) as info:
        frictiondyn.run_text(text, name="bad.nml", base_dir=tmp_path)
    message = str(info.value)
    assert "bad.nml" in message
    for word in words:
        assert word in message, message
    assert isinstance(info.value, ValueError)  # DeckError is also a ValueError
    # the same deck from a file fails the same way
    (tmp_path / "bad.nml").write_text(text)
    with pytest.raises(DeckError) as info2:
        frictiondyn.run(tmp_path / "bad.nml")
    assert str(info2.value) == message
    # nothing is left over: a good deck gives the reference result, bit for bit
    again = short_analysis().run()
    assert np.array_equal(again.data, reference.data)
    assert again.summary["stick_to_slip"] == reference.summary["stick_to_slip"]


def test_missing_deck_file_is_a_deck_error(tmp_path):
    with pytest.raises(DeckError, match="nosuch.nml"):
        frictiondyn.run(tmp_path / "nosuch.nml")


# --- no hidden state ----------------------------------------------------------------------


def test_same_deck_twice_gives_identical_results():
    a = frictiondyn.run(INPUTS / "test4_hysteretic.nml")
    b = frictiondyn.run(INPUTS / "test4_hysteretic.nml")
    assert np.array_equal(a.data, b.data)
    same_summary(a.summary, b.summary)


def test_runs_in_threads_at_once_equal_serial_runs():
    decks = [
        INPUTS / f"{n}.nml"
        for n in ("test4_velocity", "test4_hysteretic", "fig3_coarse", "test3_velocity")
    ] * 2
    serial = [frictiondyn.run(d) for d in decks]
    with ThreadPoolExecutor(max_workers=len(decks)) as pool:
        threaded = list(pool.map(frictiondyn.run, decks))
    for s, t in zip(serial, threaded, strict=True):
        assert np.array_equal(s.data, t.data)
        same_summary(s.summary, t.summary)
    # different decks really gave different answers (no cross-talk to hide)
    assert serial[0].summary["stick_to_slip"] != serial[1].summary["stick_to_slip"]


# --- files --------------------------------------------------------------------------------


def test_csv_and_npz_round_trips_are_exact(tmp_path):
    r = frictiondyn.run(INPUTS / "fig3_coarse.nml")
    r.to_csv(tmp_path / "a.csv")
    back = Result.from_files(tmp_path / "a.csv")
    assert back.names == r.names and back.units == r.units
    assert np.array_equal(back.data, r.data)
    assert back.summary == r.summary
    r.to_npz(tmp_path / "a.npz")
    z = Result.from_npz(tmp_path / "a.npz")
    assert z.names == r.names and z.units == r.units
    assert np.array_equal(z.data, r.data) and z.summary == r.summary
    assert z.summary["correctness_violations"] == FIG3_VIOLATIONS  # the Fig. 3 deck's failure, kept


def test_the_executables_csv_and_to_csv_read_back_the_same(tmp_path):
    deck = tmp_path / "test4_velocity.nml"
    shutil.copy(INPUTS / "test4_velocity.nml", deck)
    exe = Result.from_files(frictiondyn.run_executable(deck, cwd=tmp_path).history_path)
    exe.to_csv(tmp_path / "again.csv")
    assert np.array_equal(Result.from_files(tmp_path / "again.csv").data, exe.data)


# --- accessors ----------------------------------------------------------------------------


@pytest.mark.parametrize("law", ["velocity", "hysteretic"])
def test_accessors_satisfy_the_equations_of_motion(law):
    """dof() and device() return the right columns: eq. (5) holds at every row,
    m1 a1 + k1 u1 + psi k1 v1 + F = 0 and m2 a2 + k2 u2 + psi k2 v2 - F = 0, s = u1 - u2,
    s' = v1 - v2, and a sliding device carries P mu."""
    r = short_analysis(law, output=Output(output_every=1)).run()
    assert r.n_dof == 2 and r.n_devices == 1
    d1, d2, dev = r.dof(1), r.dof(2), r.device(1)
    assert set(d1) == {"u", "v", "aabs"} and set(dev) == {"s", "sdot", "F", "phase"}
    assert np.array_equal(d1["aabs"], r["aabs1"]) and np.array_equal(d2["u"], r["u2"])
    psi = r.summary["period_stuck_s"] * 0.015 / np.pi
    e1 = M1 * d1["aabs"] + K1 * (d1["u"] + psi * d1["v"]) + dev["F"]
    e2 = M2 * d2["aabs"] + K2 * (d2["u"] + psi * d2["v"]) - dev["F"]
    # N, forces ~ 10 N; measured 5.2e-10 (a = 4 (u - ...)/dt^2 amplifies the round-off of u)
    assert np.max(np.abs(e1)) < 5e-9 and np.max(np.abs(e2)) < 5e-9
    assert np.array_equal(dev["s"], d1["u"] - d2["u"])
    assert np.array_equal(dev["sdot"], d1["v"] - d2["v"])
    slide = dev["phase"] != 0
    assert slide.any() and (~slide).any()
    np.testing.assert_allclose(np.abs(dev["F"][slide]), PMU, rtol=1e-12)
    np.testing.assert_allclose(dev["F"][slide], PMU * dev["phase"][slide], rtol=1e-12)
    assert np.max(np.abs(dev["F"])) <= PMU * (1 + 1e-12)
    # the time axis is the t column, a row every dt1 (output_every = 1) from 0 to the end
    assert np.array_equal(r.time, r["t"]) and r.time[0] == 0.0
    np.testing.assert_allclose(np.diff(r.time), r.summary["dt1_s"], rtol=1e-11, atol=0)
    assert r.time[-1] == pytest.approx(3.0, rel=1e-14)
    assert r.label("aabs1") == "aabs1 [m/s²]" and r.label("phase1") == "phase1"
    assert "F1" in r and "F2" not in r
    with pytest.raises(KeyError, match="no column 'u3'"):
        r.dof(3)


def test_many_concurrent_runs_of_the_same_files_are_identical(tmp_path):
    """Regression: runs in threads once corrupted each other's text (gfortran kept the
    length of deferred-length string results in a static variable) and could not open one
    file twice (Fortran units). 300 concurrent runs of the same decks and record file."""
    rec = tmp_path / "acc.txt"
    t = np.arange(0.0, 2.0, 0.005)
    rec.write_text("\n".join(f"{-2.7 * np.sin(25.8 * x):.17e}" for x in t) + "\n")
    decks = []
    for name in ("test4_velocity", "test4_hysteretic", "fig3_coarse"):
        text = (INPUTS / f"{name}.nml").read_text().replace("duration = 40.0", "duration = 2.0")
        path = tmp_path / f"{name}.nml"
        path.write_text(text)
        decks.append(path)
    text = (INPUTS / "test4_velocity.nml").read_text()
    start = text.index("&excitation")
    end = text.index("/", start)
    record_deck = tmp_path / "record.nml"
    record_deck.write_text(text[:start] + "&excitation\n  excitation_type = 'record'\n"
                           "  record_file = 'acc.txt'\n  dt_record = 0.005\n" + text[end:])
    decks.append(record_deck)
    serial = {d: frictiondyn.run(d) for d in decks}
    work = decks * 75
    with ThreadPoolExecutor(max_workers=6) as pool:
        results = list(pool.map(frictiondyn.run, work))
    for d, r in zip(work, results, strict=True):
        assert np.array_equal(r.data, serial[d].data)
        same_summary(r.summary, serial[d].summary)


# --- the Python writer: what the user gave reaches the reader ----------------------------


def quick(duration: float = 1.0, **kw) -> Analysis:
    """short_analysis with any of its parts replaced."""
    return dataclasses.replace(short_analysis(duration=duration), **kw)


@pytest.mark.parametrize(
    "given, lower",
    [
        (Damping("Stiffness", xi=0.05), Damping.stiffness(0.05)),
        (Damping("stiffness ", xi=0.05), Damping.stiffness(0.05)),
        (Damping("RAYLEIGH", rayleigh_a0=0.5, rayleigh_a1=0.002), Damping.rayleigh(0.5, 0.002)),
    ],
)
def test_damping_type_in_any_case_damps_as_the_lower_case_deck(given, lower):
    """The reader takes damping_type in any case: the values given must reach it (they were
    dropped, and the run was undamped)."""
    damped = quick(duration=1.0, damping=given).run()
    same = quick(duration=1.0, damping=lower).run()
    undamped = quick(duration=1.0, damping=Damping()).run()
    assert damped.summary["peak_aabs_mps2"] == same.summary["peak_aabs_mps2"]
    assert np.array_equal(damped.data, same.data)
    assert damped.summary["damping_a1_s"] > 0
    assert damped.summary["peak_aabs_mps2"] != undamped.summary["peak_aabs_mps2"]


def test_write_deck_of_two_in_memory_records_keeps_each_its_own(tmp_path):
    """Two decks written into one directory, each with a Record of values: each deck runs
    its own record (the second does not overwrite the first's record.txt)."""
    t = np.arange(201) * 0.005
    a = quick(excitation=Record(0.005, values=2.0 * np.sin(2 * np.pi * t)))
    b = quick(excitation=Record(0.005, values=0.5 * np.sin(6 * np.pi * t)))
    a.write_deck(tmp_path / "a.nml")
    b.write_deck(tmp_path / "b.nml")
    ra, rb = frictiondyn.run(tmp_path / "a.nml"), frictiondyn.run(tmp_path / "b.nml")
    assert np.array_equal(ra.data, a.run().data)
    assert np.array_equal(rb.data, b.run().data)
    assert ra.summary["record"]["peak_acc_mps2"] == 2.0
    assert {p.name for p in tmp_path.glob("*.record.txt")} == {"a.record.txt", "b.record.txt"}


@pytest.mark.parametrize("relative", [False, True])
def test_run_never_writes_a_records_values_over_the_callers_file(tmp_path, monkeypatch, relative):
    """Analysis.run writes a Record's values only inside its temporary directory."""
    monkeypatch.chdir(tmp_path)
    (tmp_path / "sub").mkdir()
    mine = tmp_path / "sub" / "x.txt"
    mine.write_text("1.0\n2.0\n3.0\n")
    values = 0.7 * np.sin(2 * np.pi * np.arange(201) * 0.005)
    file = "sub/x.txt" if relative else str(mine)
    r = quick(excitation=Record(0.005, file=file, values=values)).run()
    assert mine.read_text() == "1.0\n2.0\n3.0\n"
    assert r.summary["record"]["peak_acc_mps2"] == pytest.approx(np.abs(values).max(), rel=1e-15)


@pytest.mark.parametrize("name", ["h.csv", "h.dat", "history", "h.CSV", "a.b.csv"])
def test_to_csv_and_from_files_name_the_summary_alike(tmp_path, name):
    r = quick(duration=0.5).run()
    other = quick(duration=0.5, damping=Damping()).run()
    other.write_summary(tmp_path / "h.summary.json")  # another run's summary nearby
    r.to_csv(tmp_path / name)
    back = Result.from_files(tmp_path / name)
    assert np.array_equal(back.data, r.data)
    assert back.summary == r.summary
    assert frictiondyn.read_history(tmp_path / name).summary == r.summary


def test_from_files_without_its_summary_raises_unless_told(tmp_path):
    r = quick(duration=0.5).run()
    r.to_csv(tmp_path / "h.dat")
    (tmp_path / "h.dat.summary.json").unlink()
    with pytest.raises(FileNotFoundError, match="h.dat.summary.json"):
        Result.from_files(tmp_path / "h.dat")
    alone = Result.from_files(tmp_path / "h.dat", summary=False)
    assert alone.summary == {} and np.array_equal(alone.data, r.data)


def test_a_selection_left_at_none_keeps_the_decks_selection_of_that_kind():
    a = quick(duration=0.5, output=Output(history_dofs=[2], history_devices=[]))
    cols = lambda r: [n for n in r.names if n[:1] in "uvsFp" or n.startswith("aabs")]
    assert cols(a.run()) == ["u2", "v2", "aabs2"]
    assert cols(a.run(devices=[1])) == ["u2", "v2", "aabs2", "s1", "sdot1", "F1", "phase1"]
    assert cols(a.run(dofs=[1])) == ["u1", "v1", "aabs1"]
    with frictiondyn.Session.from_text(a.deck_text()) as s:
        assert s.selection == ([2], [])
        s.select(devices=[1]).select(dofs=[1])
        assert s.selection == ([1], [1])


@pytest.mark.parametrize(
    "sel",
    [
        {"dofs": [1.9]},
        {"dofs": [1.0]},
        {"dofs": [True]},
        {"dofs": np.array([2**32 + 2])},
        {"dofs": np.array([-(2**32) + 1])},
        {"dofs": [2, 1]},
        {"dofs": [1, 1]},
        {"dofs": 2},
        {"dofs": "2"},
        {"devices": [np.float64(1.0)]},
        {"devices": [2]},
    ],
)
def test_bad_history_selections_are_refused_not_coerced(sel):
    (arg,) = sel
    with pytest.raises(DeckError, match=f"history selection: {arg}"):
        quick(duration=0.5).run(**sel)


def test_a_non_integral_history_dof_in_output_is_refused():
    with pytest.raises(DeckError, match="history_dofs must be an integer, not 1.7"):
        quick(duration=0.5, output=Output(history_dofs=[1.7])).run()
    with pytest.raises(DeckError, match="history_dofs must be an integer, not True"):
        quick(duration=0.5, output=Output(history_dofs=[True])).deck_text()


def test_a_dof_label_none_is_the_default_and_a_bare_string_is_refused():
    r = quick(duration=0.5, labels=["roof", None]).run()
    assert r.dof_labels == ["roof", "DOF 2"]
    with pytest.raises(TypeError, match="labels must be a list"):
        quick(duration=0.5, labels="ab").run()


def test_paths_numpy_numbers_and_integral_floats_are_written_as_deck_values(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    values = 0.7 * np.sin(2 * np.pi * np.arange(201) * 0.005)
    np.savetxt(tmp_path / "rec.txt", values, fmt="%.17e")
    a = quick(
        excitation=Record(0.005, file=Path("rec.txt")),
        output=Output(dir=Path("outdir"), output_every=np.int64(2), n_modes=2.0),
        integration=Integration(n1=20.0, n2=np.array(50)),
    )
    a.springs = [Spring(np.int64(1), np.int32(0), K1), Spring(2.0, 0, K2)]
    a.devices = [Device(np.int64(1), np.int64(2), p=P, mu=MU, law="velocity")]
    text = a.write_deck(tmp_path / "w.nml").read_text()
    assert "record_file = 'rec.txt'" in text and "dir = 'outdir'" in text
    assert "n1 = 20\n" in text and "n2 = 50\n" in text and "output_every = 2\n" in text
    assert "node_i = 1, 2\n" in text
    assert np.array_equal(frictiondyn.run(tmp_path / "w.nml").data, a.run().data)
    for bad, field in [
        (Integration(n1=20.5), "n1"),
        (Integration(n2=True), "n2"),
    ]:
        with pytest.raises(DeckError, match=f"{field} must be an integer"):
            quick(integration=bad).deck_text()
    with pytest.raises(DeckError, match="node_i must be an integer, not 1.5"):
        quick(devices=[Device(1.5, 2, p=P, mu=MU, law="velocity")]).deck_text()
