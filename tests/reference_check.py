"""The comparison of a run with the reference outputs in tests/reference, with the Python
standard library only: tests/test_reference.py judges the executable and the extension by
these rules, and `meson test --suite reference` (tests/meson.build) runs the executable of a
Fortran-only build on every bundled deck and judges it by the same rules.

    python3 tests/reference_check.py <executable> <deck.nml>   # exit 0: matches tests/reference
    python3 tests/reference_check.py --list <inputs dir>       # the decks, one name a line

The tolerances, and why they are what they are, are in tests/test_reference.py's docstring.
"""

from __future__ import annotations

import csv
import json
import math
import subprocess
import sys
import tempfile
from pathlib import Path

REFERENCE = Path(__file__).resolve().parent / "reference"

RTOL = 1e-9  # floats of the summary (peaks, times, periods)
ENERGY_ATOL = 1e-9  # energies, times energy_input_J
HISTORY_RTOL = 1e-8  # history values, times the column's largest reference magnitude
EXACT_COLUMNS = {"phase"}  # history columns compared exactly (by prefix)
ROUNDOFF_COUNTS: dict = {}  # counts compared with a tolerance: none at present
# fractions of 1 with components that may be 0 (mode shapes scaled to a largest component
# of 1, effective modal masses over the total): compared to RTOL absolutely
ABSOLUTE_KEYS = (
    "mode_shapes_",
    "modal_mass_ratio_",
    "energy_residual_ratio",
    "harmonic_step_error",
    "record_step_error",
)


def _is_int(x) -> bool:
    return isinstance(x, int) and not isinstance(x, bool)


def _shape(x):
    """The nesting and lengths of a JSON value (lists of lists: mode shapes, storey nodes)."""
    return [_shape(y) for y in x] if isinstance(x, list) else None


def _leaves(key: str, have, want):
    """(where, have, want) for every number or text of a (nested) list, or the value."""
    if not isinstance(want, list):
        yield key, have, want
        return
    for i, (h, w) in enumerate(zip(have, want, strict=True)):
        yield from _leaves(f"{key}[{i}]", h, w)


def _flatten(summary: dict) -> dict:
    """Nested objects (the record block) as dotted keys, compared by the same rules."""
    flat = {}
    for key, value in summary.items():
        if isinstance(value, dict):
            flat.update({f"{key}.{k}": v for k, v in value.items()})
        else:
            flat[key] = value
    return flat


def compare_summary(got: dict, ref: dict) -> list[str]:
    """Mismatches of a run's summary against a reference summary (empty list: equal)."""
    bad = []
    scale = abs(ref.get("energy_input_J", 0.0))
    got, ref = _flatten(got), _flatten(ref)
    for key, want in ref.items():
        if key not in got:
            bad.append(f"{key}: missing from the run")
            continue
        have = got[key]
        if key in ("deck", "record.file"):
            if Path(have).name != Path(want).name:
                bad.append(f"{key}: {have!r} != {want!r}")
            continue
        if _shape(want) != _shape(have):
            bad.append(f"{key}: {have!r} != reference {want!r} (shape)")
            continue
        for where, h, w in _leaves(key, have, want):
            if w is None or isinstance(w, (str, bool)):
                ok = h == w
            elif _is_int(w):
                rule = ROUNDOFF_COUNTS.get(key)
                if rule and rule[0](ref):
                    ok = _is_int(h) and abs(h - w) <= rule[1] * abs(w)
                else:
                    ok = _is_int(h) and h == w
            elif h is None or isinstance(h, (str, bool)):
                ok = False
            elif key.startswith(ABSOLUTE_KEYS):  # before energy_: the ratio is dimensionless
                ok = math.isfinite(h) and abs(h - w) <= RTOL
            elif key.startswith("energy_"):
                ok = abs(h - w) <= ENERGY_ATOL * scale
            else:
                ok = math.isfinite(h) and abs(h - w) <= RTOL * abs(w)
            if not ok:
                bad.append(f"{where}: {h!r} != reference {w!r}")
    return bad


