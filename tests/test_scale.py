"""The structure-aware linear algebra, the streamed output, the history selection, progress
and interrupt. Correctness only: speed and memory are measured in
bench/compare_opensees.py and docs/performance.md, never here.

- The banded path (reverse Cuthill-McKee, band Cholesky, rank-one updates as devices change
  phase) and the dense path (LAPACK dpotrf/dtrsv on the full matrix) give the same histories
  to 1e-10 on a 10-storey building: in a stick-slip run of each law, and for every one of
  the 2^10 combinations of locked and free devices.
- With every damper locked the building is a linear chain: its steady state under harmonic
  table motion equals the closed-form (frequency-domain) solution.
- An interrupted run (Ctrl-C in Python, SIGINT to the executable) leaves no output under its
  final name; the executable's streamed CSV equals the Python Result bit for bit.
"""

from __future__ import annotations

import itertools
import json
import os
import signal
import subprocess
import sys
import threading
import time
from pathlib import Path

import frictiondyn as fd
import numpy as np
import pytest
from conftest import ROOT, deck_text, steady_amplitude

N = 10


def building(
    n: int = N,
    law: str = "hysteretic",
    pmu=None,
    system: str = "auto",
    duration: float = 2.0,
    excitation: dict | None = None,
    output: dict | None = None,
) -> dict:
    """A shear building of n storeys (mass 1000 kg, storey stiffness 2e6 N/m, 2 % Rayleigh
    damping) with a friction damper beside every storey's spring (slip load pmu[i], brace
    stiffness 2e6 N/m for the hysteretic law), under harmonic table motion."""
    if pmu is None:
        pmu = [3000.0 * (n - i) / n + 500.0 for i in range(n)]
    friction = {
        "n_devices": n,
        "node_i": list(range(1, n + 1)),
        "node_j": list(range(0, n)),
        "law": [law] * n,
        "p": [float(x) for x in pmu],
        "mu": [1.0] * n,
    }
    if law == "hysteretic":
        friction["f"] = [max(float(x), 1.0) / 2.0e6 for x in pmu]
    else:
        friction["eps"] = [1.0e-3] * n
    return {
        "model": {"n_dof": n, "mass": [1000.0] * n},
        "springs": {
            "n_springs": n,
            "node_i": list(range(1, n + 1)),
            "node_j": list(range(0, n)),
            "k": [2.0e6] * n,
        },
        "damping": {"damping_type": "rayleigh", "rayleigh_a0": 0.2, "rayleigh_a1": 4.0e-4},
        "friction": friction,
        "excitation": excitation
        or {
            "excitation_type": "harmonic",
            "amplitude": 0.01,
            "frequency": 2.5,
            "dt_record": 0.005,
            "duration": duration,
        },
        "integration": {"n1": 5, "n2": 10, "linear_system": system},
        "output": output or {"output_every": 1},
    }


def run(groups: dict, **kw) -> fd.Result:
    return fd.run_text(deck_text(groups), name="building.nml", **kw)


def same_histories(a: fd.Result, b: fd.Result, rtol: float) -> float:
    """Largest difference of two histories relative to each column's magnitude (phases
    compared exactly)."""
    assert a.names == b.names and a.data.shape == b.data.shape
    worst = 0.0
    for j, name in enumerate(a.names):
        x, y = a.data[:, j], b.data[:, j]
        if name.startswith("phase"):
            assert np.array_equal(x, y), f"{name} differs"
            continue
        scale = max(np.max(np.abs(y)), 1e-300)
        worst = max(worst, float(np.max(np.abs(x - y)) / scale))
    assert worst <= rtol, f"histories differ by {worst:.2e} of a column's magnitude"
    return worst


# ----------------------------------------------------------------- banded against dense


