"""Outputs that batch runs can trust: the CSV and the summary of one run land as a pair
(never one run's CSV beside another run's summary), a failed write is an error naming the
file with earlier outputs untouched, no temporary file is left behind (also on SIGTERM and
SIGINT); the executable's command line (--list/--index, --version, --help)."""

from __future__ import annotations

import json
import os
import re
import signal
import subprocess
import time
from pathlib import Path

import frictiondyn
import numpy as np
import pytest
from conftest import deck_text, tmpfs

EXE = frictiondyn.executable()


def oscillator(n_dof: int, duration: float, name: str = "same", every: int = 1) -> dict:
    """n_dof masses in a chain under a harmonic table motion; output every dt1 step."""
    return {
        "model": {"n_dof": n_dof, "mass": [100.0] * n_dof},
        "springs": {"n_springs": n_dof, "node_i": list(range(1, n_dof + 1)),
                    "node_j": list(range(n_dof)), "k": [4.0e4] * n_dof},
        "damping": {"damping_type": "rayleigh", "rayleigh_a0": 0.2},
        "excitation": {"excitation_type": "harmonic", "amplitude": 0.01, "frequency": 2.0,
                       "dt_record": 0.01, "duration": duration},
        "integration": {"n1": 2},
        "output": {"name": name, "output_every": every},
    }



def free_slider() -> dict:
    """A 2 kg block on a velocity-law device to the table, no spring, no table motion: a
    rigid-body mode (no period), no forcing frequency, nothing to balance."""
    return {
        "model": {"n_dof": 1, "mass": [2.0]},
        "springs": {"n_springs": 0},
        "damping": {"damping_type": "none"},
        "friction": {"n_devices": 1, "node_i": 1, "node_j": 0, "law": "velocity",
                     "p": 19.62, "mu": 0.3, "eps": 1e-3},
        "excitation": {"excitation_type": "none", "dt_record": 0.01, "duration": 0.2},
        "output": {"name": "slider"},
    }

def pair_is_consistent(outdir: Path, name: str = "same") -> tuple[int, int]:
    """The CSV and the summary of `name` come from one run: the CSV's columns and rows are
    those the summary announces (n_dof, samples). Returns (n_dof, samples)."""
    summ = json.loads((outdir / f"{name}.summary.json").read_text())
    lines = (outdir / f"{name}.csv").read_text().splitlines()
    ncol = len(lines[0].split(","))
    assert ncol == 2 + 3 * summ["n_dof"], (ncol, summ["n_dof"])
    assert len(lines) - 1 == summ["samples"], (len(lines) - 1, summ["samples"])
    return summ["n_dof"], summ["samples"]


def leftovers(outdir: Path) -> list[str]:
    return sorted(p.name for p in outdir.iterdir() if p.name.startswith("."))


def test_two_executables_writing_one_name_never_leave_a_mixed_pair(tmp_path):
    """Two different runs (1 DOF, 2 s; 3 DOF, 1.5 s) write the same output name at the same
    time, 60 times: every time the pair on disk is one run's CSV with that run's summary,
    and no temporary or lock file is left."""
    a, b = tmp_path / "a.nml", tmp_path / "b.nml"
    a.write_text(deck_text(oscillator(1, 2.0)))
    b.write_text(deck_text(oscillator(3, 1.5)))
    out = tmp_path / "out"
    seen = set()
    for _ in range(60):
        procs = [subprocess.Popen([EXE, str(d)], cwd=tmp_path, stdout=subprocess.DEVNULL,
                                  stderr=subprocess.PIPE) for d in (a, b)]
        for p in procs:
            assert p.wait() == 0, p.stderr.read()
            p.stderr.close()
        seen.add(pair_is_consistent(out))
        assert leftovers(out) == []
    assert seen <= {(1, 401), (3, 301)}


