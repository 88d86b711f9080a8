"""Shared helpers: write decks, run the installed executable, read what it wrote."""

from __future__ import annotations

import contextlib
import os
import subprocess
import sys
from dataclasses import dataclass
from pathlib import Path

import frictiondyn
import numpy as np
import pytest

# The paper's two-mass model (Dimova, "Experimental Facility"): the package's one copy
from frictiondyn.paper import K1, K2, M1, M2, MU, TABLE1, P

ROOT = Path(__file__).resolve().parent.parent
INPUTS = ROOT / "inputs"
# the validation studies and their closed forms are tools, not installed (tools/validation)
sys.path.append(str(ROOT / "tools" / "validation"))

G = 9.81  # m/s2, the weight of block()
# The paper's Fig. 3 deck (inputs/fig3_coarse.nml, check off): its steps that violate eq. 12
# and its slide reversals (sign changes of s' within a step, Fig. 3b). Regression values of a
# deliberately incorrect run, kept in one place: tests/reference holds them too, and
# tools/update_reference.py is where an intended change of them starts.
FIG3_VIOLATIONS, FIG3_REVERSALS = 413, 312

EPS, F_STICK = 1e-3, 1e-5  # band eps = eps1 [m/s] and sticking displacement f [m] of block()


def technique_for(law: str) -> dict:
    """The &integration setting a deck of devices of this law needs: 'coulomb' (exact
    friction) is integrated by the event-driven technique, the other laws by Newmark."""
    return {"technique": "event_driven"} if law == "coulomb" else {}


def block(law, mu=0.3, m=2.0, excitation=None, v0=0.0, **integration):
    """A rigid block on a friction interface to the table (no spring), any law."""
    return {
        "model": {"n_dof": 1, "mass": [m], "v0": [v0]},
        "springs": {"n_springs": 0},
        "damping": {"damping_type": "none"},
        "friction": {
            "n_devices": 1,
            "node_i": 1,
            "node_j": 0,
            "law": law,
            "p": m * G,
            "mu": mu,
            "eps": EPS,
            "eps1": EPS,
            "f": F_STICK,
        },
        "excitation": excitation,
        "integration": {**technique_for(law), "n1": 10, "n2": 50, **integration},
        "output": {"output_every": 1},
    }



def _value(v) -> str:
    if isinstance(v, bool):
        return ".true." if v else ".false."
    if isinstance(v, str):
        return "'" + v + "'"
    if isinstance(v, (list, tuple, np.ndarray)):
        return ", ".join(_value(x) for x in v)
    if isinstance(v, float):
        return repr(v)
    return str(v)


def deck_text(groups: dict[str, dict]) -> str:
    """A namelist deck from {group: {variable: value}}."""
    out = []
    for name, variables in groups.items():
        out.append(f"&{name}")
        out.extend(f"  {k} = {_value(v)}" for k, v in variables.items())
        out.append("/")
    return "\n".join(out) + "\n"


def paper_groups(test: int = 4, law: str = "velocity", **friction) -> dict[str, dict]:
    """Deck groups of the paper's two-mass experiment for one Table 1 test."""
    freq, amp, dtr = TABLE1[test]
    fr = {"n_devices": 1, "node_i": 1, "node_j": 2, "law": law, "p": P, "mu": MU}
    fr.update(friction)
    return {
        "model": {"n_dof": 2, "mass": [M1, M2]},
        "springs": {"n_springs": 2, "node_i": [1, 2], "node_j": [0, 0], "k": [K1, K2]},
        "damping": {"damping_type": "stiffness", "xi": 0.015},
        "friction": fr,
        "excitation": {
            "excitation_type": "harmonic",
            "amplitude": amp,
            "frequency": freq,
            "dt_record": dtr,
            "duration": 40.0,
        },
        "integration": {**technique_for(law), "n1": 20, "n2": 50, "n": 10},
    }


@dataclass
class Run:
    returncode: int
    stdout: str
    stderr: str
    workdir: Path
    name: str

    @property
    def outdir(self) -> Path:
        return self.workdir / "out"

    def history(self) -> frictiondyn.Result:
        return frictiondyn.read_history(self.outdir / f"{self.name}.csv")

    def summary(self) -> dict:
        return frictiondyn.read_summary(self.outdir / f"{self.name}.summary.json")


