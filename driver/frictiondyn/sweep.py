"""Parameter sweeps: many runs of the executable, locally in parallel or as a Slurm job array.

    python -m frictiondyn sweep SPEC.toml [--jobs N] [--out DIR] [--quiet]
    python -m frictiondyn sweep SPEC.toml --slurm [--max-parallel M] [--submit] [...]
    python -m frictiondyn sweep collect DIR [--resubmit] [--quiet]
    python -m frictiondyn sweep plot DIR X Y [--by PARAM] [--out PNG]

A spec (TOML) names a base deck and the namelist variables that vary (docs/batch.md):

    name = "slip_load"
    base = "building5.nml"            # relative to the spec's directory
    [cross]                           # every combination of these
    "friction.mu" = [0.2, 0.3]
    [zip]                             # these vary together (same length), crossed with [cross]
    slip_ratio = [0.0, 0.05]          # a label (no group): in the table, not in the deck
    "friction.p" = [[0.0, 0.0], [1.0e4, 5.0e3]]

A key is "group.variable", "group.variable(i)" (one element), a label without a group, or
"deck" (the base deck itself varies). Expanding a spec writes, under the sweep directory,
``decks/<id>.nml`` (one deck per run, outputs to ``runs/<id>.csv`` and
``runs/<id>.summary.json``), ``decks.txt`` (the list the executable's ``--list`` reads) and
``manifest.json`` (runs, parameters, deck hashes). A run is complete when its summary
exists; complete runs are skipped, so an interrupted sweep resumes where it stopped. A run
that fails leaves ``runs/<id>.error.txt`` with the executable's message and does not stop
the others. ``results.csv`` collects every run's parameters, status, the frictiondyn version,
the run's deck (``run_deck``) and its SHA-256, and its summary (arrays as ``key[i]``, i from 1).
"""

from __future__ import annotations

import argparse
import csv
import hashlib
import io
import itertools
import json
import os
import re
import shlex
import signal
import subprocess
import sys
import threading
import time
from collections.abc import Sequence
from concurrent.futures import ThreadPoolExecutor, as_completed
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import f90nml

from . import __version__
from ._api import FrictiondynError
from ._exe import executable
from ._nml import copy_namelist, read_namelist, write_namelist

try:
    import tomllib
except ModuleNotFoundError:  # Python 3.10
    import tomli as tomllib  # type: ignore[no-redef]

__all__ = [
    "Run",
    "Sweep",
    "SweepError",
    "collect",
    "expand",
    "load_spec",
    "plot",
    "run_local",
    "slurm_script",
]

_KEY = re.compile(r"^(?:(?P<group>[A-Za-z_]\w*)\.)?(?P<var>[A-Za-z_]\w*)(?:\((?P<idx>\d+)\))?$")


class SweepError(ValueError):
    """A bad spec, or a sweep directory that cannot be used."""


@dataclass
class Run:
    """One run of a sweep."""

    index: int  #: 0-based: the line of decks.txt and the Slurm array task id
    id: str  #: r0000, r0001, ...
    params: dict[str, Any]  #: parameter -> value (the varied ones)
    deck: str  #: deck path relative to the sweep directory
    deck_sha256: str = ""

    @property
    def summary(self) -> str:
        return f"runs/{self.id}.summary.json"

    @property
    def history(self) -> str:
        return f"runs/{self.id}.csv"

    @property
    def error(self) -> str:
        return f"runs/{self.id}.error.txt"


@dataclass
class Sweep:
    """An expanded sweep: its directory, runs and parameters."""

    name: str
    directory: Path
    parameters: list[str]
    runs: list[Run] = field(default_factory=list)
    zipped: list[str] = field(default_factory=list)  #: the parameters of [zip]

    def complete(self, run: Run) -> bool:
        """The run's summary exists and is a complete JSON object."""
        return _read_summary(self.directory / run.summary) is not None

    def pending(self) -> list[Run]:
        return [r for r in self.runs if not self.complete(r)]


