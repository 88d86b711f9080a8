"""Parameter sweeps (python -m frictiondyn sweep): every run gives exactly what its deck
gives alone; an interrupted sweep resumes with only the missing runs; a failed run is
recorded with its message and does not stop the others; results.csv, plot, job-array
script."""

from __future__ import annotations

import contextlib
import csv
import io
import json
import os
import re
import shlex
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


# ------------------------------------------------------------------ runs tied to their decks
def _cli(*args):
    """python -m frictiondyn sweep ARGS in this process (faster than a new interpreter):
    CompletedProcess-like (returncode, stdout, stderr)."""
    from frictiondyn.cli import main as cli_main

    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        code = cli_main(["sweep", *map(str, args)])
    return subprocess.CompletedProcess(args, code, out.getvalue(), err.getvalue())


def _tiny_sweep(tmp_path, mus=(0.1, 0.2, 0.3, 0.6), extra=""):
    (tmp_path / "base.nml").write_text(deck_text(tiny()))
    spec = tmp_path / "s.toml"
    spec.write_text(f'base = "base.nml"\nwrite_history = false\n{extra}[cross]\n'
                    f'"friction.mu" = {list(mus)}\n')
    out = tmp_path / "o"
    r = subprocess.run([*SWEEP, str(spec), "--out", str(out), "--quiet"], capture_output=True,
                       text=True)
    assert r.returncode == 0, r.stderr
    return spec, out


def _rows(out):
    with open(out / "results.csv", newline="") as fh:
        return list(csv.DictReader(fh))


def test_a_summary_of_another_run_is_damaged_and_runs_again(tmp_path):
    """r0003's summary copied over r0000's (what a second spec run into the folder, or a
    careless copy, leaves): collect does not count r0000 done and does not put r0003's
    values beside r0000's parameters; it names r0000 and the sweep runs it again, giving its
    own values. The same for a summary of another frictiondyn version."""
    spec, out = _tiny_sweep(tmp_path)
    own = json.loads((out / "runs" / "r0000.summary.json").read_text())
    other = (out / "runs" / "r0003.summary.json").read_bytes()
    (out / "runs" / "r0000.summary.json").write_bytes(other)
    c = _cli("collect", str(out))
    assert c.returncode == 1, c.stdout
    assert "3 of 4 runs complete, 0 failed, 0 missing, 1 damaged" in c.stdout
    assert "damaged: r0000 (index 0): its summary is of another deck" in c.stdout
    rows = _rows(out)
    assert rows[0]["status"] == "damaged" and rows[0]["friction.mu"] == "0.1"
    assert rows[0]["peak_s_m[1]"] == ""  # no value of r0003 beside r0000's parameters
    assert float(rows[3]["peak_s_m[1]"]) == json.loads(other)["peak_s_m"][0]
    r = subprocess.run([*SWEEP, str(spec), "--out", str(out), "--quiet"], capture_output=True,
                       text=True)
    assert r.returncode == 0 and "ran 1 run(s)" in r.stdout, r.stdout + r.stderr
    again = json.loads((out / "runs" / "r0000.summary.json").read_text())
    assert again["peak_s_m"] == own["peak_s_m"] != json.loads(other)["peak_s_m"]
    assert float(_rows(out)[0]["peak_s_m[1]"]) == own["peak_s_m"][0]
    # a summary of another version is not this sweep's either
    s1 = out / "runs" / "r0001.summary.json"
    s1.write_text(s1.read_text().replace(f'"frictiondyn_version": "{frictiondyn.__version__}"',
                                         '"frictiondyn_version": "0.0.1"'))
    c = _cli("collect", str(out))
    assert "damaged: r0001 (index 1): its summary is of frictiondyn \"0.0.1\"" in c.stdout


