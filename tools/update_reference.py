"""Regenerate the reference outputs of the bundled decks (tests/reference/).

    .venv/bin/python tools/update_reference.py            # every deck in inputs/
    .venv/bin/python tools/update_reference.py test4_velocity fig3_coarse

For each deck ``inputs/<name>.nml`` this runs the installed executable and writes

- ``tests/reference/<name>.summary.json``: the summary, every key except ``run_time_s``,
  ``frictiondyn_version`` (a new release is not a change of the numbers) and ``warnings``
  (texts made from keys the reference holds), with the deck's path written relative to
  the repository;
- ``tests/reference/<name>.history.csv``: the history downsampled to about ``MAX_ROWS``
  rows (every k-th row and the last), with a first column ``row`` giving each row's
  index in the full history, values with 17 significant digits (they read back exactly).

It refuses to write when the extension (``frictiondyn.run``) does not give the executable's
result bit for bit: the references are the contract of both.

Use it ONLY when a change of behaviour is intended (a corrected equation, a new default, a
changed deck), never to make a failing test pass: tests/test_reference.py fails on a
relative change of 1e-6 of any peak, and a failure there means the numbers changed. Run
it, read ``git diff --stat tests/reference`` and the changed values, and commit the new
references together with the change that caused them, saying in the commit message what
changed and why. A deck added to inputs/ needs its references before the suite passes.
"""

from __future__ import annotations

import json
import math
import subprocess
import sys
import tempfile
from pathlib import Path

import frictiondyn
import numpy as np

ROOT = Path(__file__).resolve().parent.parent
INPUTS = ROOT / "inputs"
REFERENCE = ROOT / "tests" / "reference"
MAX_ROWS = 250  # rows of a downsampled history (plus the last row)


def downsample(n_rows: int, max_rows: int = MAX_ROWS) -> np.ndarray:
    """Indices of every k-th row (k chosen so that at most max_rows + 1 are kept) and the last."""
    stride = max(1, math.ceil((n_rows - 1) / max_rows))
    rows = np.arange(0, n_rows, stride)
    if rows[-1] != n_rows - 1:
        rows = np.append(rows, n_rows - 1)
    return rows


def read_csv(path: Path) -> tuple[list[str], np.ndarray]:
    """Column names (units dropped) and values of the executable's history CSV."""
    with path.open() as fh:
        header = fh.readline().strip().split(",")
    names = [h.split("[")[0] for h in header]
    return names, np.loadtxt(path, delimiter=",", skiprows=1, ndmin=2)


def run_executable(deck: Path, work: Path) -> tuple[dict, list[str], np.ndarray]:
    proc = subprocess.run(
        [frictiondyn.executable(), str(deck)], cwd=work, capture_output=True, text=True, check=False
    )
    if proc.returncode != 0:
        raise SystemExit(f"{deck.name}: the executable failed:\n{proc.stderr}")
    summary = json.loads((work / "out" / f"{deck.stem}.summary.json").read_text())
    names, data = read_csv(work / "out" / f"{deck.stem}.csv")
    return summary, names, data


def write_reference(name: str, summary: dict, names: list[str], data: np.ndarray) -> None:
    # the warnings are texts made from keys compared at their own tolerances (rounded to 3 or
    # 4 digits, a last-bit change of a build could move one): not a reference of their own
    drop = ("run_time_s", "frictiondyn_version", "warnings")
    summary = {k: v for k, v in summary.items() if k not in drop}
    summary["deck"] = f"inputs/{name}.nml"
    (REFERENCE / f"{name}.summary.json").write_text(json.dumps(summary, indent=1) + "\n")
    rows = downsample(len(data))
    lines = [",".join(["row", *names])]
    for i in rows:
        lines.append(",".join([str(int(i)), *(repr(float(x)) for x in data[i])]))
    (REFERENCE / f"{name}.history.csv").write_text("\n".join(lines) + "\n")


def main(argv: list[str]) -> int:
    names = argv or sorted(p.stem for p in INPUTS.glob("*.nml"))
    REFERENCE.mkdir(parents=True, exist_ok=True)
    for name in names:
        deck = INPUTS / f"{name}.nml"
        if not deck.is_file():
            raise SystemExit(f"no deck {deck}")
        with tempfile.TemporaryDirectory() as tmp:
            summary, cols, data = run_executable(deck, Path(tmp))
        ext = frictiondyn.run(deck)
        same = [n.split("[")[0] for n in ext.names] == cols and np.array_equal(ext.data, data)
        skip = {"run_time_s", "deck"}
        same = same and {k: v for k, v in ext.summary.items() if k not in skip} == {
            k: v for k, v in summary.items() if k not in skip
        }
        if not same:
            raise SystemExit(f"{name}: the extension and the executable differ; nothing written")
        write_reference(name, summary, cols, data)
        print(f"{name}: {len(downsample(len(data)))} of {len(data)} rows, {len(summary) - 1} keys")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