# ------------------------------------------------------------------------------------ spec
def load_spec(path: str | os.PathLike) -> dict:
    """Read and check a sweep spec (TOML); the keys are described in the module doc."""
    path = Path(path)
    try:
        spec = tomllib.loads(path.read_text())
    except FileNotFoundError:
        raise SweepError(f"{path}: no such spec file") from None
    except tomllib.TOMLDecodeError as exc:
        raise SweepError(f"{path}: not valid TOML: {exc}") from None
    known = {"name", "base", "cross", "zip", "write_history", "jobs", "directory"}
    unknown = set(spec) - known
    if unknown:
        raise SweepError(f"{path}: unknown key(s) {sorted(unknown)}; known: {sorted(known)}")
    for table in ("cross", "zip"):
        if not isinstance(spec.get(table, {}), dict):
            raise SweepError(f"{path}: [{table}] must be a table of parameter = [values]")
        for key, values in spec.get(table, {}).items():
            if not _KEY.match(key):
                raise SweepError(
                    f"{path}: [{table}] {key!r} is not 'group.variable', 'group.variable(i)', "
                    "a label or 'deck'"
                )
            if not isinstance(values, list) or not values:
                raise SweepError(f"{path}: [{table}] {key} must be a non-empty list of values")
    zipped = spec.get("zip", {})
    lengths = {k: len(v) for k, v in zipped.items()}
    if len(set(lengths.values())) > 1:
        raise SweepError(f"{path}: [zip] lists differ in length: {lengths}")
    both = set(spec.get("cross", {})) & set(zipped)
    if both:
        raise SweepError(f"{path}: {sorted(both)} in both [cross] and [zip]")
    if "base" not in spec and "deck" not in spec.get("cross", {}) and "deck" not in zipped:
        raise SweepError(f"{path}: give a base deck (base = 'deck.nml') or vary 'deck'")
    spec.setdefault("name", path.stem)
    if not re.fullmatch(r"[\w.-]+", spec["name"]):
        raise SweepError(f"{path}: name = {spec['name']!r}: letters, digits, '_', '-', '.' only")
    return spec


def _combinations(spec: dict) -> tuple[list[str], list[dict[str, Any]]]:
    cross = spec.get("cross", {})
    zipped = spec.get("zip", {})
    keys = list(cross) + list(zipped)
    zrows = [dict(zip(zipped, vals)) for vals in zip(*zipped.values())] if zipped else [{}]
    rows = []
    for combo in itertools.product(*cross.values()) if cross else [()]:
        for z in zrows:
            rows.append({**dict(zip(cross, combo)), **z})
    return keys, rows


def _set(nml: f90nml.Namelist, key: str, value: Any, where: str) -> None:
    m = _KEY.match(key)
    assert m is not None
    group, var, idx = m["group"].lower(), m["var"].lower(), m["idx"]
    if group not in nml:
        nml[group] = f90nml.Namelist()
    if idx is None:
        nml[group][var] = value
        nml[group].start_index.pop(var, None)  # the value given is the array from element 1
        return
    i = int(idx)
    if var in nml[group].start_index:
        raise SweepError(
            f"{where}: {key}: the base deck gives {group}.{var} by sections of a 2-D array; "
            f"vary the whole array"
        )
    cur = nml[group].get(var)
    cur = list(cur) if isinstance(cur, list) else ([] if cur is None else [cur])
    if not 1 <= i <= len(cur):
        raise SweepError(
            f"{where}: {key}: the base deck gives {len(cur)} value(s) of {group}.{var}; "
            f"element {i} can only replace one of them"
        )
    cur[i - 1] = value
    nml[group][var] = cur


def _sha256(data: bytes) -> str:
    return hashlib.sha256(data).hexdigest()


def _write_atomic(path: Path, data: str | bytes) -> None:
    tmp = path.with_name(f".{path.name}.{os.getpid()}.{threading.get_ident()}.tmp")
    try:
        if isinstance(data, str):
            tmp.write_text(data)
        else:
            tmp.write_bytes(data)
        os.replace(tmp, path)
    finally:
        tmp.unlink(missing_ok=True)