@pytest.mark.parametrize("law", ["hysteretic", "velocity"])
def test_banded_and_dense_paths_give_the_same_stick_slip_history(law):
    """A run in which the dampers stick and slip in many patterns (the banded factors follow
    by rank-one updates, the dense ones too): the same history to 1e-10."""
    banded = run(building(law=law, system="banded"))
    dense = run(building(law=law, system="dense"))
    assert banded.summary["linear_system"] == "banded"
    assert banded.summary["half_bandwidth"] == 1  # RCM makes the chain a path
    assert dense.summary["linear_system"] == "dense"
    s = banded.summary
    assert sum(s["stick_to_slip"]) > 5 * N and min(s["stick_to_slip"]) > 0  # every damper slips
    assert s["factor_updates"] > 5 * N and s["factorizations"] <= 6
    phases = banded.data[:, [j for j, c in enumerate(banded.names) if c.startswith("phase")]]
    patterns = {tuple(row != 0) for row in phases}
    assert len(patterns) > 20, f"only {len(patterns)} patterns of sliding dampers seen"
    same_histories(banded, dense, 1e-10)
    for key in ("peak_u_m", "peak_aabs_mps2", "peak_force_N"):
        np.testing.assert_allclose(s[key], dense.summary[key], rtol=1e-10)


def test_every_combination_of_locked_devices_banded_equals_dense():
    """All 2^10 combinations of locked (slip load far above any force: the damper is a brace
    of stiffness P mu / f) and free (P mu = 0) dampers: each a linear chain of its own K^,
    integrated for 0.2 s by both paths: the same history to 1e-10."""
    worst = 0.0
    for combo in itertools.product([False, True], repeat=N):
        pmu = [1.0e9 if locked else 0.0 for locked in combo]
        g = building(pmu=pmu, duration=0.2)
        g["friction"]["f"] = [1.0e9 / 2.0e6] * N  # a locked brace of 2e6 N/m
        banded = run(building_with(g, "banded"))
        dense = run(building_with(g, "dense"))
        assert sum(banded.summary["stick_to_slip"]) == 0
        worst = max(worst, same_histories(banded, dense, 1e-10))


def building_with(groups: dict, system: str) -> dict:
    g = json.loads(json.dumps(groups))
    g["integration"]["linear_system"] = system
    return g


# ----------------------------------------------------------------- locked: a linear chain


def test_locked_building_is_the_linear_chain_in_steady_state():
    """Every damper locked (hysteretic law, slip load never reached): a chain of storey
    stiffness k + P mu / f. Under table motion a0 sin(w t) (cosine ramp over 3 cycles) its
    steady state is U = (K - w^2 M + i w C)^-1 (M r a0 w^2), C = a0 M + a1 K (the springs'
    K): every storey's amplitude over the last 10 cycles within 1e-4. (Newmark's average
    acceleration shifts a mode's frequency by (w_n h)^2 / 12 = 7e-6 for the first at
    h = 1 ms, which moves the response by about twice that; the first mode's damping of 11 %
    leaves no transient after the 40 s.)"""
    freq, amp = 0.5, 0.01
    g = building(
        pmu=[1.0e9] * N,
        excitation={
            "excitation_type": "harmonic",
            "amplitude": amp,
            "frequency": freq,
            "ramp_cycles": 3,
            "dt_record": 0.005,
            "duration": 40.0,
        },
    )
    kd = 2.0e6
    g["friction"]["f"] = [1.0e9 / kd] * N
    g["damping"] = {"damping_type": "rayleigh", "rayleigh_a0": 2.0, "rayleigh_a1": 4.0e-4}
    r = run(g)
    assert sum(r.summary["stick_to_slip"]) == 0
    # the closed form
    m, k, a0, a1 = 1000.0, 2.0e6, 2.0, 4.0e-4
    kk = np.zeros((N, N))
    for i in range(N):  # storey i joins DOF i+1 to DOF i (0 = table): spring k, brace kd
        for kij in (k, kd):
            kk[i, i] += kij
            if i > 0:
                kk[i - 1, i - 1] += kij
                kk[i, i - 1] -= kij
                kk[i - 1, i] -= kij
    ks = np.zeros((N, N))
    for i in range(N):
        ks[i, i] += k
        if i > 0:
            ks[i - 1, i - 1] += k
            ks[i, i - 1] -= k
            ks[i - 1, i] -= k
    w = 2 * np.pi * freq
    mm = m * np.eye(N)
    cc = a0 * mm + a1 * ks
    # table acceleration -a0 w^2 sin(w t): load -M r x0'' = M r a0 w^2 sin(w t)
    u = np.linalg.solve(kk - w * w * mm + 1j * w * cc, mm @ np.ones(N) * amp * w * w)
    for i in range(N):
        got = steady_amplitude(r.time, r[f"u{i + 1}"], freq, 10)
        assert got == pytest.approx(abs(u[i]), rel=1e-4), f"storey {i + 1}"


