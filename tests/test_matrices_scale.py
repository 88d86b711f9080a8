"""&matrices models at scale. Modes and step checks above 200 DOFs, found without an n x n
matrix: the stuck and free systems' lowest modes by subspace iteration with the banded factor
(the linking devices as constraints through their Schur complement), the highest frequency by
Lanczos on the entries; checked against numpy's dense eigenproblems (1e-10), and a model of
4000 DOFs run under a limit of address space that its dense matrices would exceed. The
executable's peak memory does not depend on the duration."""

import os
import resource
import subprocess
import time

import numpy as np
import pytest

import frictiondyn
from conftest import deck_text

HARMONIC = {"excitation_type": "harmonic", "amplitude": 0.02, "frequency": 2.0, "dt_record": 0.01,
            "duration": 0.02}
PMU, F = 2.0e4, 1.0e-3                       # slip load [N], hysteretic f [m]


def chain_model(n: int):
    """K: a chain of springs k_i (DOF 1 to the table) plus springs from each DOF to the fifth
    on (K_x with a frame's band); M lumped, 1 to 3 t. Devices: six velocity-law links
    (two of them a loop with a third, so rank five), one to the table, four hysteretic."""
    i = np.arange(n)
    k = 2.0e6 * (1.0 + (3 * i % 7) / 10.0)
    K = np.zeros((n, n)) if n <= 1500 else None
    ent = {}

    def add(a, b, v):
        key = (max(a, b), min(a, b))
        ent[key] = ent.get(key, 0.0) + v

    for a in range(n):
        add(a, a, k[a] + (k[a + 1] if a + 1 < n else 0.0))
        if a + 1 < n:
            add(a + 1, a, -k[a + 1])
        if a + 5 < n:
            add(a + 5, a, -2.0e5 * (1 + a % 3))
            add(a, a, 2.0e5 * (1 + a % 3))
            add(a + 5, a + 5, 2.0e5 * (1 + a % 3))
    if K is not None:
        for (a, b), v in ent.items():
            K[a, b] += v
            if a != b:
                K[b, a] += v
    mass = 1.0e3 * (1.0 + 2.0 * ((7 * i) % 11) / 10.0)
    q = n // 10
    links = [(q, 2 * q), (2 * q, 3 * q), (q, 3 * q), (5 * q, 5 * q + 7), (6 * q, 8 * q), (9 * q, 0)]
    springs = [(4 * q, 4 * q + 3), (7 * q, 7 * q + 1), (8 * q + 2, 8 * q + 9), (n, n - 11)]
    return K, ent, mass, links, springs


def mtx(n: int, ent: dict) -> str:
    lines = ["%%MatrixMarket matrix coordinate real symmetric", f"{n} {n} {len(ent)}"]
    lines += [f"{a + 1} {b + 1} {float(v)!r}" for (a, b), v in sorted(ent.items(), key=lambda e: (e[0][1], e[0][0]))]
    return "\n".join(lines) + "\n"


def deck(n, ent, mass, links, springs, n_modes=5):
    devs = links + springs
    return {
        "matrices": {"k_file": "K.mtx", "m_file": "M.mtx", "influence": [1.0] * n},
        "friction": {"n_devices": len(devs), "node_i": [d[0] for d in devs], "node_j": [d[1] for d in devs],
                     "law": ["velocity"] * len(links) + ["hysteretic"] * len(springs),
                     "p": [PMU] * len(devs), "mu": [1.0] * len(devs),
                     "eps": [1.0e-3] * len(devs), "f": [F] * len(devs)},
        "damping": {"damping_type": "rayleigh", "rayleigh_a0": 0.3, "rayleigh_a1": 1.0e-3},
        "excitation": HARMONIC,
        "integration": {"n1": 10},
        "output": {"n_modes": n_modes, "write_history": False},
    }, {"K.mtx": mtx(n, ent), "M.mtx": mtx(n, {(a, a): m for a, m in enumerate(mass)})}


def direction(n, d):
    b = np.zeros(n)
    b[d[0] - 1] = 1.0
    if d[1] > 0:
        b[d[1] - 1] = -1.0
    return b


def constrained_eigenvalues(K, mass, B):
    """w^2 of K u = w^2 M u on B' u = 0, ascending (dense: the null space by SVD)."""
    if B.shape[1]:
        _, sv, vt = np.linalg.svd(B.T)
        r = int((sv > 1e-12 * sv.max()).sum())
        Z = vt[r:].T
    else:
        Z = np.eye(K.shape[0])
    L = np.linalg.cholesky(Z.T @ (mass[:, None] * Z))
    Li = np.linalg.inv(L)
    return np.linalg.eigvalsh(Li @ (Z.T @ K @ Z) @ Li.T), Z.shape[1]


# the checked build (tools/test_checked.sh): the executable under the address sanitizer, which
# reserves terabytes of address space when it starts (no RLIMIT_AS can hold it) and keeps freed
# memory in quarantine (its resident memory is not the product's)
CHECKED = bool(os.environ.get("FRICTIONDYN_CHECKED"))


