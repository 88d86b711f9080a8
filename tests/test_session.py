"""The session across the extension: one deck read once, buffers sized by the library, the
library's writer for every output file, the handle closed on every path, the GIL released
while solving."""

from __future__ import annotations

import json
import threading
import time
from pathlib import Path

import frictiondyn
import numpy as np
import pytest
from conftest import INPUTS
from frictiondyn import DeckError, FrictiondynError, OutputError, Result, Session


def _short_deck(tmp_path, name="short.nml", duration="2.0", law="velocity"):
    text = (INPUTS / "test4_velocity.nml").read_text()
    text = text.replace("duration = 40.0", f"duration = {duration}")
    text = text.replace("law = 'velocity'", f"law = '{law}'")
    path = tmp_path / name
    path.write_text(text)
    return path


def test_the_deck_is_read_once_a_file_replaced_after_open_changes_nothing(tmp_path):
    deck = _short_deck(tmp_path)
    reference = frictiondyn.run(deck)
    with Session(deck) as s:
        assert s.shape == reference.data.shape == (401, 12)  # 2 s every dt_r = 5 ms
        deck.write_text("&model\n  n_dof = -1\n/\n")  # replaced by a bad deck after open
        r = s.solve().result()
    assert np.array_equal(r.data, reference.data)
    assert r.summary["stick_to_slip"] == reference.summary["stick_to_slip"]
    with pytest.raises(DeckError, match="n_dof"):  # the new content is read by a new session
        Session(deck)


def test_shape_and_texts_are_the_librarys(tmp_path):
    deck = _short_deck(tmp_path, duration="1.0")
    with Session(deck) as s:
        assert s.output == frictiondyn._api.OutputSettings("out", "short", True)
        assert s.deck == str(deck)
        r = s.solve().result()
    assert r.data.shape == (201, 12) and r.names[:3] == ["t", "ag", "u1"]
    assert r.units["aabs1"] == "m/s2" and r.units["phase1"] == "-"
    assert r.summary["samples"] == 201 and r.summary["deck"] == str(deck)
    assert json.loads(r.summary_text) == r.summary


def test_misuse_raises_and_the_session_is_closed_on_every_path(tmp_path):
    deck = _short_deck(tmp_path, duration="0.5")
    s = Session(deck)
    with pytest.raises(FrictiondynError, match="not solved"):
        s.result()
    with pytest.raises(FrictiondynError, match="not solved"):
        s.write(tmp_path / "w")
    s.solve()
    with pytest.raises(FrictiondynError, match="already solved"):
        s.solve()
    s.close()
    assert s.closed
    s.close()  # idempotent
    with pytest.raises(FrictiondynError, match="closed"):
        s.result()
    # an exception inside the with block closes it too
    with pytest.raises(RuntimeError, match="boom"), Session(deck) as s2:
        raise RuntimeError("boom")
    assert s2.closed
    assert not (tmp_path / "w").exists()


def test_write_uses_the_executables_writer_and_files(tmp_path):
    deck = _short_deck(tmp_path, name="w.nml")
    with Session(deck) as s:
        s.solve()
        csv, summ = s.write(tmp_path / "mine")
    assert csv == tmp_path / "mine" / "w.csv" and summ == tmp_path / "mine" / "w.summary.json"
    exe = frictiondyn.run_executable(deck, cwd=tmp_path)
    assert csv.read_bytes() == exe.history_path.read_bytes()
    mine, theirs = summ.read_text().splitlines(), exe.summary_path.read_text().splitlines()
    # identical but for the run time (which may or may not coincide)
    differ = [a for a, b in zip(mine, theirs, strict=True) if a != b]
    assert all('"run_time_s"' in a for a in differ)
    assert sorted(p.name for p in (tmp_path / "mine").iterdir()) == ["w.csv", "w.summary.json"]


