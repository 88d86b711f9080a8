"""Reading the output files of a run: the time-history CSV and the JSON summary."""

from __future__ import annotations

import json
import re
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

_HEADER = re.compile(r"^(?P<name>[^\[]+)\[(?P<unit>[^\]]*)\]$")


@dataclass
class History:
    """A time-history CSV: one array per column, with the column's unit."""

    columns: dict[str, np.ndarray]
    units: dict[str, str] = field(default_factory=dict)

    def __getitem__(self, name: str) -> np.ndarray:
        return self.columns[name]

    def __contains__(self, name: str) -> bool:
        return name in self.columns

    @property
    def names(self) -> list[str]:
        return list(self.columns)


def read_history(path: str | Path) -> History:
    """Read a history CSV written by frictiondyn (header ``name[unit],...``)."""
    path = Path(path)
    with path.open() as fh:
        header = fh.readline().strip().split(",")
    data = np.loadtxt(path, delimiter=",", skiprows=1, ndmin=2)
    columns: dict[str, np.ndarray] = {}
    units: dict[str, str] = {}
    for j, item in enumerate(header):
        m = _HEADER.match(item.strip())
        if m is None:
            raise ValueError(f"{path}: column header {item!r} is not of the form name[unit]")
        columns[m["name"]] = data[:, j]
        units[m["name"]] = m["unit"]
    return History(columns, units)


def read_summary(path: str | Path) -> dict:
    """Read the JSON summary of a run."""
    return json.loads(Path(path).read_text())