def run_deck(tmp_path, groups, files, name="m", limit_bytes=None, rss=None):
    """The executable on the deck; its summary. rss: a list that gets the run's peak resident
    memory [bytes], its VmHWM polled from /proc while it runs (its own address space's high
    water mark: wait4's ru_maxrss would count the forking Python's pages too). limit_bytes:
    the address space the run may have; under the sanitizer, the largest single allocation
    instead (the dense n x n matrix the limit is there to refuse is one allocation)."""
    for fname, text in files.items():
        (tmp_path / fname).write_text(text)
    (tmp_path / f"{name}.nml").write_text(deck_text(groups))

    def limit():
        resource.setrlimit(resource.RLIMIT_AS, (limit_bytes, limit_bytes))

    env = dict(os.environ)
    preexec = limit if limit_bytes else None
    if CHECKED and limit_bytes:
        env["ASAN_OPTIONS"] = env.get("ASAN_OPTIONS", "") + f":max_allocation_size_mb={limit_bytes // 2**22}"
        preexec = None
    proc = subprocess.Popen([frictiondyn.executable(), f"{name}.nml"], cwd=tmp_path, stdout=subprocess.DEVNULL,
                            stderr=subprocess.PIPE, text=True, preexec_fn=preexec, env=env)
    hwm = 0
    while proc.poll() is None:
        try:
            status = open(f"/proc/{proc.pid}/status").read()
            hwm = max(hwm, int(status.split("VmHWM:")[1].split()[0]) * 1024)
        except (OSError, IndexError):
            pass
        time.sleep(0.005)
    stderr = proc.stderr.read()
    proc.stderr.close()
    assert proc.returncode == 0, stderr
    if rss is not None:
        rss.append(hwm)
    return frictiondyn.read_summary(tmp_path / "out" / f"{name}.summary.json")


def test_modes_of_a_general_structure_above_the_dense_size(tmp_path):
    """240 DOFs (> 200: the banded path): the free system's five lowest periods, the stuck
    system's (velocity-law devices as links, hysteretic ones as their sticking springs
    P mu / f), the stuck first period (every device a link) and the highest frequency of
    K plus the sticking springs equal numpy's dense eigenproblems: 1e-10 for the periods,
    1e-8 for the Lanczos estimate of omega_max, which never exceeds the exact value."""
    n = 240
    K, ent, mass, links, springs = chain_model(n)
    s = run_deck(tmp_path, *deck(n, ent, mass, links, springs))
    BL = np.array([direction(n, d) for d in links]).T
    BS = np.array([direction(n, d) for d in springs]).T
    w2_free, _ = constrained_eigenvalues(K, mass, np.zeros((n, 0)))
    ks = K + (PMU / F) * BS @ BS.T
    w2_stuck, nq = constrained_eigenvalues(ks, mass, BL)
    w2_first, _ = constrained_eigenvalues(K, mass, np.hstack([BL, BS]))
    assert nq == n - 5
    assert s["periods_free_s"] == pytest.approx(2 * np.pi / np.sqrt(w2_free[:5]), rel=1e-10)
    assert s["periods_stuck_s"] == pytest.approx(2 * np.pi / np.sqrt(w2_stuck[:5]), rel=1e-10)
    assert s["period_stuck_s"] == pytest.approx(2 * np.pi / np.sqrt(w2_first[0]), rel=1e-10)
    top = np.sqrt(np.linalg.eigvalsh(ks / np.sqrt(np.outer(mass, mass)))[-1])
    assert s["omega_max_rad_s"] == pytest.approx(top, rel=1e-8)
    assert s["omega_max_rad_s"] <= top * (1 + 1e-12)


def test_a_general_structure_of_4000_dofs_needs_no_dense_matrix(tmp_path):
    """4000 DOFs with eleven devices and the summary's five modes of each system, run under a
    limit of 400 MB of address space: one dense 4000 x 4000 matrix is 128 MB, and the set-up
    needs no such matrix (periods, stuck first period, highest frequency): the run completes,
    its periods plausible (ascending, the stuck system's first below the free one's)."""
    n = 4000
    _, ent, mass, links, springs = chain_model(n)
    s = run_deck(tmp_path, *deck(n, ent, mass, links, springs), limit_bytes=400 * 2**20)
    free, stuck = np.array(s["periods_free_s"]), np.array(s["periods_stuck_s"])
    assert len(free) == len(stuck) == 5
    assert np.all(np.diff(free) < 0) and np.all(np.diff(stuck) < 0)
    assert stuck[0] < free[0] and s["period_stuck_s"] <= stuck[0] * (1 + 1e-12)
    assert s["omega_max_rad_s"] > 0


@pytest.mark.skipif(CHECKED, reason="the sanitizer's quarantine and shadow memory are not the product's")
def test_peak_memory_does_not_depend_on_the_duration(tmp_path):
    """1500 DOFs, no history file (write_history = .false.): 0.1 s and 1.0 s of motion (100
    and 1000 steps dt1, 10 and 100 rows every dt_record of 4500 columns, 36 kB each) have
    the same peak resident memory within 1 MB: the executable holds no history in memory."""
    n = 1500
    _, ent, mass, links, springs = chain_model(n)
    rss = []
    for duration in (0.1, 1.0):
        groups, files = deck(n, ent, mass, links, springs, n_modes=0)
        groups["excitation"] = dict(HARMONIC, duration=duration)
        s = run_deck(tmp_path, groups, files, name=f"d{duration:g}".replace(".", "_"), rss=rss)
        assert abs(s["steps_dt1"] - duration / 1e-3) <= 0.01 * duration / 1e-3
    assert rss[0] > 0 and abs(rss[1] - rss[0]) < 2**20, rss
