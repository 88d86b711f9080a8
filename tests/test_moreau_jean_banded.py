"""Moreau-Jean's one-step problem for devices of any direction in banded form (docs/theory.md,
12.6): W = M + h theta C + (h theta)^2 K factored in band storage after reverse Cuthill-McKee,
the Delassus operator B' W^-1 B from one solve a device, a step two solves; no n x n matrix.

- The banded and the dense form (&integration's linear_system) give the same run to 1e-10:
  the eccentric building of rigid floors with Coulomb braces, and a block on a planar bearing
  under a circular table motion.
- A &matrices structure of 3000 DOFs with 100 Coulomb devices runs under Moreau-Jean within an
  address-space limit that the dense form's two n x n matrices exceed (the dense form under
  the same limit is refused for want of memory), its peak resident memory far below n^2 8 bytes.
"""
from __future__ import annotations

import os
import resource
import subprocess
import time

import numpy as np
import pytest

import frictiondyn
from conftest import deck_text, ok
from test_general_techniques import eccentric
from test_matrices_scale import CHECKED, chain_model, mtx
from test_bearings import AMP, A0, G, K, M, MU, W, matrices


def columns_agree(a, b, cols, tol=1.0e-10):
    """Every column of a equals b's to tol of its peak; and the two runs are not the same
    bits (they did take different arithmetic)."""
    differ = False
    for col in cols:
        x, y = np.asarray(a[col]), np.asarray(b[col])
        scale = max(np.max(np.abs(y)), 1e-300)
        assert np.max(np.abs(x - y)) <= tol * scale, (col, np.max(np.abs(x - y)) / scale)
        differ = differ or bool(np.any(x != y))
    return differ


def test_eccentric_building_banded_equals_dense(run):
    """The eccentric two-storey building of rigid floors (6 DOFs, four Coulomb braces of three
    terms each at plan positions, the table at 30 degrees): displacements, velocities,
    absolute accelerations, brace slips and forces of the banded form equal the dense form's
    to 1e-10 of their peaks over 150 steps of sticking and slipping; the energy balance closes
    in both."""
    dense = ok(run(eccentric("moreau_jean", n1=20, theta=0.5, linear_system="dense"), name="dense"))
    banded = ok(run(eccentric("moreau_jean", n1=20, theta=0.5, linear_system="banded"), name="banded"))
    h = banded.history()
    cols = [c for c in h.names if c[:1] in ("u", "v", "s", "F") or c.startswith("aabs")]
    assert len(cols) >= 20
    assert columns_agree(h, dense.history(), cols)
    s, sd = banded.summary(), dense.summary()
    assert sum(s["stick_to_slip"]) > 4 and s["stick_to_slip"] == sd["stick_to_slip"]
    assert abs(s["energy_residual_ratio"]) < 1e-12 and abs(sd["energy_residual_ratio"]) < 1e-12
    # the summary names the form each ran: W of 6 DOFs dense (half-bandwidth n - 1) or banded
    assert (sd["linear_system"], sd["half_bandwidth"]) == ("dense", 5)
    assert s["linear_system"] == "banded" and 0 < s["half_bandwidth"] <= 5


def circular_run(tmp_path, linear_system: str, dt_record: float = 0.004, n1: int = 2):
    """test_bearings_moreau_jean's block on a flat Coulomb slider under the circular table
    motion of two components, 12 s, in the form linear_system."""
    t = np.arange(0.0, 12.0 + dt_record / 2, dt_record)
    (tmp_path / "ax.txt").write_text("".join(f"{v:.17e}\n" for v in -AMP * W**2 * np.cos(W * t)))
    (tmp_path / "ay.txt").write_text("".join(f"{v:.17e}\n" for v in -AMP * W**2 * np.sin(W * t)))
    rec = {"excitation_type": "record", "record_format": "values", "record_units": "m/s2",
           "dt_record": dt_record}
    groups = {
        "matrices": matrices(tmp_path, K, M, True),
        "damping": {"damping_type": "rayleigh", "rayleigh_a0": A0, "rayleigh_a1": 0.0},
        "bearings": {"n_bearings": 1, "dof_xi": 1, "dof_yi": 2, "dof_xj": 0, "dof_yj": 0,
                     "p": M * G, "mu": MU, "law": "coulomb"},
        "excitation": {**rec, "record_file": "ax.txt"},
        "excitation2": {**rec, "record_file": "ay.txt"},
        "integration": {"technique": "moreau_jean", "n1": n1, "linear_system": linear_system},
        "output": {"dir": "out"},
    }
    return frictiondyn.run_text(deck_text(groups), "orbit.nml", tmp_path)


