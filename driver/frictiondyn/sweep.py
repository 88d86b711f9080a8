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
"deck" (the base deck itself varies). A ``[records]`` table crosses everything with a suite
of records, each scaled to a target intensity (docs/batch.md, "Record suites"):

    [records]
    files = ["records/*.AT2"]         # globs, relative to the spec's directory
    scale_to = "sa"                   # "pga", or "sa": the 5 %-damped PSA at `period`
    period = 1.2                      # s (for "sa"; left out: the structure's T1)
    intensities = [0.2, 0.4, 0.8]     # g

A ``[derived]`` table computes deck variables (or labels) in each run from an expression
over the run's parameters and quantities of the base deck (docs/batch.md, "Derived values"):

    [cross]
    alpha = [0.02, 0.05]              # a label
    [derived]
    "friction.p" = "alpha * device_weight_above / friction.mu"

A ``[labels]`` table names the values of a [cross] or [zip] key (``"braces.stiffness" =
["1x", "2x", "4x"]``, one name a value): the table's column of the key then holds the name
(the value in ``<key> [value]``), and so do the decks' headers and the legends of ``plot``.

Each run of a record suite then has the labels ``record`` (the file's name) and ``intensity_g`` and the deck
variables ``excitation.record_file`` and ``excitation.record_scale`` (the factor that brings
the record, read with the base deck's record settings, to the intensity); ``collect`` also
writes ``intensity.csv``: per intensity (and other parameters) the median and the 16th and
84th percentiles over the records of every numeric column. Expanding a spec writes, under the sweep directory,
``decks/<id>.nml`` (one deck per run, outputs to ``runs/<id>.csv`` and
``runs/<id>.summary.json``), ``decks.txt`` (the list the executable's ``--list`` reads) and
``manifest.json`` (runs, parameters, deck and record hashes). A run is complete when its
summary exists and is its own (its deck's and record's SHA-256 and its version those of the
manifest); complete runs are skipped, so an interrupted sweep resumes where it stopped, and
a summary that is not the run's own is reported damaged and the run is run again. A run
that fails leaves ``runs/<id>.error.txt`` with the executable's message and does not stop
the others. ``results.csv`` collects every run's parameters, status, the frictiondyn version,
the run's deck (``run_deck``) and its SHA-256, and its summary (arrays as ``key[i]``, i from 1;
a null as NaN). One sweep at a time expands into a directory or runs in it (``SweepLock``).
"""

from __future__ import annotations

import argparse
import contextlib
import csv
import datetime
import difflib
import errno
import fcntl
import hashlib
import io
import itertools
import json
import math
import os
import re
import shlex
import signal
import socket
import stat
import subprocess
import sys
import threading
import time
import warnings
from collections.abc import Sequence
from concurrent.futures import ThreadPoolExecutor, as_completed
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import f90nml

from . import __version__
from ._api import DeckError, FrictiondynError, run_text
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

_KEY = re.compile(
    r"^(?:(?P<group>[A-Za-z_]\w*)\.)?(?P<var>[A-Za-z_]\w*)(?:\((?P<idx>\d{1,9})\))?$", re.ASCII
)

#: The groups of a deck and their variables: the namelist statements of the deck reader
#: (fortran/io/fd_deck.f90; tests/test_sweep.py checks that the two agree). A sweep key that
#: names anything else stops the sweep before it writes anything.
DECK_VARIABLES: dict[str, tuple[str, ...]] = {
    "model": ("n_dof", "mass", "u0", "v0", "label"),
    "springs": ("n_springs", "node_i", "node_j", "k"),
    "damping": ("damping_type", "xi", "period", "rayleigh_a0", "rayleigh_a1", "mode_i",
                "mode_j", "mode_system", "modal_modes"),
    "friction": ("n_devices", "node_i", "node_j", "law", "p", "mu", "eps", "eps1", "f",
                 "mu_law", "mu_max", "mu_min", "mu_rate", "mu_table_v", "mu_table_mu", "label"),
    "braces": ("n_braces", "node_i", "node_j", "slip_load", "stiffness", "eps1", "label"),
    "isolators": ("n_isolators", "node_i", "node_j", "law", "weight", "mu", "radius", "eps",
                  "eps1", "f", "mu_law", "mu_max", "mu_min", "mu_rate", "mu_table_v",
                  "mu_table_mu", "label"),
    "bearings": ("n_bearings", "storey", "x", "y", "dof_xi", "dof_yi", "dof_xj", "dof_yj", "law",
                 "p", "mu", "radius", "eps", "eps1", "f", "mu_law", "mu_max", "mu_min", "mu_rate",
                 "mu_table_v", "mu_table_mu", "label", "overturning", "kv", "zeta_v"),
    "storeys": ("n_storeys", "node_i", "node_j", "spring", "height", "label"),
    "floors": ("n_floors", "mass", "inertia", "plan_x", "plan_y", "cm_x", "cm_y", "height",
               "label", "excitation_angle", "p_delta"),
    "frames": ("n_frames", "storey", "angle", "x", "y", "k"),
    "matrices": ("k_file", "m_file", "label", "influence", "influence2"),
    "floor_braces": ("n_braces", "storey", "angle", "x", "y", "slip_load", "stiffness", "eps1",
                     "eps", "law", "label"),
    "excitation": ("excitation_type", "amplitude", "frequency", "ramp_cycles", "duration",
                   "dt_record", "record_file", "record_kind", "record_scale", "record_format",
                   "record_units"),
    "excitation2": ("excitation_type", "amplitude", "frequency", "ramp_cycles", "duration",
                    "dt_record", "record_file", "record_kind", "record_scale", "record_format",
                    "record_units"),
    "excitation3": ("excitation_type", "amplitude", "frequency", "ramp_cycles", "duration",
                    "dt_record", "record_file", "record_kind", "record_scale", "record_format",
                    "record_units"),
    "integration": ("technique", "beta", "gamma", "n1", "n2", "n", "check_correctness",
                    "dt_min", "theta", "linear_system", "refinement", "tolerance",
                    "tolerance_floor"),
    "output": ("dir", "name", "output_every", "write_history", "history_dofs",
               "history_devices", "n_modes", "max_history_mb"),
}

#: Runs a spec may make unless --max-runs (``expand(max_runs=...)``) allows more: the runs
#: are counted before any is expanded, so a spec crossing into 1e12 runs is refused at once.
MAX_RUNS = 100_000
#: Parallel runs of a local sweep at most (``jobs``, ``-j``).
MAX_JOBS = 1024
#: Columns of results.csv before the parameters; a label may not take one of these names.
FIXED_COLUMNS = ("run", "status", "message", "run_deck", "deck_sha256", "frictiondyn_version",
                 "warnings", "warning_text")
_CONTROL = re.compile(r"[\x00-\x1f\x7f]")
_NAME = re.compile(r"[A-Za-z0-9_][A-Za-z0-9_.-]*", re.ASCII)
_SHA256 = re.compile(r"[0-9a-f]{64}", re.ASCII)
_RUN_ID = re.compile(r"r[0-9]{4,9}", re.ASCII)
LOCK_NAME = ".sweep.lock"


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
    record_sha256: str = ""  #: SHA-256 of the record file the deck names ("" when none)
    #: the deck sets &integration tolerance: a Python tolerance run (``python -m frictiondyn
    #: run``), which the executable refuses
    tolerance: bool = False

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
    """An expanded sweep: its directory, runs and parameters. A sweep made by ``expand``
    holds the lock of its directory until ``close()`` (or the end of a ``with`` block, or of
    the process): no other sweep can be expanded into it or run in it meanwhile."""

    name: str
    directory: Path
    parameters: list[str]
    runs: list[Run] = field(default_factory=list)
    zipped: list[str] = field(default_factory=list)  #: the parameters of [zip]
    version: str = __version__  #: the frictiondyn version the runs are for
    spec_sha256: str = ""
    jobs: int | None = None  #: the spec's ``jobs``
    records: dict | None = None  #: the spec's [records] (a record suite), if any
    labels: dict | None = None  #: key -> {"values": [...], "names": [...]} ([labels])
    derived: list[str] = field(default_factory=list)  #: the keys of [derived]
    lock: SweepLock | None = field(default=None, repr=False)

    def state(self, run: Run) -> tuple[str, dict | None, str]:
        """("done", summary, "") when the run's summary is its own and whole; ("damaged",
        None, why) when a summary is there but is not (unreadable, of another deck, record or
        version); ("absent", None, "") when there is none."""
        return _summary_state(self, run)

    def complete(self, run: Run) -> bool:
        """The run's summary exists, is a whole JSON object and is of this run's deck,
        record and version."""
        return self.state(run)[0] == "done"

    def pending(self) -> list[Run]:
        return [r for r in self.runs if not self.complete(r)]

    def close(self) -> None:
        """Release the directory's lock (if this object holds it)."""
        if self.lock is not None:
            self.lock.release()
            self.lock = None

    def __enter__(self) -> Sweep:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()


# ------------------------------------------------------------------------------------ lock
class SweepLock:
    """An exclusive ``flock`` on ``DIR/.sweep.lock``, taken without waiting: one sweep at a
    time expands into a directory or runs in it. The lock file is opened with O_NOFOLLOW and
    must be a regular file with one link: a planted symbolic link, hard link, FIFO or
    directory is refused, never followed or written. The file stays (removing a lock file
    races with its next taker); the lock dies with its process. The file holds who has the
    lock (process, host, since, spec), for the message of a sweep refused."""

    def __init__(self, directory: Path, spec: str = ""):
        self.fd: int | None = None
        self.path = Path(directory) / LOCK_NAME
        flags = os.O_RDWR | os.O_CREAT | os.O_NOFOLLOW | os.O_NONBLOCK | os.O_CLOEXEC
        try:
            fd = os.open(self.path, flags, 0o644)
        except OSError as exc:
            if exc.errno == errno.ELOOP:
                raise SweepError(f"{self.path} is a symbolic link: a sweep does not follow it; "
                                 "remove it") from None
            raise SweepError(f"cannot open the lock {self.path}: {exc.strerror}") from None
        try:
            st = os.fstat(fd)
            if not stat.S_ISREG(st.st_mode) or st.st_nlink != 1:
                raise SweepError(f"{self.path} is not a regular file of one link: a sweep does "
                                 "not use it; remove it")
            try:
                fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
            except BlockingIOError:
                holder = " ".join(os.pread(fd, 400, 0).decode("utf-8", "replace").split())
                raise SweepError(
                    f"{self.path.parent} is in use by another sweep ({holder or 'starting'}); "
                    "wait for it to end, or give another directory (--out)"
                ) from None
            except OSError as exc:
                raise SweepError(f"cannot lock {self.path}: {exc.strerror}") from None
            when = datetime.datetime.now(datetime.timezone.utc).strftime("%Y-%m-%dT%H:%M:%SZ")
            info = f"pid {os.getpid()} on {socket.gethostname()} since {when}"
            if spec:
                info += f", spec {spec}"
            os.ftruncate(fd, 0)
            os.pwrite(fd, (" ".join(info.split()) + "\n").encode("utf-8", "replace"), 0)
        except BaseException:
            os.close(fd)
            raise
        self.fd = fd

    def release(self) -> None:
        if self.fd is not None:
            os.close(self.fd)  # closing the only descriptor releases the flock
            self.fd = None

    def __del__(self) -> None:  # a safety net: a sweep dropped without close()
        self.release()


# ------------------------------------------------------------------------------------ spec
def _kind(v: Any) -> str:
    return type(v).__name__.replace("str", "string").replace("int", "integer")


def _check_value(v: Any, where: str, deck_value: bool) -> None:
    """A spec value: a string, number, boolean or a list of them (nested lists too)."""
    if isinstance(v, list):
        for x in v:
            _check_value(x, where, deck_value)
        return
    if isinstance(v, float) and not math.isfinite(v):
        raise SweepError(f"{where}: {v!r} is not a finite number")
    if not isinstance(v, (str, int, float, bool)):
        raise SweepError(f"{where}: a {_kind(v)} ({_short(v)}) is not a value of a sweep: "
                         "give strings, numbers, booleans or lists of them")
    if deck_value and isinstance(v, str) and _CONTROL.search(v):
        raise SweepError(f"{where}: {json.dumps(v)}: a string of a deck may not hold a newline "
                         "or another control character")


def _close(word: str, choices) -> str:
    near = difflib.get_close_matches(word, list(choices), n=3, cutoff=0.6)
    return f"; did you mean {' or '.join(repr(n) for n in near)}?" if near else ""


def _check_key(key: str, where: str) -> None:
    """A key naming a group must name a group and variable of the deck reader."""
    m = _KEY.match(key)
    assert m is not None
    if m["group"] is None:
        return
    group, var = m["group"].lower(), m["var"].lower()
    if group not in DECK_VARIABLES:
        raise SweepError(f"{where}: no group &{group} in a deck{_close(group, DECK_VARIABLES)}"
                         f" (the groups: {', '.join(DECK_VARIABLES)})")
    if var not in DECK_VARIABLES[group]:
        raise SweepError(f"{where}: &{group} has no variable {var!r}"
                         f"{_close(var, DECK_VARIABLES[group])} (its variables: "
                         f"{', '.join(DECK_VARIABLES[group])})")
    if group == "output" and var in ("dir", "name"):
        raise SweepError(f"{where}: the sweep sets &output dir and name itself "
                         "(runs/<id>); vary something else")


def load_spec(path: str | os.PathLike) -> dict:
    """Read and check a sweep spec (TOML); the keys are described in the module doc. Every
    error is a SweepError of one line naming the spec and the key."""
    path = Path(path)
    try:
        data = path.read_bytes()
    except FileNotFoundError:
        raise SweepError(f"{path}: no such spec file") from None
    except OSError as exc:
        raise SweepError(f"{path}: cannot read the spec: {exc.strerror}") from None
    try:
        spec = tomllib.loads(data.decode("utf-8"))
    except UnicodeDecodeError as exc:
        raise SweepError(f"{path}: not UTF-8 text (byte {exc.start})") from None
    except tomllib.TOMLDecodeError as exc:
        raise SweepError(f"{path}: not valid TOML: {exc}") from None
    except RecursionError:
        raise SweepError(f"{path}: not valid TOML: nested too deeply") from None
    known = {"name", "base", "cross", "zip", "records", "labels", "derived", "write_history",
             "jobs", "directory"}
    unknown = set(spec) - known
    if unknown:
        raise SweepError(f"{path}: unknown key(s) {sorted(unknown)}"
                         f"{_close(sorted(unknown)[0], known)} (known: {sorted(known)})")
    spec["_sha256"] = _sha256(data)
    for key in ("name", "base", "directory"):
        if key in spec:
            v = spec[key]
            if not isinstance(v, str) or not v:
                raise SweepError(f"{path}: {key} = {_short(v)}: a non-empty string is needed")
            if _CONTROL.search(v):
                raise SweepError(f"{path}: {key} = {json.dumps(v)}: a newline or another "
                                 "control character is not allowed")
    if "write_history" in spec and not isinstance(spec["write_history"], bool):
        raise SweepError(f"{path}: write_history = {_short(spec['write_history'])}: "
                         "true or false is needed")
    if "jobs" in spec:
        j = spec["jobs"]
        if isinstance(j, bool) or not isinstance(j, int) or not 1 <= j <= MAX_JOBS:
            raise SweepError(f"{path}: jobs = {_short(j)}: a whole number from 1 to {MAX_JOBS} "
                             "is needed")
    seen: dict[tuple[str, str], str] = {}
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
            m = _KEY.match(key)
            where = f"{path}: [{table}] {key}"
            _check_key(key, where)
            for v in values:
                _check_value(v, where, deck_value=m["group"] is not None)
            if key == "deck" and not all(isinstance(v, str) and v for v in values):
                raise SweepError(f"{where}: every value must be the path of a deck (a string)")
            if m["group"] is None and key != "deck" and key in FIXED_COLUMNS:
                raise SweepError(f"{where}: a label may not be named like a column of the "
                                 f"table ({', '.join(FIXED_COLUMNS)})")
            if m["group"] is not None:  # one variable (or element) set by one key only
                gv = (m["group"].lower(), m["var"].lower())
                other = seen.get(gv)
                if other is not None and (m["idx"] is None or _KEY.match(other)["idx"] is None
                                          or int(_KEY.match(other)["idx"]) == int(m["idx"])):
                    raise SweepError(f"{where}: sets what {other!r} sets; give each variable "
                                     "or element once")
                if other is None or m["idx"] is None:
                    seen[gv] = key
            if (key.lower() == "output.write_history" and "write_history" in spec):
                raise SweepError(f"{where}: write_history is given too; give one of the two")
    zipped = spec.get("zip", {})
    lengths = {k: len(v) for k, v in zipped.items()}
    if len(set(lengths.values())) > 1:
        raise SweepError(f"{path}: [zip] lists differ in length: {lengths}")
    both = set(spec.get("cross", {})) & set(zipped)
    if both:
        raise SweepError(f"{path}: {sorted(both)} in both [cross] and [zip]")
    if "base" not in spec and "deck" not in spec.get("cross", {}) and "deck" not in zipped:
        raise SweepError(f"{path}: give a base deck (base = 'deck.nml') or vary 'deck'")
    if "records" in spec:
        _check_records(spec, path, seen)
    if "labels" in spec:
        _check_labels(spec, path)
    if "derived" in spec:
        _check_derived(spec, path, seen)
    spec.setdefault("name", path.stem)
    if not _NAME.fullmatch(spec["name"]) or len(spec["name"]) > 100:
        raise SweepError(f"{path}: name = {json.dumps(spec['name'])}: letters, digits, '_', "
                         "'-', '.' only, not first '.' or '-', at most 100")
    return spec


def count_runs(spec: dict) -> int:
    """The runs a checked spec makes: the product of the [cross] lists' lengths, times the
    length of the [zip] lists (counted, not expanded)."""
    n = math.prod(len(v) for v in spec.get("cross", {}).values())
    zipped = spec.get("zip", {})
    if "records" in spec:
        n *= len(spec["records"]["_files"]) * len(spec["records"]["intensities"])
    return n * (len(next(iter(zipped.values()))) if zipped else 1)


def _combinations(spec: dict, suite: list[dict[str, Any]] | None = None
                  ) -> tuple[list[str], list[dict[str, Any]]]:
    cross = spec.get("cross", {})
    zipped = spec.get("zip", {})
    keys = list(cross) + list(zipped) + (list(suite[0]) if suite else [])
    zrows = [dict(zip(zipped, vals)) for vals in zip(*zipped.values())] if zipped else [{}]
    rows = []
    for combo in itertools.product(*cross.values()) if cross else [()]:
        for z in zrows:
            for r in suite or [{}]:
                rows.append({**dict(zip(cross, combo)), **z, **r})
    return keys, rows


def _check_derived(spec: dict, path: Path, seen: dict) -> None:
    """[derived]: key = "expression", each key a deck variable (or a label) no other table
    sets, each expression one the evaluator reads (checked again with values at expansion)."""
    derived = spec["derived"]
    if not isinstance(derived, dict) or not derived:
        raise SweepError(f"{path}: [derived] must be a table of key = \"expression\"")
    varied = {**spec.get("cross", {}), **spec.get("zip", {})}
    for key, expr in derived.items():
        where = f"{path}: [derived] {key}"
        m = _KEY.match(key)
        if m is None or key == "deck":
            raise SweepError(f"{where}: not 'group.variable', 'group.variable(i)' or a label")
        _check_key(key, where)
        if key in varied or key in SUITE_KEYS:
            raise SweepError(f"{where}: [cross], [zip] or [records] sets it too; give it once")
        if m["group"] is not None:
            gv = (m["group"].lower(), m["var"].lower())
            if gv in seen:
                raise SweepError(f"{where}: sets what {seen[gv]!r} sets; give each variable once")
            seen[gv] = key
        elif key in FIXED_COLUMNS:
            raise SweepError(f"{where}: a label may not be named like a column of the table")
        if not isinstance(expr, str) or not expr.strip() or len(expr) > 1000:
            raise SweepError(f"{where}: the expression must be a non-empty string (at most 1000 "
                             "characters)")
        try:
            _parse_expression(expr)
        except SweepError as exc:
            raise SweepError(f"{where} = {json.dumps(expr)}: {exc}") from None


#: Functions an expression of [derived] may call.
_FUNCTIONS = {"sqrt": "sqrt", "abs": "abs", "min": "min", "max": "max", "sum": "sum",
              "exp": "exp", "log": "log", "sin": "sin", "cos": "cos", "tan": "tan",
              "cumsum": "cumsum", "reverse": "reverse"}


def _parse_expression(expr: str):
    """The expression's syntax tree, when it uses only numbers, names, group.variable,
    + - * / ** (and unary -), parentheses and the functions of _FUNCTIONS."""
    import ast

    try:
        tree = ast.parse(expr.strip(), mode="eval")
    except SyntaxError as exc:
        raise SweepError(f"not an expression ({exc.msg})") from None
    allowed_ops = (ast.Add, ast.Sub, ast.Mult, ast.Div, ast.Pow, ast.USub, ast.UAdd)
    for node in ast.walk(tree):
        if isinstance(node, (ast.Expression, ast.BinOp, ast.UnaryOp, ast.Load)) or isinstance(
                node, allowed_ops):
            continue
        if isinstance(node, ast.Constant) and isinstance(node.value, (int, float)) and not isinstance(
                node.value, bool):
            continue
        if isinstance(node, ast.Name):
            continue
        if isinstance(node, ast.Attribute) and isinstance(node.value, ast.Name):
            continue
        if isinstance(node, ast.Call) and isinstance(node.func, ast.Name) and not node.keywords \
                and node.func.id in _FUNCTIONS:
            continue
        what = type(node).__name__
        if isinstance(node, ast.Call):
            what = "a call of something other than " + ", ".join(sorted(_FUNCTIONS))
        raise SweepError(f"{what} is not allowed (numbers, names, group.variable, + - * / **, "
                         f"parentheses and {', '.join(sorted(_FUNCTIONS))})")
    return tree


def _evaluate(tree, names: dict[str, Any], where: str):
    """The value of a parsed expression (a float or a numpy array) with ``names``: a name or
    'group.variable' to a number or a list of numbers."""
    import ast

    import numpy as np

    def value(node):
        if isinstance(node, ast.Expression):
            return value(node.body)
        if isinstance(node, ast.Constant):
            return float(node.value)
        if isinstance(node, (ast.Name, ast.Attribute)):
            name = node.id if isinstance(node, ast.Name) else f"{node.value.id}.{node.attr}"
            if name.lower() not in names:
                raise SweepError(f"{where}: {name!r} is not a parameter of the run or a quantity "
                                 f"of the base deck{_close(name.lower(), list(names))}")
            v = names[name.lower()]
            try:
                return np.asarray(v, dtype=float) if isinstance(v, list) else float(v)
            except (TypeError, ValueError):
                raise SweepError(f"{where}: {name} = {_short(v)} is not a number or a list of "
                                 "numbers") from None
        if isinstance(node, ast.UnaryOp):
            x = value(node.operand)
            return -x if isinstance(node.op, ast.USub) else x
        if isinstance(node, ast.BinOp):
            a, b = value(node.left), value(node.right)
            if np.ndim(a) and np.ndim(b) and np.shape(a) != np.shape(b):
                raise SweepError(f"{where}: lists of {np.size(a)} and {np.size(b)} values combined")
            op = type(node.op)
            with np.errstate(all="ignore"):
                return {ast.Add: np.add, ast.Sub: np.subtract, ast.Mult: np.multiply,
                        ast.Div: np.divide, ast.Pow: np.power}[op](a, b)
        if isinstance(node, ast.Call):
            args = [value(a) for a in node.args]
            f = node.func.id
            if f in ("min", "max") and len(args) == 2:
                return (np.minimum if f == "min" else np.maximum)(*args)
            if len(args) != 1:
                raise SweepError(f"{where}: {f}() takes one argument (min and max one or two)")
            x = args[0]
            if f in ("min", "max", "sum"):
                return float({"min": np.min, "max": np.max, "sum": np.sum}[f](x))
            if f == "cumsum":
                return np.cumsum(x)
            if f == "reverse":
                return np.asarray(x)[::-1] if np.ndim(x) else x
            with np.errstate(all="ignore"):
                return getattr(np, f)(x)
        raise SweepError(f"{where}: cannot evaluate {type(node).__name__}")

    out = value(tree)
    if not np.all(np.isfinite(out)):
        raise SweepError(f"{where}: the value is not finite ({_short(np.asarray(out).tolist())})")
    return out


def _base_quantities(nml: f90nml.Namelist) -> dict[str, Any]:
    """The quantities of a base deck an expression of [derived] may use (lower case), besides
    its variables as group.variable: g, mass, weight (m g per DOF), total_mass,
    total_weight, and with the elements' graph, weight_above (per storey of &storeys: the
    weight of the DOFs on its upper node's side once the elements joining its two nodes are
    cut), device_weight_above (the same per device of &friction), storey_height."""
    import numpy as np

    from .spectrum import G

    q: dict[str, Any] = {"g": G}
    for group, variables in nml.items():
        for var, v in variables.items():
            if isinstance(v, (int, float, list)) and not isinstance(v, bool):
                q[f"{group.lower()}.{var.lower()}"] = v
    if nml.get("floors") is not None:
        q.update(_floor_quantities(nml["floors"], nml.get("floor_braces") or {}))
        return q
    model = nml.get("model") or {}
    mass = model.get("mass")
    n = int(model.get("n_dof", 0) or 0)
    if mass is None or n < 1:
        return q
    mass = [float(x) for x in (mass if isinstance(mass, list) else [mass])][:n]
    m = np.array(mass + [0.0] * (n - len(mass)))
    q.update(mass=m.tolist(), weight=(G * m).tolist(), total_mass=float(m.sum()),
             total_weight=float(G * m.sum()))
    edges: list[tuple[int, int]] = []
    for group in ("springs", "friction", "braces", "isolators"):
        g = nml.get(group) or {}
        ni, nj = g.get("node_i"), g.get("node_j")
        if ni is None or nj is None:
            continue
        ni = ni if isinstance(ni, list) else [ni]
        nj = nj if isinstance(nj, list) else [nj]
        edges += [(int(a), int(b)) for a, b in zip(ni, nj) if a is not None and b is not None]

    def above(i: int, j: int) -> float:
        """Weight of the DOFs joined to node i once every element between i and j is cut."""
        adj: dict[int, set[int]] = {}
        for a, b in edges:
            if {a, b} == {i, j}:
                continue
            adj.setdefault(a, set()).add(b)
            adj.setdefault(b, set()).add(a)
        seen, todo = {i}, [i]
        while todo:
            k = todo.pop()
            for nb in adj.get(k, ()):
                if nb not in seen:
                    seen.add(nb)
                    todo.append(nb)
        if 0 in seen:  # still joined to the table: not a cut
            return float("nan")
        return float(G * sum(m[k - 1] for k in seen if 1 <= k <= n))

    st = nml.get("storeys") or {}
    si, sj = _as_list(st.get("node_i")), _as_list(st.get("node_j"))
    if st.get("spring") is not None:  # storey s is the two nodes of spring spring(s)
        sp = nml.get("springs") or {}
        pi, pj = _as_list(sp.get("node_i")), _as_list(sp.get("node_j"))
        si, sj = [], []
        for k in _as_list(st["spring"]):
            if not 1 <= int(k) <= min(len(pi), len(pj)):
                break  # the deck's own check names it when the run starts
            si.append(pi[int(k) - 1])
            sj.append(pj[int(k) - 1])
    if si and sj:
        q["weight_above"] = [above(int(a), int(b)) for a, b in zip(si, sj)]
        h = st.get("height")
        if h is not None:
            q["storey_height"] = [float(x) for x in (h if isinstance(h, list) else [h])]
    fr = nml.get("friction") or {}
    if fr.get("node_i") is not None and fr.get("node_j") is not None:
        fi = fr["node_i"] if isinstance(fr["node_i"], list) else [fr["node_i"]]
        fj = fr["node_j"] if isinstance(fr["node_j"], list) else [fr["node_j"]]
        q["device_weight_above"] = [above(int(a), int(b)) for a, b in zip(fi, fj)]
    return q


def _as_list(v: Any) -> list:
    """A namelist value as a list ([] when not given)."""
    if v is None:
        return []
    return v if isinstance(v, list) else [v]


def _floor_quantities(floors: dict, braces: dict) -> dict[str, Any]:
    """The quantities of a building of rigid floors: mass and weight per floor, their sums,
    weight_above (per storey s, the weight of floors s and above: storey s is the one below
    floor s), brace_weight_above (per brace of &floor_braces, that of its storey) and
    storey_height (each floor's height)."""
    from .spectrum import G

    n = int(floors.get("n_floors", 0) or 0)
    mass = [float(x) for x in _as_list(floors.get("mass"))]
    if n < 1 or len(mass) < n:
        return {}  # the deck's own check names what is missing when a run starts
    mass = mass[:n]
    out: dict[str, Any] = dict(mass=mass, weight=[G * m for m in mass], total_mass=sum(mass),
                               total_weight=G * sum(mass))
    out["weight_above"] = [G * sum(mass[s:]) for s in range(n)]
    storeys = [int(k) for k in _as_list(braces.get("storey"))]
    if storeys and all(1 <= k <= n for k in storeys):
        out["brace_weight_above"] = [out["weight_above"][k - 1] for k in storeys]
    h = _as_list(floors.get("height"))
    if h:
        out["storey_height"] = [float(x) for x in h]
    return out


def _derive(spec: dict, rows: list[dict[str, Any]], base_dir: Path, where: str) -> list[str]:
    """Each run's [derived] values (from its parameters and its base deck's quantities),
    added to its parameters; returns the derived keys."""
    import numpy as np

    quantities: dict[str, dict[str, Any]] = {}
    trees = {k: _parse_expression(e) for k, e in spec["derived"].items()}
    uses_t1 = any(re.search(r"\bt1\b", str(e), re.I) for e in spec["derived"].values())
    for row in rows:
        base = row.get("deck", spec.get("base"))
        if base not in quantities:
            base_path, nml = _read_base(base, base_dir, where)
            quantities[base] = _base_quantities(nml)
            if uses_t1:  # the base deck's first period (a run of one record step)
                quantities[base]["t1"] = _first_period(nml, base_path.parent, where)[0]
        names = dict(quantities[base])
        names.update({k.lower(): v for k, v in row.items() if k != "deck"})
        for key, tree in trees.items():
            v = _evaluate(tree, names, f"{where}: [derived] {key} = {json.dumps(spec['derived'][key])}")
            v = [float(x) for x in np.ravel(v)] if np.ndim(v) else float(v)
            if isinstance(v, list) and any(math.isnan(x) for x in v):
                raise SweepError(f"{where}: [derived] {key}: not a number at some element")
            row[key] = v
            names[key.lower()] = v
    return list(trees)


def _check_labels(spec: dict, path: Path) -> None:
    """[labels]: for a key of [cross] or [zip], one name (a non-empty string, distinct) for
    each of its values, which must be distinct too."""
    labels = spec["labels"]
    if not isinstance(labels, dict):
        raise SweepError(f"{path}: [labels] must be a table of key = [names]")
    varied = {**spec.get("cross", {}), **spec.get("zip", {})}
    for key, names in labels.items():
        where = f"{path}: [labels] {key}"
        if key not in varied:
            raise SweepError(f"{where}: not a key of [cross] or [zip]"
                             f"{_close(key, list(varied))}")
        values = varied[key]
        if (not isinstance(names, list) or len(names) != len(values)
                or not all(isinstance(n, str) and n.strip() and not _CONTROL.search(n) for n in names)):
            raise SweepError(f"{where}: one name (a non-empty string on one line) for each of its "
                             f"{len(values)} values")
        if len(set(names)) != len(names):
            raise SweepError(f"{where}: a name given twice")
        shown = [json.dumps(v, sort_keys=True) for v in values]
        if len(set(shown)) != len(shown):
            raise SweepError(f"{where}: the key's values repeat, so a name would be ambiguous")


def _label_of(labels: dict | None, key: str, value: Any) -> Any:
    """The name [labels] gives the value of a key (the value itself without one)."""
    if not labels or key not in labels:
        return None
    shown = json.dumps(value, sort_keys=True)
    for v, name in zip(labels[key]["values"], labels[key]["names"]):
        if json.dumps(v, sort_keys=True) == shown:
            return name
    return None


#: The labels and deck variables a record suite sets in each run.
SUITE_KEYS = ("record", "intensity_g", "excitation.record_file", "excitation.record_scale")


def _check_records(spec: dict, path: Path, seen: dict) -> None:
    """Check a spec's [records] table and list its files (spec["records"]["_files"])."""
    rec = spec["records"]
    where = f"{path}: [records]"
    if not isinstance(rec, dict):
        raise SweepError(f"{where} must be a table (files, scale_to, period, intensities)")
    known = {"files", "scale_to", "period", "damping", "intensities"}
    unknown = set(rec) - known
    if unknown:
        raise SweepError(f"{where}: unknown key(s) {sorted(unknown)} (known: {sorted(known)})")
    files = rec.get("files")
    if not isinstance(files, list) or not files or not all(isinstance(f, str) and f for f in files):
        raise SweepError(f"{where} files = {_short(files)}: a non-empty list of paths or globs")
    found: list[Path] = []
    for pattern in files:
        matches = sorted(path.parent.glob(pattern)) if not Path(pattern).is_absolute() else (
            sorted(Path("/").glob(pattern.lstrip("/"))))
        matches = [m for m in matches if m.is_file()]
        if not matches:
            raise SweepError(f"{where} files: {pattern!r} names no file (relative to {path.parent})")
        found += [m.resolve() for m in matches]
    if len(set(found)) != len(found):
        raise SweepError(f"{where} files: a record is named twice")
    names = [f.name for f in found]
    if len(set(names)) != len(names):
        raise SweepError(f"{where} files: two records have the same file name; rename one")
    scale_to = rec.get("scale_to", "pga")
    if scale_to not in ("pga", "sa"):
        raise SweepError(f"{where} scale_to = {_short(scale_to)}: 'pga' or 'sa'")
    if scale_to == "sa" and "period" in rec:
        t = rec.get("period")
        if isinstance(t, bool) or not isinstance(t, (int, float)) or not (0 < t < math.inf):
            raise SweepError(f"{where} period = {_short(t)}: the period of 'sa' [s], > 0 (leave it out "
                             "for the structure's first period)")
    elif "period" in rec:
        raise SweepError(f"{where} period: only with scale_to = 'sa'")
    xi = rec.get("damping", 0.05)
    if isinstance(xi, bool) or not isinstance(xi, (int, float)) or not 0 <= xi < 1:
        raise SweepError(f"{where} damping = {_short(xi)}: 0 <= damping < 1")
    levels = rec.get("intensities")
    if (not isinstance(levels, list) or not levels or any(
            isinstance(v, bool) or not isinstance(v, (int, float)) or not 0 < v < math.inf
            for v in levels)):
        raise SweepError(f"{where} intensities = {_short(levels)}: a non-empty list of numbers > 0 [g]")
    for table in ("cross", "zip"):
        for key in spec.get(table, {}):
            if key.lower() in ("record", "intensity_g", "deck") or key.lower() in (
                    "excitation.record_file", "excitation.record_scale"):
                raise SweepError(f"{path}: [{table}] {key}: [records] sets it; give it once")
    if "base" not in spec:
        raise SweepError(f"{where}: a record suite needs a base deck (base = 'deck.nml')")
    rec["_files"] = found
    rec["scale_to"] = scale_to
    rec["damping"] = float(xi)


def _suite_rows(spec: dict, spec_dir: Path, nml: f90nml.Namelist, where: str,
                base_dir: Path | None = None) -> list[dict]:
    """One row per record and intensity: the record's file and the scale that brings it,
    read with the base deck's record settings, to the intensity (the base deck's own files
    relative to ``base_dir``, its folder; default the spec's)."""
    from .spectrum import G, response_spectrum

    rec = spec["records"]
    exc = nml.get("excitation") or {}
    settings = {
        "format": str(exc.get("record_format", "auto")),
        "units": exc.get("record_units"),
        "kind": str(exc.get("record_kind", "acceleration")),
        "dt": exc.get("dt_record"),
    }
    if rec["scale_to"] == "sa" and "period" not in rec:
        rec["period"], rec["period_of"] = _first_period(nml, base_dir or spec_dir, where)
    t = float(rec.get("period", 0.0))
    rows = []
    for f in rec["_files"]:
        try:
            s = response_spectrum(f, periods=[0.0, t] if t > 0 else [0.0], xi=rec["damping"],
                                  **settings)
        except FrictiondynError as exc:
            raise SweepError(f"{where} [records]: {exc}") from None
        measured = float(s.psa[-1])  # the PGA at T = 0, else PSA(T)
        if not measured > 0:
            raise SweepError(f"{where} [records]: {f.name} has no motion to scale (its "
                             f"{'PGA' if t == 0 else f'PSA at {t} s'} is 0)")
        for level in rec["intensities"]:
            rows.append({"record": f.name, "intensity_g": level,
                         "excitation.record_file": os.path.relpath(f, spec_dir),
                         "excitation.record_scale": float(level) * G / measured})
    return rows


def _first_period(nml: f90nml.Namelist, base_dir: Path, where: str) -> tuple[float, str]:
    """The base deck's first period T1 and the system it is of: the first period of its
    stuck system (every device stuck, a brace its sticking spring), else, when that system
    has none (devices holding every mass to the table), of its free system (the devices
    removed); from a run of the deck over one record step."""
    deck = copy_namelist(nml)
    for var in TOLERANCE_VARIABLES:  # the model's modes: one setting of a tolerance run's deck
        (deck.get("integration") or {}).pop(var, None)
    exc = deck["excitation"]
    dt = exc.get("dt_record")
    if dt is None:  # an AT2 record gives its step: the record's own reading decides
        exc["duration"] = 1.0e-3
    else:
        exc["duration"] = float(dt)
    deck.setdefault("output", f90nml.Namelist())
    deck["output"]["n_modes"] = max(1, int(deck["output"].get("n_modes", 1)))
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            r = run_text(write_namelist(deck), "base.nml", base_dir)
    except FrictiondynError as exc:
        raise SweepError(f"{where} [records]: the base deck's first period for scale_to = 'sa': {exc}") from None
    for system in ("stuck", "free"):
        periods = [p for p in (r.summary.get(f"periods_{system}_s") or []) if p]
        if periods:
            return float(periods[0]), f"{system} system"
    raise SweepError(f"{where} [records]: the base deck has no finite first period (stuck or free); "
                     "give period")


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


def _read_base(base: str, base_dir: Path, where: str) -> tuple[Path, f90nml.Namelist]:
    base_path = (base_dir / base).resolve()
    try:  # the deck's bytes as the library reads them (a Latin-1 comment is no error)
        text = base_path.read_bytes().decode("utf-8", "surrogateescape")
    except FileNotFoundError:
        raise SweepError(f"{where}: base deck {base_path} does not exist") from None
    except OSError as exc:
        raise SweepError(f"{where}: cannot read the base deck {base_path}: {exc.strerror}") from None
    try:
        return base_path, _read_deck(text, base_path)
    except FrictiondynError as exc:
        raise SweepError(f"{where}: base deck: {exc}") from None


#: the variables of a tolerance run (docs/python.md, "A stated accuracy"), which the library
#: refuses as one setting: a deck that gives them is run by Python's tolerance run
TOLERANCE_VARIABLES = ("tolerance", "tolerance_floor")


def _read_deck(text: str, path: Path) -> f90nml.Namelist:
    """A base deck as read_namelist reads it; one of a tolerance run (which the library reads
    only without its tolerance variables) is read without them, and they are put back."""
    try:
        return read_namelist(text, path)
    except DeckError as exc:
        if "is a tolerance run" not in str(exc):
            raise
    from .tolerance import DEFAULT_FLOOR, _check, _strip

    stripped, tol, floor = _strip(text, path)
    # a value out of range: the tolerance run's DeckError (a tolerance varied by the spec
    # instead is checked when its run is made)
    _check(DEFAULT_FLOOR if tol is None else tol, DEFAULT_FLOOR if floor is None else floor, path)
    nml = read_namelist(stripped, path)
    integ = nml.setdefault("integration", f90nml.Namelist())
    for var, value in zip(TOLERANCE_VARIABLES, (tol, floor)):
        if value is not None:
            integ[var] = value
    return nml


def _is_tolerance_run(nml: f90nml.Namelist) -> bool:
    integ = nml.get("integration") or {}
    return any(integ.get(v) is not None for v in TOLERANCE_VARIABLES)


def _record_sha256(nml: f90nml.Namelist, decks: Path, cache: dict[str, str]) -> str:
    """SHA-256 of the record file a run's deck names (relative to decks/), "" when it names
    none or it cannot be read (the run then fails and says why)."""
    exc_group = nml.get("excitation") or {}
    rec = exc_group.get("record_file")
    kind = str(exc_group.get("excitation_type", "")).strip().lower()
    if not isinstance(rec, str) or not rec.strip() or kind not in ("record", ""):
        return ""
    path = str(decks / rec.strip())
    if path not in cache:
        h = hashlib.sha256()
        try:
            with open(path, "rb") as fh:
                for block in iter(lambda: fh.read(1 << 20), b""):
                    h.update(block)
            cache[path] = h.hexdigest()
        except OSError:
            cache[path] = ""
    return cache[path]


def sweep_directory(spec: dict, spec_path: Path, directory: str | os.PathLike | None) -> Path:
    """The sweep directory of a checked spec: ``directory`` (--out), else the spec's
    ``directory``, else ``sweeps/<name>`` in the working directory."""
    sdir = Path(directory or spec.get("directory") or Path("sweeps") / spec["name"]).resolve()
    if _CONTROL.search(str(sdir)):
        raise SweepError(f"{spec_path}: the sweep directory {json.dumps(str(sdir))} holds a "
                         "newline or another control character: give another (--out)")
    try:
        st = os.stat(sdir)
    except FileNotFoundError:
        return sdir
    except OSError as exc:  # a name too long, a file on the way, no permission
        raise SweepError(f"{spec_path}: the sweep directory {sdir}: {exc.strerror}") from None
    if not stat.S_ISDIR(st.st_mode):
        raise SweepError(f"{spec_path}: the sweep directory {sdir} is not a directory")
    return sdir


def expand(
    spec_path: str | os.PathLike,
    directory: str | os.PathLike | None = None,
    max_runs: int = MAX_RUNS,
) -> Sweep:
    """Write one deck per run, decks.txt and manifest.json under the sweep directory
    (default: spec ``directory``, else ``sweeps/<name>`` in the working directory). A run
    whose deck changed since an earlier expansion loses its old outputs.

    Everything that can be wrong with the spec (its keys and values, the count of runs
    against ``max_runs``, the base decks, an element a base deck does not give) is found
    before anything is written. The returned sweep holds the directory's lock
    (``SweepLock``): ``close()`` it, or use it in a ``with`` block."""
    spec_path = Path(spec_path).resolve()
    spec = load_spec(spec_path)
    where = str(spec_path)
    base_dir = spec_path.parent
    name = spec["name"]
    n = count_runs(spec)
    if n > max_runs:
        sizes = [f"{len(v):,}" for v in spec.get("cross", {}).values()]
        if spec.get("zip"):
            sizes.append(f"{len(next(iter(spec['zip'].values()))):,} zipped")
        raise SweepError(f"{where}: the spec makes {n:,} runs ({' x '.join(sizes)}), more than "
                         f"the limit of {max_runs:,}; raise it with --max-runs if you mean it")
    sdir = sweep_directory(spec, spec_path, directory)
    suite = None
    if "records" in spec:  # each record's scale, from the base deck's record settings
        base_path, nml = _read_base(spec["base"], base_dir, where)
        suite = _suite_rows(spec, base_dir, nml, where, base_path.parent)
    keys, rows = _combinations(spec, suite)
    if "derived" in spec:  # each run's derived values, from its parameters and the base deck
        keys += _derive(spec, rows, base_dir, where)
    # every base deck read, and every key set in each, before anything is written
    bases: dict[str, tuple[Path, f90nml.Namelist]] = {}
    for params in rows:
        base = params.get("deck", spec.get("base"))
        if base not in bases:
            bases[base] = _read_base(base, base_dir, where)
    first = rows[0]
    for base_path, nml in bases.values():
        probe = copy_namelist(nml)
        for key, value in first.items():
            if key != "deck" and "." in key:
                _set(probe, key, value, f"{where}: with base deck {base_path}")
    made = [p for p in [*reversed(sdir.parents), sdir] if not os.path.lexists(p)]
    try:
        for p in [*made, sdir / "decks", sdir / "runs", sdir / "logs"]:
            p.mkdir(exist_ok=True)
    except OSError as exc:
        for p in reversed(made):  # nothing left of a directory that could not be made
            with contextlib.suppress(OSError):
                p.rmdir()
        raise SweepError(f"{where}: cannot make the sweep directory {sdir}: {exc.strerror}") from None
    lock = SweepLock(sdir, str(spec_path))
    try:
        sweep = _write_runs(spec, spec_path, sdir, keys, rows, bases)
    except BaseException:
        lock.release()
        raise
    sweep.lock = lock
    return sweep


def _write_runs(spec, spec_path, sdir, keys, rows, bases) -> Sweep:
    where = str(spec_path)
    base_dir = spec_path.parent
    name = spec["name"]
    width = max(4, len(str(len(rows) - 1)))
    sweep = Sweep(name=name, directory=sdir, parameters=keys, zipped=list(spec.get("zip", {})),
                  spec_sha256=spec["_sha256"], jobs=spec.get("jobs"),
                  records={k: v for k, v in spec["records"].items() if not k.startswith("_")}
                  if "records" in spec else None,
                  labels=_spec_labels(spec), derived=list(spec.get("derived", {})))
    records: dict[str, str] = {}
    for index, params in enumerate(rows):
        base_path, base_nml = bases[params.get("deck", spec.get("base"))]
        nml = copy_namelist(base_nml)
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
            nml["output"]["write_history"] = spec["write_history"]
        shown = ", ".join(f"{k} = {_short(_label_of(sweep.labels, k, v) or v)}"
                          for k, v in params.items())
        text = _deck_text(nml, f"! frictiondyn sweep '{name}', run {rid}: {shown}\n")
        deck = sdir / "decks" / f"{rid}.nml"
        data = text.encode("utf-8", "surrogateescape")
        try:
            old = deck.read_bytes()
        except OSError:
            old = None
        if old != data:
            for stale in (f"runs/{rid}.summary.json", f"runs/{rid}.csv", f"runs/{rid}.error.txt"):
                (sdir / stale).unlink(missing_ok=True)
            _write_atomic(deck, data)
        run = Run(index, rid, params, f"decks/{rid}.nml", _sha256(data),
                  _record_sha256(nml, sdir / "decks", records), _is_tolerance_run(nml))
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
        "spec_sha256": spec["_sha256"],
        "frictiondyn_version": __version__,
        "parameters": keys,
        "zip": sweep.zipped,
        "records": sweep.records,
        "labels": sweep.labels,
        "derived": sweep.derived,
        "runs": [
            {"index": r.index, "id": r.id, "deck": r.deck, "deck_sha256": r.deck_sha256,
             "record_sha256": r.record_sha256, "params": r.params,
             **({"tolerance": True} if r.tolerance else {})}
            for r in sweep.runs
        ],
    }
    _write_atomic(sdir / "manifest.json", json.dumps(manifest, indent=1) + "\n")
    return sweep


