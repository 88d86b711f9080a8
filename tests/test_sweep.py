"""Parameter sweeps (python -m frictiondyn sweep): every run gives exactly what its deck
gives alone; an interrupted sweep resumes with only the missing runs; a failed run is
recorded with its message and does not stop the others; results.csv, plot, job-array
script."""

from __future__ import annotations

import csv
import json
import os
import signal
import subprocess
import sys
import time
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

import frictiondyn
import pytest
from conftest import INPUTS, deck_text

from frictiondyn import sweep as sw

EXE = frictiondyn.executable()
SWEEP = [sys.executable, "-m", "frictiondyn", "sweep"]


def same_summary(a: dict, b: dict) -> None:
    skip = {"run_time_s", "deck"}
    assert {k: v for k, v in a.items() if k not in skip} == {
        k: v for k, v in b.items() if k not in skip
    }


P_SPEC = """
name = "p12"
base = "{inputs}/test4_coulomb.nml"
[cross]
deck = ["{inputs}/test4_velocity.nml", "{inputs}/test5_velocity.nml"]
"friction.law" = ["coulomb"]
"integration.technique" = ["event_driven"]
"friction.p" = [59.0, 60.5, 99.5]
"excitation.duration" = [300.0, 400.0]
"output.output_every" = [2000]
"""


