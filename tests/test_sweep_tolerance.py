"""Sweeps of tolerance runs: a run whose deck sets &integration tolerance (the base deck's, or a
varied key's) is a Python tolerance run (frictiondyn.tolerance), which the executable refuses;
the sweep makes it through ``python -m frictiondyn run``, locally and in the Slurm job script,
and its table carries the estimated errors. Each run equals the same deck's tolerance run
made alone."""

from __future__ import annotations

import csv
import hashlib
import json
import os
import subprocess
import sys
import warnings
from pathlib import Path

import frictiondyn as fd
import pytest

from frictiondyn import sweep as sw

SWEEP = [sys.executable, "-m", "frictiondyn", "sweep"]

# a block on a spring held by Coulomb friction, released from 20 mm (the exact technique:
# one run per tolerance run, its estimate round-off)
BASE = """&model
  n_dof = 1, mass = 1000.0, u0 = 0.02
/
&springs
  n_springs = 1, node_i = 1, node_j = 0, k = 4.0e5
/
&damping
  damping_type = 'none'
/
&friction
  n_devices = 1, node_i = 1, node_j = 0, law = 'coulomb', p = 400.0, mu = 1.0
/
&excitation
  excitation_type = 'none', dt_record = 0.01, duration = 2.0
/
&integration
  technique = 'event_driven', n1 = 10{tolerance}
/
&output
  write_history = .false.
/
"""
COMPARED = ("peak_u_m", "peak_aabs_mps2", "peak_force_N", "energy_friction_J", "slip_reversals",
            "estimated_error", "estimate_method", "tolerance_run")


def table(path: Path) -> list[dict[str, str]]:
    with open(path, newline="") as f:
        return list(csv.DictReader(f))


def alone(text: str) -> dict:
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", fd.FrictiondynWarning)
        return fd.run_text(text, name="alone.nml").summary


def check_against_alone(out: Path, texts: list[str]) -> list[dict[str, str]]:
    """Every run done, its summary that of the same deck run alone, its table row carrying
    the estimated errors; the summary names the sweep's deck (deck_sha256)."""
    rows = table(out / "results.csv")
    assert [r["status"] for r in rows] == ["done"] * len(texts), rows
    for i, (row, text) in enumerate(zip(rows, texts)):
        summary = json.loads((out / "runs" / f"r{i:04d}.summary.json").read_text())
        want = alone(text)
        for key in COMPARED:
            assert summary[key] == want[key], key
        deck = (out / "decks" / f"r{i:04d}.nml").read_bytes()
        assert summary["deck_sha256"] == row["deck_sha256"] == hashlib.sha256(deck).hexdigest()
        assert float(row["estimated_error.peak_u_m[1]"]) == want["estimated_error"]["peak_u_m"][0]
        assert row["tolerance_run.technique"] == "event_driven"
        assert float(row["tolerance_run.tolerance"]) == want["tolerance_run"]["tolerance"]
    return rows


def test_a_base_deck_with_a_tolerance(tmp_path):
    """Two runs of a base deck with tolerance = 1e-3 (P varied), run by the sweep command,
    against the same two decks' tolerance runs made one by one; resumed, nothing runs again."""
    (tmp_path / "fv.nml").write_text(BASE.format(tolerance=", tolerance = 1e-3"))
    spec = tmp_path / "s.toml"
    spec.write_text('name = "tol"\nbase = "fv.nml"\n[cross]\n"friction.p" = [400.0, 800.0]\n')
    out = tmp_path / "out"
    p = subprocess.run([*SWEEP, str(spec), "--out", str(out), "-j", "2", "--quiet"],
                       capture_output=True, text=True)
    assert p.returncode == 0, p.stderr
    texts = [BASE.format(tolerance=", tolerance = 1e-3").replace("p = 400.0", f"p = {x}")
             for x in ("400.0", "800.0")]
    rows = check_against_alone(out, texts)
    # the two P give different answers: the runs are not one run twice
    assert rows[0]["peak_force_N[1]"] != rows[1]["peak_force_N[1]"]
    with sw.load(out) as sweep:
        assert [r.tolerance for r in sweep.runs] == [True, True]
        assert sweep.pending() == []
    p = subprocess.run([*SWEEP, str(spec), "--out", str(out), "--quiet"], capture_output=True, text=True)
    assert p.returncode == 0 and "2 skipped" in p.stdout, p.stdout + p.stderr