# ----------------------------------------------------------------- history selection


def test_selected_columns_equal_those_of_the_full_history():
    full = run(building())
    part = run(building(), dofs=[3, 10], devices=[1])
    assert part.names == ["t", "ag", "u3", "v3", "aabs3", "u10", "v10", "aabs10",
                          "s1", "sdot1", "F1", "phase1"]
    for name in part.names:
        assert np.array_equal(part[name], full[name]), name
    assert part.summary == {**full.summary, "run_time_s": part.summary["run_time_s"]}
    # the deck's &output selects the executable's columns the same way
    g = building(output={"output_every": 1, "history_dofs": [3, 10], "history_devices": [1]})
    same = run(g)
    assert same.names == part.names and np.array_equal(same.data, part.data)
    none = run(building(output={"output_every": 1, "history_dofs": 0, "history_devices": 0}))
    assert none.names == ["t", "ag"]


def test_bad_selection_is_named():
    with pytest.raises(fd.FrictiondynError, match="DOF 11 is not in 1..10"):
        run(building(), dofs=[11])
    with pytest.raises(fd.DeckError, match=r"history_dofs\(2\) = 2 is invalid"):
        run(building(output={"history_dofs": [3, 2]}))


# ----------------------------------------------------------------- streaming


def test_streamed_csv_equals_the_python_result_bit_for_bit(tmp_path):
    """The executable writes its history as the run goes; the CSV reads back to exactly the
    Result of the same deck run through the extension (17 digits: an exact round trip),
    and Session.stream() writes the same bytes as Session.write() of a history in memory."""
    g = building(duration=3.0, output={"output_every": 1, "dir": "out", "name": "b"})
    deck = tmp_path / "b.nml"
    deck.write_text(deck_text(g))
    proc = subprocess.run([fd.executable(), str(deck)], cwd=tmp_path, capture_output=True, text=True)
    assert proc.returncode == 0, proc.stderr
    csv = tmp_path / "out" / "b.csv"
    exe = fd.Result.from_files(csv)
    ext = fd.run(deck)
    assert exe.names == ext.names and np.array_equal(exe.data, ext.data)
    assert not [p for p in (tmp_path / "out").iterdir() if p.name.startswith(".")]
    with fd.Session(deck) as s:
        s.stream(tmp_path / "streamed")
        s.solve(history=False)
        streamed_csv, _ = s.write()
    with fd.Session(deck) as s:
        memory_csv, _ = s.solve().write(tmp_path / "memory")
    assert streamed_csv.read_bytes() == memory_csv.read_bytes() == csv.read_bytes()


def test_a_stream_not_written_is_removed(tmp_path):
    deck = tmp_path / "b.nml"
    deck.write_text(deck_text(building(duration=0.5, output={"dir": "out", "name": "b"})))
    with fd.Session(deck) as s:
        s.stream(tmp_path / "out").solve(history=False)
        assert [p.name for p in (tmp_path / "out").iterdir()][0].startswith(".b.csv.")
    assert not (tmp_path / "out").exists()  # the directory made for it goes too
    (tmp_path / "mine").mkdir()  # one that was there stays, empty
    with fd.Session(deck) as s:
        s.stream(tmp_path / "mine").solve(history=False)
    assert list((tmp_path / "mine").iterdir()) == []


# ----------------------------------------------------------------- progress and interrupt


def long_deck(tmp_path: Path, seconds: float = 3000.0) -> Path:
    deck = tmp_path / "long.nml"
    deck.write_text(
        deck_text(building(duration=seconds, output={"output_every": 20, "dir": "out", "name": "long"}))
    )
    return deck


