"""Building an analysis in Python: the same content as a namelist deck, written out with
f90nml, so that ``Analysis.run()`` and ``frictiondyn DECK`` read the very same deck.

An optional value left at None is left out of the deck: the Fortran reader owns every
default (docs/namelist.md), and Python restates none of them.
"""

from __future__ import annotations

import io
import os
import tempfile
from dataclasses import dataclass, field
from pathlib import Path

import f90nml
import numpy as np

from ._api import Result, run_text

__all__ = [
    "Analysis",
    "Damping",
    "Device",
    "FreeVibration",
    "Harmonic",
    "Integration",
    "Output",
    "Record",
    "Spring",
]


@dataclass
class Spring:
    """Linear spring k [N/m] between node_i (a DOF) and node_j (a DOF, or 0 = table)."""

    node_i: int
    node_j: int
    k: float


@dataclass
class Device:
    """Friction device between node_i and node_j (0 = table): normal force p [N], friction
    coefficient mu, law 'velocity' (band eps [m/s]), 'hysteretic' (f [m], eps1 [m/s]) or
    'coulomb' (the exact technique). eps, eps1, f: None takes the reader's default."""

    node_i: int
    node_j: int
    p: float
    mu: float
    law: str
    eps: float | None = None
    eps1: float | None = None
    f: float | None = None


@dataclass
class Damping:
    """Viscous damping: 'stiffness' (C = psi K, psi = T xi / pi; T computed when the period
    is not given), 'rayleigh' (C = a0 M + a1 K) or 'none'. Values left at None take the
    reader's defaults."""

    type: str = "none"
    xi: float | None = None
    period: float | None = None
    rayleigh_a0: float | None = None
    rayleigh_a1: float | None = None

    @classmethod
    def stiffness(cls, xi: float, period: float | None = None) -> Damping:
        return cls("stiffness", xi=xi, period=period)

    @classmethod
    def rayleigh(cls, a0: float, a1: float) -> Damping:
        return cls("rayleigh", rayleigh_a0=a0, rayleigh_a1=a1)

    def group(self) -> dict:
        g: dict = {"damping_type": self.type}
        if self.type == "stiffness":
            _put(g, xi=self.xi, period=self.period)
        elif self.type == "rayleigh":
            _put(g, rayleigh_a0=self.rayleigh_a0, rayleigh_a1=self.rayleigh_a1)
        return g


@dataclass
class Harmonic:
    """Table displacement x0 = amplitude sin(2 pi frequency t), cosine ramp over ramp_cycles
    (None: the reader's default, no ramp)."""

    amplitude: float
    frequency: float
    dt_record: float
    duration: float
    ramp_cycles: int | None = None

    def group(self, directory: Path | None) -> dict:
        g: dict = {
            "excitation_type": "harmonic",
            "amplitude": float(self.amplitude),
            "frequency": float(self.frequency),
        }
        _put(g, ramp_cycles=self.ramp_cycles)
        g.update(dt_record=float(self.dt_record), duration=float(self.duration))
        return g


@dataclass
class Record:
    """Recorded table acceleration (or displacement) sampled at dt_record: a file, or
    values that are written to ``file`` next to the deck. kind, scale, duration: None takes
    the reader's default (acceleration, 1, the whole record)."""

    dt_record: float
    file: str = "record.txt"
    values: np.ndarray | None = None
    kind: str | None = None
    scale: float | None = None
    duration: float | None = None

    def group(self, directory: Path | None) -> dict:
        if self.values is not None:
            if directory is None:
                raise ValueError("a Record with values needs a directory to write its file")
            np.savetxt(directory / self.file, np.asarray(self.values, float), fmt="%.17e")
        g: dict = {"excitation_type": "record", "record_file": self.file}
        _put(g, record_kind=self.kind, record_scale=self.scale)
        g["dt_record"] = float(self.dt_record)
        _put(g, duration=self.duration)
        return g


@dataclass
class FreeVibration:
    """No table motion: free vibration from the initial conditions."""

    dt_record: float
    duration: float

    def group(self, directory: Path | None) -> dict:
        return {
            "excitation_type": "none",
            "dt_record": float(self.dt_record),
            "duration": float(self.duration),
        }