def reference_history(name: str) -> tuple[list[str], list[int], list[list[float]]]:
    """Column names, row indices and rows of values of a reference history."""
    with (REFERENCE / f"{name}.history.csv").open(newline="") as fh:
        lines = list(csv.reader(fh))
    rows = [int(float(r[0])) for r in lines[1:]]
    return lines[0][1:], rows, [[float(x) for x in r[1:]] for r in lines[1:]]


def compare_history(names: list[str], data, ref_name: str) -> list[str]:
    """Mismatches of a full history (columns `names`; data[i][j] the value of row i, column
    j: a list of rows or a 2-D array) against the reference rows."""
    ref_names, rows, ref = reference_history(ref_name)
    if rows[-1] >= len(data):
        return [f"history has {len(data)} rows, the reference goes to row {rows[-1]}"]
    bad = []
    for j, col in enumerate(ref_names):
        if col not in names:
            bad.append(f"column {col}: missing from the run")
            continue
        c = names.index(col)
        have = [float(data[r][c]) for r in rows]
        want = [row[j] for row in ref]
        if any(col.startswith(p) for p in EXACT_COLUMNS):
            wrong = [k for k in range(len(rows)) if have[k] != want[k]]
        else:
            tol = HISTORY_RTOL * max(abs(w) for w in want)
            wrong = [k for k in range(len(rows)) if not abs(have[k] - want[k]) <= tol]
        if wrong:
            k = max(wrong, key=lambda i: abs(have[i] - want[i]) if math.isfinite(have[i]) else math.inf)
            bad.append(
                f"column {col}: {len(wrong)} of {len(rows)} rows differ, worst row {rows[k]}: "
                f"{have[k]!r} != reference {want[k]!r}"
            )
    return bad


def read_csv(path: Path) -> tuple[list[str], list[list[float]]]:
    """The executable's history CSV: names without units, rows of values."""
    with path.open(newline="") as fh:
        lines = list(csv.reader(fh))
    names = [h.split("[")[0] for h in lines[0]]
    return names, [[float(x) for x in r] for r in lines[1:] if r]


def check_executable(exe: str, deck: Path) -> list[str]:
    """Run the executable on a deck in a temporary directory; mismatches with the reference."""
    name = deck.stem
    with tempfile.TemporaryDirectory(prefix="fd_reference_") as tmp:
        proc = subprocess.run([str(Path(exe).resolve()), str(deck.resolve())], cwd=tmp, capture_output=True, text=True,
                              check=False)
        if proc.returncode != 0:
            return [f"exit status {proc.returncode}: {proc.stderr.strip()[-1000:]}"]
        out = Path(tmp) / "out"
        summary = json.loads((out / f"{name}.summary.json").read_text())
        ref = json.loads((REFERENCE / f"{name}.summary.json").read_text())
        bad = compare_summary(summary, ref)
        names, data = read_csv(out / f"{name}.csv")
    if len(data) != summary.get("samples"):
        bad.append(f"history has {len(data)} rows, the summary says {summary.get('samples')}")
    return bad + compare_history(names, data, name)


def main(argv: list[str]) -> int:
    if len(argv) == 2 and argv[0] == "--list":
        print("\n".join(sorted(p.stem for p in Path(argv[1]).glob("*.nml"))))
        return 0
    if len(argv) != 2:
        print(__doc__, file=sys.stderr)
        return 2
    deck = Path(argv[1])
    if not (REFERENCE / f"{deck.stem}.summary.json").is_file():
        print(f"no reference for {deck}: run tools/update_reference.py {deck.stem}", file=sys.stderr)
        return 1
    bad = check_executable(argv[0], deck)
    if bad:
        print(f"{deck.stem} differs from tests/reference:\n  " + "\n  ".join(bad), file=sys.stderr)
        return 1
    print(f"{deck.stem}: matches tests/reference")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
