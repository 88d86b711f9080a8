"""Running decks through the f2py extension, and the Result of a run.

The deck is read by the same Fortran namelist reader as the executable's (one parser);
the extension returns the history, its header and the JSON summary, and every non-zero
status becomes an exception here, in one place.
"""

from __future__ import annotations

import json
import math
import os
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from . import _core

__all__ = [
    "DeckError",
    "FrictiondynError",
    "OutputSettings",
    "Result",
    "SolverError",
    "fortran_es",
    "read_history",
    "read_summary",
    "run",
    "run_text",
    "summary_text",
]


class FrictiondynError(RuntimeError):
    """Base of the package's exceptions; the message names the offending input."""


class DeckError(FrictiondynError, ValueError):
    """The deck (or a record file it names) is missing, malformed or invalid."""


class SolverError(FrictiondynError):
    """The analysis failed (singular system, divergence)."""


_ERRORS = {1: DeckError, 2: SolverError, 3: FrictiondynError}


def _text(buf: np.ndarray) -> str:
    return buf.tobytes().decode("utf-8", errors="replace").rstrip()


def _check(status: int, message: np.ndarray) -> None:
    if status != 0:
        raise _ERRORS.get(int(status), FrictiondynError)(_text(message))


def _run(path: str, text: str, from_text: int) -> Result:
    ncol, nout, lhead, outdir, outname, history, status, message = _core.fd_shape(
        path, text, from_text
    )
    _check(status, message)
    lsum = 16384 + 512 * ncol
    hist, header, summary, status, message = _core.fd_run(
        path, text, from_text, ncol, nout, lhead, lsum
    )
    _check(status, message)
    result = Result.from_arrays(
        _text(header), np.asarray(hist).T.copy(), json.loads(_text(summary))
    )
    result.output = OutputSettings(_text(outdir), _text(outname), bool(history))
    return result


def fortran_es(x: float) -> str:
    """``x`` as Fortran's ``es24.16e3`` writes it (17 significant digits, 3-digit exponent),
    without the padding."""
    if math.isnan(x):
        return "NaN"
    if math.isinf(x):
        return "Infinity" if x > 0 else "-Infinity"
    mant, _, exp = f"{x:.16E}".partition("E")
    return f"{mant}E{exp[0]}{abs(int(exp)):03d}"


def _json_value(value: object) -> str:
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, int):
        return str(value)
    if isinstance(value, float):
        return fortran_es(value)
    if isinstance(value, str):
        return json.dumps(value)
    if isinstance(value, list):
        return "[" + ", ".join(_json_value(v) for v in value) + "]"
    return json.dumps(value)


def summary_text(summary: dict) -> str:
    """The summary JSON as the executable writes it (one key a line, reals in es format)."""
    items = [f"  {json.dumps(k)}: {_json_value(v)}" for k, v in summary.items()]
    return "{\n" + ",\n".join(items) + "\n}\n"


@dataclass
class OutputSettings:
    """The deck's &output settings, as the Fortran reader read them."""

    dir: str = "out"
    name: str = "deck"
    write_history: bool = True


def run(deck: str | os.PathLike) -> Result:
    """Run a namelist deck file and return its Result (no output file is written).

    Raises DeckError for a missing, malformed or invalid deck, SolverError when the
    analysis fails.
    """
    return _run(os.fspath(deck), "", 0)


def run_text(text: str, name: str = "deck.nml", base_dir: str | os.PathLike = ".") -> Result:
    """Run a deck given as text. ``name`` names it in messages; a relative record_file is
    looked up in ``base_dir``."""
    return _run(os.path.join(os.fspath(base_dir), name), text, 1)


_UNITS_LABEL = {"m/s2": "m/s²"}