def _spec_labels(spec: dict) -> dict | None:
    if "labels" not in spec:
        return None
    varied = {**spec.get("cross", {}), **spec.get("zip", {})}
    return {k: {"values": varied[k], "names": names} for k, names in spec["labels"].items()}


def _short(v: Any) -> str:
    text = json.dumps(v, default=str)
    return text if len(text) <= 60 else text[:57] + "..."


def _damaged_manifest(sdir: Path, why: str) -> SweepError:
    return SweepError(f"{sdir / 'manifest.json'} is damaged ({why}): expand the spec again "
                      "(python -m frictiondyn sweep SPEC --expand-only)")


def load(directory: str | os.PathLike) -> Sweep:
    """The sweep expanded in a directory (from its manifest.json, every field checked: a
    damaged manifest is a SweepError naming what is wrong)."""
    sdir = Path(directory).resolve()
    try:
        data = (sdir / "manifest.json").read_bytes()
    except FileNotFoundError:
        raise SweepError(f"{sdir}: no manifest.json (not a sweep directory)") from None
    except OSError as exc:
        raise SweepError(f"{sdir / 'manifest.json'}: cannot read it: {exc.strerror}") from None
    try:
        m = json.loads(data.decode("utf-8"), parse_constant=_no_constant)
    except UnicodeDecodeError as exc:
        raise _damaged_manifest(sdir, f"not UTF-8 text at byte {exc.start}") from None
    except ValueError as exc:
        raise _damaged_manifest(sdir, f"not valid JSON: {exc}") from None
    except RecursionError:
        raise _damaged_manifest(sdir, "not valid JSON: nested too deeply") from None

    def want(obj, key, kind, what):
        v = obj.get(key) if isinstance(obj, dict) else None
        if not isinstance(v, kind) or isinstance(v, bool):
            raise _damaged_manifest(sdir, f"{what} is {_short(v)}, not a {kind.__name__}")
        return v

    if not isinstance(m, dict):
        raise _damaged_manifest(sdir, f"a JSON {type(m).__name__}, not an object")
    name = want(m, "name", str, "name")
    if not _NAME.fullmatch(name):
        raise _damaged_manifest(sdir, f"name {json.dumps(name)}")
    params = want(m, "parameters", list, "parameters")
    zipped = m.get("zip", [])
    if not all(isinstance(p, str) for p in params) or not isinstance(zipped, list) or not all(
            isinstance(p, str) for p in zipped):
        raise _damaged_manifest(sdir, "parameters or zip not lists of names")
    version = m.get("frictiondyn_version", "")
    if not isinstance(version, str):
        raise _damaged_manifest(sdir, f"frictiondyn_version is {_short(version)}")
    runs = []
    ids = set()
    for i, r in enumerate(want(m, "runs", list, "runs")):
        what = f"runs[{i}]"
        if not isinstance(r, dict):
            raise _damaged_manifest(sdir, f"{what} is {_short(r)}")
        rid = want(r, "id", str, f"{what}.id")
        index = want(r, "index", int, f"{what}.index")
        deck = want(r, "deck", str, f"{what}.deck")
        sha = want(r, "deck_sha256", str, f"{what}.deck_sha256")
        rec = r.get("record_sha256", "")
        p = want(r, "params", dict, f"{what}.params")
        tolerance = r.get("tolerance", False)
        if (index != i or not _RUN_ID.fullmatch(rid) or rid in ids or deck != f"decks/{rid}.nml"
                or not _SHA256.fullmatch(sha) or not isinstance(rec, str)
                or not isinstance(tolerance, bool)
                or (rec and not _SHA256.fullmatch(rec))
                or (runs and len(rid) != len(runs[0].id))):
            raise _damaged_manifest(sdir, f"{what} = {_short(r)}")
        ids.add(rid)
        runs.append(Run(index, rid, p, deck, sha, rec, tolerance))
    if not runs:
        raise _damaged_manifest(sdir, "no runs")
    spec_sha = m.get("spec_sha256", "")
    records = m.get("records")
    if records is not None and (not isinstance(records, dict) or not all(
            k in params for k in SUITE_KEYS)):
        raise _damaged_manifest(sdir, f"records is {_short(records)}")
    labels = m.get("labels")
    if labels is not None and (not isinstance(labels, dict) or not all(
            k in params and isinstance(v, dict) and isinstance(v.get("values"), list)
            and isinstance(v.get("names"), list) for k, v in labels.items())):
        raise _damaged_manifest(sdir, f"labels is {_short(labels)}")
    derived = m.get("derived", [])
    if not isinstance(derived, list) or not all(isinstance(k, str) and k in params for k in derived):
        raise _damaged_manifest(sdir, f"derived is {_short(derived)}")
    return Sweep(name=name, directory=sdir, parameters=params, runs=runs, zipped=zipped,
                 version=version, spec_sha256=spec_sha if isinstance(spec_sha, str) else "",
                 records=records, labels=labels, derived=derived)