def _deck_text(nml: f90nml.Namelist, header: str) -> str:
    return header + write_namelist(nml)


def expand(spec_path: str | os.PathLike, directory: str | os.PathLike | None = None) -> Sweep:
    """Write one deck per run, decks.txt and manifest.json under the sweep directory
    (default: spec ``directory``, else ``sweeps/<name>`` in the working directory). A run
    whose deck changed since an earlier expansion loses its old outputs."""
    spec_path = Path(spec_path).resolve()
    spec = load_spec(spec_path)
    where = str(spec_path)
    base_dir = spec_path.parent
    name = spec["name"]
    sdir = Path(directory or spec.get("directory") or Path("sweeps") / name).resolve()
    (sdir / "decks").mkdir(parents=True, exist_ok=True)
    (sdir / "runs").mkdir(exist_ok=True)
    (sdir / "logs").mkdir(exist_ok=True)
    keys, rows = _combinations(spec)
    width = max(4, len(str(len(rows) - 1)))
    sweep = Sweep(name=name, directory=sdir, parameters=keys, zipped=list(spec.get("zip", {})))
    bases: dict[str, f90nml.Namelist] = {}
    for index, params in enumerate(rows):
        base = params.get("deck", spec.get("base"))
        if not isinstance(base, str):
            raise SweepError(f"{where}: deck = {base!r} is not a path")
        base_path = (base_dir / base).resolve()
        if base not in bases:
            try:  # the deck's bytes as the library reads them (a Latin-1 comment is no error)
                text = base_path.read_bytes().decode("utf-8", "surrogateescape")
            except FileNotFoundError:
                raise SweepError(f"{where}: base deck {base_path} does not exist") from None
            except OSError as exc:
                raise SweepError(f"{where}: cannot read the base deck {base_path}: {exc}") from None
            try:
                bases[base] = read_namelist(text, base_path)
            except FrictiondynError as exc:
                raise SweepError(f"{where}: base deck: {exc}") from None
        nml = copy_namelist(bases[base])
        # a relative record file is relative to the deck that names it
        exc_group = nml.get("excitation", {})
        rec = exc_group.get("record_file") if exc_group else None
        if isinstance(rec, str) and not rec.startswith("/"):
            nml["excitation"]["record_file"] = os.path.relpath(
                base_path.parent / rec, sdir / "decks"
            )
        for key, value in params.items():
            if key == "deck" or "." not in key:
                continue  # the base deck, or a label
            if key.lower() == "excitation.record_file" and isinstance(value, str):
                value = value if value.startswith("/") else os.path.relpath(
                    base_dir / value, sdir / "decks"
                )
            _set(nml, key, value, where)
        if "output" not in nml:
            nml["output"] = f90nml.Namelist()
        rid = f"r{index:0{width}d}"
        nml["output"]["dir"] = "runs"
        nml["output"]["name"] = rid
        if "write_history" in spec:
            nml["output"]["write_history"] = bool(spec["write_history"])
        shown = ", ".join(f"{k} = {_short(v)}" for k, v in params.items())
        text = _deck_text(nml, f"! frictiondyn sweep '{name}', run {rid}: {shown}\n")
        deck = sdir / "decks" / f"{rid}.nml"
        data = text.encode("utf-8", "surrogateescape")
        old = deck.read_bytes() if deck.exists() else None
        if old != data:
            for stale in (f"runs/{rid}.summary.json", f"runs/{rid}.csv", f"runs/{rid}.error.txt"):
                (sdir / stale).unlink(missing_ok=True)
            _write_atomic(deck, data)
        run = Run(index, rid, params, f"decks/{rid}.nml", _sha256(data))
        sweep.runs.append(run)
    # decks of a larger earlier expansion are no longer part of the sweep
    wanted = {r.deck for r in sweep.runs}
    for old in (sdir / "decks").glob("r*.nml"):
        if f"decks/{old.name}" not in wanted:
            old.unlink()
            for ext in (".summary.json", ".csv", ".error.txt"):
                (sdir / "runs" / (old.stem + ext)).unlink(missing_ok=True)
    _write_atomic(sdir / "decks.txt", "".join(r.deck + "\n" for r in sweep.runs))
    manifest = {
        "name": name,
        "spec": str(spec_path),
        "frictiondyn_version": __version__,
        "parameters": keys,
        "zip": sweep.zipped,
        "runs": [
            {"index": r.index, "id": r.id, "deck": r.deck, "deck_sha256": r.deck_sha256,
             "params": r.params}
            for r in sweep.runs
        ],
    }
    _write_atomic(sdir / "manifest.json", json.dumps(manifest, indent=1) + "\n")
    return sweep