def test_a_varied_tolerance_in_python_and_in_the_job_script(tmp_path):
    """The base deck has no tolerance; [cross] varies integration.tolerance: each run is a
    tolerance run at its value, through run_local; the job script runs a task of them with
    Python's tolerance run (its summary that of run_local), not the executable."""
    (tmp_path / "fv.nml").write_text(BASE.format(tolerance=""))
    spec = tmp_path / "s.toml"
    spec.write_text('name = "tol2"\nbase = "fv.nml"\n[cross]\n"integration.tolerance" = [1e-2, 1e-3]\n')
    out = tmp_path / "out"
    with sw.expand(spec, out) as sweep:
        assert [r.tolerance for r in sweep.runs] == [True, True]
        counts = sw.run_local(sweep, 2, progress=False)
        assert counts == {"skipped": 0, "done": 2, "failed": 0}
        sw.collect(sweep)
    texts = [BASE.format(tolerance=f", tolerance = {t}") for t in ("1e-2", "1e-3")]
    check_against_alone(out, texts)
    local = (out / "runs" / "r0001.summary.json").read_text()
    (out / "runs" / "r0001.summary.json").unlink()
    with sw.load(out) as sweep:
        script = sw.slurm_script(sweep)
    text = script.read_text()
    assert f"{sys.executable} -m frictiondyn run" in text and "--list decks.txt" in text
    env = {**os.environ, "SLURM_ARRAY_TASK_ID": "1", "SLURM_ARRAY_JOB_ID": "1"}
    t = subprocess.run(["bash", str(script)], env=env, capture_output=True, text=True)
    assert t.returncode == 0, t.stdout + t.stderr
    task = json.loads((out / "runs" / "r0001.summary.json").read_text())
    for key in COMPARED + ("deck_sha256",):
        assert task[key] == json.loads(local)[key], key
    assert not (out / "runs" / "r0001.error.txt").exists()


def test_a_deck_without_a_tolerance_runs_the_executable(tmp_path):
    """A sweep without a tolerance is unchanged: its runs are the executable's, and its job
    script names no Python."""
    (tmp_path / "fv.nml").write_text(BASE.format(tolerance=""))
    spec = tmp_path / "s.toml"
    spec.write_text('name = "plain"\nbase = "fv.nml"\n[cross]\n"friction.p" = [400.0]\n')
    with sw.expand(spec, tmp_path / "out") as sweep:
        assert [r.tolerance for r in sweep.runs] == [False]
        assert "-m frictiondyn" not in sw.slurm_script(sweep).read_text()
    manifest = json.loads((tmp_path / "out" / "manifest.json").read_text())
    assert "tolerance" not in manifest["runs"][0]


def test_a_bad_tolerance_fails_its_run_with_the_message(tmp_path):
    """A varied tolerance out of (0, 1) is refused when the run is made: the run fails with the
    library's message naming the variable and the value; the other run is done."""
    (tmp_path / "fv.nml").write_text(BASE.format(tolerance=""))
    spec = tmp_path / "s.toml"
    spec.write_text('name = "bad"\nbase = "fv.nml"\n[cross]\n"integration.tolerance" = [1e-3, 1.5]\n')
    out = tmp_path / "out"
    p = subprocess.run([*SWEEP, str(spec), "--out", str(out), "--quiet"], capture_output=True, text=True)
    assert p.returncode == 1
    rows = table(out / "results.csv")
    assert [r["status"] for r in rows] == ["done", "failed"]
    assert "tolerance = 1.5 is invalid" in rows[1]["message"], rows[1]["message"]


@pytest.mark.parametrize("bad", ["tolerance = 2.0", "tolerance = 1e-3, tolerance_floor = -1.0"])
def test_a_bad_tolerance_in_the_base_deck_stops_the_sweep(tmp_path, bad):
    (tmp_path / "fv.nml").write_text(BASE.format(tolerance=f", {bad}"))
    spec = tmp_path / "s.toml"
    spec.write_text('name = "badbase"\nbase = "fv.nml"\n[cross]\n"friction.p" = [400.0]\n')
    with pytest.raises(sw.SweepError, match=r"base deck: .*is invalid"):
        sw.expand(spec, tmp_path / "out")
    assert not (tmp_path / "out").exists()
