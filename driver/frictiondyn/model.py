"""Building an analysis in Python: the same content as a namelist deck, so that
``Analysis.run()`` and ``frictiondyn DECK`` read the very same deck (``namelist()`` gives it
as an f90nml Namelist; ``deck_text()`` writes the same namelist text directly, with the values
as f90nml writes them: a run of a small model should not wait on the writer).

An optional value left at None is left out of the deck: the Fortran reader owns every
default (docs/namelist.md), and Python restates none of them.
"""

from __future__ import annotations

import io
import os
import re
import tempfile
import warnings
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from pathlib import Path

import f90nml
import numpy as np

from ._api import DeckError, FrictiondynWarning, Result, _user_stacklevel, run_text

__all__ = [
    "Analysis",
    "Bearing",
    "Damping",
    "Device",
    "Floor",
    "FloorBrace",
    "Floors",
    "Frame",
    "FreeVibration",
    "FrictionBrace",
    "Harmonic",
    "Integration",
    "Matrices",
    "Output",
    "Record",
    "SlidingIsolator",
    "Spring",
    "Storey",
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
    'coulomb' (the exact technique). eps, eps1, f: None takes the reader's default.

    Velocity-dependent friction (velocity law): ``Device.exponential(...)`` (mu_max,
    mu_min, mu_rate) or ``Device.table(...)`` (points (v, mu)); mu is then None. ``label``
    names the device in outputs and plots."""

    node_i: int
    node_j: int
    p: float
    mu: float | None
    law: str
    eps: float | None = None
    eps1: float | None = None
    f: float | None = None
    mu_law: str | None = None
    mu_max: float | None = None
    mu_min: float | None = None
    mu_rate: float | None = None
    mu_table: list[tuple[float, float]] | None = None
    label: str | None = None

    @classmethod
    def exponential(
        cls,
        node_i: int,
        node_j: int,
        p: float,
        mu_max: float,
        mu_min: float,
        mu_rate: float,
        eps: float | None = None,
        label: str | None = None,
    ) -> Device:
        """Velocity law with mu(v) = mu_max - (mu_max - mu_min) exp(-mu_rate |v|)."""
        return cls(
            node_i,
            node_j,
            p,
            None,
            "velocity",
            eps=eps,
            mu_law="exponential",
            mu_max=mu_max,
            mu_min=mu_min,
            mu_rate=mu_rate,
            label=label,
        )

    @classmethod
    def table(
        cls,
        node_i: int,
        node_j: int,
        p: float,
        points: list[tuple[float, float]],
        eps: float | None = None,
        label: str | None = None,
    ) -> Device:
        """Velocity law with mu(v) linear between the points (v [m/s], mu)."""
        return cls(
            node_i,
            node_j,
            p,
            None,
            "velocity",
            eps=eps,
            mu_law="table",
            mu_table=[(float(v), float(m)) for v, m in points],
            label=label,
        )


@dataclass
class FrictionBrace:
    """A friction damper in series with an elastic brace (Pall type) between node_i and
    node_j: the damper slips at slip_load [N]; the brace's horizontal stiffness [N/m].
    Written as &braces: one hysteretic device with P mu = slip_load and f = slip_load /
    stiffness (docs/namelist.md). eps1 None takes the reader's default."""

    node_i: int
    node_j: int
    slip_load: float
    stiffness: float
    eps1: float | None = None
    label: str | None = None


@dataclass
class SlidingIsolator:
    """A flat (radius 0 or None) or curved sliding isolator between node_i and node_j
    (usually 0, the table) carrying weight [N]: a friction device with P = weight and, when
    curved, a spring weight / radius. Written as &isolators; law, mu and the other friction
    values as for Device (mu None with an mu_law 'exponential' or 'table')."""

    node_i: int
    node_j: int
    weight: float
    mu: float | None
    law: str
    radius: float | None = None
    eps: float | None = None
    eps1: float | None = None
    f: float | None = None
    mu_law: str | None = None
    mu_max: float | None = None
    mu_min: float | None = None
    mu_rate: float | None = None
    mu_table: list[tuple[float, float]] | None = None
    label: str | None = None


@dataclass(kw_only=True)
class Bearing:
    """A planar sliding bearing (&bearings): a flat slider or a friction pendulum whose
    friction force has one magnitude P mu along its sliding direction in the plane. It stands,
    in a building of rigid floors (``Analysis.floors``), at the plan point (x, y) [m] of
    storey ``storey``; in a model of masses or matrices it joins the DOFs dof_xi, dof_yi of the
    sliding body (along x and y) to dof_xj, dof_yj of what it slides on (0 = the table). law
    'velocity' (band eps [m/s]), 'hysteretic' (f [m], eps1 [m/s]) or 'coulomb' (technique
    'moreau_jean'); p the normal force [N] (rigid floors: None takes the gravity share); mu,
    or mu_law 'exponential' (mu_max, mu_min, mu_rate) or 'table' (mu_table: points
    (v [m/s], mu)); radius [m] of the concave surface (0: flat). A vertical ground motion
    (``Analysis.excitation3``) changes its normal force: on a rigid vertical support (kv None or
    0) N = p (1 + a_z / g); kv [N/m] > 0 puts its share p / g of the mass on a vertical spring
    with the damping ratio zeta_v (a vertical oscillator that can lift off). Keyword arguments
    only; None takes the reader's default (docs/namelist.md, &bearings)."""

    storey: int | None = None
    x: float | None = None
    y: float | None = None
    dof_xi: int | None = None
    dof_yi: int | None = None
    dof_xj: int | None = None
    dof_yj: int | None = None
    law: str | None = None
    p: float | None = None
    mu: float | None = None
    radius: float | None = None
    eps: float | None = None
    eps1: float | None = None
    f: float | None = None
    mu_law: str | None = None
    mu_max: float | None = None
    mu_min: float | None = None
    mu_rate: float | None = None
    mu_table: list[tuple[float, float]] | None = None
    label: str | None = None
    kv: float | None = None
    zeta_v: float | None = None


_BEARING_PLAN = ("storey", "x", "y")
_BEARING_DOFS = ("dof_xi", "dof_yi", "dof_xj", "dof_yj")
_BEARING_REALS = ("x", "y", "p", "mu", "radius", "eps", "eps1", "f", "mu_max", "mu_min", "mu_rate", "kv",
                  "zeta_v")
_BEARING_TEXTS = ("law", "mu_law", "label")


def _real(x: object, name: str) -> float:
    """A real setting as a Python float: a bool, a string or anything not a real number
    raises DeckError naming the setting and the value."""
    v = _value(x)
    if isinstance(v, bool) or not isinstance(v, (int, float)):
        raise DeckError(f"{name} must be a number, not {x!r}")
    return float(v)


def _bearing(b: object, i: int, floors: bool) -> Bearing:
    """Bearing i of Analysis.bearings checked for what the deck cannot say of it: its type,
    where it stands (a plan point for rigid floors, DOFs otherwise), and the type of each
    value; its values are checked by the reader."""
    where = f"Analysis.bearings[{i}]"
    if not isinstance(b, Bearing):
        raise DeckError(f"{where} must be a Bearing, not {b!r}")
    wrong, right = (_BEARING_DOFS, _BEARING_PLAN) if floors else (_BEARING_PLAN, _BEARING_DOFS)
    for key in wrong:
        if getattr(b, key) is not None:
            model = "a building of rigid floors" if floors else "a model of masses or matrices"
            raise DeckError(f"{where}.{key} = {getattr(b, key)!r}: a bearing of {model} is "
                            f"placed by {', '.join(right)}")
    for key in ("storey",) + _BEARING_DOFS:
        if getattr(b, key) is not None:
            _int(getattr(b, key), f"{where}.{key}")
    for key in _BEARING_REALS:
        if getattr(b, key) is not None:
            _real(getattr(b, key), f"{where}.{key}")
    for key in _BEARING_TEXTS:
        value = getattr(b, key)
        if value is not None and not isinstance(value, str):
            raise DeckError(f"{where}.{key} must be a string, not {value!r}")
    if b.mu_table is not None:
        table = b.mu_table
        if isinstance(table, (str, bytes)) or np.ndim(table) != 2 or np.shape(table)[1] != 2:
            raise DeckError(f"{where}.mu_table must be a list of points (v, mu), not {table!r}")
        for point in table:
            for value in point:
                _real(value, f"{where}.mu_table")
    return b


def _bearings_group(items: object, floors: bool) -> dict:
    """The &bearings group of Analysis.bearings (floors: the structure is a building of rigid
    floors)."""
    if isinstance(items, (Bearing, str, bytes)) or not isinstance(items, Sequence):
        raise DeckError(f"Analysis.bearings must be a list of Bearing, not {items!r}")
    b = [_bearing(x, i, floors) for i, x in enumerate(items)]
    group: dict = {"n_bearings": len(b)}
    for key in ("storey",) + _BEARING_DOFS:
        _per_device(group, key, [_opt_int(getattr(x, key), key) for x in b])
    for key in ("x", "y", "law", "p", "radius", "kv", "zeta_v"):
        _per_device(group, key, [getattr(x, key) for x in b])
    _friction_values(group, b)
    return group


@dataclass
class Storey:
    """A storey whose drift and shear are reported: upper node_i and lower node_j (0 = the
    table), or ``Storey.of_spring(s)``, the two nodes of spring s (1-based, of ``springs``).
    height [m] gives the drift ratio."""

    node_i: int | None = None
    node_j: int | None = None
    height: float | None = None
    label: str | None = None
    spring: int | None = None

    @classmethod
    def of_spring(
        cls, spring: int, height: float | None = None, label: str | None = None
    ) -> Storey:
        return cls(height=height, label=label, spring=spring)


@dataclass
class Floor:
    """One rigid floor of a building (&floors): its mass [kg], its rotational inertia
    [kg m2] or its plan plan_x by plan_y [m] (a uniform rectangle about the centre of mass),
    its centre of mass (cm_x, cm_y) [m] in plan, the height [m] of the storey below it and a
    label. None takes the reader's default (cm 0, height not given, 'floor f')."""

    mass: float
    plan_x: float | None = None
    plan_y: float | None = None
    inertia: float | None = None
    cm_x: float | None = None
    cm_y: float | None = None
    height: float | None = None
    label: str | None = None


@dataclass
class Floors:
    """A building of rigid floors (&floors), floor 1 the lowest: three DOFs a floor (ux, uy,
    rz at its centre of mass), instead of ``masses``; the table moves along
    excitation_angle [deg] in plan; p_delta adds the gravity loads' geometric stiffness.
    Its lateral elements are ``Analysis.frames``, its friction braces
    ``Analysis.floor_braces`` (docs/namelist.md, &floors)."""

    floors: list[Floor]
    excitation_angle: float | None = None
    p_delta: bool | None = None

    def group(self) -> dict:
        fl = self.floors
        if isinstance(fl, Floor) or not len(fl):
            raise DeckError("Floors.floors must be a list of at least one Floor")
        g: dict = {"n_floors": len(fl), "mass": [float(x.mass) for x in fl]}
        for key in ("inertia", "plan_x", "plan_y", "cm_x", "cm_y", "height", "label"):
            _per_device(g, key, [getattr(x, key) for x in fl])
        _put(g, excitation_angle=self.excitation_angle, p_delta=self.p_delta)
        return g


@dataclass
class Frame:
    """A frame or wall of a building of rigid floors (&frames): a shear spring of stiffness
    k [N/m] in storey ``storey`` (between floor storey and the one below) along the plan
    direction ``angle`` [deg from x] through the plan point (x, y) [m]."""

    storey: int
    angle: float
    x: float
    y: float
    k: float


@dataclass
class FloorBrace:
    """A brace with a friction damper in a building of rigid floors (&floor_braces): one
    device in storey ``storey`` along ``angle`` [deg] through (x, y) [m], slipping at
    slip_load [N]; law 'hysteretic' (the reader's default: the damper in series with a
    brace of ``stiffness`` [N/m]), 'velocity' or 'coulomb' (a rigid brace, no stiffness).
    None takes the reader's default."""

    storey: int
    angle: float
    x: float
    y: float
    slip_load: float
    stiffness: float | None = None
    law: str | None = None
    eps: float | None = None
    eps1: float | None = None
    label: str | None = None


@dataclass
class Matrices:
    """A structure from its stiffness and lumped mass matrices (&matrices), instead of
    ``masses``: ``k`` and ``m`` each a Matrix Market file (a path, relative to the working
    directory for ``run``) or a matrix (a numpy array or a scipy sparse matrix, written as a
    Matrix Market file for the run); ``influence`` the table motion's component along each
    DOF (r, the load -M r a_g), ``influence2`` that of ``Analysis.excitation2``; ``labels``
    a name per DOF."""

    k: str | os.PathLike | np.ndarray | object
    m: str | os.PathLike | np.ndarray | object
    influence: Sequence[float]
    influence2: Sequence[float] | None = None
    labels: list[str] | None = None

    def group(self, directory: Path | None, cwd: Path | None, stem: str) -> dict:
        g: dict = {
            "k_file": _matrix_file(self.k, directory, cwd, f"{stem}.K.mtx", "k"),
            "m_file": _matrix_file(self.m, directory, cwd, f"{stem}.M.mtx", "m"),
        }
        if self.labels is not None:
            _per_device(g, "label", [None if x is None else str(x) for x in self.labels])
        g["influence"] = [float(x) for x in self.influence]
        if self.influence2 is not None:
            g["influence2"] = [float(x) for x in self.influence2]
        return g


def _matrix_file(a: object, directory: Path | None, cwd: Path | None, name: str, what: str) -> str:
    """A matrix of Matrices as the deck names it: a path (made absolute against cwd when
    given), or a matrix written to ``directory/name`` in the Matrix Market coordinate format
    (every nonzero entry, 17 significant digits)."""
    if isinstance(a, (str, os.PathLike)):
        file = os.fspath(a)
        if cwd is not None and not os.path.isabs(file):
            file = os.fspath(Path(cwd) / file)
        return file
    if directory is None:
        raise ValueError(f"Matrices.{what} given as a matrix needs a directory to write its file")
    if hasattr(a, "tocoo"):
        coo = a.tocoo()
        rows, cols, vals, shape = coo.row, coo.col, coo.data, coo.shape
    else:
        dense = np.asarray(a, dtype=float)
        if dense.ndim != 2:
            raise DeckError(f"Matrices.{what} must be a matrix (2-D), not of shape {dense.shape}")
        rows, cols = np.nonzero(dense)
        vals, shape = dense[rows, cols], dense.shape
    lines = ["%%MatrixMarket matrix coordinate real general",
             f"{shape[0]} {shape[1]} {len(vals)}"]
    lines += [f"{i + 1} {j + 1} {float(v):.17e}" for i, j, v in zip(rows, cols, vals, strict=True)]
    (Path(directory) / name).write_text("\n".join(lines) + "\n")
    return name


@dataclass
class Damping:
    """Viscous damping: 'stiffness' (C = psi K, psi = T xi / pi; T computed when the period
    is not given), 'rayleigh' (C = a0 M + a1 K), 'modal' (the ratio xi, or one ratio per
    mode, in each kept mode of the stuck system) or 'none'. Values left at None take the
    reader's defaults. The type and every value given are written as they are: the reader
    takes the type in any case, and ignores a value the type does not use ('modal' refuses
    them)."""

    type: str = "none"
    xi: float | Sequence[float] | None = None
    period: float | None = None
    rayleigh_a0: float | None = None
    rayleigh_a1: float | None = None

    @classmethod
    def stiffness(cls, xi: float, period: float | None = None) -> Damping:
        return cls("stiffness", xi=xi, period=period)

    mode_i: int | None = None
    mode_j: int | None = None
    mode_system: str | None = None
    modal_modes: int | None = None

    @classmethod
    def modal(cls, xi: float | Sequence[float], modes: int | None = None) -> Damping:
        """Modal damping: the ratio xi in each of the lowest `modes` modes of the stuck
        system (default: every mode, at most 50), or one ratio per mode (a sequence: as
        many modes as ratios). The modes above those kept have none."""
        return cls("modal", xi=xi, modal_modes=modes)

    @classmethod
    def rayleigh(cls, a0: float, a1: float) -> Damping:
        return cls("rayleigh", rayleigh_a0=a0, rayleigh_a1=a1)

    @classmethod
    def rayleigh_modes(
        cls, xi: float, mode_i: int, mode_j: int, system: str | None = None
    ) -> Damping:
        """Rayleigh damping with the ratio xi at modes mode_i and mode_j (1-based) of the
        'stuck' (default) or 'free' system: a0, a1 computed by the reader."""
        return cls("rayleigh", xi=xi, mode_i=mode_i, mode_j=mode_j, mode_system=system)

    def group(self) -> dict:
        g: dict = {"damping_type": _value(self.type)}
        xi = self.xi
        if xi is not None and not isinstance(xi, (str, bytes)) and np.ndim(xi) == 1:
            xi = [_value(x) for x in xi]
        _put(
            g,
            xi=xi,
            period=self.period,
            rayleigh_a0=self.rayleigh_a0,
            rayleigh_a1=self.rayleigh_a1,
            mode_i=_opt_int(self.mode_i, "mode_i"),
            mode_j=_opt_int(self.mode_j, "mode_j"),
            mode_system=self.mode_system,
            modal_modes=_opt_int(self.modal_modes, "modal_modes"),
        )
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

    def group(
        self, directory: Path | None, cwd: Path | None = None, record_name: str | None = None
    ) -> dict:
        g: dict = {
            "excitation_type": "harmonic",
            "amplitude": float(self.amplitude),
            "frequency": float(self.frequency),
        }
        _put(g, ramp_cycles=_opt_int(self.ramp_cycles, "ramp_cycles"))
        g.update(dt_record=float(self.dt_record), duration=float(self.duration))
        return g


@dataclass
class Record:
    """Recorded table acceleration (or displacement) sampled at dt_record: a file, or
    values that are written to a file for the run: by ``write_deck`` to ``file`` (relative
    to the deck's directory), or when ``file`` is None to ``<deck stem>.record.txt`` next to
    the deck; by ``run`` to a temporary directory (the base name of ``file``, or
    ``<stem of run's name>.record.txt``). dt_record, kind, scale, duration, format, units:
    None takes the reader's default (an AT2 file's DT, acceleration, 1, the whole record,
    'auto', the file's or SI units; dt_record is required but for an AT2 file)."""

    dt_record: float | None = None
    file: str | os.PathLike | None = None
    values: np.ndarray | None = None
    kind: str | None = None
    scale: float | None = None
    duration: float | None = None
    format: str | None = None
    units: str | None = None

    def group(
        self, directory: Path | None, cwd: Path | None = None, record_name: str | None = None
    ) -> dict:
        """The &excitation group; a Record with values writes them to ``directory`` under
        ``record_name`` (default: ``file``, or ``record.txt``). With ``cwd``, a relative file
        of a Record without values is made absolute against it (``Analysis.run`` passes the
        caller's working directory)."""
        file = None if self.file is None else os.fspath(self.file)
        if self.values is not None:
            if directory is None:
                raise ValueError("a Record with values needs a directory to write its file")
            file = record_name or file or "record.txt"
            np.savetxt(Path(directory) / file, np.asarray(self.values, float), fmt="%.17e")
        elif file is None:
            raise DeckError("a Record needs a file or values")
        elif cwd is not None and not os.path.isabs(file):
            file = os.fspath(Path(cwd) / file)
        g: dict = {"excitation_type": "record", "record_file": file}
        _put(g, record_kind=self.kind, record_scale=self.scale, record_format=self.format,
             record_units=self.units)
        if self.dt_record is not None:
            g["dt_record"] = float(self.dt_record)
        _put(g, duration=self.duration)
        return g


@dataclass
class FreeVibration:
    """No table motion: free vibration from the initial conditions."""

    dt_record: float
    duration: float

    def group(
        self, directory: Path | None, cwd: Path | None = None, record_name: str | None = None
    ) -> dict:
        return {
            "excitation_type": "none",
            "dt_record": float(self.dt_record),
            "duration": float(self.duration),
        }


@dataclass
class Integration:
    """Technique, Newmark and step-control settings (docs/namelist.md, &integration); None
    takes the reader's default. ``technique`` is 'newmark', 'event_driven' (exact, for
    'coulomb' devices) or 'moreau_jean' (time stepping for 'coulomb' devices; ``theta``).
    ``refinement`` is 'step' (the paper: a dt1 step with a phase change redone as n2 steps
    dt2), 'nested' (split by the prime factors of n2, only where a phase changes) or
    'implicit' (the dt1 step redone in the phases it ends in, as Newton-Raphson codes such as
    OpenSees resolve an elastic-perfectly-plastic link; transitions located to within dt1)."""

    technique: str | None = None
    beta: float | None = None
    gamma: float | None = None
    n1: int | None = None
    n2: int | None = None
    n: float | None = None
    check_correctness: bool | None = None
    dt_min: float | None = None
    theta: float | None = None
    refinement: str | None = None
    tolerance: float | None = None  #: a tolerance run (frictiondyn.tolerance)
    tolerance_floor: float | None = None

    def group(self) -> dict:
        g: dict = {}
        _put(
            g,
            technique=self.technique,
            beta=self.beta,
            gamma=self.gamma,
            n1=_opt_int(self.n1, "n1"),
            n2=_opt_int(self.n2, "n2"),
            n=self.n,
            check_correctness=self.check_correctness,
            dt_min=self.dt_min,
            theta=self.theta,
            refinement=self.refinement,
            tolerance=self.tolerance,
            tolerance_floor=self.tolerance_floor,
        )
        return g


@dataclass
class Output:
    """Output settings for the executable (&output); None takes the reader's default (dir
    'out', name the deck's stem, a row every dt_record, the history written, of every DOF
    and device)."""

    dir: str | None = None
    name: str | None = None
    output_every: int | None = None
    write_history: bool | None = None
    #: DOFs and devices (1-based) whose columns the history has; None: all, []: none
    history_dofs: list[int] | None = None
    history_devices: list[int] | None = None
    n_modes: int | None = None
    #: largest history the run may keep in memory or write [MB]; None: the reader's default
    max_history_mb: float | None = None

    def group(self) -> dict:
        g: dict = {}
        _put(
            g,
            dir=self.dir,
            name=self.name,
            output_every=_opt_int(self.output_every, "output_every"),
            write_history=self.write_history,
            n_modes=_opt_int(self.n_modes, "n_modes"),
            max_history_mb=self.max_history_mb,
        )
        for key in ("history_dofs", "history_devices"):
            value = getattr(self, key)
            if value is not None:
                if isinstance(value, (str, bytes)) or np.ndim(value) != 1:
                    raise DeckError(f"&output {key} must be a list of numbers, not {value!r}")
                g[key] = [_int(x, key) for x in value] if len(value) else 0
        return g


def _value(x: object) -> object:
    """A value as the deck holds it (numpy scalars and 0-d arrays to Python's, a path to its
    str)."""
    if isinstance(x, np.ndarray) and x.ndim == 0:
        x = x.item()
    if isinstance(x, np.generic):
        x = x.item()
    if isinstance(x, os.PathLike):
        return os.fspath(x)
    if isinstance(x, bool):
        return bool(x)
    if isinstance(x, int):
        return int(x)
    if isinstance(x, float):
        return float(x)
    if isinstance(x, str):
        return str(x)
    return x


def _int(x: object, name: str) -> int:
    """An integer setting (a node, n1, output_every, ...) as a Python int: a numpy integer or
    an integral float (20.0) is converted; a bool or a non-integral value raises DeckError
    naming the setting."""
    v = _value(x)
    if isinstance(v, float) and v.is_integer():
        return int(v)
    if isinstance(v, int) and not isinstance(v, bool):
        return v
    raise DeckError(f"{name} must be an integer, not {x!r}")


def _opt_int(x: object, name: str) -> int | None:
    return None if x is None else _int(x, name)


def _nodes(items: list, key: str) -> list[int]:
    return [_int(getattr(x, key), key) for x in items]


def _put(group: dict, **values: object) -> None:
    """Add the values that are given (not None) to a group."""
    for key, x in values.items():
        if x is not None:
            group[key] = _value(x)


def _fortran(x: object) -> str:
    """A value as f90nml writes it: repr of a float or int, a quoted string, .true./.false.,
    nothing for None (a null value: the reader keeps its default)."""
    if x is None:
        return ""
    if isinstance(x, bool):
        return ".true." if x else ".false."
    if isinstance(x, str):
        return "'" + x.replace("'", "''") + "'"
    return repr(x)


def _group_text(name: str, values: dict) -> str:
    """One namelist group, lists wrapped at about 72 columns (a group with a table, a list
    of lists, is written by f90nml, which knows the (:, i) form)."""
    if any(isinstance(v, list) and any(isinstance(x, list) for x in v) for v in values.values()):
        buf = io.StringIO()
        f90nml.Namelist({name: f90nml.Namelist(values)}).write(buf)
        return buf.getvalue()
    lines = [f"&{name}"]
    for key, value in values.items():
        head = f"    {key} = "
        if not isinstance(value, list):
            lines.append(head + _fortran(value))
            continue
        items = [_fortran(x) for x in value]
        line, indent = head, " " * len(head)
        for k, item in enumerate(items):
            piece = item + (", " if k < len(items) - 1 else "")
            if len(line) + len(piece) > 76 and line.strip() and line != head:
                lines.append(line.rstrip())
                line = indent
            line += piece
        lines.append(line.rstrip())
    lines.append("/")
    return "\n".join(lines) + "\n"


def _per_device(group: dict, key: str, values: list) -> None:
    """An optional per-device value: left out when no device gives it; a device that does
    not is a null value, which the reader fills with its default."""
    if any(x is not None for x in values):
        group[key] = [None if x is None else _value(x) for x in values]


def _friction_values(group: dict, items: list) -> None:
    """The per-item friction values shared by &friction and &isolators: mu (None items
    null), eps, eps1, f, mu(v), labels; tables as mu_table_v(:, i), mu_table_mu(:, i)."""
    _per_device(group, "mu", [x.mu for x in items])
    for key in ("eps", "eps1", "f", "mu_law", "mu_max", "mu_min", "mu_rate", "label"):
        _per_device(group, key, [getattr(x, key) for x in items])
    if any(x.mu_table is not None for x in items):
        n = max(len(x.mu_table or []) for x in items)
        for key, column in (("mu_table_v", 0), ("mu_table_mu", 1)):
            group[key] = [
                [float(point[column]) for point in x.mu_table or []]
                + [None] * (n - len(x.mu_table or []))
                for x in items
            ]


#: Where each deck group's variables live in an Analysis: the attribute (a list of items
#: when the group has an index) and the deck variable's field name where they differ.
_GROUP_FIELDS: dict[str, tuple[str, bool, dict[str, str]]] = {
    "model": ("", False, {"mass": "masses", "u0": "u0", "v0": "v0", "label": "labels",
                          "n_dof": "masses"}),
    "springs": ("springs", True, {}),
    "damping": ("damping", False, {"damping_type": "type"}),
    "friction": ("devices", True, {"mu_table_v": "mu_table", "mu_table_mu": "mu_table"}),
    "braces": ("braces", True, {}),
    "isolators": ("isolators", True, {"mu_table_v": "mu_table", "mu_table_mu": "mu_table"}),
    "bearings": ("bearings", True, {"mu_table_v": "mu_table", "mu_table_mu": "mu_table"}),
    "storeys": ("storeys", True, {}),
    "floors": ("floors.floors", True, {}),
    "frames": ("frames", True, {}),
    "floor_braces": ("floor_braces", True, {}),
    "matrices": ("matrices", False, {"k_file": "k", "m_file": "m", "label": "labels"}),
    "excitation": ("excitation", False, {"record_file": "file", "record_kind": "kind",
                                         "record_scale": "scale", "record_format": "format",
                                         "record_units": "units"}),
    "excitation2": ("excitation2", False, {"record_file": "file", "record_kind": "kind",
                                           "record_scale": "scale", "record_format": "format",
                                           "record_units": "units"}),
    "excitation3": ("excitation3", False, {"record_file": "file", "record_kind": "kind",
                                           "record_scale": "scale", "record_format": "format",
                                           "record_units": "units"}),
    "integration": ("integration", False, {}),
    "output": ("output", False, {}),
}
_DECK_PLACE = re.compile(
    r"group &(?P<group>[a-z_0-9]+): (?P<var>[a-z_0-9]+)(?:\((?P<i>\d+|:)(?:, *(?P<j>\d+))?\))?"
)


def python_place(message: str) -> str | None:
    """The Analysis attribute a deck message's "group &g: var(i)" names (devices[1].p for
    &friction p(2)); None when the message names none."""
    m = _DECK_PLACE.search(message)
    if m is None or m["group"] not in _GROUP_FIELDS:
        return None
    attr, indexed, names = _GROUP_FIELDS[m["group"]]
    var = names.get(m["var"], m["var"])
    index = m["j"] or (m["i"] if m["i"] != ":" else None)  # mu_table_v(:, i): item i
    if attr == "":  # &model: the Analysis's own lists
        return f"{var}[{int(index) - 1}]" if index else var
    if m["group"] == "floors" and (m["var"] in ("excitation_angle", "p_delta") or not index):
        return f"floors.{var}"  # the building's, or a list of every floor's
    if indexed and index and m["var"] not in ("n_springs", "n_devices", "n_braces", "n_isolators",
                                              "n_storeys", "n_frames", "n_floors", "n_bearings"):
        return f"{attr}[{int(index) - 1}].{var}"
    if indexed:
        return attr
    return f"{attr}.{var}"


def _run_named(name: str, base_dir: str | os.PathLike, run: Callable[[], Result]) -> Result:
    """run() of a generated deck: a DeckError says which attribute of the Analysis is
    wrong, and errors and warnings name the Analysis instead of the deck file the caller
    never wrote (warnings re-issued at the caller's line)."""
    deck = os.path.join(os.fspath(base_dir), name)
    try:
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always", FrictiondynWarning)
            result = run()
    except DeckError as exc:
        text = str(exc)
        for sep in (", ", ": "):  # "deck, group &g: ..." and "deck: group &g is ..."
            text = text.replace(deck + sep, "Analysis: ", 1)
        place = python_place(text)
        if place is not None:
            text = f"Analysis.{place}: " + text.replace("Analysis: ", "", 1)
        raise DeckError(text) from None
    level = _user_stacklevel()
    for w in caught:
        if issubclass(w.category, FrictiondynWarning):
            text = str(w.message).replace(deck + ": ", "Analysis: ", 1)
            warnings.warn(text, w.category, stacklevel=level)
        else:
            warnings.warn_explicit(w.message, w.category, w.filename, w.lineno)
    return result


#: the file names of the components' values next to a deck: <deck stem> + suffix
_RECORD_SUFFIXES = (".record.txt", ".record2.txt", ".record3.txt")


@dataclass
class Analysis:
    """One run: masses, springs, damping, friction devices, table motion and settings. The
    structure is ``masses`` (one DOF each, joined by ``springs``), or ``floors`` (a building
    of rigid floors with its ``frames`` and ``floor_braces``), or ``matrices`` (K and M);
    ``bearings`` are planar sliding bearings (``Bearing``) on any of them; ``excitation2`` is
    a second horizontal component of the table motion (with ``floors`` or ``matrices``),
    ``excitation3`` the vertical one (upward positive: it scales the bearings' normal
    forces; with ``bearings``)."""

    masses: list[float] | None = None
    springs: list[Spring] = field(default_factory=list)
    excitation: Harmonic | Record | FreeVibration | None = None
    damping: Damping = field(default_factory=Damping)
    devices: list[Device] = field(default_factory=list)
    integration: Integration = field(default_factory=Integration)
    output: Output = field(default_factory=Output)
    u0: list[float] | None = None
    v0: list[float] | None = None
    braces: list[FrictionBrace] = field(default_factory=list)
    isolators: list[SlidingIsolator] = field(default_factory=list)
    storeys: list[Storey] = field(default_factory=list)
    labels: list[str] | None = None  #: a name per DOF ('floor 3')
    floors: Floors | None = None
    frames: list[Frame] = field(default_factory=list)
    floor_braces: list[FloorBrace] = field(default_factory=list)
    matrices: Matrices | None = None
    excitation2: Harmonic | Record | None = None
    bearings: list[Bearing] = field(default_factory=list)
    excitation3: Harmonic | Record | None = None
    tolerance: float | None = None  #: a tolerance run: Integration's tolerance, given here

    def namelist(
        self, directory: Path | None = None, cwd: Path | None = None, record_name: str | None = None,
        record_name2: str | None = None, stem: str = "analysis", record_name3: str | None = None,
    ) -> f90nml.Namelist:
        """The deck as an f90nml Namelist (writes a Record's values into directory; with
        cwd, a relative record file is made absolute against it)."""
        nml = f90nml.Namelist()
        for name, values in self.groups(directory, cwd, record_name, record_name2, stem,
                                        record_name3):
            nml[name] = f90nml.Namelist(values)
        return nml

    def _structure(self, directory: Path | None, cwd: Path | None, stem: str) -> list[tuple[str, dict]]:
        """The groups of the structure: &model, or &floors and &frames, or &matrices."""
        given = [k for k, v in (("masses", self.masses), ("floors", self.floors),
                                ("matrices", self.matrices)) if v is not None]
        if len(given) != 1:
            raise DeckError("Analysis: give the structure as one of masses, floors or matrices"
                            + (f", not {' and '.join(given)}" if given else ""))
        if self.floors is not None:
            groups = [("floors", self.floors.group())]
            fr = self.frames
            if fr:
                frames = {"n_frames": len(fr), "storey": _nodes(fr, "storey")}
                for key in ("angle", "x", "y", "k"):
                    frames[key] = [float(getattr(x, key)) for x in fr]
                groups.append(("frames", frames))
            return groups
        if self.matrices is not None:
            return [("matrices", self.matrices.group(directory, cwd, stem))]
        n = len(self.masses)
        model = {"n_dof": n, "mass": [float(m) for m in self.masses]}
        if self.u0 is not None:
            model["u0"] = [float(x) for x in self.u0]
        if self.v0 is not None:
            model["v0"] = [float(x) for x in self.v0]
        if self.labels is not None:
            if isinstance(self.labels, (str, bytes)):
                raise TypeError(f"labels must be a list (a label per DOF), not {self.labels!r}")
            # None: the default label of that DOF (a null value in the deck)
            _per_device(model, "label", [None if x is None else str(x) for x in self.labels])
        return [("model", model)]

    def groups(
        self, directory: Path | None = None, cwd: Path | None = None, record_name: str | None = None,
        record_name2: str | None = None, stem: str = "analysis", record_name3: str | None = None,
    ) -> list[tuple[str, dict]]:
        """The deck's groups and their values, in order (writes a Record's values, and the
        matrices of ``matrices`` given as arrays, into directory, the second component's
        values under record_name2, the vertical one's under record_name3, the matrices as
        <stem>.K.mtx and <stem>.M.mtx; with cwd, a relative record or matrix file is made
        absolute against it)."""
        if self.excitation is None:
            raise DeckError("Analysis.excitation: the table motion is required (Harmonic, Record "
                            "or FreeVibration)")
        groups = self._structure(directory, cwd, stem)
        if self.springs or self.masses is not None:
            springs = {"n_springs": len(self.springs)}
            if self.springs:
                springs.update(
                    node_i=_nodes(self.springs, "node_i"),
                    node_j=_nodes(self.springs, "node_j"),
                    k=[float(s.k) for s in self.springs],
                )
            groups.append(("springs", springs))
        groups.append(("damping", self.damping.group()))
        if self.devices:
            d = self.devices
            friction = {
                "n_devices": len(d),
                "node_i": _nodes(d, "node_i"),
                "node_j": _nodes(d, "node_j"),
                "law": [x.law for x in d],
                "p": [float(x.p) for x in d],
            }
            _friction_values(friction, d)
            groups.append(("friction", friction))
        if self.braces:
            b = self.braces
            braces = {
                "n_braces": len(b),
                "node_i": _nodes(b, "node_i"),
                "node_j": _nodes(b, "node_j"),
                "slip_load": [float(x.slip_load) for x in b],
                "stiffness": [float(x.stiffness) for x in b],
            }
            for key in ("eps1", "label"):
                _per_device(braces, key, [getattr(x, key) for x in b])
            groups.append(("braces", braces))
        if self.isolators:
            s = self.isolators
            isolators = {
                "n_isolators": len(s),
                "node_i": _nodes(s, "node_i"),
                "node_j": _nodes(s, "node_j"),
                "law": [x.law for x in s],
                "weight": [float(x.weight) for x in s],
            }
            _per_device(isolators, "radius", [x.radius for x in s])
            _friction_values(isolators, s)
            groups.append(("isolators", isolators))
        if self.floor_braces:
            fb = self.floor_braces
            braces = {"n_braces": len(fb), "storey": _nodes(fb, "storey")}
            for key in ("angle", "x", "y", "slip_load"):
                braces[key] = [float(getattr(x, key)) for x in fb]
            for key in ("stiffness", "law", "eps", "eps1", "label"):
                _per_device(braces, key, [getattr(x, key) for x in fb])
            groups.append(("floor_braces", braces))
        bearings = self.bearings
        if bearings is not None and (not isinstance(bearings, Sequence)
                                     or isinstance(bearings, (str, bytes)) or len(bearings)):
            groups.append(("bearings", _bearings_group(bearings, self.floors is not None)))
        if self.storeys:
            st = self.storeys
            storeys: dict = {"n_storeys": len(st)}
            for key in ("node_i", "node_j", "spring"):
                _per_device(storeys, key, [_opt_int(getattr(x, key), key) for x in st])
            for key in ("height", "label"):
                _per_device(storeys, key, [getattr(x, key) for x in st])
            groups.append(("storeys", storeys))
        for attr in ("excitation", "excitation2", "excitation3"):  # not the reader's temporary file
            rec = getattr(self, attr)
            if isinstance(rec, Record) and rec.values is not None and rec.dt_record is None \
                    and np.ndim(rec.values) == 1:
                raise DeckError(f"Analysis.{attr}.dt_record: a Record of values needs its step "
                                "dt_record [s] (an AT2 file gives its own DT)")
        groups.append(("excitation", self.excitation.group(directory, cwd, record_name)))
        if self.excitation2 is not None:
            groups.append(("excitation2", self.excitation2.group(directory, cwd, record_name2)))
        if self.excitation3 is not None:
            if not isinstance(self.excitation3, (Harmonic, Record)):
                raise DeckError("Analysis.excitation3 must be a Harmonic or a Record (the vertical "
                                f"ground motion), not {self.excitation3!r}")
            groups.append(("excitation3", self.excitation3.group(directory, cwd, record_name3)))
        integration = self.integration.group()
        if integration:
            groups.append(("integration", integration))
        out = self.output.group()
        if out:
            groups.append(("output", out))
        return groups

    def deck_text(
        self, directory: Path | None = None, cwd: Path | None = None, record_name: str | None = None,
        record_name2: str | None = None, stem: str = "analysis", record_name3: str | None = None,
    ) -> str:
        """The deck as namelist text (writes a Record's values into directory, under
        record_name (record_name2 for ``excitation2``, record_name3 for ``excitation3``) or
        the Record's file, and matrices given as arrays as <stem>.K.mtx, <stem>.M.mtx; with
        cwd, a relative record or matrix file is made absolute against it)."""
        return "\n".join(
            _group_text(name, values)
            for name, values in self.groups(directory, cwd, record_name, record_name2, stem,
                                            record_name3)
        )

    def write_deck(self, path: str | os.PathLike) -> Path:
        """Write the deck (and a Record's values next to it: to its ``file``, or when that is
        None to ``<deck stem>.record.txt`` (``.record2.txt`` for ``excitation2``,
        ``.record3.txt`` for ``excitation3``), so that decks written into one directory do not
        share one record file; matrices given as arrays to ``<deck stem>.K.mtx``, ``.M.mtx``)
        for the executable."""
        path = Path(path)
        names = []
        for ex, suffix in zip(self._components(), _RECORD_SUFFIXES, strict=True):
            unnamed = isinstance(ex, Record) and ex.values is not None and ex.file is None
            names.append(path.stem + suffix if unnamed else None)
        path.write_text(self.deck_text(path.parent, None, names[0], names[1], path.stem, names[2]))
        return path

    def _components(self) -> tuple:
        """The three components of the ground motion (None where not given)."""
        return (self.excitation, self.excitation2, self.excitation3)

    def _needs_directory(self) -> bool:
        """Whether the deck needs files written for it: a Record's values, a matrix."""
        records = any(isinstance(ex, Record) and ex.values is not None for ex in self._components())
        mats = self.matrices is not None and not all(
            isinstance(a, (str, os.PathLike)) for a in (self.matrices.k, self.matrices.m))
        return records or mats

    def run(
        self,
        name: str = "analysis.nml",
        dofs: Sequence[int] | None = None,
        devices: Sequence[int] | None = None,
        progress: Callable[[float, float], object] | None = None,
    ) -> Result:
        """Run through the extension (no deck file needed; a Record's values go to a
        temporary directory for the duration of the run, under the base name of its
        ``file``: no file of the caller's is written; a Record's relative ``file`` without
        values is the caller's, relative to the current working directory). ``dofs``,
        ``devices``, ``progress``: as for ``frictiondyn.run`` (each None: the ``output``'s
        history_dofs, history_devices)."""
        kw = {"dofs": dofs, "devices": devices, "progress": progress, "tolerance": self.tolerance}
        cwd = Path.cwd()
        stem = Path(name).stem
        if not self._needs_directory():
            text = self.deck_text(None, cwd, stem=stem)
            return _run_named(name, ".", lambda: run_text(text, name=name, base_dir=".", **kw))
        # only inside the temporary directory: a file given with a directory (absolute or
        # not) is never written to
        # (no file: named as write_deck names it, <stem of name>.record.txt, .record2.txt,
        # .record3.txt; a name another component took: that default)
        names: list[str] = []
        for ex, suffix in zip(self._components(), _RECORD_SUFFIXES, strict=True):
            file = ex.file if isinstance(ex, Record) else None
            default = stem + suffix
            name_k = default if file is None else (Path(os.fspath(file)).name or default)
            names.append(default if name_k in names else name_k)
        with tempfile.TemporaryDirectory() as tmp:
            directory = Path(tmp)
            text = self.deck_text(directory, cwd, names[0], names[1], stem, names[2])
            return _run_named(name, directory,
                              lambda: run_text(text, name=name, base_dir=directory, **kw))