def _short(v: Any) -> str:
    text = json.dumps(v)
    return text if len(text) <= 60 else text[:57] + "..."


def load(directory: str | os.PathLike) -> Sweep:
    """The sweep expanded in a directory (from its manifest.json)."""
    sdir = Path(directory).resolve()
    try:
        m = json.loads((sdir / "manifest.json").read_text())
    except FileNotFoundError:
        raise SweepError(f"{sdir}: no manifest.json (not a sweep directory)") from None
    runs = [Run(r["index"], r["id"], r["params"], r["deck"], r["deck_sha256"]) for r in m["runs"]]
    return Sweep(name=m["name"], directory=sdir, parameters=m["parameters"], runs=runs,
                 zipped=m.get("zip", []))


# ------------------------------------------------------------------------------- running
class _Interrupted(Exception):
    pass


def run_local(
    sweep: Sweep,
    jobs: int | None = None,
    exe: str | None = None,
    progress: bool = True,
) -> dict[str, int]:
    """Run the pending runs, ``jobs`` processes at a time (default: the CPU count). A
    failure is written to ``runs/<id>.error.txt`` and the others go on. SIGINT or SIGTERM
    stop the sweep: running executables get SIGTERM (they remove their temporary files)
    and what completed stays complete. Returns counts: done, failed, skipped."""
    exe = exe or executable()
    jobs = max(1, jobs or os.cpu_count() or 1)
    pending = sweep.pending()
    counts = {"skipped": len(sweep.runs) - len(pending), "done": 0, "failed": 0}
    procs: set[subprocess.Popen] = set()
    lock = threading.Lock()
    stopping = threading.Event()

    def one(run: Run) -> tuple[Run, int, str]:
        if stopping.is_set():
            return run, -1, "not started"
        p = subprocess.Popen(
            [exe, run.deck], cwd=sweep.directory, stdout=subprocess.DEVNULL,
            stderr=subprocess.PIPE, text=True,
        )
        with lock:
            procs.add(p)
        _, err = p.communicate()
        with lock:
            procs.discard(p)
        return run, p.returncode, err

    bar = None
    if progress:
        from tqdm import tqdm

        bar = tqdm(total=len(sweep.runs), initial=counts["skipped"], unit="run",
                   desc=sweep.name, file=sys.stderr)
    old_term = signal.getsignal(signal.SIGTERM)

    def on_term(signum, frame):
        raise _Interrupted()

    if threading.current_thread() is threading.main_thread():
        signal.signal(signal.SIGTERM, on_term)
    pool = ThreadPoolExecutor(max_workers=jobs)
    try:
        futures = [pool.submit(one, r) for r in pending]
        for fut in as_completed(futures):
            run, code, err = fut.result()
            if code == 0:
                counts["done"] += 1
                (sweep.directory / run.error).unlink(missing_ok=True)
            elif code > 0 or not stopping.is_set():
                counts["failed"] += 1
                _write_atomic(sweep.directory / run.error, err.strip() + "\n" if err.strip()
                              else f"frictiondyn exited with status {code}\n")
            if bar is not None:
                bar.update(1)
    except (KeyboardInterrupt, _Interrupted):
        stopping.set()
        pool.shutdown(wait=False, cancel_futures=True)
        with lock:
            for p in procs:
                p.send_signal(signal.SIGTERM)
        for p in list(procs):
            p.wait()
        raise KeyboardInterrupt from None
    finally:
        pool.shutdown(wait=True, cancel_futures=True)
        if bar is not None:
            bar.close()
        if threading.current_thread() is threading.main_thread():
            signal.signal(signal.SIGTERM, old_term)
    return counts