def test_block_on_a_bearing_banded_equals_dense(tmp_path):
    """A block on a flat planar Coulomb bearing under the circular table motion of two
    components (the friction disc's block Gauss-Seidel on the Delassus operator): the banded
    form's orbit, velocities and bearing forces equal the dense form's to 1e-10."""
    (tmp_path / "d").mkdir()
    (tmp_path / "b").mkdir()
    dense = circular_run(tmp_path / "d", "dense")
    banded = circular_run(tmp_path / "b", "banded")
    assert columns_agree(banded, dense, ["u1", "u2", "v1", "v2", "F1", "F2", "aabs1", "aabs2"])
    f = np.hypot(banded["F1"], banded["F2"])
    assert np.max(f) == pytest.approx(MU * M * G, rel=1e-12)   # it slides on the rim


N, ND = 3000, 100


def big_deck(linear_system: str):
    """chain_model's structure (K_x with a frame's band) of 3000 DOFs and 100 Coulomb devices,
    each between DOF i and the DOF three below it (or the table), 20 steps of Moreau-Jean."""
    _, ent, mass, _, _ = chain_model(N)
    node_i = [30 * d + 5 for d in range(ND)]
    node_j = [i - 3 if d else 0 for d, i in enumerate(node_i)]
    groups = {
        "matrices": {"k_file": "K.mtx", "m_file": "M.mtx", "influence": [1.0] * N},
        "friction": {"n_devices": ND, "node_i": node_i, "node_j": node_j, "law": ["coulomb"] * ND,
                     "p": [2.0e4] * ND, "mu": [1.0] * ND},
        "damping": {"damping_type": "rayleigh", "rayleigh_a0": 0.3, "rayleigh_a1": 1.0e-3},
        "excitation": {"excitation_type": "harmonic", "amplitude": 0.02, "frequency": 2.0, "dt_record": 0.01,
                       "duration": 0.02},
        "integration": {"technique": "moreau_jean", "n1": 10, "linear_system": linear_system},
        "output": {"n_modes": 0, "write_history": False},
    }
    files = {"K.mtx": mtx(N, ent), "M.mtx": mtx(N, {(a, a): m for a, m in enumerate(mass)})}
    return groups, files


def run_limited(tmp_path, name, groups, files, limit_bytes):
    """The executable under an address-space limit (under the sanitizer, its largest single
    allocation instead: test_matrices_scale's run_deck); its return code, stderr and peak
    resident memory (VmHWM)."""
    for fname, text in files.items():
        (tmp_path / fname).write_text(text)
    (tmp_path / f"{name}.nml").write_text(deck_text(groups))

    def limit():
        resource.setrlimit(resource.RLIMIT_AS, (limit_bytes, limit_bytes))

    env = dict(os.environ, OPENBLAS_NUM_THREADS="1")
    preexec = limit
    if CHECKED:
        env["ASAN_OPTIONS"] = env.get("ASAN_OPTIONS", "") + f":max_allocation_size_mb={limit_bytes // 2**22}" \
                                                            ":allocator_may_return_null=1"
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
    return proc.returncode, stderr, hwm


LIMIT = 100 * 2**20      # the dense form's K and factor alone: 2 x 72 MB


def test_3000_dofs_and_100_devices_need_no_dense_matrix(tmp_path):
    """3000 DOFs, 100 devices under Moreau-Jean ('auto': the banded form) within 100 MB of
    address space, which the dense form's K and its factor (2 n^2 8 bytes = 144 MB) exceed: the run completes, every step taken, the devices slide; its
    peak resident memory is below a third of one n x n matrix (72 MB). The dense form under
    the same limit ends with an error naming the memory it could not have."""
    groups, files = big_deck("auto")
    code, err, hwm = run_limited(tmp_path, "auto", groups, files, LIMIT)
    assert code == 0, err
    s = frictiondyn.read_summary(tmp_path / "out" / "auto.summary.json")
    assert s["steps_dt1"] == 20 and sum(s["stick_to_slip"]) > 0
    if not CHECKED:   # the sanitizer's quarantine and shadow memory are not the product's
        assert 0 < hwm < N * N * 8 / 3, hwm
    groups, files = big_deck("dense")
    code, err, _ = run_limited(tmp_path, "dense", groups, files, LIMIT)
    assert code != 0
    assert "not enough memory for the dense Moreau-Jean system of 3000 DOFs and 100 devices" in err