def test_a_failed_write_is_an_output_error_and_leaves_nothing(tmp_path):
    deck = _short_deck(tmp_path, duration="0.5")
    (tmp_path / "file").write_text("not a directory")
    with Session(deck) as s:
        s.solve()
        with pytest.raises(OutputError, match="cannot create the output directory") as info:
            s.write(tmp_path / "file" / "sub")
    assert isinstance(info.value, OSError)
    # Result.to_csv: a path under a regular file cannot be created, even by root
    before = sorted(p.name for p in tmp_path.iterdir())
    r = frictiondyn.run(deck)
    with pytest.raises(OutputError, match="cannot create"):
        r.to_csv(tmp_path / "file" / "a.csv")
    assert sorted(p.name for p in tmp_path.iterdir()) == before
    assert (tmp_path / "file").read_text() == "not a directory"


def test_to_csv_writes_through_the_library_and_a_changed_summary_as_json(tmp_path):
    deck = _short_deck(tmp_path, name="c.nml", duration="0.5")
    exe = frictiondyn.run_executable(deck, cwd=tmp_path)
    r = Result.from_files(exe.history_path)
    r.to_csv(tmp_path / "again.csv")
    assert (tmp_path / "again.csv").read_bytes() == exe.history_path.read_bytes()
    assert (tmp_path / "again.summary.json").read_bytes() == exe.summary_path.read_bytes()
    r.summary["note"] = "changed in Python"
    r.write_summary(tmp_path / "changed.json")
    back = json.loads((tmp_path / "changed.json").read_text())
    assert back == r.summary and back["note"] == "changed in Python"
    # the .npz keeps the library's text
    r2 = Result.from_files(exe.history_path)
    r2.to_npz(tmp_path / "r.npz")
    Result.from_npz(tmp_path / "r.npz").to_csv(tmp_path / "npz.csv")
    assert (tmp_path / "npz.summary.json").read_bytes() == exe.summary_path.read_bytes()


def test_solve_releases_the_gil(tmp_path):
    """While one thread solves, Python code runs in another (the ground for cancelling a run
    from the main thread): the main thread's loop never stalls for the length of the solve."""
    # 200 s: long enough that the solve takes well over 0.05 s on a fast machine (40 s took
    # 0.048 s with the banded Newmark, too short to show the loop running beside it)
    deck = _short_deck(tmp_path, duration="200.0", law="hysteretic")
    with Session(deck) as s:
        worker = threading.Thread(target=s.solve)
        gaps = []
        start = last = time.perf_counter()
        worker.start()
        while worker.is_alive():
            now = time.perf_counter()
            gaps.append(now - last)
            last = now
        elapsed = time.perf_counter() - start
        worker.join()
        assert s.result().data.shape == (40001, 12)  # 200 s, a row every dt_r
    # with the GIL held, the loop would stop for the whole solve (tenths of a second)
    assert elapsed > 0.05
    assert max(gaps) < 0.5 * elapsed, (max(gaps), elapsed)


def test_status_codes_and_text_ids_have_one_source():
    """The extension's status codes and text ids are fd_session.f90's status_* and text_*
    parameters, generated into frictiondyn._codes: the Python side keeps no number of its
    own. Every failure status has its exception, and each text id gives its text."""
    import re

    from conftest import ROOT
    from frictiondyn import _api, _codes

    source = (ROOT / "fortran" / "fd_session.f90").read_text()
    fortran = {
        name.upper(): int(value)
        for name, value in re.findall(r"::\s*((?:status|text)_\w+)\s*=\s*(\d+)", source)
    }
    generated = {k: v for k, v in vars(_codes).items() if k.startswith(("STATUS_", "TEXT_"))}
    assert generated == fortran and len(fortran) == 15
    failures = {v for k, v in fortran.items() if k.startswith("STATUS_") and k != "STATUS_OK"}
    assert set(_api._ERRORS) == failures
    assert len(set(_api._ERRORS.values())) == len(failures)
    with Session(INPUTS / "test4_velocity.nml") as s:
        assert Path(s._text(_codes.TEXT_DECK)).name == "test4_velocity.nml"
        assert s._text(_codes.TEXT_OUTPUT_NAME) == "test4_velocity"