# ---------------------------------------------------------------------------------- Slurm
def array_ranges(indices: Sequence[int]) -> str:
    """0,1,2,5,7,8 -> '0-2,5,7-8'."""
    out = []
    for _, grp in itertools.groupby(enumerate(sorted(indices)), lambda p: p[1] - p[0]):
        g = [i for _, i in grp]
        out.append(str(g[0]) if len(g) == 1 else f"{g[0]}-{g[-1]}")
    return ",".join(out)


def slurm_script(
    sweep: Sweep,
    indices: Sequence[int] | None = None,
    max_parallel: int = 32,
    exe: str | None = None,
    job_name: str | None = None,
    time_limit: str | None = None,
    partition: str | None = None,
    extra: Sequence[str] = (),
    name: str = "sweep.sbatch",
) -> Path:
    """Write a job-array script: task i runs ``frictiondyn --list decks.txt --index i`` in
    the sweep directory (no Python needed on the compute node). ``indices`` default to the
    pending runs. Returns the script's path."""
    exe = os.path.abspath(exe or executable())
    if indices is None:
        indices = [r.index for r in sweep.pending()]
    if not indices:
        raise SweepError(f"{sweep.directory}: every run is complete; nothing to submit")
    width = len(sweep.runs[0].id) - 1
    lines = [
        "#!/bin/bash",
        f"#SBATCH --job-name={job_name or 'fd-' + sweep.name}",
        f"#SBATCH --array={array_ranges(indices)}%{max(1, int(max_parallel))}",
        "#SBATCH --ntasks=1",
        "#SBATCH --cpus-per-task=1",
        f"#SBATCH --chdir={sweep.directory}",
        f"#SBATCH --output={sweep.directory}/logs/%A_%a.out",
    ]
    if time_limit:
        lines.append(f"#SBATCH --time={time_limit}")
    if partition:
        lines.append(f"#SBATCH --partition={partition}")
    lines += [f"#SBATCH {x}" for x in extra]
    lines += [
        f"# frictiondyn sweep '{sweep.name}': {len(indices)} of {len(sweep.runs)} runs.",
        "# Each task runs the standalone executable on its own deck (decks.txt, 0-based);",
        "# a failure leaves runs/<id>.error.txt with the executable's message.",
        "set -u",
        f"cd {shlex.quote(str(sweep.directory))} || exit 1",
        f'id=$(printf "r%0{width}d" "$SLURM_ARRAY_TASK_ID")',
        f'{shlex.quote(exe)} --list decks.txt --index "$SLURM_ARRAY_TASK_ID" 2> "logs/$id.err"',
        "status=$?",
        'if [ "$status" -ne 0 ]; then',
        '  { cat "logs/$id.err"; echo "(exit status $status, job ${SLURM_ARRAY_JOB_ID}_'
        '${SLURM_ARRAY_TASK_ID} on $(hostname))"; } > "runs/.$id.error.txt.$$" &&',
        '    mv "runs/.$id.error.txt.$$" "runs/$id.error.txt"',
        "else",
        '  rm -f "runs/$id.error.txt"',
        "fi",
        'exit "$status"',
    ]
    path = sweep.directory / name
    _write_atomic(path, "\n".join(lines) + "\n")
    path.chmod(0o755)
    return path


def submit(script: Path) -> str:
    """sbatch the script; return the job id."""
    try:
        p = subprocess.run(["sbatch", "--parsable", str(script)], capture_output=True, text=True)
    except FileNotFoundError:
        raise SweepError("sbatch is not installed (the script is written: submit it on the cluster)")
    if p.returncode != 0:
        raise SweepError(f"sbatch {script} failed: {p.stderr.strip()}")
    return p.stdout.strip().split(";")[0]


