"""Temporaries of killed writers: a run killed where nothing can clean up (SIGKILL; a Python
process ended by SIGTERM while it streams) leaves its temporary files; the next run of the
name removes them, and never one of a live process, of another machine, or a non-file."""

from __future__ import annotations

import os
import signal
import socket
import subprocess
import sys
import time
from pathlib import Path

import frictiondyn as fd
import pytest
from conftest import chain, deck_text

EXE = fd.executable()
HOST = socket.gethostname().replace("/", "-").replace(".", "-").replace("_", "-")


def chain20(duration: float) -> dict:
    """Twenty masses; a run of 3000 s keeps every 100th step (well within max_history_mb)."""
    return chain(20, duration, n1=10, every=1 if duration < 10 else 100)


def hidden(out: Path) -> list[str]:
    return sorted(p.name for p in out.iterdir() if p.name.startswith("."))


def wait_for_temp(proc: subprocess.Popen, out: Path) -> None:
    deadline = time.monotonic() + 60
    while time.monotonic() < deadline and proc.poll() is None:
        if out.is_dir() and [n for n in hidden(out) if n.startswith(".run.csv.")]:
            return
        time.sleep(0.01)
    pytest.fail("the run never wrote its temporary history")


def test_a_killed_executables_temporaries_go_with_the_next_run_and_no_others(tmp_path):
    deck = tmp_path / "run.nml"
    deck.write_text(deck_text(chain20(3000.0)))
    out = tmp_path / "out"
    p = subprocess.Popen([EXE, "run.nml"], cwd=tmp_path, stdout=subprocess.DEVNULL,
                         stderr=subprocess.DEVNULL)
    wait_for_temp(p, out)
    p.send_signal(signal.SIGKILL)
    assert p.wait(30) == -signal.SIGKILL
    stale = hidden(out)
    assert len(stale) == 1 and stale[0].startswith(f".run.csv.{p.pid}_{HOST}_")
    # temporaries the next run must leave: a live process's (this one), another machine's
    # (whose processes cannot be asked), an untagged name, a directory, another name's
    keep = [f".run.csv.{os.getpid()}_{HOST}_0.tmp", f".run.csv.{p.pid}_other-host_0.tmp",
            ".run.csv.mine.tmp", f".other.csv.{p.pid}_{HOST}_0.tmp"]
    for name in keep:
        (out / name).write_text("x")
    (out / f".run.summary.json.{p.pid}_{HOST}_1.tmp").mkdir()
    keep.append(f".run.summary.json.{p.pid}_{HOST}_1.tmp")
    (out / f".run.summary.json.{p.pid}_{HOST}_2.tmp").write_text("{")  # stale too
    deck.write_text(deck_text(chain20(0.5)))
    r = subprocess.run([EXE, "run.nml"], cwd=tmp_path, capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    assert hidden(out) == sorted(keep)
    assert (out / "run.csv").is_file() and (out / "run.summary.json").is_file()


def test_a_python_stream_ended_by_sigterm_is_cleaned_by_the_next_session(tmp_path):
    deck = tmp_path / "run.nml"
    deck.write_text(deck_text(chain20(3000.0)))
    out = tmp_path / "out"
    code = f"""
import frictiondyn as fd
with fd.Session({str(deck)!r}) as s:
    s.stream({str(out)!r})
    s.solve(history=False)
"""
    p = subprocess.Popen([sys.executable, "-c", code], stdout=subprocess.DEVNULL,
                         stderr=subprocess.DEVNULL)
    wait_for_temp(p, out)
    p.send_signal(signal.SIGTERM)
    assert p.wait(30) == -signal.SIGTERM
    assert len(hidden(out)) == 1  # Python's default SIGTERM ends the process at once
    deck.write_text(deck_text(chain20(0.5)))
    with fd.Session(deck) as s:
        s.stream(out)
        s.solve(history=False)
        s.write()
    assert hidden(out) == []
    assert fd.Result.from_files(out / "run.csv").summary["duration_s"] == pytest.approx(0.5)


def test_a_live_writers_temporary_is_never_taken(tmp_path):
    """A long run streams its history; a short run of the same name writes meanwhile: the
    long run's temporary survives, and the long run, stopped by SIGTERM, cleans up itself."""
    (tmp_path / "long.nml").write_text(deck_text(chain20(3000.0)))
    (tmp_path / "short.nml").write_text(deck_text(chain20(0.5)))
    out = tmp_path / "out"
    p = subprocess.Popen([EXE, "long.nml"], cwd=tmp_path, stdout=subprocess.DEVNULL,
                         stderr=subprocess.DEVNULL)
    wait_for_temp(p, out)
    mine = hidden(out)
    r = subprocess.run([EXE, "short.nml"], cwd=tmp_path, capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    assert hidden(out) == mine and p.poll() is None
    p.send_signal(signal.SIGTERM)
    assert p.wait(30) == -signal.SIGTERM
    assert hidden(out) == []
