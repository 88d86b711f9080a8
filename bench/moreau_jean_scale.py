"""Moreau-Jean's one-step problem for devices of any direction: the dense form against the
banded form (&integration's linear_system) on eccentric buildings of rigid floors, 2 to 50
storeys (6 to 150 DOFs), where the crossover that linear_system = 'auto' uses is measured.

    .venv/bin/python bench/moreau_jean_scale.py                       # about 15 min on a shared machine
    .venv/bin/python bench/moreau_jean_scale.py --storeys 5,10,20 --durations 2,4

The building: floors of 3e5 kg, 20 m x 12 m, the centre of mass 0.5 m off the frames'
centre of stiffness; per storey four frames (two along x of unequal stiffness, two along y)
and two Coulomb braces (one along x at y = -6 m, one along y at x = 8 m, slip loads falling
with height); Rayleigh damping; the table moves at 30 degrees from x, harmonic, 0.02 m at
2 Hz; dt_record = 10 ms, n1 = 10 (dt1 = 1 ms), theta = 1/2; no history file. Each case runs
for two durations, each in a process of its own; the time per step is the difference of the
processor times (user + system of the child: the machine may be shared) over the difference
of the steps, so that the set-up cancels. Writes <work>/moreau_jean_scale.json and prints the
command and the table. Nothing here asserts a speed.
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent
EXE = ROOT / ".venv" / "bin" / "frictiondyn"
sys.path.insert(0, str(ROOT / "tests"))
from conftest import deck_text  # noqa: E402


def building(storeys: int, linear_system: str, duration: float) -> dict:
    n = storeys
    st = [s for s in range(1, n + 1) for _ in range(4)]
    k = [[260.0e6, 200.0e6, 300.0e6, 300.0e6][j % 4] * (1.0 - 0.5 * (s - 1) / n) for j, s in enumerate(st)]
    slip = [[300.0e3, 200.0e3][j % 2] * (1.0 - 0.5 * (s - 1) / n) for j, s in enumerate(
        [s for s in range(1, n + 1) for _ in range(2)])]
    return {
        "floors": {"n_floors": n, "mass": [3.0e5] * n, "plan_x": [20.0] * n, "plan_y": [12.0] * n,
                   "cm_x": [0.5] * n, "height": [3.0] * n, "excitation_angle": 30.0},
        "frames": {"n_frames": 4 * n, "storey": st, "angle": [0.0, 0.0, 90.0, 90.0] * n,
                   "x": [0.0, 0.0, -10.0, 10.0] * n, "y": [-6.0, 6.0, 0.0, 0.0] * n, "k": k},
        "floor_braces": {"n_braces": 2 * n, "storey": [s for s in range(1, n + 1) for _ in range(2)],
                         "angle": [0.0, 90.0] * n, "x": [0.0, 8.0] * n, "y": [-6.0, 0.0] * n,
                         "slip_load": slip, "law": ["coulomb"] * (2 * n)},
        "damping": {"damping_type": "rayleigh", "rayleigh_a0": 0.3, "rayleigh_a1": 8.0e-4},
        "excitation": {"excitation_type": "harmonic", "amplitude": 0.02, "frequency": 2.0, "dt_record": 0.01,
                       "duration": duration},
        "integration": {"technique": "moreau_jean", "n1": 10, "theta": 0.5, "linear_system": linear_system},
        "output": {"write_history": False, "n_modes": 0},
    }


def run(work: Path, name: str, groups: dict) -> dict:
    """The executable on the deck in a process of its own: its processor time and summary."""
    work.mkdir(parents=True, exist_ok=True)
    (work / f"{name}.nml").write_text(deck_text(groups))
    with open(work / f"{name}.log", "wb") as log:
        p = subprocess.Popen([str(EXE), f"{name}.nml"], cwd=work, stdout=log, stderr=subprocess.STDOUT,
                             env=dict(os.environ, OPENBLAS_NUM_THREADS="1"))
        _, status, ru = os.wait4(p.pid, 0)
    if os.waitstatus_to_exitcode(status) != 0:
        raise RuntimeError(f"{name}: {(work / f'{name}.log').read_text()[-800:]}")
    summary = json.loads((work / "out" / f"{name}.summary.json").read_text())
    return {"cpu_s": ru.ru_utime + ru.ru_stime, "steps": int(summary["steps_dt1"]),
            "transitions": int(sum(summary["stick_to_slip"]))}


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--storeys", default="2,3,4,5,7,10,20,50")
    ap.add_argument("--durations", default="1,3", help="two durations [s]")
    ap.add_argument("--work", default=str(ROOT / "build" / "moreau_jean_scale"))
    args = ap.parse_args()
    if not EXE.exists():
        sys.exit(f"{EXE} is missing: run tools/setup.sh first")
    d0, d1 = (float(x) for x in args.durations.split(","))
    work = Path(args.work)
    results = []
    print("command: " + " ".join([Path(sys.executable).name, "bench/moreau_jean_scale.py"] + sys.argv[1:]), flush=True)
    print(f"{'storeys':>7s} {'DOFs':>5s} {'devices':>7s} {'dense us/step':>13s} {'banded us/step':>14s} "
          f"{'dense/banded':>12s}", flush=True)
    for storeys in (int(s) for s in args.storeys.split(",")):
        row = {"storeys": storeys, "n": 3 * storeys, "devices": 2 * storeys}
        for form in ("dense", "banded"):
            a = run(work / f"s{storeys}", f"{form}_a", building(storeys, form, d0))
            b = run(work / f"s{storeys}", f"{form}_b", building(storeys, form, d1))
            row[form] = 1e6 * (b["cpu_s"] - a["cpu_s"]) / max(b["steps"] - a["steps"], 1)
            row[f"{form}_transitions"] = b["transitions"]
        results.append(row)
        print(f"{storeys:7d} {row['n']:5d} {row['devices']:7d} {row['dense']:13.1f} {row['banded']:14.1f} "
              f"{row['dense'] / max(row['banded'], 1e-9):12.2f}", flush=True)
    work.mkdir(parents=True, exist_ok=True)
    (work / "moreau_jean_scale.json").write_text(json.dumps(results, indent=1))
    return 0


if __name__ == "__main__":
    sys.exit(main())