# ------------------------------------------------------------------------------- results
def _read_summary(path: Path) -> dict | None:
    try:
        return json.loads(path.read_text())
    except (FileNotFoundError, ValueError):
        return None


def _flatten(prefix: str, value: Any, out: dict[str, Any]) -> None:
    if isinstance(value, dict):
        for k, v in value.items():
            _flatten(f"{prefix}.{k}" if prefix else k, v, out)
    elif isinstance(value, list):
        for i, v in enumerate(value, 1):
            out[f"{prefix}[{i}]"] = v
    else:
        out[prefix] = value


@dataclass
class Collected:
    """The state of every run: rows of results.csv, and the runs not complete."""

    rows: list[dict[str, Any]]
    failed: list[Run]
    missing: list[Run]
    table: Path


def collect(sweep: Sweep, write: bool = True) -> Collected:
    """Gather every run's status and summary into ``results.csv`` (and ``results.parquet``
    when pyarrow is installed); report failed runs (with their message) and missing ones."""
    rows, failed, missing = [], [], []
    for run in sweep.runs:
        summ = _read_summary(sweep.directory / run.summary)
        row: dict[str, Any] = {"run": run.id}
        if summ is not None:
            row["status"], row["message"] = "done", ""
        elif (sweep.directory / run.error).exists():
            text = (sweep.directory / run.error).read_text().strip()
            row["status"] = "failed"
            row["message"] = " ".join(text.split())
            failed.append(run)
        else:
            row["status"], row["message"] = "missing", ""
            missing.append(run)
        for k in sweep.parameters:
            v = run.params.get(k)
            row[k] = json.dumps(v) if isinstance(v, list) else v
        row["run_deck"] = run.deck
        row["deck_sha256"] = run.deck_sha256
        row["frictiondyn_version"] = (summ or {}).get("frictiondyn_version", "")
        if summ is not None:
            flat: dict[str, Any] = {}
            skip = ("deck", "frictiondyn_version", "warnings")
            _flatten("", {k: v for k, v in summ.items() if k not in skip}, flat)
            row.update(flat)
            # the run's warnings (fd_warnings): how many, and their texts in one cell (empty
            # cells for a summary of an older build, which does not say)
            if "warnings" in summ:
                row["warnings"] = len(summ["warnings"])
                row["warning_text"] = " | ".join(summ["warnings"])
            else:
                row["warnings"] = row["warning_text"] = ""
        rows.append(row)
    table = sweep.directory / "results.csv"
    if write:
        columns: list[str] = []
        for row in rows:
            columns += [c for c in row if c not in columns]
        buf = io.StringIO()
        w = csv.DictWriter(buf, fieldnames=columns, lineterminator="\n")
        w.writeheader()
        for row in rows:
            w.writerow({k: _csv_value(v) for k, v in row.items()})
        _write_atomic(table, buf.getvalue())
        _write_parquet(table)
    return Collected(rows, failed, missing, table)


def _csv_value(v: Any) -> Any:
    if isinstance(v, float):
        return repr(v)
    if isinstance(v, bool):
        return str(v).lower()
    return v


def _write_parquet(table: Path) -> Path | None:
    try:
        import pyarrow.csv as pacsv
        import pyarrow.parquet as pq
    except ImportError:
        return None
    out = table.with_suffix(".parquet")
    tmp = out.with_name(f".{out.name}.{os.getpid()}.tmp")
    pq.write_table(pacsv.read_csv(table), tmp)
    os.replace(tmp, out)
    return out


def read_results(directory: str | os.PathLike) -> list[dict[str, str]]:
    """The rows of a sweep's results.csv, as strings."""
    with open(Path(directory) / "results.csv", newline="") as fh:
        return list(csv.DictReader(fh))