def test_a_summary_of_another_record_is_damaged(tmp_path):
    """A record changed after the sweep was expanded: the summary of a run of the old record
    (its record.sha256) is not the expanded run's."""
    rec = tmp_path / "rec.txt"
    rec.write_text("".join(f"{0.5 * (i % 7 - 3):.3f}\n" for i in range(200)))
    groups = tiny()
    groups["excitation"] = {"excitation_type": "record", "record_file": "rec.txt",
                            "record_format": "values", "record_units": "m/s2",
                            "dt_record": 0.01}
    (tmp_path / "base.nml").write_text(deck_text(groups))
    (tmp_path / "s.toml").write_text('base = "base.nml"\nwrite_history = false\n[cross]\n'
                                     '"friction.mu" = [0.1, 0.2]\n')
    out = tmp_path / "o"
    r = subprocess.run([*SWEEP, str(tmp_path / "s.toml"), "--out", str(out), "--quiet"],
                       capture_output=True, text=True)
    assert r.returncode == 0, r.stdout + r.stderr
    manifest = json.loads((out / "manifest.json").read_text())
    assert manifest["runs"][0]["record_sha256"] == sw._sha256(rec.read_bytes())
    s0 = out / "runs" / "r0000.summary.json"
    summ = json.loads(s0.read_text())
    assert summ["record"]["sha256"] == manifest["runs"][0]["record_sha256"]
    s0.write_text(s0.read_text().replace(summ["record"]["sha256"], "0" * 64))
    c = _cli("collect", str(out))
    assert "damaged: r0000 (index 0): its summary is of another record" in c.stdout


def test_a_second_sweep_into_a_folder_in_use_is_refused(tmp_path):
    """While a sweep holds its folder (expand -> run -> collect), another spec run into it
    stops at once, naming the holder, and writes nothing; once the first ends it goes on.
    The lock file is opened without following a symbolic link: a planted link (or hard link)
    is refused and its target left as it was."""
    (tmp_path / "base.nml").write_text(deck_text(tiny()))
    a, b = tmp_path / "a.toml", tmp_path / "b.toml"
    a.write_text('base = "base.nml"\nwrite_history = false\n[cross]\n"friction.mu" = [0.1, 0.2]\n')
    b.write_text('base = "base.nml"\nwrite_history = false\n[cross]\n"friction.mu" = [0.3, 0.4]\n')
    out = tmp_path / "o"
    first = sw.expand(a, out)
    try:
        before = {p: p.read_bytes() for p in out.rglob("*") if p.is_file()}
        r = subprocess.run([*SWEEP, str(b), "--out", str(out), "--quiet"], capture_output=True,
                           text=True)
        assert r.returncode == 1
        assert f"{out} is in use by another sweep (pid {os.getpid()}" in r.stderr, r.stderr
        assert f"spec {a}" in r.stderr and len(r.stderr.splitlines()) == 1
        assert {p: p.read_bytes() for p in out.rglob("*") if p.is_file()} == before
        with pytest.raises(sw.SweepError, match="in use by another sweep"):
            sw.run_local(sw.load(out), jobs=1, progress=False)
        sw.run_local(first, jobs=1, progress=False)
    finally:
        first.close()
    r = subprocess.run([*SWEEP, str(b), "--out", str(out), "--quiet"], capture_output=True,
                       text=True)
    assert r.returncode == 0 and "2 of 2 runs complete" in r.stdout, r.stderr
    assert [x["friction.mu"] for x in _rows(out)] == ["0.3", "0.4"]
    # planted links
    victim = tmp_path / "victim.txt"
    victim.write_text("keep me\n")
    for plant in (os.symlink, os.link):
        (out / ".sweep.lock").unlink()
        plant(victim, out / ".sweep.lock")
        r = subprocess.run([*SWEEP, str(b), "--out", str(out), "--quiet"], capture_output=True,
                           text=True)
        assert r.returncode == 1 and ".sweep.lock is" in r.stderr and "remove it" in r.stderr
        assert victim.read_text() == "keep me\n"


HOSTILE = {
    "quote": "it's a sweep",
    "command": "s $(touch INJECTED_1)",
    "backticks": "s `touch INJECTED_2`",
    "spaces and hash": "my sweep # 2",
    "variable": "s ${HOME} $PATH ;touch INJECTED_3",
}