@dataclass
class Integration:
    """Technique, Newmark and step-control settings (docs/namelist.md, &integration); None
    takes the reader's default. ``technique`` is 'newmark', 'event_driven' (exact, for
    'coulomb' devices) or 'moreau_jean' (time stepping for 'coulomb' devices; ``theta``)."""

    technique: str | None = None
    beta: float | None = None
    gamma: float | None = None
    n1: int | None = None
    n2: int | None = None
    n: float | None = None
    check_correctness: bool | None = None
    dt_min: float | None = None
    theta: float | None = None

    def group(self) -> dict:
        g: dict = {}
        _put(
            g,
            technique=self.technique,
            beta=self.beta,
            gamma=self.gamma,
            n1=self.n1,
            n2=self.n2,
            n=self.n,
            check_correctness=self.check_correctness,
            dt_min=self.dt_min,
            theta=self.theta,
        )
        return g


@dataclass
class Output:
    """Output settings for the executable (&output); None takes the reader's default (dir
    'out', name the deck's stem, a row every dt_record, the history written)."""

    dir: str | None = None
    name: str | None = None
    output_every: int | None = None
    write_history: bool | None = None

    def group(self) -> dict:
        g: dict = {}
        _put(
            g,
            dir=self.dir,
            name=self.name,
            output_every=self.output_every,
            write_history=self.write_history,
        )
        return g


def _value(x: object) -> object:
    """A value as the deck holds it (numpy scalars to Python's)."""
    if isinstance(x, (bool, np.bool_)):
        return bool(x)
    if isinstance(x, (int, np.integer)):
        return int(x)
    if isinstance(x, (float, np.floating)):
        return float(x)
    return x


def _put(group: dict, **values: object) -> None:
    """Add the values that are given (not None) to a group."""
    for key, x in values.items():
        if x is not None:
            group[key] = _value(x)


def _per_device(group: dict, key: str, values: list) -> None:
    """An optional per-device value: left out when no device gives it; a device that does
    not is a null value, which the reader fills with its default."""
    if any(x is not None for x in values):
        group[key] = [None if x is None else float(x) for x in values]


@dataclass
class Analysis:
    """One run: masses, springs, damping, friction devices, table motion and settings."""

    masses: list[float]
    springs: list[Spring]
    excitation: Harmonic | Record | FreeVibration
    damping: Damping = field(default_factory=Damping)
    devices: list[Device] = field(default_factory=list)
    integration: Integration = field(default_factory=Integration)
    output: Output = field(default_factory=Output)
    u0: list[float] | None = None
    v0: list[float] | None = None

    def namelist(self, directory: Path | None = None) -> f90nml.Namelist:
        """The deck as an f90nml Namelist (writes a Record's values into directory)."""
        n = len(self.masses)
        model = {"n_dof": n, "mass": [float(m) for m in self.masses]}
        if self.u0 is not None:
            model["u0"] = [float(x) for x in self.u0]
        if self.v0 is not None:
            model["v0"] = [float(x) for x in self.v0]
        groups = [("model", model)]
        springs = {"n_springs": len(self.springs)}
        if self.springs:
            springs.update(
                node_i=[s.node_i for s in self.springs],
                node_j=[s.node_j for s in self.springs],
                k=[float(s.k) for s in self.springs],
            )
        groups.append(("springs", springs))
        groups.append(("damping", self.damping.group()))
        if self.devices:
            d = self.devices
            friction = {
                "n_devices": len(d),
                "node_i": [x.node_i for x in d],
                "node_j": [x.node_j for x in d],
                "law": [x.law for x in d],
                "p": [float(x.p) for x in d],
                "mu": [float(x.mu) for x in d],
            }
            for key in ("eps", "eps1", "f"):
                _per_device(friction, key, [getattr(x, key) for x in d])
            groups.append(("friction", friction))
        groups.append(("excitation", self.excitation.group(directory)))
        integration = self.integration.group()
        if integration:
            groups.append(("integration", integration))
        out = self.output.group()
        if out:
            groups.append(("output", out))
        nml = f90nml.Namelist()
        for name, values in groups:
            nml[name] = f90nml.Namelist(values)
        return nml

    def deck_text(self, directory: Path | None = None) -> str:
        buf = io.StringIO()
        self.namelist(directory).write(buf)
        return buf.getvalue()

    def write_deck(self, path: str | os.PathLike) -> Path:
        """Write the deck (and a Record's values next to it) for the executable."""
        path = Path(path)
        path.write_text(self.deck_text(path.parent))
        return path

    def run(self, name: str = "analysis.nml") -> Result:
        """Run through the extension (no deck file needed; a Record's values go to a
        temporary directory for the duration of the run)."""
        with tempfile.TemporaryDirectory() as tmp:
            directory = Path(tmp)
            return run_text(self.deck_text(directory), name=name, base_dir=directory)