def run_deck_file(deck: Path, workdir: Path) -> Run:
    proc = subprocess.run(
        [frictiondyn.executable(), str(deck)], cwd=workdir, capture_output=True, text=True
    )
    return Run(proc.returncode, proc.stdout, proc.stderr, workdir, deck.stem)


@pytest.fixture
def run(tmp_path):
    """run(groups or text, name='case', files={}) -> Run, in a fresh directory."""
    counter = [0]

    def _run(deck, name: str | None = None, files: dict[str, str] | None = None) -> Run:
        counter[0] += 1
        work = tmp_path / f"run{counter[0]}"
        work.mkdir()
        for fname, text in (files or {}).items():
            (work / fname).write_text(text)
        text = deck if isinstance(deck, str) else deck_text(deck)
        path = work / f"{name or 'case'}.nml"
        path.write_text(text)
        return run_deck_file(path, work)

    return _run


def ok(r: Run) -> Run:
    assert r.returncode == 0, r.stderr
    return r


def steady_amplitude(t: np.ndarray, x: np.ndarray, freq: float, cycles: int) -> float:
    """Amplitude of the component at freq over the last whole cycles (least squares)."""
    w = 2 * np.pi * freq
    m = t >= t[-1] - cycles / freq - 1e-12
    a = np.column_stack([np.sin(w * t[m]), np.cos(w * t[m])])
    coef, *_ = np.linalg.lstsq(a, x[m], rcond=None)
    return float(np.hypot(*coef))


@contextlib.contextmanager
def tmpfs(mnt: Path, options: str):
    """A tmpfs mounted at mnt (created) with the mount options given, unmounted afterwards;
    the test is skipped where it cannot be mounted (mounting needs root: CI runs as root)."""
    if os.geteuid() != 0:
        pytest.skip("mounting a tmpfs needs root (CI runs as root)")
    mnt.mkdir()
    r = subprocess.run(["mount", "-t", "tmpfs", "-o", options, "tmpfs", str(mnt)],
                       capture_output=True, text=True)
    if r.returncode != 0:
        pytest.skip(f"cannot mount a tmpfs here: {r.stderr.strip()}")
    try:
        yield mnt
    finally:
        subprocess.run(["umount", "-l", str(mnt)], check=False)


@pytest.fixture
def small_fs(tmp_path):
    """A 160 KiB tmpfs, to fill."""
    with tmpfs(tmp_path / "fs", "size=160k") as mnt:
        yield mnt


def chain(n: int, duration: float, *, name: str = "run", out: str = "out", n1: int = 2,
          every: int = 1) -> dict:
    """Deck groups of n masses (100 kg) in a chain of springs (4e4 N/m) under a harmonic
    table motion (10 mm, 2 Hz), damped, every `every` dt1 steps in the history `out`/`name`."""
    return {
        "model": {"n_dof": n, "mass": [100.0] * n},
        "springs": {"n_springs": n, "node_i": list(range(1, n + 1)), "node_j": list(range(n)),
                    "k": [4.0e4] * n},
        "damping": {"damping_type": "rayleigh", "rayleigh_a0": 0.2},
        "excitation": {"excitation_type": "harmonic", "amplitude": 0.01, "frequency": 2.0,
                       "dt_record": 0.01, "duration": duration},
        "integration": {"n1": n1},
        "output": {"name": name, "output_every": every, "dir": out},
    }


def opensees_models():
    """bench/opensees_models.py as a module, for the cross-checks against OpenSeesPy; the
    calling test module is skipped when openseespy cannot be imported (not installed, or
    installed without its shared library)."""
    import importlib.util

    try:
        import openseespy.opensees  # noqa: F401
    except Exception as exc:  # noqa: BLE001 - any failure to load the library
        pytest.skip(f"openseespy is not importable: {exc}", allow_module_level=True)
    if "opensees_models" not in sys.modules:
        spec = importlib.util.spec_from_file_location("opensees_models",
                                                      ROOT / "bench" / "opensees_models.py")
        module = importlib.util.module_from_spec(spec)
        sys.modules["opensees_models"] = module
        spec.loader.exec_module(module)
    return sys.modules["opensees_models"]