def test_threads_writing_one_name_through_the_library(tmp_path):
    """The same from one process: the library's writer in threads (through the executable
    is covered above; here many writers share a process, as the extension's users do)."""
    from concurrent.futures import ThreadPoolExecutor

    a, b = tmp_path / "a.nml", tmp_path / "b.nml"
    a.write_text(deck_text(oscillator(1, 0.5)))
    b.write_text(deck_text(oscillator(2, 0.4)))

    def one(d):
        return subprocess.run([EXE, str(d)], cwd=tmp_path, capture_output=True).returncode

    with ThreadPoolExecutor(8) as pool:
        assert set(pool.map(one, [a, b] * 40)) == {0}
    pair_is_consistent(tmp_path / "out")
    assert leftovers(tmp_path / "out") == []


def test_full_file_system_fails_with_a_message_and_keeps_earlier_outputs(tmp_path, small_fs):
    """A first run fits; a second run of the same name does not: exit status 1, the message
    names the file and says the disk is full, the first run's pair is untouched, no
    temporary file is left."""
    deck = tmp_path / "run.nml"
    g = oscillator(1, 1.0, name="run")
    g["output"]["dir"] = str(small_fs)
    deck.write_text(deck_text(g))
    first = subprocess.run([EXE, str(deck)], cwd=tmp_path, capture_output=True, text=True)
    assert first.returncode == 0, first.stderr
    before = {p.name: p.read_bytes() for p in small_fs.iterdir()}
    assert set(before) == {"run.csv", "run.summary.json"}
    g["excitation"]["duration"] = 20.0  # 2001 rows of 5 columns: about 250 KB
    deck.write_text(deck_text(g))
    second = subprocess.run([EXE, str(deck)], cwd=tmp_path, capture_output=True, text=True)
    assert second.returncode == 1
    assert "frictiondyn: error:" in second.stderr
    assert "No space left on device" in second.stderr
    assert f"cannot write '{small_fs}/.run.csv." in second.stderr
    after = {p.name: p.read_bytes() for p in small_fs.iterdir()}
    assert after == before


@pytest.mark.parametrize("sig", [signal.SIGTERM, signal.SIGINT])
def test_signal_while_writing_leaves_no_temporary_file(tmp_path, sig):
    """A run with a large history (60 DOF, every dt1 step: about 180 MB) is stopped by the
    signal while it writes its CSV: the process dies of that signal, the temporary files
    are gone, the earlier outputs of the name are untouched."""
    g = oscillator(60, 0.05, name="big")
    (tmp_path / "big.nml").write_text(deck_text(g))
    assert subprocess.run([EXE, "big.nml"], cwd=tmp_path, capture_output=True).returncode == 0
    out = tmp_path / "out"
    before = {p.name: p.read_bytes() for p in out.iterdir()}
    g["excitation"]["duration"] = 40.0
    g["integration"]["n1"] = 10
    (tmp_path / "big.nml").write_text(deck_text(g))
    p = subprocess.Popen([EXE, "big.nml"], cwd=tmp_path, stdout=subprocess.DEVNULL,
                         stderr=subprocess.DEVNULL)
    deadline = time.monotonic() + 60
    while time.monotonic() < deadline and p.poll() is None:
        tmp = [f for f in out.iterdir() if f.name.startswith(".big.csv.")]
        if tmp and tmp[0].stat().st_size > 1_000_000:
            break
        time.sleep(0.01)
    assert p.poll() is None, "the run ended before it was stopped"
    p.send_signal(sig)
    assert p.wait(30) == -sig
    assert leftovers(out) == []
    assert {f.name: f.read_bytes() for f in out.iterdir()} == before