def test_progress_callback_sees_the_run_advance(tmp_path):
    seen: list[tuple[float, float]] = []
    fd.run(long_deck(tmp_path, 20.0), progress=lambda t, d: seen.append((t, d)))
    assert seen and seen[-1] == (20.0, 20.0)
    ts = [t for t, _ in seen]
    assert ts == sorted(ts)


def test_cancel_from_another_thread_raises_run_cancelled(tmp_path):
    with fd.Session(long_deck(tmp_path)) as s:
        s.stream(tmp_path / "out")
        threading.Timer(0.3, s.cancel).start()
        t0 = time.perf_counter()
        with pytest.raises(fd.RunCancelled, match="cancelled at t = "):
            s.solve(history=False)
        assert time.perf_counter() - t0 < 5.0  # the run would take a minute and more
        assert 0.0 < s.progress()[0] < 3000.0
    assert not (tmp_path / "out").exists() or list((tmp_path / "out").iterdir()) == []


@pytest.mark.skipif(sys.platform == "win32", reason="POSIX signals")
def test_ctrl_c_stops_a_python_run_and_leaves_no_output(tmp_path):
    """SIGINT during Session.solve (Ctrl-C in a terminal or a notebook): KeyboardInterrupt,
    promptly, and neither the final nor any temporary output is left."""
    code = f"""
import os, signal, threading, time, frictiondyn as fd
deck = {str(long_deck(tmp_path))!r}
threading.Timer(0.5, lambda: os.kill(os.getpid(), signal.SIGINT)).start()
t0 = time.perf_counter()
try:
    with fd.Session(deck) as s:
        s.stream({str(tmp_path / 'out')!r})
        s.solve()
        s.write()
except KeyboardInterrupt:
    print("interrupted after", time.perf_counter() - t0)
"""
    # five times: a session freed under a running solve would crash some runs (a race)
    for _ in range(5):
        proc = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
        assert proc.returncode == 0 and "interrupted after" in proc.stdout, (
            proc.returncode,
            proc.stdout + proc.stderr,
        )
        assert float(proc.stdout.split()[-1]) < 5.0
        out = tmp_path / "out"
        assert not out.exists() or list(out.iterdir()) == []


def test_a_solve_whose_call_raised_in_its_thread_fails_and_the_next_runs():
    """A solve whose call raises in its thread (here the extension refusing a history buffer)
    is reported and fails with status 3; the next solve runs."""
    code = f"""
import frictiondyn as fd
from frictiondyn import _api
deck = {str(ROOT / "inputs" / "test4_velocity.nml")!r}
with _api.Session(deck) as s:
    print(_api.Session._run(s._handle, 1, "not an array", None))
print(fd.run(deck).data.shape[0])
"""
    proc = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=60)
    assert proc.returncode == 0, proc.stdout + proc.stderr
    assert proc.stdout.split() == ["3", "8001"], proc.stdout + proc.stderr
    assert "Exception in thread frictiondyn-solve" in proc.stderr and "TypeError" in proc.stderr


def test_a_progress_callback_that_raises_stops_the_run(tmp_path):
    """An exception from the progress callback is raised from solve, promptly (the run would
    take minutes), after the solve has stopped: the session is not freed under the running
    solve (the process would die, SIGSEGV)."""
    code = f"""
import time, frictiondyn as fd
def progress(t, duration):
    if t > 0.0:
        raise ValueError("stop here")
t0 = time.perf_counter()
try:
    fd.run({str(long_deck(tmp_path))!r}, progress=progress)
except ValueError as e:
    print(e.args[0].split()[0], time.perf_counter() - t0)
"""
    for _ in range(3):
        proc = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
        assert proc.returncode == 0, (proc.returncode, proc.stdout + proc.stderr)
        word, seconds = proc.stdout.split()
        assert word == "stop" and float(seconds) < 5.0, proc.stdout