def _no_constant(name: str):
    raise ValueError(f"{name}, which frictiondyn never writes")


def load_locked(directory: str | os.PathLike) -> Sweep:
    """``load`` with the directory's lock held (refused while another sweep holds it)."""
    sdir = Path(directory).resolve()
    if not (sdir / "manifest.json").exists():
        return load(sdir)  # its error
    lock = SweepLock(sdir)
    try:
        sweep = load(sdir)
    except BaseException:
        lock.release()
        raise
    sweep.lock = lock
    return sweep


# ------------------------------------------------------------------------------- running
class _Interrupted(Exception):
    pass


def run_local(
    sweep: Sweep,
    jobs: int | None = None,
    exe: str | None = None,
    progress: bool = True,
) -> dict[str, int]:
    """Run the pending runs, ``jobs`` processes at a time (default: the CPU count): each deck
    by the executable, a tolerance run's (``Run.tolerance``) by ``python -m frictiondyn run``
    with this Python. A failure is written to ``runs/<id>.error.txt`` and the others go on.
    SIGINT or SIGTERM stop the sweep: running processes get SIGTERM (the executable removes
    its temporary files) and what completed stays complete. Returns counts: done, failed,
    skipped."""
    exe = exe or executable()
    if jobs is not None and (isinstance(jobs, bool) or not 1 <= jobs <= MAX_JOBS):
        raise SweepError(f"jobs = {jobs}: a whole number from 1 to {MAX_JOBS} is needed")
    jobs = jobs or os.cpu_count() or 1
    if sweep.lock is None:  # a sweep loaded from its directory: lock it while it runs
        with load_locked(sweep.directory) as locked:
            if [(r.id, r.deck_sha256) for r in locked.runs] != [
                    (r.id, r.deck_sha256) for r in sweep.runs]:
                raise SweepError(f"{sweep.directory}: expanded again since it was loaded; "
                                 "load it again")
            return run_local(locked, jobs, exe, progress)
    pending = sweep.pending()
    counts = {"skipped": len(sweep.runs) - len(pending), "done": 0, "failed": 0}
    procs: set[subprocess.Popen] = set()
    lock = threading.Lock()
    stopping = threading.Event()

    def one(run: Run) -> tuple[Run, int, str]:
        if stopping.is_set():
            return run, -1, "not started"
        command = (_tolerance_command(run.deck) if run.tolerance else [exe, run.deck])
        p = subprocess.Popen(
            command, cwd=sweep.directory, stdout=subprocess.DEVNULL,
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


def _tolerance_command(deck: str) -> list[str]:
    """A tolerance run's command: Python's tolerance run of the deck, written as the
    executable writes a run (the deck's &output), its summary with the estimated errors
    (the job script's names the deck by the task's id: it keeps all but the last two)."""
    return [sys.executable, "-m", "frictiondyn", "run", deck, "--quiet"]


# ---------------------------------------------------------------------------------- Slurm
def array_ranges(indices: Sequence[int]) -> str:
    """0,1,2,5,7,8 -> '0-2,5,7-8'."""
    out = []
    for _, grp in itertools.groupby(enumerate(sorted(indices)), lambda p: p[1] - p[0]):
        g = [i for _, i in grp]
        out.append(str(g[0]) if len(g) == 1 else f"{g[0]}-{g[-1]}")
    return ",".join(out)


def _sbatch_arg(value: str, option: str) -> str:
    """A value as one argument of an #SBATCH line. Such a line is a comment to the shell,
    read by sbatch alone, which splits it at blanks and takes '#' for the start of a
    comment unless quoted: a value holding those is written in double quotes. A newline or
    another control character (it would end the line: what follows would be a command) and
    a double quote or backslash (sbatch's quoting cannot hold them plainly) are refused."""
    if _CONTROL.search(value) or '"' in value or "\\" in value:
        raise SweepError(f"{option} {json.dumps(value)}: a newline, control character, '\"' or "
                         "'\\' cannot be written in an #SBATCH line; give another")
    if not value or re.search(r"[\s#']", value):
        return f'"{value}"'
    return value


def check_slurm_values(
    directory: Path,
    exe: str,
    time_limit: str | None = None,
    partition: str | None = None,
    extra: Sequence[str] = (),
    job_name: str | None = None,
) -> None:
    """The values a job script names can be written in it: SweepError otherwise."""
    sdir = str(directory)
    for what, value in (("the sweep directory", sdir), ("the executable's path",
                                                        os.path.abspath(exe))):
        if _CONTROL.search(value):  # a newline would end an #SBATCH line (or a command)
            raise SweepError(f"{what} {json.dumps(value)} holds a newline or another control "
                             "character: a job script cannot name it; give another")
    _sbatch_arg(sdir, "--chdir")
    for value, option in ((time_limit, "--time"), (partition, "--partition"),
                          (job_name, "--job-name")):
        if value:
            _sbatch_arg(value, option)
    for x in extra:
        if _CONTROL.search(x):
            raise SweepError(f"--sbatch {json.dumps(x)}: a newline or another control "
                             "character cannot be written in an #SBATCH line")


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
    the sweep directory (no Python needed on the compute node), or, for a tolerance run
    (``Run.tolerance``), ``python -m frictiondyn run decks/<id>.nml`` with this Python.
    ``indices`` default to the pending runs. Returns the script's path."""
    exe = os.path.abspath(exe or executable())
    check_slurm_values(sweep.directory, exe, time_limit, partition, extra, job_name)
    if indices is None:
        indices = [r.index for r in sweep.pending()]
    tolerance = sorted(r.index for r in sweep.runs if r.tolerance and r.index in set(indices))
    if tolerance and _CONTROL.search(sys.executable):
        raise SweepError(f"the Python path {json.dumps(sys.executable)} holds a newline or another "
                         "control character: a job script cannot name it")
    if not indices:
        raise SweepError(f"{sweep.directory}: every run is complete; nothing to submit")
    if not all(_RUN_ID.fullmatch(r.id) for r in sweep.runs) or not _NAME.fullmatch(sweep.name):
        raise SweepError(f"{sweep.directory}: run ids or sweep name not as a sweep writes them")
    if isinstance(max_parallel, bool) or not isinstance(max_parallel, int) or max_parallel < 1:
        raise SweepError(f"--max-parallel {max_parallel}: a whole number from 1 is needed")
    if not set(indices) <= {r.index for r in sweep.runs}:
        raise SweepError(f"{sweep.directory}: array indices outside the sweep's runs")
    width = len(sweep.runs[0].id) - 1
    sdir = str(sweep.directory)
    lines = [
        "#!/bin/bash",
        f"#SBATCH --job-name={_sbatch_arg(job_name or 'fd-' + sweep.name, '--job-name')}",
        f"#SBATCH --array={array_ranges(indices)}%{max_parallel}",
        "#SBATCH --ntasks=1",
        "#SBATCH --cpus-per-task=1",
        f"#SBATCH --chdir={_sbatch_arg(sdir, '--chdir')}",
        # a file name pattern: '%' of the directory itself doubled
        f"#SBATCH --output={_sbatch_arg(sdir.replace('%', '%%') + '/logs/%A_%a.out', '--output')}",
    ]
    if time_limit:
        lines.append(f"#SBATCH --time={_sbatch_arg(time_limit, '--time')}")
    if partition:
        lines.append(f"#SBATCH --partition={_sbatch_arg(partition, '--partition')}")
    lines += [f"#SBATCH {x}" for x in extra]
    lines += [
        f"# frictiondyn sweep '{sweep.name}': {len(indices)} of {len(sweep.runs)} runs.",
        "# Each task runs the standalone executable on its own deck (decks.txt, 0-based)"
        + (", or Python's tolerance run on a deck that sets &integration tolerance;" if tolerance else ";"),
        "# a failure leaves runs/<id>.error.txt with its message.",
        "set -u",
        f"cd {shlex.quote(str(sweep.directory))} || exit 1",
        f'id=$(printf "r%0{width}d" "$SLURM_ARRAY_TASK_ID")',
    ]
    run_exe = f'{shlex.quote(exe)} --list decks.txt --index "$SLURM_ARRAY_TASK_ID" 2> "logs/$id.err"'
    if tolerance:  # the executable refuses a tolerance run's deck: Python runs it
        lines += [
            "# the runs whose deck sets &integration tolerance: Python's tolerance run",
            f'tolerance_runs=" {" ".join(map(str, tolerance))} "',
            'if [[ "$tolerance_runs" == *" $SLURM_ARRAY_TASK_ID "* ]]; then',
            f'  {shlex.join(_tolerance_command("DECK")[:-2])} "decks/$id.nml" --quiet '
            '2> "logs/$id.err"',
            "else",
            "  " + run_exe,
            "fi",
        ]
    else:
        lines.append(run_exe)
    lines += [
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
    """The summary at ``path`` as a dict, None when absent or unreadable."""
    try:
        summ = _load_summary(path)
    except (FileNotFoundError, _Damaged):
        return None
    return summ


class _Damaged(Exception):
    """A summary that is there but cannot be this run's (the message says why)."""


def _load_summary(path: Path) -> dict:
    try:
        data = path.read_bytes()
    except FileNotFoundError:
        raise
    except OSError as exc:
        raise _Damaged(f"its summary cannot be read: {exc.strerror}") from None
    try:
        summ = json.loads(data.decode("utf-8"), parse_constant=_no_constant)
    except UnicodeDecodeError as exc:
        raise _Damaged(f"its summary is not UTF-8 text (byte {exc.start})") from None
    except ValueError as exc:
        raise _Damaged(f"its summary is not valid JSON ({exc})") from None
    except RecursionError:
        raise _Damaged("its summary is not valid JSON (nested too deeply)") from None
    if not isinstance(summ, dict):
        raise _Damaged(f"its summary is a JSON {_json_kind(summ)}, not an object")
    for key in ("frictiondyn_version", "deck_sha256"):
        if not isinstance(summ.get(key), str):
            raise _Damaged(f"its summary's {key} is {_short(summ.get(key))}, not a string")
    w = summ.get("warnings", [])
    if not isinstance(w, list) or not all(isinstance(x, str) for x in w):
        raise _Damaged(f"its summary's warnings are {_short(w)}, not a list of strings")
    rec = summ.get("record")
    if rec is not None and not (isinstance(rec, dict) and isinstance(rec.get("sha256", ""), str)):
        raise _Damaged(f"its summary's record is {_short(rec)}")
    return summ


def _json_kind(v: Any) -> str:
    return {list: "array", str: "string", int: "number", float: "number", bool: "boolean",
            type(None): "null"}.get(type(v), type(v).__name__)


def _summary_state(sweep: Sweep, run: Run) -> tuple[str, dict | None, str]:
    try:
        summ = _load_summary(sweep.directory / run.summary)
    except FileNotFoundError:
        return "absent", None, ""
    except _Damaged as exc:
        return "damaged", None, str(exc)
    if summ["deck_sha256"] != run.deck_sha256:
        return "damaged", None, (f"its summary is of another deck (deck_sha256 "
                                 f"{summ['deck_sha256'][:12]}..., the run's deck "
                                 f"{run.deck_sha256[:12]}...)")
    rec = (summ.get("record") or {}).get("sha256", "")
    if run.record_sha256 and rec and rec != run.record_sha256:
        return "damaged", None, (f"its summary is of another record (sha256 {rec[:12]}..., "
                                 f"the record expanded {run.record_sha256[:12]}...)")
    if sweep.version and summ["frictiondyn_version"] != sweep.version:
        return "damaged", None, (f"its summary is of frictiondyn "
                                 f"{_short(summ['frictiondyn_version'])}, the sweep's "
                                 f"{sweep.version}")
    return "done", summ, ""


def _flatten(prefix: str, value: Any, out: dict[str, Any]) -> None:
    if isinstance(value, dict):
        for k, v in value.items():
            _flatten(f"{prefix}.{k}" if prefix else k, v, out)
    elif isinstance(value, list):
        for i, v in enumerate(value, 1):
            out[f"{prefix}[{i}]"] = json.dumps(v) if isinstance(v, (list, dict)) else v
    else:
        out[prefix] = value


@dataclass
class Collected:
    """The state of every run: rows of results.csv, and the runs not complete."""

    rows: list[dict[str, Any]]
    failed: list[Run]
    missing: list[Run]
    table: Path
    damaged: list[Run] = field(default_factory=list)  #: a summary there but not the run's
    notes: list[str] = field(default_factory=list)  #: what could not be written, and why


def _read_error(path: Path) -> str | None:
    """A failed run's message (None when the run left none), at most 64 KiB of it."""
    try:
        with open(path, "rb") as fh:
            data = fh.read(1 << 16)
    except FileNotFoundError:
        return None
    except OSError as exc:
        return f"(its error.txt cannot be read: {exc.strerror})"
    return " ".join(data.decode("utf-8", "replace").split())


def collect(sweep: Sweep, write: bool = True) -> Collected:
    """Gather every run's status and summary into ``results.csv`` (and ``results.parquet``
    when pyarrow is installed); report failed runs (with their message), missing ones and
    damaged ones (a summary there that is not the run's own and whole: unreadable, of the
    wrong type, of another deck, record or version). A row holds a summary's values only
    when its run is done; a null of a summary (an undefined quantity) is written NaN."""
    rows, failed, missing, damaged = [], [], [], []
    summaries: list[tuple[dict[str, Any], dict]] = []  # (row, summary) of the done runs
    reserved = set(FIXED_COLUMNS) | set(sweep.parameters) | {
        f"{k} [value]" for k in (sweep.labels or {})}
    for run in sweep.runs:
        state, summ, why = _summary_state(sweep, run)
        row: dict[str, Any] = {"run": run.id}
        error = None if state == "done" else _read_error(sweep.directory / run.error)
        if state == "done":
            row["status"], row["message"] = "done", ""
        elif error is not None:
            row["status"], row["message"] = "failed", error
            failed.append(run)
        elif state == "damaged":
            row["status"], row["message"] = "damaged", why
            damaged.append(run)
        else:
            row["status"], row["message"] = "missing", ""
            missing.append(run)
        for k in sweep.parameters:
            v = run.params.get(k)
            name = _label_of(sweep.labels, k, v)
            shown = json.dumps(v) if isinstance(v, (list, dict)) else v
            if name is None:
                row[k] = shown
            else:  # the name in the key's column, the value beside it
                row[k] = name
                row[f"{k} [value]"] = shown
        row["run_deck"] = run.deck
        row["deck_sha256"] = run.deck_sha256
        row["frictiondyn_version"] = summ["frictiondyn_version"] if summ else ""
        if summ is not None:
            flat: dict[str, Any] = {}
            skip = ("deck", "frictiondyn_version", "warnings", "deck_sha256")
            _flatten("", {k: v for k, v in summ.items() if k not in skip}, flat)
            # a summary key named like a parameter or a fixed column keeps apart
            row.update({(f"summary.{k}" if k in reserved else k): v for k, v in flat.items()})
            # the run's warnings (fd_warnings): how many, and their texts in one cell (empty
            # cells for a summary of an older build, which does not say)
            if "warnings" in summ:
                row["warnings"] = len(summ["warnings"])
                row["warning_text"] = " | ".join(summ["warnings"])
            else:
                row["warnings"] = row["warning_text"] = ""
            summaries.append((row, summ))
        rows.append(row)
    table = sweep.directory / "results.csv"
    notes: list[str] = []
    if write:
        _write_table(table, rows)
        note = _write_parquet(table)
        if note:
            notes.append(note)
        if sweep.records is not None:
            _write_intensity_table(sweep, rows)
        for entity in LONG_TABLES:
            note = _write_long_table(sweep, summaries, entity)
            if note:
                notes.append(note)
    return Collected(rows, failed, missing, table, damaged, notes)


#: The long tables of collect: one row per run and storey, device or DOF, with the summary
#: keys that hold one value each (their names as in the summary) and the labels' key.
LONG_TABLES: dict[str, tuple[str, tuple[str, ...]]] = {
    "storey": ("storey_labels", ("storey_height_m", "peak_drift_m", "peak_drift_time_s",
                                 "residual_drift_m", "peak_drift_ratio", "residual_drift_ratio",
                                 "peak_storey_shear_N", "peak_storey_shear_time_s",
                                 "residual_storey_shear_N")),
    "device": ("device_labels", ("device_law", "peak_s_m", "peak_force_N", "residual_s_m",
                                 "stick_to_slip", "slip_to_stick", "slip_reversals",
                                 "slip_excursions", "dissipated_energy_J", "slip_travel_m")),
    "dof": ("dof_labels", ("peak_u_m", "peak_u_time_s", "peak_v_mps", "peak_aabs_mps2",
                           "peak_aabs_time_s")),
}


def long_rows(sweep: Sweep, summaries: list[tuple[dict[str, Any], dict]], entity: str
              ) -> list[dict[str, Any]]:
    """One row per done run and storey (device, DOF): the run, its parameters as in
    results.csv, the item's number (from 1) and label, and the summary's value of each
    of the entity's keys for that item (a key the summary lacks is left out)."""
    labels_key, keys = LONG_TABLES[entity]
    params = [c for c in (summaries[0][0] if summaries else {})
              if c in sweep.parameters or c.endswith(" [value]")]
    out = []
    for row, summ in summaries:
        labels = summ.get(labels_key) or []
        for i, label in enumerate(labels):
            r: dict[str, Any] = {"run": row["run"], **{k: row.get(k) for k in params},
                                 entity: i + 1, f"{entity}_label": label}
            for k in keys:
                v = summ.get(k)
                if isinstance(v, list) and len(v) == len(labels):
                    r[k] = v[i]
            out.append(r)
    return out


def _write_long_table(sweep: Sweep, summaries, entity: str) -> str | None:
    rows = long_rows(sweep, summaries, entity)
    path = sweep.directory / f"results_{entity}s.csv"
    if not rows:
        path.unlink(missing_ok=True)
        path.with_suffix(".parquet").unlink(missing_ok=True)
        return None
    _write_table(path, rows)
    return _write_parquet(path)


def _write_table(path: Path, rows: list[dict[str, Any]]) -> None:
    """A CSV of rows (the columns in the order they first appear; a missing value empty, a
    null NaN), written whole under a temporary name and renamed."""
    columns: list[str] = []
    seen: set[str] = set()
    for row in rows:
        for c in row:
            if c not in seen:
                seen.add(c)
                columns.append(c)
    buf = io.StringIO()
    w = csv.DictWriter(buf, fieldnames=columns, lineterminator="\n")
    w.writeheader()
    for row in rows:
        w.writerow({k: _csv_value(v) for k, v in row.items()})
    try:
        _write_atomic(path, buf.getvalue())
    except OSError as exc:
        raise SweepError(f"{path}: cannot write the table: {exc.strerror}") from None


def intensity_statistics(sweep: Sweep, rows: list[dict[str, Any]]) -> list[dict[str, Any]]:
    """Per intensity (and every other parameter's value), over the records whose runs are
    done: their count, and the median and the 16th and 84th percentiles (linear
    interpolation, numpy's default) of every numeric summary column."""
    import numpy as np

    others = [k for k in sweep.parameters if k not in SUITE_KEYS]
    groups: dict[tuple, list[dict[str, Any]]] = {}
    for row in rows:
        if row["status"] != "done":
            continue
        key = tuple(json.dumps(row.get(k)) for k in others) + (row["intensity_g"],)
        groups.setdefault(key, []).append(row)
    skip = set(FIXED_COLUMNS) | set(sweep.parameters) | {f"{k} [value]" for k in (sweep.labels or {})}
    out = []
    for key, members in groups.items():
        stats: dict[str, Any] = {k: members[0].get(k) for k in others}
        stats["intensity_g"] = key[-1]
        stats["records"] = len(members)
        columns = [c for c in members[0] if c not in skip]
        for c in columns:
            vals = [m.get(c) for m in members]
            if not all(isinstance(v, (int, float)) and not isinstance(v, bool) and v is not None
                       for v in vals):
                continue
            x = np.asarray(vals, dtype=float)
            if not np.all(np.isfinite(x)):
                continue
            stats[f"{c}.median"] = float(np.median(x))
            stats[f"{c}.p16"] = float(np.percentile(x, 16))
            stats[f"{c}.p84"] = float(np.percentile(x, 84))
        out.append(stats)
    return out


def _write_intensity_table(sweep: Sweep, rows: list[dict[str, Any]]) -> None:
    _write_table(sweep.directory / "intensity.csv", intensity_statistics(sweep, rows))


def _csv_value(v: Any) -> Any:
    if v is None:  # a summary's null: a quantity the run does not define
        return "NaN"
    if isinstance(v, float):
        return repr(v)
    if isinstance(v, bool):
        return str(v).lower()
    return v


def _write_parquet(table: Path) -> str | None:
    """A Parquet copy beside the table (results.parquet beside results.csv) when pyarrow is
    installed; a note when it cannot be written (then no older copy stays beside the new
    table)."""
    try:
        import pyarrow.csv as pacsv
        import pyarrow.parquet as pq
    except ImportError:
        return None
    out = table.with_suffix(".parquet")
    tmp = out.with_name(f".{out.name}.{os.getpid()}.tmp")
    try:
        pq.write_table(pacsv.read_csv(table), tmp)
        os.replace(tmp, out)
    except Exception as exc:  # noqa: BLE001 - pyarrow raises several kinds
        tmp.unlink(missing_ok=True)
        out.unlink(missing_ok=True)
        return f"{out.name} not written: {' '.join(str(exc).split())[:200]}"
    return None


def read_results(directory: str | os.PathLike) -> list[dict[str, str]]:
    """The rows of a sweep's results.csv, as strings."""
    path = Path(directory) / "results.csv"
    try:
        with open(path, newline="", encoding="utf-8", errors="replace") as fh:
            return list(csv.DictReader(fh))
    except FileNotFoundError:
        raise SweepError(f"{path}: no such file (run 'sweep collect' first)") from None
    except (OSError, csv.Error) as exc:
        raise SweepError(f"{path}: cannot be read: {exc}") from None


def _number(text: str | None) -> float | None:
    """The number of a cell; None for text, an empty cell and NaN (an undefined value)."""
    try:
        v = float(text)  # type: ignore[arg-type]
    except (TypeError, ValueError):
        return None
    return v if math.isfinite(v) else None


def _no_column(col: str, columns: list[str]) -> SweepError:
    near = difflib.get_close_matches(col, columns, n=5, cutoff=0.5)
    hint = (f"close matches: {', '.join(near)}" if near else
            "no close match (the header of results.csv lists them)")
    return SweepError(f"{col!r} is not a column of results.csv; {hint}")


#: a summary column's SI unit from its name's suffix (peak_aabs_mps2[5]: m/s2)
_COLUMN_UNITS = (("_mps2", "m/s2"), ("_mps", "m/s"), ("_m", "m"), ("_N", "N"), ("_Nm", "N m"),
                 ("_J", "J"), ("_s", "s"), ("_rad", "rad"), ("_deg", "deg"), ("_per_s", "1/s"))


def column_axis(column: str, units: str | None = None) -> tuple[float, str]:
    """How ``sweep plot`` shows a results.csv column: (factor, axis label). Its SI unit from
    its name (``peak_aabs_mps2[5]``: m/s2), shown in ``units`` (text as for ``run --units``:
    "mm,kN,g"); a drift ratio in %; a column of no known unit as it is."""
    from .plots import Units

    base = re.sub(r"\[\d+\]$", "", column)
    if re.search(r"drift_ratio$", base):
        return 100.0, f"{column} [%]"
    try:
        shown = Units.parse(units)
    except ValueError as exc:
        raise SweepError(f"--units {units}: {exc}") from None
    for suffix, si in _COLUMN_UNITS:
        if base.endswith(suffix):
            return shown.factor(si), f"{column} [{shown.name(si)}]"
    return 1.0, column


def plot(
    directory: str | os.PathLike,
    x: str,
    y: str,
    by: str | None = None,
    out: str | os.PathLike | None = None,
    dpi: int = 150,
    units: str | None = None,
) -> Path:
    """One summary quantity (``y``, a results.csv column such as ``peak_u_m[5]``) against
    one parameter (``x``), one line per value of ``by`` (default: the other varied
    parameters, together, less those zipped with ``x``, which vary with it, a record
    suite's file and scale, which follow its record and intensity, and the [derived] keys,
    which follow the parameters they are computed from). Writes a PNG (default
    ``<dir>/<y>_vs_<x>.png``, ``dpi`` dots per inch). Each axis is in its column's unit
    (``column_axis``: ``units`` such as "mm,kN,g", a drift ratio in %). A point whose x or y is
    not a number (NaN: a quantity the run does not define) is left out."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    sweep = load(directory)
    rows = [r for r in read_results(directory) if r.get("status") == "done"]
    if not rows:
        raise SweepError(f"{directory}: no complete run to plot (run 'sweep collect' first)")
    columns = list(rows[0].keys())
    for col in (x, y) + ((by,) if by else ()):
        if col not in rows[0]:
            raise _no_column(col, columns)
    (fx, x_axis), (fy, y_axis) = column_axis(x, units), column_axis(y, units)
    along = sweep.zipped if x in sweep.zipped else [x]
    others = [by] if by else [p for p in sweep.parameters
                              if p not in along and p in rows[0] and p not in SUITE_KEYS[2:]
                              and p not in sweep.derived]
    groups: dict[str, list[tuple[float, float]]] = {}
    skipped = 0
    for r in rows:
        xv, yv = _number(r[x]), _number(r[y])
        if xv is None or yv is None:
            skipped += 1
            continue
        label = ", ".join(f"{k} = {r.get(k, '')}" for k in others)
        groups.setdefault(label, []).append((fx * xv, fy * yv))
    if not groups:
        raise SweepError(f"{directory}: no complete run has numbers for both {x!r} and {y!r} "
                         f"({skipped} left out: text or NaN, a quantity the run does not define)")
    fig = Figure(figsize=(7, 4.5))
    FigureCanvasAgg(fig)
    ax = fig.add_subplot()
    for label, pts in groups.items():
        pts.sort()
        ax.plot([p[0] for p in pts], [p[1] for p in pts], marker="o", label=label or None)
    ax.set_xlabel(x_axis)
    ax.set_ylabel(y_axis)
    title = f"sweep '{sweep.name}'"
    if skipped:
        title += f" ({skipped} run(s) left out: {y} or {x} not a number)"
    ax.set_title(title, fontsize="medium")
    ax.grid(True, alpha=0.3)
    if len(groups) > 1 or next(iter(groups), ""):
        ax.legend(fontsize="small")
    safe = re.sub(r"[^\w.-]+", "_", f"{y}_vs_{x}").strip("_")
    path = Path(out) if out else Path(directory) / f"{safe}.png"
    fig.savefig(path, dpi=dpi, bbox_inches="tight")
    return path


#: The storey quantities of ``envelope``: the long table's column, the axis label and
#: how a value is shown (its unit kind for --units, or a factor to %).
ENVELOPE_QUANTITIES = {
    "drift_ratio": ("peak_drift_ratio", "peak drift ratio [%]", "percent"),
    "drift": ("peak_drift_m", "peak drift", "length"),
    "shear": ("peak_storey_shear_N", "peak storey shear", "force"),
    "residual_drift_ratio": ("residual_drift_ratio", "residual drift ratio [%]", "percent"),
}


def _storey_table(directory: str | os.PathLike, quantity: str, units: str | None,
                  what: str) -> tuple[Sweep, Path, list[dict[str, str]], str, str, float, str]:
    """results_storeys.csv of a collected sweep and how to show a storey quantity of it:
    (sweep, path, rows, column, axis label, factor, unit text)."""
    from .plots import _FACTORS, Units

    if quantity not in ENVELOPE_QUANTITIES:
        raise SweepError(f"{what} quantity {quantity!r}: one of {', '.join(ENVELOPE_QUANTITIES)}")
    column, axis, kind = ENVELOPE_QUANTITIES[quantity]
    sweep = load(directory)
    path = Path(directory) / "results_storeys.csv"
    try:
        with open(path, newline="", encoding="utf-8") as fh:
            rows = list(csv.DictReader(fh))
    except FileNotFoundError:
        raise SweepError(f"{path}: no such file (the sweep has no storeys, or run 'sweep "
                         "collect' first)") from None
    if kind == "percent":
        return sweep, path, rows, column, axis, 100.0, ""
    name = getattr(Units.parse(units), kind)
    return sweep, path, rows, column, axis, _FACTORS[kind][name], f" [{name}]"


def envelope(
    directory: str | os.PathLike,
    quantity: str = "drift_ratio",
    by: str | None = None,
    out: str | os.PathLike | None = None,
    units: str | None = None,
    dpi: int = 150,
) -> Path:
    """Envelopes over the storeys (results_storeys.csv of ``collect``): a storey quantity
    (``ENVELOPE_QUANTITIES``: the peak drift ratio in %, the peak drift, the peak storey
    shear, the residual drift ratio) against the storey, one curve per run, or with ``by``
    per value of that parameter the median over its runs with the band of their 16th and
    84th percentiles (a record suite's envelopes per intensity: ``by='intensity_g'``).
    Writes a PNG (default ``<dir>/envelope_<quantity>.png``)."""
    import numpy as np
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    sweep, path, rows, column, axis, factor, unit = _storey_table(directory, quantity, units, "envelope")
    if not rows:
        raise SweepError(f"{path}: no storey of a complete run")
    if by is not None and by not in rows[0]:
        raise _no_column(by, [c for c in rows[0] if c in sweep.parameters])
    n = max(int(r["storey"]) for r in rows)
    labels = {int(r["storey"]): r["storey_label"] for r in rows}
    series: dict[str, dict[int, list[float]]] = {}
    for r in rows:
        v = _number(r.get(column))
        if v is None:
            continue
        if by is None:
            key = r["run"] + ": " + ", ".join(f"{k} = {r[k]}" for k in sweep.parameters
                                               if k in r and k not in SUITE_KEYS[2:])
        else:
            key = f"{by} = {r[by]}"
        series.setdefault(key, {}).setdefault(int(r["storey"]), []).append(factor * v)
    if not series:
        raise SweepError(f"{path}: no run has a number for {column} (a storey without a height "
                         "has no drift ratio)")
    fig = Figure(figsize=(6, 1.6 + 0.45 * n))
    FigureCanvasAgg(fig)
    ax = fig.add_subplot()
    for key, per in series.items():
        levels = sorted(per)
        med = [float(np.median(per[s])) for s in levels]
        line, = ax.plot(med, levels, marker="o", label=key)
        if by is not None and any(len(per[s]) > 1 for s in levels):
            ax.fill_betweenx(levels, [float(np.percentile(per[s], 16)) for s in levels],
                             [float(np.percentile(per[s], 84)) for s in levels],
                             color=line.get_color(), alpha=0.2)
    ax.set_yticks(range(1, n + 1), [labels.get(s, str(s)) for s in range(1, n + 1)])
    ax.set_xlabel(axis + unit)
    ax.set_ylabel("storey")
    what = "median and 16th-84th percentiles" if by else "each run"
    ax.set_title(f"sweep '{sweep.name}': {axis.split(' [')[0]}, {what}", fontsize="medium")
    ax.set_xlim(left=0)
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize="small")
    target = Path(out) if out else Path(directory) / f"envelope_{quantity}.png"
    fig.savefig(target, dpi=dpi, bbox_inches="tight")
    return target


def ida_curves(
    directory: str | os.PathLike,
    quantity: str = "drift_ratio",
    by: str | None = None,
    units: str | None = None,
    where: dict[str, str] | None = None,
) -> dict[str, dict[str, Any]]:
    """The incremental dynamic analysis curves of a record suite (results_storeys.csv of
    ``collect``): per group (one, or one per value of the parameter ``by``) each record's
    points (intensity [g], largest storey quantity of the run, ``ENVELOPE_QUANTITIES``, in %
    or ``units``) and, per intensity, the median over the records and their 16th and 84th
    percentiles: ``{group: {"records": {record: [(intensity, value)]}, "intensity": [...],
    "median": [...], "p16": [...], "p84": [...], "axis": label, "intensity_axis": the
    intensity's label ("Sa(0.814 s, 5 % damped) [g]" or "PGA [g]")}}``. ``where`` keeps the runs
    whose parameters have these values (as results_storeys.csv writes them); a record's point
    that would pool several runs (another parameter varies) is an error naming it."""
    import numpy as np

    sweep, path, rows, column, axis, factor, unit = _storey_table(directory, quantity, units, "ida")
    if not rows or "intensity_g" not in rows[0]:
        raise SweepError(f"{path}: an IDA needs a record suite ([records]: intensity_g, record)")
    if by is not None and by not in rows[0]:
        raise _no_column(by, [c for c in rows[0] if c in sweep.parameters])
    for k, value in (where or {}).items():
        if k not in rows[0]:
            raise _no_column(k, [c for c in rows[0] if c in sweep.parameters])
        rows = [r for r in rows if r[k] == value]
        if not rows:
            raise SweepError(f"{path}: no run has {k} = {value}")
    peak: dict[tuple[str, str, float], float] = {}   # (group, record, intensity) -> max over storeys
    runs: dict[tuple[str, str, float], set[str]] = {}
    for r in rows:
        v = _number(r.get(column))
        if v is None:
            continue
        key = ("" if by is None else f"{by} = {r[by]}", r["record"], float(r["intensity_g"]))
        peak[key] = max(peak.get(key, 0.0), factor * abs(v))
        runs.setdefault(key, set()).add(r["run"])
    pooled = [k for k, ids in runs.items() if len(ids) > 1]
    if pooled:
        g, rec, level = pooled[0]
        others = [p for p in sweep.parameters if p not in SUITE_KEYS and p != by and p not in (where or {})]
        raise SweepError(f"{path}: record {rec} at {level} g{' with ' + g if g else ''} has "
                         f"{len(runs[pooled[0]])} runs: fix the other parameters ({', '.join(others)}) "
                         "with --where, or give one as --by")
    if not peak:
        raise SweepError(f"{path}: no run has a number for {column}")
    curves: dict[str, dict[str, Any]] = {}
    for group in sorted({k[0] for k in peak}):
        records = {rec: sorted((i, x) for (g, rr, i), x in peak.items() if g == group and rr == rec)
                   for rec in sorted({k[1] for k in peak if k[0] == group})}
        levels = sorted({k[2] for k in peak if k[0] == group})
        values = [[x for (g, _, i), x in peak.items() if g == group and i == lev] for lev in levels]
        curves[group] = {"records": records, "intensity": levels,
                         "median": [float(np.median(v)) for v in values],
                         "p16": [float(np.percentile(v, 16)) for v in values],
                         "p84": [float(np.percentile(v, 84)) for v in values],
                         "axis": "largest " + axis + unit, "sweep": sweep.name,
                         "intensity_axis": intensity_label(sweep.records)}
    return curves


def intensity_label(records: dict | None) -> str:
    """The intensity measure of a record suite ([records] as the manifest holds it) as an
    axis label: "Sa(0.814 s, 5 % damped) [g]" or "PGA [g]"."""
    records = records or {}
    if records.get("scale_to") == "sa" and isinstance(records.get("period"), (int, float)):
        damping = records.get("damping", 0.05)
        return f"Sa({records['period']:.3g} s, {100 * damping:g} % damped) [g]"
    if records.get("scale_to", "pga") == "pga":
        return "PGA [g]"
    return "intensity [g]"


def ida(
    directory: str | os.PathLike,
    quantity: str = "drift_ratio",
    by: str | None = None,
    out: str | os.PathLike | None = None,
    units: str | None = None,
    dpi: int = 150,
    where: dict[str, str] | None = None,
) -> Path:
    """The IDA curves of ``ida_curves`` drawn: each record's curve, the median and the band
    of the 16th and 84th percentiles. Writes a PNG (default ``<dir>/ida_<quantity>.png``)."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    curves = ida_curves(directory, quantity, by, units, where)
    fig = Figure(figsize=(6, 4.5))
    FigureCanvasAgg(fig)
    ax = fig.add_subplot()
    for g, (group, c) in enumerate(curves.items()):
        color = f"C{g}"
        for pts in c["records"].values():
            ax.plot([x for _, x in pts], [i for i, _ in pts], color=color, alpha=0.35, linewidth=0.8)
        ax.plot(c["median"], c["intensity"], color=color, marker="o", linewidth=2.0,
                label=f"{group}, median" if group else "median")
        ax.fill_betweenx(c["intensity"], c["p16"], c["p84"], color=color, alpha=0.15)
    first = next(iter(curves.values()))
    ax.set_xlabel(first["axis"])
    ax.set_ylabel(first["intensity_axis"])
    ax.set_title(f"sweep '{first['sweep']}': IDA, each record, median and 16th-84th percentiles",
                 fontsize="medium")
    ax.set_xlim(left=0)
    ax.set_ylim(bottom=0)
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize="small")
    target = Path(out) if out else Path(directory) / f"ida_{quantity}.png"
    fig.savefig(target, dpi=dpi, bbox_inches="tight")
    return target


# -------------------------------------------------------------------------- command line
def add_parser(sub: argparse._SubParsersAction) -> None:
    """Register ``sweep`` on the command line of ``python -m frictiondyn``."""
    p = sub.add_parser(
        "sweep",
        help="parameter sweeps: run locally or as a Slurm job array; collect; plot",
        description="sweep SPEC.toml [options] | sweep collect DIR [--resubmit] | "
        "sweep plot DIR X Y | sweep envelope DIR | sweep ida DIR (docs/batch.md)",
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
    p.add_argument("--max-runs", type=int, default=MAX_RUNS, metavar="N",
                   help=f"refuse a spec that makes more than N runs (default {MAX_RUNS:,})")
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
          f"{len(c.failed)} failed, {len(c.missing)} missing, {len(c.damaged)} damaged")
    message = {r["run"]: r["message"] for r in c.rows}
    for run in c.failed:
        print(f"  failed: {run.id} (index {run.index}): {message[run.id]}")
    for run in c.damaged:
        print(f"  damaged: {run.id} (index {run.index}): {message[run.id]}; it runs again")
    if c.missing:
        print(f"  missing: {array_ranges([r.index for r in c.missing])} (indices)")
    for note in c.notes:
        print(f"  note: {note}")
    print(f"table: {c.table}")


def main(argv: Sequence[str]) -> int:
    argv = list(argv)
    if argv and argv[0] == "collect":
        p = argparse.ArgumentParser(prog="python -m frictiondyn sweep collect",
                                    description="Gather the results of a sweep; report "
                                    "failed, missing and damaged runs; resubmit them.")
        p.add_argument("directory")
        p.add_argument("--resubmit", action="store_true",
                       help="write resubmit.sbatch for the failed, missing and damaged runs "
                       "and sbatch it")
        p.add_argument("--max-parallel", type=int, default=32, metavar="M")
        p.add_argument("--exe")
        a = p.parse_args(argv[1:])
        with (load_locked if a.resubmit else load)(a.directory) as sweep:
            c = collect(sweep)
            _report(c, sweep)
            if a.resubmit:
                todo = sorted(r.index for r in c.failed + c.missing + c.damaged)
                if not todo:
                    print("nothing to resubmit")
                    return 0
                script = slurm_script(sweep, todo, a.max_parallel, a.exe, name="resubmit.sbatch")
                for run in c.failed:
                    (sweep.directory / run.error).unlink(missing_ok=True)
                print(f"script: {script}")
                print(f"submitted: job {submit(script)} ({len(todo)} tasks)")
        return 0 if not (c.failed or c.missing or c.damaged) else 1
    if argv and argv[0] == "plot":
        p = argparse.ArgumentParser(prog="python -m frictiondyn sweep plot",
                                    description="Plot one results.csv column against one "
                                    "parameter.")
        p.add_argument("directory")
        p.add_argument("x", help="parameter (a column of results.csv), e.g. friction.p")
        p.add_argument("y", help="summary quantity, e.g. 'peak_u_m[5]'")
        p.add_argument("--by", help="one line per value of this parameter")
        p.add_argument("--units", help="units of the axes, e.g. mm,kN,g (default SI; a drift "
                       "ratio in %%)")
        p.add_argument("--dpi", type=int, default=150, help="resolution (default 150; 300 for a report)")
        p.add_argument("--out", metavar="PNG")
        a = p.parse_args(argv[1:])
        print(f"plot: {plot(a.directory, a.x, a.y, a.by, a.out, a.dpi, a.units)}")
        return 0
    if argv and argv[0] == "envelope":
        p = argparse.ArgumentParser(prog="python -m frictiondyn sweep envelope",
                                    description="Envelopes over the storeys, one curve per run "
                                    "or per value of a parameter (docs/batch.md).")
        p.add_argument("directory")
        p.add_argument("--quantity", default="drift_ratio", choices=list(ENVELOPE_QUANTITIES))
        p.add_argument("--by", help="median and 16th-84th percentile band per value of this parameter")
        p.add_argument("--units", help="units of drift and shear, e.g. mm,kN (default SI)")
        p.add_argument("--dpi", type=int, default=150, help="resolution (default 150; 300 for a report)")
        p.add_argument("--out", metavar="PNG")
        a = p.parse_args(argv[1:])
        print(f"plot: {envelope(a.directory, a.quantity, a.by, a.out, a.units, a.dpi)}")
        return 0
    if argv and argv[0] == "ida":
        p = argparse.ArgumentParser(prog="python -m frictiondyn sweep ida",
                                    description="Incremental dynamic analysis curves of a record "
                                    "suite: intensity against the largest storey quantity, each "
                                    "record, and the median with its 16th-84th percentiles "
                                    "(docs/batch.md).")
        p.add_argument("directory")
        p.add_argument("--quantity", default="drift_ratio", choices=list(ENVELOPE_QUANTITIES))
        p.add_argument("--by", help="one set of curves per value of this parameter")
        p.add_argument("--where", action="append", default=[], metavar="PARAM=VALUE",
                       help="keep the runs with this value of a parameter (repeatable)")
        p.add_argument("--units", help="units of drift and shear, e.g. mm,kN (default SI)")
        p.add_argument("--dpi", type=int, default=150, help="resolution (default 150; 300 for a report)")
        p.add_argument("--out", metavar="PNG")
        a = p.parse_args(argv[1:])
        where = {}
        for item in a.where:
            if "=" not in item:
                raise SweepError(f"--where {item!r}: PARAM=VALUE")
            k, v = item.split("=", 1)
            where[k.strip()] = v.strip()
        print(f"plot: {ida(a.directory, a.quantity, a.by, a.out, a.units, a.dpi, where)}")
        return 0
    a = _run_parser().parse_args(argv)
    if a.max_runs < 1:
        raise SweepError(f"--max-runs {a.max_runs}: a whole number from 1 is needed")
    if a.jobs is not None and not 1 <= a.jobs <= MAX_JOBS:
        raise SweepError(f"-j {a.jobs}: a whole number from 1 to {MAX_JOBS} is needed")
    if a.slurm:  # what the job script must name, checked before anything is written
        spec_path = Path(a.spec).resolve()
        sdir = sweep_directory(load_spec(spec_path), spec_path, a.out)
        check_slurm_values(sdir, a.exe or executable(), a.time_limit, a.partition, a.sbatch)
    with expand(a.spec, a.out, a.max_runs) as sweep:
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
                      f"python -m frictiondyn sweep collect {shlex.quote(str(sweep.directory))}")
            return 0
        t0 = time.perf_counter()
        counts = run_local(sweep, a.jobs or sweep.jobs, a.exe, progress=not a.quiet)
        print(f"ran {counts['done'] + counts['failed']} run(s) in {time.perf_counter() - t0:.1f} s: "
              f"{counts['done']} done, {counts['failed']} failed, {counts['skipped']} skipped "
              "(complete before)")
        c = collect(sweep)
        _report(c, sweep)
        return 0 if not (c.failed or c.missing or c.damaged) else 1
