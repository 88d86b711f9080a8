"""Building an analysis in Python: the same content as a namelist deck, written out with
f90nml, so that ``Analysis.run()`` and ``frictiondyn DECK`` read the very same deck.
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
    coefficient mu, law 'velocity' (band eps [m/s]) or 'hysteretic' (f [m], eps1 [m/s])."""

    node_i: int
    node_j: int
    p: float
    mu: float
    law: str = "velocity"
    eps: float = 1e-3
    eps1: float = 1e-3
    f: float = 1e-5


@dataclass
class Damping:
    """Viscous damping: 'stiffness' (C = psi K, psi = T xi / pi; T computed when 0),
    'rayleigh' (C = a0 M + a1 K) or 'none'."""

    type: str = "none"
    xi: float = 0.0
    period: float = 0.0
    rayleigh_a0: float = 0.0
    rayleigh_a1: float = 0.0

    @classmethod
    def stiffness(cls, xi: float, period: float = 0.0) -> Damping:
        return cls("stiffness", xi=xi, period=period)

    @classmethod
    def rayleigh(cls, a0: float, a1: float) -> Damping:
        return cls("rayleigh", rayleigh_a0=a0, rayleigh_a1=a1)

    def group(self) -> dict:
        g = {"damping_type": self.type}
        if self.type == "stiffness":
            g.update(xi=self.xi, period=self.period)
        elif self.type == "rayleigh":
            g.update(rayleigh_a0=self.rayleigh_a0, rayleigh_a1=self.rayleigh_a1)
        return g


@dataclass
class Harmonic:
    """Table displacement x0 = amplitude sin(2 pi frequency t), cosine ramp over ramp_cycles."""

    amplitude: float
    frequency: float
    dt_record: float
    duration: float
    ramp_cycles: int = 0

    def group(self, directory: Path | None) -> dict:
        return {
            "excitation_type": "harmonic",
            "amplitude": self.amplitude,
            "frequency": self.frequency,
            "ramp_cycles": self.ramp_cycles,
            "dt_record": self.dt_record,
            "duration": self.duration,
        }


@dataclass
class Record:
    """Recorded table acceleration (or displacement) sampled at dt_record: a file, or
    values that are written to ``file`` next to the deck."""

    dt_record: float
    file: str = "record.txt"
    values: np.ndarray | None = None
    kind: str = "acceleration"
    scale: float = 1.0
    duration: float | None = None

    def group(self, directory: Path | None) -> dict:
        if self.values is not None:
            if directory is None:
                raise ValueError("a Record with values needs a directory to write its file")
            np.savetxt(directory / self.file, np.asarray(self.values, float), fmt="%.17e")
        g = {
            "excitation_type": "record",
            "record_file": self.file,
            "record_kind": self.kind,
            "record_scale": self.scale,
            "dt_record": self.dt_record,
        }
        if self.duration is not None:
            g["duration"] = self.duration
        return g


@dataclass
class FreeVibration:
    """No table motion: free vibration from the initial conditions."""

    dt_record: float
    duration: float

    def group(self, directory: Path | None) -> dict:
        return {"excitation_type": "none", "dt_record": self.dt_record, "duration": self.duration}


@dataclass
class Integration:
    """Technique, Newmark and step-control settings (see docs/namelist.md, &integration).

    ``technique`` is 'newmark' or 'event_driven' (exact, for 'coulomb' devices); None
    leaves it out of the deck, which then uses the library's default ('newmark')."""

    technique: str | None = None
    beta: float = 0.25
    gamma: float = 0.5
    n1: int = 20
    n2: int = 50
    n: float = 10.0
    check_correctness: bool = True
    dt_min: float = 0.0


@dataclass
class Output:
    """Output settings for the executable (&output)."""

    dir: str = "out"
    name: str | None = None
    output_every: int = 0
    write_history: bool = True


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
            groups.append(
                (
                    "friction",
                    {
                        "n_devices": len(d),
                        "node_i": [x.node_i for x in d],
                        "node_j": [x.node_j for x in d],
                        "law": [x.law for x in d],
                        "p": [float(x.p) for x in d],
                        "mu": [float(x.mu) for x in d],
                        "eps": [float(x.eps) for x in d],
                        "eps1": [float(x.eps1) for x in d],
                        "f": [float(x.f) for x in d],
                    },
                )
            )
        groups.append(("excitation", self.excitation.group(directory)))
        i = self.integration
        integration = {} if i.technique is None else {"technique": i.technique}
        groups.append(
            (
                "integration",
                integration
                | {
                    "beta": float(i.beta),
                    "gamma": float(i.gamma),
                    "n1": int(i.n1),
                    "n2": int(i.n2),
                    "n": float(i.n),
                    "check_correctness": bool(i.check_correctness),
                    "dt_min": float(i.dt_min),
                },
            )
        )
        o = self.output
        out = {
            "dir": o.dir,
            "output_every": int(o.output_every),
            "write_history": bool(o.write_history),
        }
        if o.name:
            out["name"] = o.name
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