@pytest.mark.parametrize("launched", [True, False])
def test_ctrl_c_while_the_solve_thread_starts(tmp_path, launched):
    """Ctrl-C can land inside Thread.start, after the thread was launched or before: either
    way KeyboardInterrupt is raised promptly, the session is not freed under a running solve
    (the process lives on), and the next solve runs. The interrupt is made deterministic by
    a Thread.start that raises it once, after or before starting the thread."""
    code = f"""
import threading, time, frictiondyn as fd
start = threading.Thread.start
def interrupted_start(self):
    threading.Thread.start = start
    if {launched!r}:
        start(self)
    raise KeyboardInterrupt
threading.Thread.start = interrupted_start
t0 = time.perf_counter()
try:
    fd.run({str(long_deck(tmp_path))!r})
except KeyboardInterrupt:
    print("interrupted", time.perf_counter() - t0)
print(fd.run({str(ROOT / "inputs" / "test4_velocity.nml")!r}).data.shape[0])
"""
    proc = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    assert proc.returncode == 0, (proc.returncode, proc.stdout + proc.stderr)
    words = proc.stdout.split()
    assert words[0] == "interrupted" and float(words[1]) < 5.0 and words[2] == "8001", proc.stdout


@pytest.mark.skipif(sys.platform == "win32", reason="POSIX signals")
def test_sigint_to_the_executable_leaves_no_output(tmp_path):
    deck = long_deck(tmp_path)
    proc = subprocess.Popen([fd.executable(), str(deck)], cwd=tmp_path, stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE)
    time.sleep(0.5)
    assert proc.poll() is None
    # the history is being written under its temporary name
    tmp = [p.name for p in (tmp_path / "out").iterdir()]
    assert tmp and all(name.startswith(".long.csv.") for name in tmp), tmp
    proc.send_signal(signal.SIGINT)
    proc.wait(timeout=30)
    assert proc.returncode == -signal.SIGINT
    assert list((tmp_path / "out").iterdir()) == []


def test_runs_in_threads_overlap_without_the_gil(tmp_path):
    """Two runs in two threads both make progress at once (the solve releases the GIL):
    while one runs, the other's time advances too. (How much they overlap in wall-clock
    time is measured by bench/compare_opensees.py --threads, not here.)"""
    deck = long_deck(tmp_path, 30.0)
    sessions = [fd.Session(deck), fd.Session(deck)]
    threads = [threading.Thread(target=s.solve, kwargs={"history": False}) for s in sessions]
    for t in threads:
        t.start()
    both = False
    while any(t.is_alive() for t in threads):
        a, b = (s.progress()[0] for s in sessions)
        both = both or (0.0 < a < 30.0 and 0.0 < b < 30.0)
        time.sleep(0.01)
    for t in threads:
        t.join()
    for s in sessions:
        s.close()
    assert both, "the two runs never advanced together"


# ----------------------------------------------------------------- one observer, every technique