@dataclass
class Result:
    """Time histories and summary of one run.

    ``result["u1"]`` is a column by name (see ``names``, ``units``); ``time`` is ``t``;
    ``dof(i)`` and ``device(d)`` group the series of one DOF or device (1-based);
    ``summary`` is the run's summary (peaks, transitions, steps, correctness violations,
    energy) as a dict.
    """

    names: list[str]
    units: dict[str, str]
    data: np.ndarray  # (samples, columns)
    summary: dict = field(default_factory=dict)
    output: OutputSettings = field(default_factory=OutputSettings)

    @classmethod
    def from_arrays(cls, header: str, data: np.ndarray, summary: dict) -> Result:
        names, units = [], {}
        for item in header.split(","):
            name, _, unit = item.partition("[")
            names.append(name)
            units[name] = unit.rstrip("]")
        if data.shape[1] != len(names):
            raise FrictiondynError(f"history has {data.shape[1]} columns but {len(names)} names")
        return cls(names, units, data, summary)

    @classmethod
    def from_files(cls, csv: str | os.PathLike, summary: str | os.PathLike | None = None) -> Result:
        """A Result from the executable's (or to_csv's) CSV and its summary JSON."""
        csv = Path(csv)
        with csv.open() as fh:
            header = fh.readline().strip()
        data = np.loadtxt(csv, delimiter=",", skiprows=1, ndmin=2)
        if summary is None:
            candidate = csv.with_name(csv.name[: -len(".csv")] + ".summary.json")
            summary = candidate if candidate.exists() else None
        summ = json.loads(Path(summary).read_text()) if summary is not None else {}
        return cls.from_arrays(header, data, summ)

    @classmethod
    def from_npz(cls, path: str | os.PathLike) -> Result:
        """A Result from a .npz written by to_npz."""
        with np.load(path, allow_pickle=False) as z:
            names = [str(x) for x in z["names"]]
            units = dict(zip(names, (str(x) for x in z["units"])))
            return cls(names, units, z["data"], json.loads(str(z["summary"])))

    def __getitem__(self, name: str) -> np.ndarray:
        try:
            return self.data[:, self.names.index(name)]
        except ValueError:
            raise KeyError(f"no column {name!r}; columns are {', '.join(self.names)}") from None

    def __contains__(self, name: str) -> bool:
        return name in self.names

    @property
    def time(self) -> np.ndarray:
        return self["t"]

    @property
    def n_dof(self) -> int:
        return int(self.summary.get("n_dof", sum(n.startswith("aabs") for n in self.names)))

    @property
    def n_devices(self) -> int:
        return int(self.summary.get("n_devices", sum(n.startswith("phase") for n in self.names)))

    def dof(self, i: int) -> dict[str, np.ndarray]:
        """Relative displacement u, relative velocity v and absolute acceleration aabs of DOF i."""
        return {"u": self[f"u{i}"], "v": self[f"v{i}"], "aabs": self[f"aabs{i}"]}

    def device(self, d: int) -> dict[str, np.ndarray]:
        """Relative displacement s, velocity sdot, force F and phase (0 stick, +-1 slip) of device d."""
        return {
            "s": self[f"s{d}"],
            "sdot": self[f"sdot{d}"],
            "F": self[f"F{d}"],
            "phase": self[f"phase{d}"],
        }

    def label(self, name: str) -> str:
        """Axis label 'name [unit]'."""
        unit = self.units.get(name, "")
        return f"{name} [{_UNITS_LABEL.get(unit, unit)}]" if unit and unit != "-" else name

    def to_csv(self, path: str | os.PathLike) -> Path:
        """Write the history exactly as the executable does (header ``name[unit],...``,
        ``es24.16e3`` values) and the summary next to it as <stem>.summary.json, each to a
        temporary name renamed when complete."""
        path = Path(path)
        tmp = path.with_name(path.name + ".tmp")
        header = ",".join(f"{n}[{self.units[n]}]" for n in self.names)
        with tmp.open("w") as fh:
            fh.write(header + "\n")
            for row in self.data:
                fh.write(",".join(fortran_es(float(x)).rjust(24) for x in row) + "\n")
        tmp.replace(path)
        self.write_summary(path.with_name(path.name.removesuffix(".csv") + ".summary.json"))
        return path

    def write_summary(self, path: str | os.PathLike) -> Path:
        """Write the summary JSON as the executable does."""
        path = Path(path)
        tmp = path.with_name(path.name + ".tmp")
        tmp.write_text(summary_text(self.summary))
        tmp.replace(path)
        return path

    def to_npz(self, path: str | os.PathLike) -> Path:
        """Write names, units, data and the summary (as JSON) to a .npz file."""
        path = Path(path)
        np.savez(
            path,
            names=np.array(self.names),
            units=np.array([self.units[n] for n in self.names]),
            data=self.data,
            summary=np.array(json.dumps(self.summary)),
        )
        return path


def read_history(path: str | os.PathLike) -> Result:
    """The executable's history CSV (with its summary JSON next to it, when present)."""
    return Result.from_files(path)


def read_summary(path: str | os.PathLike) -> dict:
    """The executable's summary JSON."""
    return json.loads(Path(path).read_text())