@pytest.mark.parametrize("name", list(HOSTILE))
def test_the_job_script_runs_nothing_a_directory_name_smuggles_in(tmp_path, name):
    """The job script of a sweep whose directory (and executable path) is named to inject
    commands, run by bash as a task would be (no sbatch or srun on PATH but stubs that leave
    a mark): it runs the executable on its deck in that directory (the run is complete) and
    nothing else (no file the name asks to create, no stub called). The #SBATCH lines, which
    sbatch splits at blanks, hold the path in double quotes."""
    (tmp_path / "base.nml").write_text(deck_text(tiny()))
    (tmp_path / "s.toml").write_text('base = "base.nml"\nwrite_history = false\n[cross]\n'
                                     '"friction.mu" = [0.1, 0.2]\n')
    out = tmp_path / HOSTILE[name]
    bindir = tmp_path / f"bin {HOSTILE[name]}"
    bindir.mkdir()
    exe = bindir / "frictiondyn"
    exe.symlink_to(EXE)
    stubs = tmp_path / "stubs"
    stubs.mkdir()
    for tool in ("sbatch", "srun", "touch"):
        (stubs / tool).write_text(f"#!/bin/sh\necho {tool} >> {shlex.quote(str(tmp_path))}/STUB_CALLED\n")
        (stubs / tool).chmod(0o755)
    r = subprocess.run([*SWEEP, str(tmp_path / "s.toml"), "--out", str(out), "--slurm",
                        "--exe", str(exe)], capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    script = out / "sweep.sbatch"
    text = script.read_text()
    assert f'#SBATCH --chdir="{out}"' in text
    env = {"PATH": f"{stubs}:/usr/bin:/bin", "SLURM_ARRAY_TASK_ID": "1", "SLURM_ARRAY_JOB_ID": "7"}
    t = subprocess.run(["bash", str(script)], env=env, cwd=tmp_path, capture_output=True)
    assert t.returncode == 0, t.stderr
    assert json.loads((out / "runs" / "r0001.summary.json").read_text())["n_dof"] == 1
    assert not (out / "runs" / "r0000.summary.json").exists()
    assert not list(tmp_path.rglob("INJECTED*"))  # no name of the test starts so
    assert not (tmp_path / "STUB_CALLED").exists()
    # and as sbatch reads the #SBATCH lines: its splitting and quoting
    opts = dict(_sbatch_options(text))
    assert opts["--chdir"] == str(out)
    assert opts["--output"] == str(out).replace("%", "%%") + "/logs/%A_%a.out"


def _sbatch_options(text: str):
    """The options of a script's #SBATCH lines as sbatch reads them: each line split at
    blanks, double or single quotes holding blanks and '#', an unquoted '#' starting a
    comment."""
    for line in text.splitlines():
        if not line.startswith("#SBATCH "):
            continue
        rest, arg, quote = line[len("#SBATCH "):].lstrip(), "", ""
        for ch in rest:
            if quote:
                if ch == quote:
                    quote = ""
                else:
                    arg += ch
            elif ch in "\"'":
                quote = ch
            elif ch.isspace() or ch == "#":
                break
            else:
                arg += ch
        key, _, value = arg.partition("=")
        yield key, value


@pytest.mark.parametrize("where", ["--out", "directory"])
def test_a_directory_a_job_script_cannot_name_is_refused(tmp_path, where):
    """A newline in the sweep directory (from --out or the spec's directory) would end an
    #SBATCH line and make the rest a command of the job script: the sweep refuses it before
    it writes anything."""
    (tmp_path / "base.nml").write_text(deck_text(tiny()))
    evil = "sweep\ntouch INJECTED #"
    spec = tmp_path / "s.toml"
    text = 'base = "base.nml"\n[cross]\n"friction.mu" = [0.1]\n'
    args = [*SWEEP, str(spec), "--slurm"]
    if where == "--out":
        args += ["--out", str(tmp_path / evil)]
    else:
        text = f"directory = {json.dumps(evil)}\n" + text
    spec.write_text(text)
    r = subprocess.run(args, capture_output=True, text=True, cwd=tmp_path)
    assert r.returncode == 1 and "newline or another control character" in r.stderr, r.stderr
    assert len(r.stderr.strip().splitlines()) == 1
    assert sorted(p.name for p in tmp_path.iterdir()) == ["base.nml", "s.toml"]
    # and slurm_script refuses such a directory however the sweep got there
    sweep = sw.Sweep("s", tmp_path / evil, [], [sw.Run(0, "r0000", {}, "decks/r0000.nml")])
    with pytest.raises(sw.SweepError, match="control character"):
        sw.slurm_script(sweep, [0], exe=EXE)
    for opt in ("time_limit", "partition"):
        sweep.directory = tmp_path
        with pytest.raises(sw.SweepError, match="#SBATCH line"):
            sw.slurm_script(sweep, [0], exe=EXE, **{opt: "1\ntouch INJECTED"})
    with pytest.raises(sw.SweepError, match="#SBATCH line"):
        sw.slurm_script(sweep, [0], exe=EXE, extra=["--mem=1G\ntouch INJECTED"])
    assert not list(tmp_path.rglob("*.sbatch"))


def test_a_spec_of_1e12_runs_is_refused_before_it_is_expanded(tmp_path):
    """Twelve keys of ten values each cross into 1e12 runs: the runs are counted first and
    the spec refused at once (in well under a second, with little memory), naming the count
    and --max-runs; a spec of 9 runs is refused under --max-runs 8 and runs under 9."""
    (tmp_path / "base.nml").write_text(deck_text(tiny()))
    keys = ["friction.mu", "friction.p", "excitation.amplitude", "excitation.frequency",
            "excitation.duration", "springs.k", "model.mass", "friction.eps1", "friction.f",
            "integration.n1", "integration.n2", "output.output_every"]
    text = 'base = "base.nml"\n[cross]\n' + "".join(
        f'"{k}" = {[float(i + 1) for i in range(10)]}\n' for k in keys)
    (tmp_path / "big.toml").write_text(text)
    t0 = time.perf_counter()
    # the memory the refusal may take: 1 GiB of address space; under the address sanitizer
    # (the checked build, whose interpreter preloads libasan and reserves terabytes of address
    # space as it starts) no such limit can be set, and the time bound alone stops a spec
    # that would be expanded
    limit = "" if os.environ.get("FRICTIONDYN_CHECKED") else \
        "resource.setrlimit(resource.RLIMIT_AS, (1 << 30, 1 << 30))"
    code = f"""
import resource, sys
{limit}
from frictiondyn.cli import main
sys.exit(main(sys.argv[1:]))
"""
    r = subprocess.run([sys.executable, "-c", code, "sweep", str(tmp_path / "big.toml"), "--out",
                        str(tmp_path / "o")], capture_output=True, text=True, timeout=60)
    assert time.perf_counter() - t0 < 20
    assert r.returncode == 1
    assert "makes 1,000,000,000,000 runs" in r.stderr and "--max-runs" in r.stderr, r.stderr
    assert not (tmp_path / "o").exists()
    (tmp_path / "nine.toml").write_text(
        'base = "base.nml"\n[cross]\n"friction.mu" = [0.1, 0.2, 0.3]\n"friction.p" = [1.0, 2.0, 3.0]\n')
    r = subprocess.run([*SWEEP, str(tmp_path / "nine.toml"), "--out", str(tmp_path / "n"),
                        "--expand-only", "--max-runs", "8"], capture_output=True, text=True)
    assert r.returncode == 1 and "makes 9 runs (3 x 3), more than the limit of 8" in r.stderr
    r = subprocess.run([*SWEEP, str(tmp_path / "nine.toml"), "--out", str(tmp_path / "n"),
                        "--expand-only", "--max-runs", "9"], capture_output=True, text=True)
    assert r.returncode == 0 and len(list((tmp_path / "n" / "decks").glob("*.nml"))) == 9


@pytest.mark.parametrize(
    "text, words",
    [
        ("name = 5\n", ["name = 5: a non-empty string is needed"]),
        ("name = '..'\n", ['name = "..": letters, digits']),
        ("name = 'a/b'\n", ['name = "a/b"']),
        ("directory = 5\n", ["directory = 5: a non-empty string"]),
        (f"directory = '{'x' * 300}'\n", ["the sweep directory", "File name too long"]),
        ("jobs = 'x'\n", ['jobs = "x": a whole number from 1 to 1024']),
        ("jobs = 0\n", ["jobs = 0: a whole number"]),
        ("write_history = 'no'\n", ['write_history = "no": true or false is needed']),
        ("name = 1979-05-27T07:32:00Z\n", ["name = \"1979-05-27 07:32:00+00:00\""]),
        ("[cross]\n'friction.mu' = [1979-05-27]\n", ["[cross] friction.mu: a date"]),
        ("[cross]\n'friction.mu' = [{a = 1}]\n", ["[cross] friction.mu: a dict"]),
        ("[cross]\n'braces.stifness' = [1.0]\n",
         ["&braces has no variable 'stifness'; did you mean 'stiffness'?"]),
        ("[cross]\n'brace.stiffness' = [1.0]\n", ["no group &brace in a deck; did you mean 'braces'?"]),
        ("[zip]\n'friction.muu' = [1.0]\n", ["[zip] friction.muu: &friction has no variable 'muu'",
                                              "did you mean 'mu'"]),
        ("[cross]\n'output.name' = ['x']\n", ["the sweep sets &output dir and name itself"]),
        ("[cross]\n'friction.mu' = [0.1]\n'Friction.MU' = [0.2]\n", ["sets what 'friction.mu' sets"]),
        ("[cross]\n'friction.mu' = [0.1]\n'friction.mu(1)' = [0.2]\n", ["sets what 'friction.mu' sets"]),
        ("[cross]\nstatus = ['a']\n", ["a label may not be named like a column"]),
        ("[cross]\n'friction.law' = [\"a\\nb\"]\n", ["may not hold a newline"]),
        ("[cross]\n'friction.mu' = [nan]\n", ["nan is not a finite number"]),
        ("bogus = 1\n", ["unknown key(s) ['bogus']"]),
        ("nmae = 'x'\n", ["unknown key(s) ['nmae']; did you mean 'name'?"]),
    ],
)
def test_a_spec_value_of_the_wrong_kind_is_one_line_naming_the_key(tmp_path, text, words):
    """Values of the wrong type, hostile names and misspelt keys (with the close names of
    the deck reader's tables): one line naming the spec and the key, before anything is
    written, never a traceback."""
    (tmp_path / "b.nml").write_text(deck_text(tiny()))
    (tmp_path / "s.toml").write_text("base = 'b.nml'\n" + text)
    out = [] if text.startswith("directory") else ["--out", str(tmp_path / "o")]
    r = subprocess.run([*SWEEP, str(tmp_path / "s.toml"), *out, "--slurm"],
                       capture_output=True, text=True, cwd=tmp_path)
    assert r.returncode == 1
    assert r.stderr.startswith(f"frictiondyn: error: {tmp_path / 's.toml'}: "), r.stderr
    assert len(r.stderr.splitlines()) == 1, r.stderr
    for w in words:
        assert w in r.stderr, (w, r.stderr)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["b.nml", "s.toml"]


def test_deck_variables_are_the_deck_readers(tmp_path):
    """The sweep's table of groups and variables (its check of keys, its 'did you mean')
    is the deck reader's: the namelist statements of fortran/io/fd_deck.f90."""
    src = (Path(__file__).resolve().parents[1] / "fortran" / "io" / "fd_deck.f90").read_text()
    src = re.sub(r"&[ \t]*\n[ \t]*&?", " ", src)
    found = {m[1].lower(): tuple(v.strip().lower() for v in m[2].split(","))
             for m in re.finditer(r"namelist\s*/(\w+)/([^\n!]*)", src, re.I)}
    # &excitation2, the second horizontal component, is read with &excitation's statement
    found["excitation2"] = found["excitation"]
    found["excitation3"] = found["excitation"]   # the vertical component, likewise
    assert found == {g: tuple(v) for g, v in sw.DECK_VARIABLES.items()}


def test_collect_reports_damaged_runs_and_writes_what_it_can_read(tmp_path):
    """A summary that is [1, 2] or 123, truncated, not UTF-8, a directory; an error.txt not
    UTF-8: collect names each run and why, writes results.csv with every run (values only
    for the runs done), never a traceback; a manifest that is [] or not UTF-8 is one line."""
    spec, out = _tiny_sweep(tmp_path, mus=(0.1, 0.15, 0.2, 0.25, 0.3, 0.35))
    runs = out / "runs"
    (runs / "r0000.summary.json").write_text("[1, 2]")
    (runs / "r0001.summary.json").write_text("123")
    s2 = runs / "r0002.summary.json"
    s2.write_bytes(s2.read_bytes()[:100])
    s3 = runs / "r0003.summary.json"
    s3.write_bytes(b"\xff\xfe" + s3.read_bytes())
    (runs / "r0004.summary.json").unlink()
    (runs / "r0004.summary.json").mkdir()
    (runs / "r0005.summary.json").unlink()
    (runs / "r0005.error.txt").write_bytes(b"frictiondyn: error: \xff\xfe bad\n")
    c = _cli("collect", str(out))
    assert c.returncode == 1 and "Traceback" not in c.stderr, c.stderr
    assert "0 of 6 runs complete, 1 failed, 0 missing, 5 damaged" in c.stdout
    for rid, why in [("r0000", "is a JSON array, not an object"), ("r0001", "is a JSON number"),
                     ("r0002", "is not valid JSON"), ("r0003", "is not UTF-8 text (byte 0)"),
                     ("r0004", "cannot be read: Is a directory")]:
        assert f"damaged: {rid} (index {int(rid[1:])}): its summary {why}"[:60] in c.stdout, rid
    assert "failed: r0005 (index 5): frictiondyn: error: \ufffd\ufffd bad" in c.stdout
    rows = _rows(out)
    assert [r["status"] for r in rows] == ["damaged"] * 5 + ["failed"]
    assert [r["friction.mu"] for r in rows] == ["0.1", "0.15", "0.2", "0.25", "0.3", "0.35"]
    for bad in (b"[]", b"\xff{}", b'{"name": "s", "runs": 5}', b'{"name": "s\\n", "runs": []}'):
        (out / "manifest.json").write_bytes(bad)
        c = _cli("collect", str(out))
        assert c.returncode == 1 and c.stdout == "", c.stdout
        assert c.stderr.startswith(f"frictiondyn: error: {out / 'manifest.json'} is damaged")
        assert len(c.stderr.splitlines()) == 1


def test_a_null_of_a_summary_is_nan_in_the_table_and_left_out_of_plots(tmp_path):
    """A summary's null (a quantity the run does not define, e.g. the stuck period of a rigid
    system) is written NaN in results.csv, not an empty cell; sweep plot leaves such a point
    out, and says so when no point is left."""
    spec, out = _tiny_sweep(tmp_path)
    for rid in ("r0001", "r0002"):
        p = out / "runs" / f"{rid}.summary.json"
        summ = json.loads(p.read_text())
        summ["period_stuck_s"] = None
        summ["peak_u_m"] = [None]
        p.write_text(json.dumps(summ))
    c = _cli("collect", str(out))
    assert c.returncode == 0, c.stdout + c.stderr
    rows = _rows(out)
    assert [r["period_stuck_s"] for r in rows][1:3] == ["NaN", "NaN"]
    assert [r["peak_u_m[1]"] for r in rows][1:3] == ["NaN", "NaN"]
    assert float(rows[0]["peak_u_m[1]"]) > float(rows[3]["peak_u_m[1]"]) > 0
    p = _cli("plot", out, "friction.mu", "peak_u_m[1]")
    assert p.returncode == 0, p.stderr
    assert Path(p.stdout.split("plot: ")[1].strip()).read_bytes()[:4] == b"\x89PNG"
    for rid in ("r0000", "r0003"):
        s = out / "runs" / f"{rid}.summary.json"
        s.write_text(s.read_text().replace('"period_stuck_s": ', '"period_stuck_s": null, "x": '))
    _cli("collect", out)
    p = _cli("plot", str(out), "friction.mu", "period_stuck_s")
    assert p.returncode == 1 and "no complete run has numbers for both" in p.stderr, p.stderr


def test_plot_of_a_wrong_column_names_the_close_ones(tmp_path):
    spec, out = _tiny_sweep(tmp_path, mus=(0.1, 0.2))
    p = _cli("plot", str(out), "friction.mu", "peak_s_m[1")
    assert p.returncode == 1
    assert "'peak_s_m[1' is not a column of results.csv; close matches: peak_s_m[1]" in p.stderr
    assert len(p.stderr) < 300 and "energy_input_J" not in p.stderr
    p = _cli("plot", out, "friction.mu", "peak_s_m[1]", "--by", "zzz")
    assert p.returncode == 1 and "'zzz' is not a column" in p.stderr


def _fuzz(module: str):
    sys.path.insert(0, str(Path(__file__).resolve().parent / "fuzz"))
    try:
        return __import__(module)
    finally:
        sys.path.pop(0)


def test_a_short_sweep_spec_fuzz_campaign_has_no_failure():
    """tests/fuzz/sweep_spec.py, 60 mutated specs (seed 2024): every case a clean one-line
    SweepError with nothing written, or a correct sweep whose job script, run by bash, runs
    the executable once in the sweep directory and nothing else. The long campaign is run by
    hand: python tests/fuzz/sweep_spec.py --count 5000 --seed 1."""
    fz = _fuzz("sweep_spec")
    rep = fz.report(fz.campaign(60, 2024), 2024)
    assert rep["runs"] == 60
    assert rep["sweeps"] >= 5 and rep["clean errors"] >= 30, rep
    assert not any(rep[k] for k in fz.FAILURES), rep["failures"][:5]


def test_a_short_collect_fuzz_campaign_has_no_failure():
    """tests/fuzz/collect_damage.py, 80 damaged folders (seed 2024): no traceback; a
    damaged manifest one line; otherwise the table of every run, each run not done named,
    and a done row only with its own run's values. The long campaign is run by hand:
    python tests/fuzz/collect_damage.py --count 5000 --seed 1."""
    fz = _fuzz("collect_damage")
    rep = fz.report(fz.campaign(80, 2024), 2024)
    assert rep["runs"] == 80
    assert rep["tables"] >= 40 and rep["clean errors"] >= 5, rep
    assert not any(rep[k] for k in fz.FAILURES), rep["failures"][:5]