@pytest.mark.parametrize("technique", ["event_driven", "moreau_jean"])
def test_run_control_is_the_same_for_the_coulomb_techniques(tmp_path, technique):
    """The exact and Moreau-Jean techniques report through the same observer as Newmark:
    selected columns (the exact technique's maxima between rows, peak_*, of the DOFs and
    devices selected) equal those of the full history, the executable's streamed CSV equals
    the Result bit for bit, progress reaches the end, a cancelled run raises RunCancelled
    promptly and leaves no output."""
    n = 4

    def coulomb(duration, output):
        g = building(n=n, law="coulomb", duration=duration, output=output)
        g["integration"] = {"technique": technique, "n1": 5}
        return g

    g = coulomb(1.0, {"output_every": 1, "dir": "out", "name": "c"})
    full = run(g)
    assert full.summary["technique"] == technique
    part = run(g, dofs=[2, 4], devices=[3])
    names = ["t", "ag", "u2", "v2", "aabs2", "u4", "v4", "aabs4", "s3", "sdot3", "F3", "phase3"]
    if technique == "event_driven":  # the maxima between rows follow the selection
        names += ["peak_u2", "peak_v2", "peak_aabs2", "peak_u4", "peak_v4", "peak_aabs4", "peak_s3", "peak_F3"]
    assert part.names == names
    for name in part.names:
        assert np.array_equal(part[name], full[name]), name
    assert part.summary == {**full.summary, "run_time_s": part.summary["run_time_s"]}
    deck = tmp_path / "c.nml"
    deck.write_text(deck_text(g))
    proc = subprocess.run([fd.executable(), str(deck)], cwd=tmp_path, capture_output=True, text=True)
    assert proc.returncode == 0, proc.stderr
    exe = fd.Result.from_files(tmp_path / "out" / "c.csv")
    assert exe.names == full.names and np.array_equal(exe.data, full.data)
    seen: list[tuple[float, float]] = []
    fd.run(deck, progress=lambda t, d: seen.append((t, d)))
    assert seen and seen[-1] == (1.0, 1.0)
    # a run of hours of motion, cancelled from another thread
    long = tmp_path / "long.nml"
    long.write_text(deck_text(coulomb(1.0e5, {"output_every": 1000, "dir": "out2", "name": "long"})))
    with fd.Session(long) as s:
        s.stream(tmp_path / "out2")
        threading.Timer(0.3, s.cancel).start()
        t0 = time.perf_counter()
        with pytest.raises(fd.RunCancelled, match="cancelled at t = "):
            s.solve(history=False)
        assert time.perf_counter() - t0 < 5.0
        assert 0.0 < s.progress()[0] < 1.0e5
    assert not (tmp_path / "out2").exists() or list((tmp_path / "out2").iterdir()) == []


@pytest.mark.parametrize("technique", ["newmark", "event_driven", "moreau_jean"])
def test_storey_columns_are_kept_whatever_the_selection(technique):
    """The storeys' columns (drift, V per storey, Vb; for the exact technique their maxima
    between rows, peak_*) are not selected: a history keeping one DOF and no device still has
    all of them, equal to the full history's, and a storey's drift is the difference of its
    floors' displacements."""
    n = 4
    g = building(n=n, law="hysteretic" if technique == "newmark" else "coulomb", duration=0.5)
    g["storeys"] = {"n_storeys": n, "spring": list(range(1, n + 1))}
    if technique != "newmark":
        g["integration"] = {"technique": technique, "n1": 5}
    full = run(g)
    part = run(g, dofs=[2], devices=[])
    storeys = [f"{q}{s}" for s in range(1, n + 1) for q in ("drift", "V")] + ["Vb"]
    names = ["t", "ag", "u2", "v2", "aabs2"] + storeys
    if technique == "event_driven":
        names += ["peak_u2", "peak_v2", "peak_aabs2"] + ["peak_" + x for x in storeys]
    assert part.names == names
    for name in part.names:
        assert np.array_equal(part[name], full[name]), name
    assert part.summary == {**full.summary, "run_time_s": part.summary["run_time_s"]}
    assert np.allclose(full["drift1"], full["u1"], rtol=0, atol=1e-15)
    assert np.allclose(full["drift3"], full["u3"] - full["u2"], rtol=0, atol=1e-15)
    assert np.max(np.abs(full["Vb"])) > 0.0


# ----------------------------------------------------------------- capacity, modes


def test_a_deck_of_12000_storeys_runs(tmp_path):
    """12 000 storeys: read, its stuck period computed by
    the subspace iteration (the free chain's closed form, dampers with P mu = 0), run."""
    n = 12000
    g = building(n=n, pmu=[0.0] * n, duration=0.01, output={"history_dofs": [n], "history_devices": 0})
    g["damping"] = {"damping_type": "stiffness", "xi": 0.02}
    r = run(g)
    m, k = 1000.0, 2.0e6
    w1 = 2 * np.sqrt(k / m) * np.sin(np.pi / (2 * (2 * n + 1)))
    assert r.summary["period_stuck_s"] == pytest.approx(2 * np.pi / w1, rel=1e-10)
    assert r.summary["xi_stuck"] == pytest.approx(0.02, rel=1e-10)
    assert r.names == ["t", "ag", f"u{n}", f"v{n}", f"aabs{n}"]