def test_list_and_index(tmp_path):
    """--list/--index run line index+1 of the list (paths relative to the list's folder);
    an index past the end and an empty line are errors naming the list and the line."""
    (tmp_path / "decks").mkdir()
    for i, n in enumerate((1, 2, 3)):
        g = oscillator(n, 0.3, name=f"run{i}")
        (tmp_path / "decks" / f"d{i}.nml").write_text(deck_text(g))
    (tmp_path / "list.txt").write_text("decks/d0.nml\ndecks/d1.nml\n\ndecks/d2.nml\n")
    work = tmp_path / "w"
    work.mkdir()
    r = subprocess.run([EXE, "--list", str(tmp_path / "list.txt"), "--index", "1"], cwd=work,
                       capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    assert pair_is_consistent(work / "out", "run1")[0] == 2
    alone = subprocess.run([EXE, str(tmp_path / "decks" / "d1.nml")], cwd=tmp_path,
                           capture_output=True, text=True)
    assert alone.returncode == 0
    assert (work / "out" / "run1.csv").read_bytes() == (tmp_path / "out" / "run1.csv").read_bytes()
    r = subprocess.run([EXE, "--list", "list.txt", "--index", "2"], cwd=tmp_path,
                       capture_output=True, text=True)
    assert r.returncode == 1 and "line 3 (--index 2) is empty" in r.stderr
    r = subprocess.run([EXE, "--list", "list.txt", "--index", "9"], cwd=tmp_path,
                       capture_output=True, text=True)
    assert r.returncode == 1 and "has only 4 line(s)" in r.stderr and "line 10" in r.stderr
    for bad in (["--list", "list.txt"], ["--index", "1"], ["--list", "list.txt", "--index", "-1"],
                ["a.nml", "b.nml"], ["--frobnicate"]):
        r = subprocess.run([EXE, *bad], cwd=tmp_path, capture_output=True, text=True)
        assert r.returncode == 2 and "usage:" in r.stderr, bad


def test_version_and_help():
    r = subprocess.run([EXE, "--version"], capture_output=True, text=True)
    assert r.returncode == 0 and r.stdout.strip() == f"frictiondyn {frictiondyn.__version__}"
    r = subprocess.run([EXE, "--help"], capture_output=True, text=True)
    assert r.returncode == 0 and "--list DECKS.txt --index I" in r.stdout


def test_summary_names_the_version(run):
    r = run(oscillator(1, 0.1), name="v")
    assert r.returncode == 0
    summ = json.loads((r.workdir / "out" / "same.summary.json").read_text())
    assert summ["frictiondyn_version"] == frictiondyn.__version__
    assert np.isfinite(summ["energy_residual_J"])


def test_planted_lock_symlink_is_not_followed(tmp_path):
    """The commit lock out/.<name>.lock planted as a symbolic link (to a file that does not
    exist, as an attacker would point it anywhere): the writer neither follows it nor creates
    its target; the run fails with a message naming the lock, and leaves no output and no
    temporary file (the planted link alone stays)."""
    deck = tmp_path / "same.nml"
    deck.write_text(deck_text(oscillator(1, 0.2)))
    out = tmp_path / "out"
    out.mkdir()
    target = tmp_path / "elsewhere" / "victim"
    target.parent.mkdir()
    (out / ".same.lock").symlink_to(target)
    r = subprocess.run([EXE, str(deck)], cwd=tmp_path, capture_output=True, text=True)
    assert r.returncode == 1, r.stdout
    assert "same.nml: cannot lock 'out/.same.lock': it is a symbolic link" in r.stderr
    assert not target.exists() and list(target.parent.iterdir()) == []
    assert sorted(p.name for p in out.iterdir()) == [".same.lock"]
    assert (out / ".same.lock").is_symlink()


def test_file_size_limit_is_a_clean_write_error(tmp_path):
    """Under a file-size limit (`ulimit -f`, 64 KiB) a history of about 250 KB cannot be
    written: the executable is not killed by SIGXFSZ (status 153) but ends with the usual
    error (status 1) naming the file and the reason, and leaves no file behind."""
    deck = tmp_path / "big.nml"
    deck.write_text(deck_text(oscillator(1, 20.0, name="big")))
    r = subprocess.run(["bash", "-c", f'ulimit -f 64; exec "{EXE}" big.nml'], cwd=tmp_path,
                       capture_output=True, text=True)
    assert r.returncode == 1, (r.returncode, r.stderr[-500:])
    assert "frictiondyn: error:" in r.stderr
    assert re.search(r"cannot write 'out/\.big\.csv\.[^']*\.tmp': File too large",
                     r.stderr), r.stderr
    assert "Backtrace" not in r.stderr and "signal" not in r.stderr
    out = tmp_path / "out"
    assert not out.exists() or list(out.iterdir()) == []


def test_output_directory_that_cannot_be_made_gives_the_system_reason(tmp_path):
    """A new output directory under a regular file: the error names the directory and
    gives the system's reason."""
    (tmp_path / "plain").write_text("a file, not a directory\n")
    g = oscillator(1, 0.2)
    g["output"]["dir"] = "plain/out"
    (tmp_path / "d.nml").write_text(deck_text(g))
    r = subprocess.run([EXE, "d.nml"], cwd=tmp_path, capture_output=True, text=True)
    assert r.returncode == 1
    assert ("&output: cannot create the output directory dir = 'plain/out': Not a directory"
            in r.stderr), r.stderr


def test_read_only_file_system_output_directory_gives_the_system_reason(tmp_path):
    """A new output directory on a read-only file system (a tmpfs mounted read-only): the
    error gives the system's reason, "Read-only file system"."""
    with tmpfs(tmp_path / "ro", "ro,size=16k") as mnt:
        g = oscillator(1, 0.2)
        g["output"]["dir"] = f"{mnt}/new/out"
        (tmp_path / "d.nml").write_text(deck_text(g))
        r = subprocess.run([EXE, "d.nml"], cwd=tmp_path, capture_output=True, text=True)
    assert r.returncode == 1
    assert f"cannot create the output directory dir = '{mnt}/new/out': Read-only file system" in r.stderr


def test_latin1_path_and_label_give_a_valid_utf8_summary(tmp_path):
    """A deck in a directory whose name has Latin-1 bytes ('d\\xe9j\\xe0'), with a Latin-1
    label ('caf\\xe9') and a tab in another: the summary is valid UTF-8 JSON (strict), each
    such byte the character of its Latin-1 reading, and Result.from_files reads it."""
    work = os.path.join(os.fsencode(tmp_path), b"d\xe9j\xe0")
    os.mkdir(work)
    g = oscillator(2, 0.2, name="lat")
    deck = deck_text(g).encode().replace(
        b"  mass = 100.0, 100.0\n", b"  mass = 100.0, 100.0\n  label = 'caf\xe9', 'a\tb'\n")
    with open(os.path.join(work, b"lat.nml"), "wb") as fh:
        fh.write(deck)
    r = subprocess.run([os.fsencode(EXE), os.path.join(work, b"lat.nml")], cwd=work,
                       capture_output=True)
    assert r.returncode == 0, r.stderr
    out = os.path.join(work, b"out")
    raw = open(os.path.join(out, b"lat.summary.json"), "rb").read()
    summ = json.loads(raw.decode("utf-8", errors="strict"), strict=True)
    assert summ["deck"] == os.path.join(work, b"lat.nml").decode("latin-1")
    assert summ["dof_labels"] == ["café", "a\tb"]
    res = frictiondyn.Result.from_files(os.fsdecode(os.path.join(out, b"lat.csv")))
    assert res.dof_labels == ["café", "a\tb"]
    assert res.summary == summ


def _undefined():
    import sys
    sys.path.insert(0, str(Path(__file__).resolve().parent / "fuzz"))
    import undefined  # the one list of keys that can be null: docs/namelist.md
    return undefined


def test_undefined_summary_values_are_null_never_0(tmp_path):
    """Values a run does not define are JSON null, only in the keys docs/namelist.md lists
    ("Undefined values"), and the executable prints "not defined (why)":
    - a braced mass (a velocity-law device and a spring to the table, a storey without a
      height): the stuck system is rigid, so period_stuck_s and xi_stuck are null (the
      executable printed 'stuck period .000000 s'), and so are the drift ratios;
    - the event-driven technique: omega_max_rad_s, omega_max_dt1 (no step dt1);
    - a flat slider at rest with no table motion: the free system's rigid-body mode (period
      and damping ratio), excitation_frequency_Hz, energy_residual_ratio (no energy passed),
      the times of peaks that never occurred."""
    und = _undefined()
    keys = und.undefined_keys()
    braced = oscillator(1, 0.5, name="braced")
    braced["friction"] = {"n_devices": 1, "node_i": 1, "node_j": 0, "law": "velocity",
                          "p": 1000.0, "mu": 0.3, "eps": 1e-3}
    braced["damping"] = {"damping_type": "none"}
    braced["storeys"] = {"n_storeys": 1, "node_i": 1, "node_j": 0}
    event = {**oscillator(1, 0.5, name="event")}
    event["friction"] = {"n_devices": 1, "node_i": 1, "node_j": 0, "law": "coulomb",
                         "p": 100.0, "mu": 0.3}
    event["integration"] = {"technique": "event_driven", "n1": 2}
    slider = free_slider()
    # a building of rigid floors given by its inertia: its plan, hence its corners, unknown
    floor = {"floors": {"n_floors": 1, "mass": [1.0e5], "inertia": [2.0e6], "height": [3.0]},
             "frames": {"n_frames": 3, "storey": [1, 1, 1], "angle": [0.0, 0.0, 90.0], "x": [0.0, 0.0, 0.0],
                        "y": [-5.0, 5.0, 0.0], "k": [1.0e7, 1.0e7, 2.0e7]},
             "damping": {"damping_type": "none"}, "excitation": braced["excitation"],
             "output": {"dir": "out", "name": "floor"}}
    summ = {}
    for g in (braced, event, slider, floor):
        name = g["output"]["name"]
        (tmp_path / f"{name}.nml").write_text(deck_text(g))
        r = subprocess.run([EXE, f"{name}.nml"], cwd=tmp_path, capture_output=True, text=True)
        assert r.returncode == 0, r.stderr
        summ[name] = json.loads((tmp_path / "out" / f"{name}.summary.json").read_text())
        assert und.null_keys(summ[name]) <= keys, und.null_keys(summ[name]) - keys
        # the list names real keys (those of rigid floors in a building of rigid floors only,
        # the bearing_* and peak_isolation_* keys with &bearings only: tests/test_bearings.py)
        floor_only = {k for k in keys if "corner" in k or k.startswith(
            ("floor_", "device_", "peak_floor_", "peak_base_shear_x", "peak_base_shear_y", "peak_base_torque",
             "bearing_", "peak_isolation_"))}
        assert keys - floor_only <= set(summ[name]), keys - set(summ[name])
        if name == "braced":
            assert ("rigid-link period not defined (with every device a rigid link the structure has "
                    "no free DOF or a rigid-body mode)") in r.stdout
    b, e, s = summ["braced"], summ["event"], summ["slider"]
    assert summ["floor"]["peak_corner_drift_m"] == [None, None]
    assert summ["floor"]["peak_corner_drift_ratio"] == [None, None]
    assert b["period_stuck_s"] is None and b["xi_stuck"] is None
    assert b["storey_height_m"] == [0.0]
    assert b["peak_drift_ratio"] == [None] and b["residual_drift_ratio"] == [None]
    assert b["peak_drift_m"][0] > 0 and b["omega_max_rad_s"] > 0
    assert e["omega_max_rad_s"] is None and e["omega_max_dt1"] is None
    assert e["mode_resolution"] == "not applicable"
    assert s["modes_free_status"] == "unrestrained"
    assert s["periods_free_s"] == [None] and s["modal_xi_free"] == [None]
    assert s["excitation_frequency_Hz"] is None and s["energy_residual_ratio"] is None
    assert s["peak_u_m"] == [0.0] and s["peak_u_time_s"] == [None]
    assert s["peak_aabs_time_s"] == [None] and s["mu_unconverged_s"] is None


def test_python_reads_undefined_values_as_none_and_nan(tmp_path):
    """Python's Result holds an undefined summary value as None (as json.loads reads null),
    in the run's Result and in Result.from_files alike; modes() gives inf for a rigid-body
    mode's period and nan for its damping ratio."""
    g = free_slider()
    (tmp_path / "slider.nml").write_text(deck_text(g))
    res = frictiondyn.run(tmp_path / "slider.nml")
    assert res.summary["period_stuck_s"] is None and res.summary["periods_free_s"] == [None]
    modes = res.modes("free")
    assert modes.status == "unrestrained"
    assert np.isinf(modes.periods[0]) and np.isnan(modes.xi[0]) and modes.frequencies[0] == 0.0
    res.to_csv(tmp_path / "h.csv")
    back = frictiondyn.Result.from_files(tmp_path / "h.csv")
    assert back.summary == res.summary and back.summary["excitation_frequency_Hz"] is None