def test_sweep_resumes_and_each_run_equals_its_deck_alone(tmp_path):
    """The paper's tests 4 and 5 (exact technique) at P = 59, 60.5, 99.5 N, for 300 s and
    400 s: 12 runs. The sweep is stopped (SIGINT) after a few runs; run again, it runs only
    the missing ones (the complete ones are not touched). Every run's CSV and summary equal
    those of its deck run alone. Physics (docs/validation.md: test 5 stops sliding above
    59.62 N, test 4 above 100.02 N): test 5 still slides between 300 s and 400 s at 59 N and
    not at 60.5 N; test 4 slides at all three.

    The durations are long enough for the sweep to be caught while it runs: at 30 s and
    40 s the 12 runs took 0.2 s in all, and the poll below could miss them (a run of this
    test failed so). A history row every 2000 steps keeps the files small."""
    spec = tmp_path / "p12.toml"
    spec.write_text(P_SPEC.format(inputs=INPUTS))
    sdir = tmp_path / "s"
    p = subprocess.Popen([*SWEEP, str(spec), "--out", str(sdir), "-j", "2", "--quiet"],
                         stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    deadline = time.monotonic() + 120
    while time.monotonic() < deadline and p.poll() is None:
        if len(list((sdir / "runs").glob("*.summary.json"))) >= 2:
            break
        time.sleep(0.01)
    assert p.poll() is None, p.communicate()
    p.send_signal(signal.SIGINT)
    out, err = p.communicate(timeout=60)
    assert p.returncode == 130, (out, err)
    done = {f.name: (f.stat().st_ino, f.stat().st_mtime_ns)
            for f in (sdir / "runs").glob("*.summary.json")}
    assert 2 <= len(done) < 12
    assert not [f for f in (sdir / "runs").iterdir() if f.name.startswith(".")]

    r = subprocess.run([*SWEEP, str(spec), "--out", str(sdir), "-j", "2", "--quiet"],
                       capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    assert f"({len(done)} already complete)" in r.stdout
    assert f"ran {12 - len(done)} run(s)" in r.stdout
    assert "12 of 12 runs complete, 0 failed, 0 missing" in r.stdout
    for name, ident in done.items():
        f = sdir / "runs" / name
        assert (f.stat().st_ino, f.stat().st_mtime_ns) == ident, f"{name} was run again"

    # every deck alone, in another directory
    sweep = sw.load(sdir)
    alone = tmp_path / "alone"
    alone.mkdir()

    def run_alone(run):
        return subprocess.run([EXE, str(sdir / run.deck)], cwd=alone, capture_output=True)

    with ThreadPoolExecutor(2) as pool:
        assert all(c.returncode == 0 for c in pool.map(run_alone, sweep.runs))
    for run in sweep.runs:
        assert (sdir / run.history).read_bytes() == (alone / run.history).read_bytes()
        same_summary(json.loads((sdir / run.summary).read_text()),
                     json.loads((alone / run.summary).read_text()))

    rows = sw.read_results(sdir)
    assert len(rows) == 12 and {r["status"] for r in rows} == {"done"}
    assert {r["frictiondyn_version"] for r in rows} == {frictiondyn.__version__}
    for r, run in zip(rows, sweep.runs):
        assert r["deck_sha256"] == sw._sha256((sdir / run.deck).read_bytes())
    s2s = {(r["deck"][-14], float(r["friction.p"]), float(r["excitation.duration"])):
           int(r["stick_to_slip[1]"]) for r in rows}
    slides = {(t, p): s2s[(t, p, 400.0)] - s2s[(t, p, 300.0)] for t, p, _ in s2s}
    assert slides[("5", 59.0)] > 0 and slides[("5", 60.5)] == 0 and slides[("5", 99.5)] == 0
    assert all(slides[("4", p)] > 0 for p in (59.0, 60.5, 99.5))


def tiny(mu=0.3) -> dict:
    return {
        "model": {"n_dof": 1, "mass": [10.0]},
        "springs": {"n_springs": 1, "node_i": [1], "node_j": [0], "k": [1.0e4]},
        "damping": {"damping_type": "none"},
        "friction": {"n_devices": 1, "node_i": 1, "node_j": 0, "law": "hysteretic",
                     "p": 98.1, "mu": mu},
        "excitation": {"excitation_type": "harmonic", "amplitude": 0.02, "frequency": 3.0,
                       "dt_record": 0.01, "duration": 2.0},
    }


def test_failed_run_is_recorded_and_the_others_complete(tmp_path):
    (tmp_path / "base.nml").write_text(deck_text(tiny()))
    (tmp_path / "s.toml").write_text(
        'base = "base.nml"\nwrite_history = false\n[zip]\nlabel = ["a", "b", "c", "d"]\n'
        '"friction.mu" = [0.1, -1.0, 0.3, 0.6]\n'
    )
    r = subprocess.run([*SWEEP, str(tmp_path / "s.toml"), "--out", str(tmp_path / "o"),
                        "--quiet"], capture_output=True, text=True)
    assert r.returncode == 1
    assert "3 of 4 runs complete, 1 failed, 0 missing" in r.stdout
    assert "failed: r0001 (index 1)" in r.stdout and "mu(1) = -1.0" in r.stdout
    rows = sw.read_results(tmp_path / "o")
    assert [x["status"] for x in rows] == ["done", "failed", "done", "done"]
    assert "&friction" in rows[1]["message"] and "mu(1) = -1.0" in rows[1]["message"]
    assert [x["label"] for x in rows] == ["a", "b", "c", "d"]
    assert not (tmp_path / "o" / "runs" / "r0000.csv").exists()  # write_history = false
    # more friction, less slip: a physical check that the parameter reached the deck
    peaks = [float(x["peak_s_m[1]"]) for x in rows if x["status"] == "done"]
    assert peaks[0] > peaks[1] > peaks[2]
    c = subprocess.run([*SWEEP, "collect", str(tmp_path / "o")], capture_output=True, text=True)
    assert c.returncode == 1 and "1 failed" in c.stdout
    png = subprocess.run([*SWEEP, "plot", str(tmp_path / "o"), "friction.mu", "peak_s_m[1]"],
                         capture_output=True, text=True)
    assert png.returncode == 0, png.stderr
    path = Path(png.stdout.split("plot: ")[1].strip())
    assert path.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    bad = subprocess.run([*SWEEP, "plot", str(tmp_path / "o"), "friction.mu", "nope"],
                         capture_output=True, text=True)
    assert bad.returncode == 1 and "'nope' is not a column" in bad.stderr


def test_elements_given_from_above_1_stay_where_the_deck_puts_them(tmp_path):
    """A base deck giving u0(2) alone, and a speed-dependent mu by its table's second
    column: f90nml keeps such starts apart from the values, and a sweep that copied only
    the values moved u0(2) to u0(1) (peak |u| 2-8 % off, exit 0). Each run of a sweep that
    varies only a label equals the base deck run alone, and a swept element of u0 lands at
    its index: u0(1) = 0.001 with the base's u0(2) = 0.002 kept."""
    text = (INPUTS / "test4_velocity.nml").read_text().replace("40.0", "2.0")
    text = text.replace("&model\n", "&model\n  u0(2) = 0.002\n", 1)
    assert "u0(2) = 0.002" in text
    (tmp_path / "base.nml").write_text(text)
    (tmp_path / "s.toml").write_text(
        'base = "base.nml"\n[zip]\nlabel = ["a"]\n"model.mass" = [[6.301, 2.530]]\n'
    )
    r = subprocess.run([*SWEEP, str(tmp_path / "s.toml"), "--out", str(tmp_path / "o"),
                        "--quiet"], capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    alone = frictiondyn.run_text(text, base_dir=INPUTS)
    run = json.loads((tmp_path / "o" / "runs" / "r0000.summary.json").read_text())
    for key in ("peak_u_m", "peak_s_m", "stick_to_slip", "energy_friction_J"):
        assert run[key] == alone.summary[key], key
    h = frictiondyn.read_history(tmp_path / "o" / "runs" / "r0000.csv")
    assert h["u1"][0] == 0.0 and h["u2"][0] == 0.002
    # an element swept: element 1 of the array, the base deck's element 2 kept
    (tmp_path / "s.toml").write_text('base = "base.nml"\n[zip]\n"model.u0(1)" = [0.001]\n')
    r = subprocess.run([*SWEEP, str(tmp_path / "s.toml"), "--out", str(tmp_path / "o2"),
                        "--quiet"], capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    h = frictiondyn.read_history(tmp_path / "o2" / "runs" / "r0000.csv")
    assert h["u1"][0] == 0.001 and h["u2"][0] == 0.002


@pytest.mark.parametrize(
    "change, words",
    [
        (("u0 = 0.0, 0.0", "u0(2:1:-1) = 0.002, 0.001"), ["cannot read it as the library does",
                                                         "0.002 is not assigned"]),
        (("node_j = 0, 0", "node_j = 0; 0"), ["written again it gives", "node_j"]),
        (("k = 1084.0, 2895.0", "k = 1084.0, 2895.0_8"), ["group &springs", "'k'"]),
    ],
    ids=["negative stride", "semicolon", "underscore"],
)
def test_a_base_deck_f90nml_reads_otherwise_is_refused(tmp_path, change, words):
    """Decks the library reads (the first two) or refuses (the third) but that f90nml,
    which writes a sweep's decks, reads otherwise (drops the values of a negative-stride
    section; takes ';' for a value; takes 2895.0_8 for 2895.08): the sweep refuses the
    base deck with the reason, before it writes or runs anything."""
    text = (INPUTS / "test4_velocity.nml").read_text()
    old, new = change
    if old not in text:  # the paper's decks give u0 only by its default
        text = text.replace("&model\n", f"&model\n  {old}\n", 1)
    text = text.replace(old, new, 1)
    assert new in text
    (tmp_path / "base.nml").write_text(text)
    (tmp_path / "s.toml").write_text('base = "base.nml"\n[zip]\nlabel = ["a"]\n')
    r = subprocess.run([*SWEEP, str(tmp_path / "s.toml"), "--out", str(tmp_path / "o"),
                        "--quiet"], capture_output=True, text=True)
    assert r.returncode == 1 and "base deck" in r.stderr, r.stderr
    for w in words:
        assert w in r.stderr, (w, r.stderr)
    assert not list((tmp_path / "o" / "decks").glob("*.nml")) if (tmp_path / "o").exists() else True


def test_changed_spec_reruns_only_changed_decks(tmp_path):
    (tmp_path / "base.nml").write_text(deck_text(tiny()))
    spec = tmp_path / "s.toml"
    spec.write_text('base = "base.nml"\n[cross]\n"friction.mu" = [0.1, 0.2, 0.3]\n')
    out = tmp_path / "o"
    assert subprocess.run([*SWEEP, str(spec), "--out", str(out), "--quiet"],
                          capture_output=True).returncode == 0
    spec.write_text('base = "base.nml"\n[cross]\n"friction.mu" = [0.1, 0.25, 0.3]\n')
    r = subprocess.run([*SWEEP, str(spec), "--out", str(out), "--quiet"],
                       capture_output=True, text=True)
    assert "(2 already complete)" in r.stdout and "ran 1 run(s)" in r.stdout


@pytest.mark.parametrize(
    "text, words",
    [
        ("base = 'b.nml'\n[zip]\nx = [1, 2]\ny = [1]\n", ["[zip] lists differ in length"]),
        ("base = 'b.nml'\n[cross]\n'a b' = [1]\n", ["is not 'group.variable'"]),
        ("[cross]\n'friction.mu' = [1]\n", ["give a base deck"]),
        ("base = 'b.nml'\nbogus = 1\n", ["unknown key(s) ['bogus']"]),
        ("base = 'nope.nml'\n[cross]\n'friction.mu' = [1.0]\n", ["does not exist"]),
        ("base = 'b.nml'\n[cross]\n'friction.mu(3)' = [1.0]\n", ["element 3"]),
        ("base = \n", ["not valid TOML"]),
    ],
)
def test_bad_spec(tmp_path, text, words):
    (tmp_path / "b.nml").write_text(deck_text(tiny()))
    (tmp_path / "s.toml").write_text(text)
    r = subprocess.run([*SWEEP, str(tmp_path / "s.toml"), "--out", str(tmp_path / "o")],
                       capture_output=True, text=True)
    assert r.returncode == 1
    assert r.stderr.startswith("frictiondyn: error:")
    for w in words:
        assert w in r.stderr


def test_slurm_script(tmp_path):
    """The job-array script runs the executable on deck i of decks.txt (no Python) for the
    pending runs only, at most M at once."""
    (tmp_path / "base.nml").write_text(deck_text(tiny()))
    (tmp_path / "s.toml").write_text('base = "base.nml"\n[cross]\n"friction.mu" = [0.1, 0.2, 0.3, 0.4, 0.5]\n')
    out = tmp_path / "o"
    r = subprocess.run([*SWEEP, str(tmp_path / "s.toml"), "--out", str(out), "--slurm",
                        "--max-parallel", "3", "--time", "00:10:00"], capture_output=True,
                       text=True)
    assert r.returncode == 0, r.stderr
    text = (out / "sweep.sbatch").read_text()
    assert "#SBATCH --array=0-4%3" in text and "#SBATCH --time=00:10:00" in text
    assert f'{EXE} --list decks.txt --index "$SLURM_ARRAY_TASK_ID"' in text
    assert "python" not in text.lower().replace("frictiondyn sweep", "")
    lines = (out / "decks.txt").read_text().splitlines()
    assert lines == [f"decks/r000{i}.nml" for i in range(5)]
    # runs 1 and 3 complete: the array holds the others
    for i in (1, 3):
        assert subprocess.run([EXE, "--list", "decks.txt", "--index", str(i)], cwd=out,
                              capture_output=True).returncode == 0
    r = subprocess.run([*SWEEP, str(tmp_path / "s.toml"), "--out", str(out), "--slurm"],
                       capture_output=True, text=True)
    assert "#SBATCH --array=0,2,4%32" in (out / "sweep.sbatch").read_text()
    # the script itself, run as a task would be, writes the run's outputs
    env = {**os.environ, "SLURM_ARRAY_TASK_ID": "2", "SLURM_ARRAY_JOB_ID": "1"}
    t = subprocess.run(["bash", str(out / "sweep.sbatch")], env=env, capture_output=True)
    assert t.returncode == 0 and (out / "runs" / "r0002.summary.json").exists()
    assert sw.array_ranges([0, 1, 2, 5, 7, 8]) == "0-2,5,7-8"


def test_results_csv_counts_each_runs_warnings(tmp_path):
    """A spring of 1e9 N/m on 10 kg (omega dt1 = 1e4 dt1 > 2) warns that dt1 does not resolve
    the highest mode, the 1e4 N/m one does not: results.csv counts each run's warnings and
    holds their texts, those of its summary."""
    (tmp_path / "base.nml").write_text(deck_text(tiny()))
    (tmp_path / "s.toml").write_text('base = "base.nml"\n[cross]\n"springs.k" = [1.0e4, 1.0e9]\n')
    subprocess.run([*SWEEP, str(tmp_path / "s.toml"), "--out", str(tmp_path / "o"), "--quiet"],
                   check=True, capture_output=True)
    with open(tmp_path / "o" / "results.csv", newline="") as fh:
        rows = list(csv.DictReader(fh))
    assert [r["springs.k"] for r in rows] == ["10000.0", "1000000000.0"]
    assert rows[0]["warnings"] == "0" and rows[0]["warning_text"] == ""
    assert int(rows[1]["warnings"]) >= 1
    assert "does not resolve the highest modes" in rows[1]["warning_text"]
    for row in rows:
        summary = json.loads((tmp_path / "o" / "runs" / f"{row['run']}.summary.json").read_text())
        assert row["warning_text"] == " | ".join(summary["warnings"])
    # a summary of an older build has no key: the cells say nothing rather than 0
    old = tmp_path / "o" / "runs" / f"{rows[1]['run']}.summary.json"
    old.write_text(json.dumps({k: v for k, v in json.loads(old.read_text()).items() if k != "warnings"}))
    subprocess.run([*SWEEP, "collect", str(tmp_path / "o")], check=True, capture_output=True)
    with open(tmp_path / "o" / "results.csv", newline="") as fh:
        rows = list(csv.DictReader(fh))
    assert rows[0]["warnings"] == "0" and rows[1]["warnings"] == rows[1]["warning_text"] == ""


def test_results_csv_columns(tmp_path):
    (tmp_path / "base.nml").write_text(deck_text(tiny()))
    (tmp_path / "s.toml").write_text('base = "base.nml"\n[cross]\n"friction.mu" = [0.1, 0.2]\n')
    subprocess.run([*SWEEP, str(tmp_path / "s.toml"), "--out", str(tmp_path / "o"), "--quiet"],
                   check=True, capture_output=True)
    with open(tmp_path / "o" / "results.csv", newline="") as fh:
        cols = next(csv.reader(fh))
    for c in ("run", "status", "message", "friction.mu", "run_deck", "deck_sha256",
              "frictiondyn_version", "peak_u_m[1]", "stick_to_slip[1]", "energy_residual_J"):
        assert c in cols
    manifest = json.loads((tmp_path / "o" / "manifest.json").read_text())
    assert [r["params"]["friction.mu"] for r in manifest["runs"]] == [0.1, 0.2]