def _number(text: str) -> float | None:
    try:
        return float(text)
    except (TypeError, ValueError):
        return None


def plot(
    directory: str | os.PathLike,
    x: str,
    y: str,
    by: str | None = None,
    out: str | os.PathLike | None = None,
) -> Path:
    """One summary quantity (``y``, a results.csv column such as ``peak_u_m[5]``) against
    one parameter (``x``), one line per value of ``by`` (default: the other varied
    parameters, together, less those zipped with ``x``, which vary with it). Writes a PNG
    (default ``<dir>/<y>_vs_<x>.png``)."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    sweep = load(directory)
    rows = [r for r in read_results(directory) if r["status"] == "done"]
    if not rows:
        raise SweepError(f"{directory}: no complete run to plot (run 'sweep collect' first)")
    for col in (x, y):
        if col not in rows[0]:
            raise SweepError(f"{col!r} is not a column of results.csv; columns: "
                             + ", ".join(rows[0].keys()))
    along = sweep.zipped if x in sweep.zipped else [x]
    others = [by] if by else [p for p in sweep.parameters if p not in along]
    groups: dict[str, list[tuple[float, float]]] = {}
    for r in rows:
        xv, yv = _number(r[x]), _number(r[y])
        if xv is None or yv is None:
            continue
        label = ", ".join(f"{k} = {r.get(k, '')}" for k in others)
        groups.setdefault(label, []).append((xv, yv))
    fig = Figure(figsize=(7, 4.5))
    FigureCanvasAgg(fig)
    ax = fig.add_subplot()
    for label, pts in groups.items():
        pts.sort()
        ax.plot([p[0] for p in pts], [p[1] for p in pts], marker="o", label=label or None)
    ax.set_xlabel(x)
    ax.set_ylabel(y)
    ax.set_title(f"sweep '{sweep.name}'")
    ax.grid(True, alpha=0.3)
    if len(groups) > 1 or next(iter(groups), ""):
        ax.legend(fontsize="small")
    safe = re.sub(r"[^\w.-]+", "_", f"{y}_vs_{x}").strip("_")
    path = Path(out) if out else Path(directory) / f"{safe}.png"
    fig.savefig(path, dpi=110, bbox_inches="tight")
    return path


# -------------------------------------------------------------------------- command line
def add_parser(sub: argparse._SubParsersAction) -> None:
    """Register ``sweep`` on the command line of ``python -m frictiondyn``."""
    p = sub.add_parser(
        "sweep",
        help="parameter sweeps: run locally or as a Slurm job array; collect; plot",
        description="sweep SPEC.toml [options] | sweep collect DIR [--resubmit] | "
        "sweep plot DIR X Y (docs/batch.md)",
        add_help=False,
    )
    p.add_argument("args", nargs=argparse.REMAINDER)
    p.set_defaults(func=lambda a: main(a.args))


def _run_parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(prog="python -m frictiondyn sweep",
                                description="Expand a sweep spec and run it (docs/batch.md).")
    p.add_argument("spec", help="the sweep spec (TOML)")
    p.add_argument("--out", metavar="DIR", help="sweep directory (default: sweeps/<name>)")
    p.add_argument("-j", "--jobs", type=int, help="parallel runs (default: the CPU count)")
    p.add_argument("--exe", help="the frictiondyn executable (default: the installed one)")
    p.add_argument("--quiet", action="store_true", help="no progress bar")
    p.add_argument("--expand-only", action="store_true", help="write the decks, run nothing")
    g = p.add_argument_group("Slurm")
    g.add_argument("--slurm", action="store_true",
                   help="write a job-array script (sweep.sbatch) instead of running here")
    g.add_argument("--max-parallel", type=int, default=32, metavar="M",
                   help="at most M tasks at once (%%M of --array; default 32)")
    g.add_argument("--time", dest="time_limit", help="#SBATCH --time of each task")
    g.add_argument("--partition", help="#SBATCH --partition")
    g.add_argument("--sbatch", action="append", default=[], metavar="OPTION",
                   help="one more #SBATCH line, e.g. --sbatch=--mem=1G (repeatable)")
    g.add_argument("--submit", action="store_true", help="submit the script with sbatch")
    return p


def _report(c: Collected, sweep: Sweep) -> None:
    done = sum(1 for r in c.rows if r["status"] == "done")
    print(f"sweep '{sweep.name}': {done} of {len(sweep.runs)} runs complete, "
          f"{len(c.failed)} failed, {len(c.missing)} missing")
    for run in c.failed:
        msg = next(r["message"] for r in c.rows if r["run"] == run.id)
        print(f"  failed: {run.id} (index {run.index}): {msg}")
    if c.missing:
        print(f"  missing: {array_ranges([r.index for r in c.missing])} (indices)")
    print(f"table: {c.table}")


def main(argv: Sequence[str]) -> int:
    argv = list(argv)
    if argv and argv[0] == "collect":
        p = argparse.ArgumentParser(prog="python -m frictiondyn sweep collect",
                                    description="Gather the results of a sweep; report "
                                    "failed and missing runs; resubmit them.")
        p.add_argument("directory")
        p.add_argument("--resubmit", action="store_true",
                       help="write resubmit.sbatch for the failed and missing runs and sbatch it")
        p.add_argument("--max-parallel", type=int, default=32, metavar="M")
        p.add_argument("--exe")
        a = p.parse_args(argv[1:])
        sweep = load(a.directory)
        c = collect(sweep)
        _report(c, sweep)
        if a.resubmit:
            todo = sorted(r.index for r in c.failed + c.missing)
            if not todo:
                print("nothing to resubmit")
                return 0
            for run in c.failed:
                (sweep.directory / run.error).unlink(missing_ok=True)
            script = slurm_script(sweep, todo, a.max_parallel, a.exe, name="resubmit.sbatch")
            print(f"script: {script}")
            print(f"submitted: job {submit(script)} ({len(todo)} tasks)")
        return 0 if not (c.failed or c.missing) else 1
    if argv and argv[0] == "plot":
        p = argparse.ArgumentParser(prog="python -m frictiondyn sweep plot",
                                    description="Plot one results.csv column against one "
                                    "parameter.")
        p.add_argument("directory")
        p.add_argument("x", help="parameter (a column of results.csv), e.g. friction.p")
        p.add_argument("y", help="summary quantity, e.g. 'peak_u_m[5]'")
        p.add_argument("--by", help="one line per value of this parameter")
        p.add_argument("--out", metavar="PNG")
        a = p.parse_args(argv[1:])
        print(f"plot: {plot(a.directory, a.x, a.y, a.by, a.out)}")
        return 0
    a = _run_parser().parse_args(argv)
    sweep = expand(a.spec, a.out)
    pending = sweep.pending()
    print(f"sweep '{sweep.name}': {len(sweep.runs)} runs in {sweep.directory} "
          f"({len(sweep.runs) - len(pending)} already complete)")
    if a.expand_only:
        return 0
    if a.slurm:
        if not pending:
            print("every run is complete")
            return 0
        script = slurm_script(sweep, None, a.max_parallel, a.exe, time_limit=a.time_limit,
                              partition=a.partition, extra=a.sbatch)
        print(f"script: {script}")
        if a.submit:
            print(f"submitted: job {submit(script)} ({len(pending)} tasks); then: "
                  f"python -m frictiondyn sweep collect {sweep.directory}")
        return 0
    spec = load_spec(a.spec)
    t0 = time.perf_counter()
    counts = run_local(sweep, a.jobs or spec.get("jobs"), a.exe, progress=not a.quiet)
    print(f"ran {counts['done'] + counts['failed']} run(s) in {time.perf_counter() - t0:.1f} s: "
          f"{counts['done']} done, {counts['failed']} failed, {counts['skipped']} skipped "
          "(complete before)")
    c = collect(sweep)
    _report(c, sweep)
    return 0 if not c.failed else 1
