"""Plots of one or several Results for reports (matplotlib Figures on the Agg canvas; no
pyplot state).

Every function takes a Result or a sequence of Results (overlaid, one line each) and
returns the Figure; keyword options are common to all:

- ``path``: a PNG (or any format matplotlib writes) is saved there, at ``dpi`` (default 150);
- ``ax``: draw into this Axes instead of a new figure, so that figures compose as subplots
  (``fig, axes = plots.figure(2, 2)``, then one call per panel, then ``plots.save``);
- ``t_range``: ``(t0, t1)``, or ``"all"`` for the whole run; by default the last
  ``cycles`` (5) cycles of a harmonic run and the whole of any other run. Long histories are
  thinned to at most ``max_points`` points per line by keeping each interval's minimum and
  maximum, so peaks survive and the plot is not a solid block of ink;
- ``units``: ``plots.Units(...)``, or text such as ``"mm,kN,g"`` (length m/cm/mm, force
  N/kN/MN, acceleration m/s2/cm/s2/g, velocity m/s/cm/s/mm/s); SI by default;
- ``labels``: legend names of the results (default: the deck's name); the deck's ``label``
  of each DOF, device and storey names panels and axes ("roof", "damper 2");
- ``title``: the panel's title (``""`` for none; a descriptive one by default);
- ``cycles`` (5) and ``max_points`` (5000; 0: no thinning), as above.

The profiles take ``ax``, ``labels``, ``title``, ``units`` and ``dpi``. An unknown option is a
TypeError naming it.

Time histories: ``plot_acceleration``, ``plot_relative_velocity``, ``plot_phase``,
``plot_drift``, ``plot_storey_shear``, ``plot_base_shear``, ``plot_columns``; loops:
``plot_hysteresis`` (device force vs slip), ``plot_storey_loop`` (storey shear vs drift);
profiles over the height: ``plot_drift_profile``, ``plot_acceleration_profile``; a building
of rigid floors: ``plot_orbit`` (the roof's ux against uy), ``plot_device_plan`` (the braces
in plan with their peak forces); sets: ``plot_compare`` and ``plot_all`` (what the command
line writes).
"""

from __future__ import annotations

import os
from collections.abc import Sequence
from dataclasses import dataclass
from itertools import pairwise
from pathlib import Path

import numpy as np
from matplotlib.axes import Axes
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure

from ._api import Result

__all__ = [
    "REPORT_UNITS",
    "SI",
    "Units",
    "auto_window",
    "figure",
    "plot_acceleration",
    "plot_acceleration_profile",
    "plot_all",
    "plot_base_shear",
    "plot_columns",
    "plot_compare",
    "plot_device_plan",
    "plot_drift",
    "plot_drift_profile",
    "plot_hysteresis",
    "plot_orbit",
    "plot_phase",
    "plot_relative_velocity",
    "plot_storey_loop",
    "plot_storey_shear",
    "save",
    "thin",
    "window",
]

Results = Result | Sequence[Result]
TRange = tuple[float, float] | str | None
PathLike = str | os.PathLike | None

G = 9.80665  # standard gravity [m/s2], for accelerations in g

_SIZE = (8.0, 4.0)
_DPI = 150
_CYCLES = 5
_MAX_POINTS = 5000

# unit name -> factor from SI, per kind
_FACTORS = {
    "length": {"m": 1.0, "cm": 100.0, "mm": 1000.0},
    "force": {"N": 1.0, "kN": 1e-3, "MN": 1e-6},
    "acceleration": {"m/s2": 1.0, "cm/s2": 100.0, "g": 1.0 / G},
    "velocity": {"m/s": 1.0, "cm/s": 100.0, "mm/s": 1000.0},
}
# the SI unit of a column -> its kind
_KIND = {"m": "length", "N": "force", "m/s2": "acceleration", "m/s": "velocity"}
_PRETTY = {"m/s2": "m/s²", "cm/s2": "cm/s²"}


@dataclass(frozen=True)
class Units:
    """Units of the plotted quantities (the results stay SI)."""

    length: str = "m"
    force: str = "N"
    acceleration: str = "m/s2"
    velocity: str = "m/s"

    def __post_init__(self) -> None:
        for kind, table in _FACTORS.items():
            if getattr(self, kind) not in table:
                choices = ", ".join(table)
                raise ValueError(f"{kind} unit {getattr(self, kind)!r}: one of {choices}")

    @classmethod
    def parse(cls, spec: Units | str | None) -> Units:
        """Units from ``None`` (SI), a Units, or text naming some units: ``"mm,kN,g"``."""
        if spec is None:
            return SI
        if isinstance(spec, Units):
            return spec
        chosen: dict[str, str] = {}
        for token in str(spec).replace(" ", ",").split(","):
            if not token:
                continue
            kinds = [k for k, table in _FACTORS.items() if token in table]
            if not kinds:
                known = ", ".join(u for table in _FACTORS.values() for u in table)
                raise ValueError(f"unit {token!r} is not one of {known}")
            chosen[kinds[0]] = token
        return cls(**chosen)

    def factor(self, si_unit: str) -> float:
        kind = _KIND.get(si_unit)
        return _FACTORS[kind][getattr(self, kind)] if kind else 1.0

    def name(self, si_unit: str) -> str:
        kind = _KIND.get(si_unit)
        unit = getattr(self, kind) if kind else si_unit
        return _PRETTY.get(unit, unit)


SI = Units()
REPORT_UNITS = Units("mm", "kN", "g", "mm/s")  #: the usual units of a design report


# --------------------------------------------------------------------------- helpers


def _as_list(results: Results) -> list[Result]:
    out = [results] if isinstance(results, Result) else list(results)
    if not out:
        raise ValueError("nothing to plot: no result given")
    return out


def default_label(result: Result, index: int) -> str:
    """The deck's name (file name without directory and extension), or 'result <index+1>'."""
    deck = result.summary.get("deck") if result.summary else None
    if deck:
        name = Path(str(deck)).name
        return name.rsplit(".", 1)[0] if "." in name else name
    return f"result {index + 1}"


def _labels(results: list[Result], labels: Sequence[str] | None) -> list[str]:
    if labels is None:
        return [default_label(r, i) for i, r in enumerate(results)]
    if len(labels) != len(results):
        raise ValueError(f"{len(labels)} labels for {len(results)} results")
    return [str(x) for x in labels]


def window(result: Result, t_range: tuple[float, float] | None) -> np.ndarray:
    """Boolean mask of the rows with t0 <= t <= t1 (every row when t_range is None)."""
    t = result.time
    if t_range is None:
        return np.ones(t.shape, bool)
    t0, t1 = t_range
    if not t1 > t0:
        raise ValueError(f"empty time range: t0 = {t0} s, t1 = {t1} s")
    mask = (t >= t0) & (t <= t1)
    if not mask.any():
        raise ValueError(
            f"no history row in t = {t0:g} ... {t1:g} s; the result covers "
            f"t = {t[0]:g} ... {t[-1]:g} s"
        )
    return mask


def auto_window(result: Result, cycles: int = _CYCLES) -> tuple[float, float] | None:
    """The default time window: the last ``cycles`` cycles of a harmonic run (from the
    summary's excitation), None (the whole run) otherwise."""
    s = result.summary or {}
    freq = s.get("excitation_frequency_Hz")
    t = result.time
    if s.get("excitation_type") == "harmonic" and freq and len(t) > 1:
        t1 = float(t[-1])
        t0 = max(float(t[0]), t1 - cycles / float(freq))
        if t0 < t1:
            return (t0, t1)
    return None


def _resolve(result: Result, t_range: TRange, cycles: int) -> tuple[float, float] | None:
    if t_range is None:
        return auto_window(result, cycles)
    if isinstance(t_range, str):
        if t_range != "all":
            raise ValueError(f"t_range {t_range!r}: (t0, t1), 'all' or None")
        return None
    return (float(t_range[0]), float(t_range[1]))


def thin(
    x: np.ndarray, y: np.ndarray, max_points: int = _MAX_POINTS
) -> tuple[np.ndarray, np.ndarray]:
    """At most about ``max_points`` points of the line (x, y), x increasing: each of
    max_points / 2 intervals keeps its minimum and maximum of y in their order, so every
    peak of y is kept. Lines that are short enough are returned as they are."""
    n = len(x)
    if max_points <= 0 or n <= max_points:
        return x, y
    buckets = max(1, max_points // 2)
    edges = np.linspace(0, n, buckets + 1).astype(int)
    keep = []
    for a, b in pairwise(edges):
        if b <= a:
            continue
        seg = y[a:b]
        i, j = a + int(np.argmin(seg)), a + int(np.argmax(seg))
        keep.extend(sorted({i, j}))
    keep = np.unique(np.array(keep + [0, n - 1]))
    return x[keep], y[keep]


def _figure(size: tuple[float, float]) -> Figure:
    """A Figure on the Agg canvas, outside pyplot (no global state, safe in threads)."""
    fig = Figure(figsize=size, layout="constrained")
    FigureCanvasAgg(fig)
    return fig


def figure(
    rows: int = 1, cols: int = 1, size: tuple[float, float] | None = None, **kw
) -> tuple[Figure, np.ndarray]:
    """A figure of rows x cols panels on the Agg canvas and its Axes (a 2-D array), to fill
    with the plot functions' ``ax=``; ``kw`` go to ``Figure.subplots`` (e.g. sharex)."""
    fig = _figure(size or (5.0 * cols, 3.2 * rows))
    axes = fig.subplots(rows, cols, squeeze=False, **kw)
    return fig, axes


def save(fig: Figure, path: str | os.PathLike, dpi: int | None = None) -> Path:
    """Save a figure (format from the suffix) at ``dpi`` (default 150)."""
    fig.savefig(os.fspath(path), dpi=dpi or _DPI)
    return Path(path)


def _axes(ax: Axes | None, size: tuple[float, float] = _SIZE) -> tuple[Figure, Axes]:
    if ax is not None:
        return ax.figure, ax
    fig = _figure(size)
    return fig, fig.add_subplot()


def _finish(fig: Figure, path: PathLike, dpi: int | None) -> Figure:
    if path is not None:
        save(fig, path, dpi)
    return fig


def _title(ax: Axes, title: str | None, default: str) -> None:
    text = default if title is None else title
    if text:
        ax.set_title(text)


def _check_column(results: list[Result], name: str) -> None:
    for i, r in enumerate(results):
        if name not in r:
            raise KeyError(
                f"result {i + 1} has no column {name!r}; its columns are {', '.join(r.names)}"
            )


_DESCRIPTION = {
    "t": "time",
    "ag": "table acceleration",
    "u": "relative displacement",
    "v": "relative velocity",
    "aabs": "absolute acceleration",
    "s": "relative displacement",
    "sdot": "relative velocity",
    "F": "friction force",
    "phase": "phase",
    "drift": "drift",
    "V": "storey shear",
    "Vb": "base shear",
}


def _prefix(name: str) -> str:
    return name.rstrip("0123456789")


def _axis_label(result: Result, name: str, units: Units, describe: bool) -> str:
    unit = result.units.get(name, "")
    text = _DESCRIPTION.get(_prefix(name), name) if describe else name
    if not unit or unit == "-":
        return text
    return f"{text} [{units.name(unit)}]"


@dataclass
class _Options:
    """The keyword options every time-history and loop plot takes (module docstring)."""

    ax: Axes | None = None
    t_range: TRange = None
    labels: Sequence[str] | None = None
    title: str | None = None
    units: Units | str | None = None
    dpi: int | None = None
    cycles: int = _CYCLES
    max_points: int = _MAX_POINTS

    @classmethod
    def of(cls, function: str, options: dict) -> _Options:
        unknown = set(options) - set(cls.__dataclass_fields__)
        if unknown:
            known = ", ".join(cls.__dataclass_fields__)
            raise TypeError(f"{function}() got unknown options {sorted(unknown)}; options: {known}")
        return cls(**options)


def _overlay(
    ax: Axes,
    results: list[Result],
    x: str,
    y: str,
    opt: _Options,
    *,
    describe: bool = True,
    drawstyle: str = "default",
    loop: bool = False,
) -> None:
    _check_column(results, x)
    _check_column(results, y)
    units = Units.parse(opt.units)
    for r, name in zip(results, _labels(results, opt.labels), strict=True):
        m = window(r, _resolve(r, opt.t_range, opt.cycles))
        xs = r[x][m] * units.factor(r.units.get(x, ""))
        ys = r[y][m] * units.factor(r.units.get(y, ""))
        if not loop and drawstyle == "default":
            xs, ys = thin(xs, ys, opt.max_points)
        elif loop and len(xs) > 4 * opt.max_points > 0:
            step = int(np.ceil(len(xs) / (4 * opt.max_points)))
            xs, ys = xs[::step], ys[::step]
        ax.plot(xs, ys, label=name, linewidth=0.9, drawstyle=drawstyle)
    ax.set_xlabel(_axis_label(results[0], x, units, describe))
    ax.set_ylabel(_axis_label(results[0], y, units, describe))
    ax.grid(True, linewidth=0.3)
    if len(results) > 1:
        ax.legend(fontsize="small")


def _item_label(results: list[Result], kind: str, k: int) -> str:
    names = getattr(results[0], f"{kind}_labels")
    return names[k - 1] if 0 < k <= len(names) else f"{kind} {k}"


def _plot(
    function: str,
    results: Results,
    x: str,
    y: str,
    default_title: str,
    path: PathLike,
    options: dict,
    *,
    size: tuple[float, float] = _SIZE,
    **overlay,
) -> tuple[Figure, Axes, _Options]:
    """One panel of y against x for each result, with the common options; saved when path."""
    opt = _Options.of(function, options)
    rs = _as_list(results)
    _check_column(rs, y)
    fig, ax = _axes(opt.ax, size)
    _overlay(ax, rs, x, y, opt, **overlay)
    _title(ax, opt.title, default_title)
    return fig, ax, opt


# --------------------------------------------------------------------------- time histories


def plot_columns(
    results: Results, y: str, path: PathLike = None, *, x: str = "t", **options
) -> Figure:
    """Column ``y`` against column ``x`` (default time) of each result, overlaid; the axes
    are named by the columns ("u1 [m]")."""
    fig, _, opt = _plot(
        "plot_columns", results, x, y, f"{y} vs {x}", path, options, describe=False, loop=x != "t"
    )
    return _finish(fig, path, opt.dpi)


def plot_acceleration(results: Results, dof: int, path: PathLike = None, **options) -> Figure:
    """Absolute acceleration of DOF ``dof`` (1-based) vs time, one line per result (the
    paper's Figs. 3a, 4a, 4b)."""
    name = _item_label(_as_list(results), "dof", dof)
    fig, _, opt = _plot(
        "plot_acceleration",
        results,
        "t",
        f"aabs{dof}",
        f"{name}: absolute acceleration",
        path,
        options,
    )
    return _finish(fig, path, opt.dpi)


def plot_relative_velocity(
    results: Results, device: int, path: PathLike = None, *, band: float | None = None, **options
) -> Figure:
    """Relative velocity difference s' of device ``device`` vs time (the paper's Fig. 3b).
    ``band`` (eps or eps1 [m/s]) adds two dashed lines at +-band."""
    name = _item_label(_as_list(results), "device", device)
    fig, ax, opt = _plot(
        "plot_relative_velocity",
        results,
        "t",
        f"sdot{device}",
        f"{name}: relative velocity",
        path,
        options,
    )
    if band is not None:
        f = Units.parse(opt.units).factor("m/s")
        for sign in (1.0, -1.0):
            ax.axhline(sign * band * f, color="0.4", linestyle="--", linewidth=0.7)
    return _finish(fig, path, opt.dpi)


def plot_phase(results: Results, device: int, path: PathLike = None, **options) -> Figure:
    """Phase of device ``device`` vs time: -1 slip -, 0 stick, +1 slip + (steps; every row)."""
    name = _item_label(_as_list(results), "device", device)
    fig, ax, opt = _plot(
        "plot_phase",
        results,
        "t",
        f"phase{device}",
        f"{name}: stick/slip phase",
        path,
        options,
        size=(8.0, 3.0),
        drawstyle="steps-post",
    )
    ax.set_yticks([-1, 0, 1], ["slip \u2212", "stick", "slip +"])
    ax.set_ylim(-1.3, 1.3)
    return _finish(fig, path, opt.dpi)


def plot_drift(results: Results, storey: int, path: PathLike = None, **options) -> Figure:
    """Drift of storey ``storey`` (1-based; decks with &storeys) vs time."""
    name = _item_label(_as_list(results), "storey", storey)
    fig, _, opt = _plot(
        "plot_drift", results, "t", f"drift{storey}", f"{name}: drift", path, options
    )
    return _finish(fig, path, opt.dpi)


def plot_storey_shear(results: Results, storey: int, path: PathLike = None, **options) -> Figure:
    """Storey shear of storey ``storey`` (1-based; decks with &storeys) vs time."""
    name = _item_label(_as_list(results), "storey", storey)
    fig, _, opt = _plot(
        "plot_storey_shear", results, "t", f"V{storey}", f"{name}: storey shear", path, options
    )
    return _finish(fig, path, opt.dpi)


def plot_base_shear(results: Results, path: PathLike = None, **options) -> Figure:
    """Base shear vs time (decks with &storeys)."""
    fig, _, opt = _plot("plot_base_shear", results, "t", "Vb", "base shear", path, options)
    return _finish(fig, path, opt.dpi)


# --------------------------------------------------------------------------- loops


def plot_hysteresis(results: Results, device: int, path: PathLike = None, **options) -> Figure:
    """Friction force F vs relative displacement s of device ``device``: its loops (the
    paper's Fig. 2)."""
    name = _item_label(_as_list(results), "device", device)
    fig, _, opt = _plot(
        "plot_hysteresis",
        results,
        f"s{device}",
        f"F{device}",
        f"{name}: force-displacement loop",
        path,
        options,
        size=(6.0, 4.5),
        loop=True,
    )
    return _finish(fig, path, opt.dpi)


def plot_storey_loop(results: Results, storey: int, path: PathLike = None, **options) -> Figure:
    """Storey shear vs drift of storey ``storey``: the loops of the whole storey (frame,
    damping and devices)."""
    name = _item_label(_as_list(results), "storey", storey)
    fig, _, opt = _plot(
        "plot_storey_loop",
        results,
        f"drift{storey}",
        f"V{storey}",
        f"{name}: shear vs drift",
        path,
        options,
        size=(6.0, 4.5),
        loop=True,
    )
    return _finish(fig, path, opt.dpi)


# --------------------------------------------------------------------------- profiles


def _storey_levels(r: Result) -> tuple[np.ndarray, bool]:
    """Bottom and top level of each storey: heights [m] when the storeys form a stack from
    the table and some heights are given (a storey without one, such as an isolation layer,
    counts as 0 m), else storey numbers; (levels (ns, 2), in metres)."""
    s = r.summary
    nodes = s.get("storey_nodes") or []
    heights = list(s.get("storey_height_m") or [])  # 0: not given
    z = {0: 0.0}
    if nodes and any(h > 0 for h in heights):
        pending = list(range(len(nodes)))
        while pending:
            done = [k for k in pending if nodes[k][1] in z]
            if not done:
                break
            for k in done:
                z[nodes[k][0]] = z[nodes[k][1]] + float(heights[k])
                pending.remove(k)
        if not pending:
            return np.array([[z[j], z[i]] for i, j in nodes]), True
    n = len(nodes)
    return np.column_stack([np.arange(n), np.arange(1, n + 1)]).astype(float), False


def _storey_chains(r: Result) -> list[list[int]]:
    """The storeys (0-based) as stacks from the table: each stack the storeys one above the
    other, bottom first (a building of rigid floors has one along x and one along y). A
    storey in no stack from the table is a stack of its own."""
    nodes = [tuple(n) for n in (r.summary.get("storey_nodes") or [])]
    above = {}
    for k, (i, j) in enumerate(nodes):
        above.setdefault(j, []).append(k)
    chains, seen = [], set()
    for k in above.get(0, []):
        chain = [k]
        while len(above.get(nodes[chain[-1]][0], [])) == 1:
            chain.append(above[nodes[chain[-1]][0]][0])
        chains.append(chain)
        seen.update(chain)
    return chains + [[k] for k in range(len(nodes)) if k not in seen] if chains else [list(range(len(nodes)))]


def _chain_name(r: Result, chain: list[int]) -> str:
    """The direction a stack of storeys shares ('x' of 'storey 1 x', ...), '' if none."""
    words = {lab.split()[-1] for lab in (r.storey_labels[k] for k in chain) if len(lab.split()) > 1}
    return words.pop() if len(words) == 1 and len(chain) > 1 and next(iter(words), "") in ("x", "y") else ""


def _floor_levels(r: Result) -> tuple[np.ndarray, bool]:
    """Level of each DOF: its height when the storeys give it, else its number."""
    levels, metres = _storey_levels(r)
    nodes = r.summary.get("storey_nodes") or []
    if metres:
        z = {i: top for (i, _), (_, top) in zip(nodes, levels, strict=True)}
        if all(i in z for i in range(1, r.n_dof + 1)):
            return np.array([z[i] for i in range(1, r.n_dof + 1)]), True
    return np.arange(1, r.n_dof + 1, dtype=float), False


def plot_drift_profile(
    results: Results,
    path: PathLike = None,
    *,
    ax: Axes | None = None,
    ratio: bool | None = None,
    residual: bool = False,
    labels: Sequence[str] | None = None,
    title: str | None = None,
    units: Units | str | None = None,
    dpi: int | None = None,
) -> Figure:
    """Peak inter-storey drift of every storey over the height (decks with &storeys), one
    profile per result: constant over each storey, against the height when the storeys give
    it. ``ratio`` plots the drift ratio in % (default: when every storey has a height);
    ``residual`` adds the residual drifts (dashed)."""
    rs = _as_list(results)
    names = _labels(rs, labels)
    fig, ax = _axes(ax, (4.5, 5.0))
    u = Units.parse(units)
    for k, (r, name) in enumerate(zip(rs, names, strict=True)):
        s = r.summary
        if not r.n_storeys:
            raise ValueError(f"{name}: no storeys (give &storeys in the deck)")
        use_ratio = ratio if ratio is not None else all(h > 0 for h in s["storey_height_m"])
        key = "drift_ratio" if use_ratio else "drift_m"
        if use_ratio and not all(h > 0 for h in s["storey_height_m"]):
            raise ValueError(f"{name}: drift ratios need every storey's height")
        scale = 100.0 if use_ratio else u.factor("m")
        levels, metres = _storey_levels(r)
        chains = _storey_chains(r)
        for c, chain in enumerate(chains):
            color = f"C{k * len(chains) + c}"
            direction = _chain_name(r, chain)
            for kind, style in (("peak", "-"), ("residual", "--")):
                if kind == "residual" and not residual:
                    continue
                values = np.abs(np.array(s[f"{kind}_{key}"], dtype=float)[chain]) * scale
                xs = np.repeat(values, 2)
                ys = levels[chain].reshape(-1)
                lab = name if not direction else f"{name}, {direction}" if len(rs) > 1 else direction
                lab = lab if kind == "peak" else f"{lab}, residual"
                ax.plot(xs, ys, style, color=color, linewidth=1.2, label=lab)
                ax.plot(values, levels[chain].mean(axis=1), "o", color=color, markersize=3.5)
    r0 = rs[0]
    levels, metres = _storey_levels(r0)
    if metres:
        ax.set_ylabel("height [m]")
    else:
        chain = _storey_chains(r0)[0]
        ax.set_yticks(levels[chain].mean(axis=1), [r0.storey_labels[k] for k in chain])
        ax.set_ylabel("storey")
    ax.set_ylim(bottom=0.0)
    ax.set_xlim(0.0, 1.08 * max(ln.get_xdata().max() for ln in ax.get_lines()))
    use_ratio = ratio if ratio is not None else all(h > 0 for h in r0.summary["storey_height_m"])
    ax.set_xlabel("drift ratio [%]" if use_ratio else f"drift [{u.name('m')}]")
    ax.grid(True, linewidth=0.3)
    if len(rs) > 1 or residual or len(_storey_chains(r0)) > 1:
        ax.legend(fontsize="small", loc="best")
    _title(ax, title, "peak inter-storey drift")
    return _finish(fig, path, dpi)


def plot_acceleration_profile(
    results: Results,
    path: PathLike = None,
    *,
    ax: Axes | None = None,
    labels: Sequence[str] | None = None,
    title: str | None = None,
    units: Units | str | None = None,
    dpi: int | None = None,
) -> Figure:
    """Peak absolute acceleration of every DOF (floor) over the height, with the table's
    peak acceleration at level 0, one profile per result (peaks over every step, from the
    summary; the table's from the history rows)."""
    rs = _as_list(results)
    names = _labels(rs, labels)
    fig, ax = _axes(ax, (4.5, 5.0))
    u = Units.parse(units)
    f = u.factor("m/s2")
    for r, name in zip(rs, names, strict=True):
        peaks = np.array(r.summary["peak_aabs_mps2"], dtype=float) * f
        chains = _storey_chains(r) if r.n_storeys else []
        if len(chains) > 1:
            # one curve per stack of storeys (rigid floors: along x and along y), the DOFs at
            # their tops; no table point (the history's ag is the first component alone)
            slevels, _ = _storey_levels(r)
            nodes = r.summary["storey_nodes"]
            for chain in chains:
                direction = _chain_name(r, chain)
                dofs = [nodes[k][0] - 1 for k in chain]
                ys = slevels[chain, 1]
                xs = peaks[dofs]
                ax.plot(xs, ys, "-o", linewidth=1.2, markersize=3.5,
                        label=f"{name}, {direction}" if len(rs) > 1 else direction or name)
            continue
        levels, metres = _floor_levels(r)
        order = np.argsort(levels, kind="stable")
        ys = np.concatenate([[0.0], levels[order]])
        xs = np.concatenate([[float(np.max(np.abs(r["ag"]))) * f], peaks[order]])
        ax.plot(xs, ys, "-o", linewidth=1.2, markersize=3.5, label=name)
    r0 = rs[0]
    levels, metres = _floor_levels(r0)
    stacks = r0.n_storeys and len(_storey_chains(r0)) > 1
    if metres or (stacks and _storey_levels(r0)[1]):
        ax.set_ylabel("height [m]")
    elif not stacks:
        ax.set_yticks(np.concatenate([[0.0], levels]), ["table", *r0.dof_labels])
        ax.set_ylabel("level")
    ax.set_xlim(0.0, 1.08 * max(ln.get_xdata().max() for ln in ax.get_lines()))
    ax.set_xlabel(f"peak absolute acceleration [{u.name('m/s2')}]")
    ax.grid(True, linewidth=0.3)
    if len(rs) > 1 or stacks:
        ax.legend(fontsize="small")
    _title(ax, title, "peak floor acceleration")
    return _finish(fig, path, dpi)


# --------------------------------------------------------------------------- rigid floors


def _floors(r: Result, name: str) -> int:
    """The number of rigid floors of a result (its summary's floor_cm_x_m), or a ValueError."""
    cm = (r.summary or {}).get("floor_cm_x_m")
    if not cm:
        raise ValueError(f"{name}: not a building of rigid floors (give &floors in the deck)")
    return len(cm)


def orbit_series(r: Result, floor: int | None = None) -> dict[str, np.ndarray]:
    """The plan motion of a floor (default: the top one) from the history rows: ``cm`` (ux,
    uy of its centre of mass) and, when its plan is known, ``corner`` (ux - rz dy, uy + rz
    dx at the corner (dx, dy) = (+-plan_x / 2, +-plan_y / 2) from the centre of mass whose
    orbit reaches farthest out), ``corner_at`` that (dx, dy) [m]; SI."""
    f = floor or _floors(r, "result")
    cols = [f"u{3 * f - 2}", f"u{3 * f - 1}", f"u{3 * f}"]
    _check_column([r], cols[0])
    _check_column([r], cols[2])
    ux, uy, rz = (np.asarray(r[c], dtype=float) for c in cols)
    out = {"cm": np.column_stack([ux, uy])}
    s = r.summary
    lx, ly = s["floor_plan_x_m"][f - 1], s["floor_plan_y_m"][f - 1]
    if lx is not None and ly is not None:
        best = None
        for dx in (-lx / 2, lx / 2):
            for dy in (-ly / 2, ly / 2):
                xy = np.column_stack([ux - rz * dy, uy + rz * dx])
                reach = float(np.hypot(xy[:, 0], xy[:, 1]).max())
                if best is None or reach > best[0]:
                    best = (reach, xy, (dx, dy))
        out["corner"], out["corner_at"] = best[1], np.array(best[2])
    return out


def plot_orbit(
    results: Results,
    path: PathLike = None,
    *,
    ax: Axes | None = None,
    floor: int | None = None,
    labels: Sequence[str] | None = None,
    title: str | None = None,
    units: Units | str | None = None,
    dpi: int | None = None,
) -> Figure:
    """The orbit of a floor of a building of rigid floors (default: the roof, the top
    floor): uy against ux of its centre of mass and of its corner that goes farthest out,
    from the history rows (every row: t_range does not apply), equal axes."""
    rs = _as_list(results)
    names = _labels(rs, labels)
    fig, ax = _axes(ax, (5.0, 5.0))
    u = Units.parse(units)
    f = u.factor("m")
    for k, (r, name) in enumerate(zip(rs, names, strict=True)):
        top = floor or _floors(r, name)
        series = orbit_series(r, top)
        pre = f"{name}, " if len(rs) > 1 else ""
        cm = series["cm"] * f
        ax.plot(cm[:, 0], cm[:, 1], "-", color=f"C{2 * k}", linewidth=0.9, label=f"{pre}centre of mass")
        if "corner" in series:
            dx, dy = series["corner_at"]
            c = series["corner"] * f
            ax.plot(c[:, 0], c[:, 1], "-", color=f"C{2 * k + 1}", linewidth=0.7,
                    label=f"{pre}corner ({dx:+g}, {dy:+g}) m")
    ax.set_aspect("equal", adjustable="datalim")
    ax.axhline(0.0, color="0.6", linewidth=0.5)
    ax.axvline(0.0, color="0.6", linewidth=0.5)
    ax.set_xlabel(f"ux [{u.name('m')}]")
    ax.set_ylabel(f"uy [{u.name('m')}]")
    ax.grid(True, linewidth=0.3)
    ax.legend(fontsize="small", loc="best")
    r0 = rs[0]
    label = r0.dof_labels[3 * (floor or _floors(r0, names[0])) - 3].removesuffix(" ux")
    _title(ax, title, f"{label}: orbit in plan")
    return _finish(fig, path, dpi)


def brace_segments(r: Result, storey: int, length: float) -> tuple[np.ndarray, np.ndarray, list[int]]:
    """The braces of &floor_braces in a storey as plan segments of ``length`` [m] centred at
    the point of each one's line nearest its floor's centre of mass, along its angle:
    (segments (n, 2, 2) [m], peak forces (n) [N], devices (1-based))."""
    s = r.summary
    devices = [d + 1 for d, st in enumerate(s["device_storey"]) if st == storey]
    segs = []
    for d in devices:
        x, y = s["device_plan_x_m"][d - 1], s["device_plan_y_m"][d - 1]
        a = np.radians(s["device_angle_deg"][d - 1])
        h = 0.5 * length * np.array([np.cos(a), np.sin(a)])
        segs.append([[x - h[0], y - h[1]], [x + h[0], y + h[1]]])
    forces = np.array([s["peak_force_N"][d - 1] for d in devices], dtype=float)
    return np.array(segs, dtype=float).reshape(-1, 2, 2), forces, devices


def plot_device_plan(
    result: Result,
    path: PathLike = None,
    *,
    storeys: Sequence[int] | None = None,
    title: str | None = None,
    units: Units | str | None = None,
    dpi: int | None = None,
) -> Figure:
    """A plan view of the braces of a building of rigid floors (&floor_braces), one panel
    per storey (``storeys``, default every storey with a brace, at most 12): the floor's
    outline and centre of mass, each brace drawn along its direction through its position,
    coloured by its peak force (one colour scale for all panels) and labelled with it."""
    from matplotlib import colormaps
    from matplotlib.collections import LineCollection
    from matplotlib.colors import Normalize

    r = result
    nf = _floors(r, default_label(r, 0))
    s = r.summary
    u = Units.parse(units)
    braced = sorted({st for st in s["device_storey"] if st > 0})
    chosen = list(storeys) if storeys is not None else braced[:12]
    if not chosen:
        raise ValueError(f"{default_label(r, 0)}: no brace of &floor_braces to draw")
    bad = [st for st in chosen if not 1 <= st <= nf]
    if bad:
        raise ValueError(f"storeys {bad}: the building has storeys 1 to {nf}")
    forces_all = np.array([s["peak_force_N"][d] for d, st in enumerate(s["device_storey"]) if st > 0])
    norm = Normalize(0.0, float(forces_all.max()) if forces_all.size and forces_all.max() > 0 else 1.0)
    cmap = colormaps["viridis"]
    cols = min(3, len(chosen))
    rows = (len(chosen) + cols - 1) // cols
    fig = _figure((4.2 * cols + 1.0, 3.6 * rows))
    axes = fig.subplots(rows, cols, squeeze=False)
    fu = u.factor("N")
    for ax, st in zip(axes.flat, chosen, strict=False):
        cx, cy = s["floor_cm_x_m"][st - 1], s["floor_cm_y_m"][st - 1]
        lx, ly = s["floor_plan_x_m"][st - 1], s["floor_plan_y_m"][st - 1]
        if lx is not None and ly is not None:
            ax.plot(cx + np.array([-1, 1, 1, -1, -1]) * lx / 2, cy + np.array([-1, -1, 1, 1, -1]) * ly / 2,
                    "-", color="0.4", linewidth=0.8)
        ax.plot([cx], [cy], "+", color="k", markersize=8)
        size = max(lx or 0.0, ly or 0.0)
        segs, forces, devices = brace_segments(r, st, 0.15 * size if size > 0 else 2.0)
        lc = LineCollection(segs, cmap=cmap, norm=norm, linewidths=4.0)
        lc.set_array(forces)
        ax.add_collection(lc)
        for seg, force, d in zip(segs, forces, devices, strict=True):
            mid = seg.mean(axis=0)
            ax.annotate(f"{r.device_labels[d - 1]}\n{force * fu:.4g} {u.name('N')}", mid, fontsize=7,
                        xytext=(4, 4), textcoords="offset points")
        ax.autoscale_view()
        ax.set_aspect("equal", adjustable="datalim")
        ax.set_xlabel("x [m]")
        ax.set_ylabel("y [m]")
        ax.grid(True, linewidth=0.3)
        ax.set_title(f"storey {st}")
    for ax in list(axes.flat)[len(chosen):]:
        ax.set_visible(False)
    bar = fig.colorbar(LineCollection([], cmap=cmap, norm=norm), ax=axes, shrink=0.8)
    bar.ax.set_ylabel(f"peak force [{u.name('N')}]")
    bar.ax.yaxis.set_major_formatter(lambda x, _: f"{x * fu:.4g}")
    if title is None:
        title = "braces in plan, coloured by their peak force"
    if title:
        fig.suptitle(title)
    return _finish(fig, path, dpi)


# --------------------------------------------------------------------------- sets


def _common(results: list[Result], attr: str) -> int:
    return min(getattr(r, attr) for r in results)


def plot_compare(
    results: Results,
    path: PathLike = None,
    *,
    t_range: TRange = None,
    labels: Sequence[str] | None = None,
    max_panels: int = 8,
    units: Units | str | None = None,
    dpi: int | None = None,
    title: str | None = None,
) -> Figure:
    """One figure: absolute acceleration of each DOF and the force loop of each device that
    all results have, overlaid (at most ``max_panels`` panels, DOFs first)."""
    rs = _as_list(results)
    names = _labels(rs, labels)
    items = [("dof", i) for i in range(1, _common(rs, "n_dof") + 1)]
    items += [("device", d) for d in range(1, _common(rs, "n_devices") + 1)]
    items = items[:max_panels]
    fig = _figure((8.0, 2.8 * len(items)))
    axes = fig.subplots(len(items), 1, squeeze=False)[:, 0]
    for ax, (kind, k) in zip(axes, items, strict=True):
        if kind == "dof":
            plot_acceleration(rs, k, ax=ax, t_range=t_range, labels=names, units=units)
        else:
            plot_hysteresis(rs, k, ax=ax, t_range=t_range, labels=names, units=units)
    if title:
        fig.suptitle(title)
    return _finish(fig, path, dpi)


def bearing_series(r: Result, b: int) -> dict[str, np.ndarray]:
    """A planar bearing's history (1-based ``b``, as the summary's ``bearing_*`` lists): its
    components' displacements (n, 2) [m] and forces (n, 2) [N], found by their device labels
    ('<label> x', '<label> y')."""
    labels = (r.summary or {}).get("bearing_labels") or []
    if not 1 <= b <= len(labels):
        raise ValueError(f"bearing {b}: the run has {len(labels)} planar bearing(s) (&bearings)")
    devices = r.device_labels
    dx, dy = (devices.index(f"{labels[b - 1]} {c}") + 1 for c in ("x", "y"))
    for d in (dx, dy):
        if f"s{d}" not in r or f"F{d}" not in r:
            raise ValueError(f"bearing {b}: device {d} is not in the history (history_devices)")
    s = np.column_stack([r[f"s{dx}"], r[f"s{dy}"]])
    f = np.column_stack([r[f"F{dx}"], r[f"F{dy}"]])
    return {"s": s, "F": f}


def plot_bearings(
    results: Results,
    path: PathLike = None,
    *,
    bearings: Sequence[int] | None = None,
    labels: Sequence[str] | None = None,
    title: str | None = None,
    units: Units | str | None = None,
    dpi: int | None = None,
) -> Figure:
    """Planar bearings (&bearings): left, each bearing's orbit (s_y against s_x, equal axes);
    right, its resultant force |F| against its resultant displacement |s|, from the history
    rows. ``bearings``: 1-based, default every bearing (at most 8)."""
    rs = _as_list(results)
    names = _labels(rs, labels)
    u = Units.parse(units)
    fl, ff = u.factor("m"), u.factor("N")
    fig = Figure(figsize=(10.0, 4.6))
    FigureCanvasAgg(fig)
    ax_o, ax_f = fig.subplots(1, 2)
    for k, (r, name) in enumerate(zip(rs, names, strict=True)):
        count = len((r.summary or {}).get("bearing_labels") or [])
        if count == 0:
            raise ValueError(f"{name}: no planar bearing (&bearings)")
        chosen = list(bearings) if bearings else list(range(1, min(count, 8) + 1))
        for b in chosen:
            ser = bearing_series(r, b)
            tag = (f"{name}, " if len(rs) > 1 else "") + r.summary["bearing_labels"][b - 1]
            color = f"C{(k * len(chosen) + b - 1) % 10}"
            s, f = ser["s"] * fl, ser["F"] * ff
            ax_o.plot(s[:, 0], s[:, 1], "-", color=color, linewidth=0.8, label=tag)
            ax_f.plot(np.hypot(s[:, 0], s[:, 1]), np.hypot(f[:, 0], f[:, 1]), "-", color=color,
                      linewidth=0.8, label=tag)
    ax_o.set_aspect("equal", adjustable="datalim")
    ax_o.axhline(0.0, color="0.6", linewidth=0.5)
    ax_o.axvline(0.0, color="0.6", linewidth=0.5)
    ax_o.set_xlabel(f"s_x [{u.name('m')}]")
    ax_o.set_ylabel(f"s_y [{u.name('m')}]")
    ax_f.set_xlabel(f"|s| [{u.name('m')}]")
    ax_f.set_ylabel(f"|F| [{u.name('N')}]")
    for ax in (ax_o, ax_f):
        ax.grid(True, linewidth=0.3)
    ax_o.legend(fontsize="small", loc="best")
    _title(ax_o, title, "bearings: orbits in plan")
    _title(ax_f, None, "resultant force against resultant displacement")
    return _finish(fig, path, dpi)


#: What plot_all can write, in its order; KEY_PLOTS is the default set.
PLOT_KINDS = ("aabs", "sdot", "hysteresis", "phase", "drift_profile", "acceleration_profile",
              "storey_loop", "base_shear", "orbit", "device_plan", "bearings")
KEY_PLOTS = "key"


def plot_kinds(text: str | None) -> tuple[str, ...] | str:
    """``"key"`` (the default: the roof's acceleration, the hysteresis of the device with the
    largest force, and with storeys the drift and acceleration profiles and the base shear),
    ``"all"`` (every kind), or kinds separated by commas; an unknown kind is a ValueError."""
    if text is None or text == KEY_PLOTS:
        return KEY_PLOTS
    if text == "all":
        return PLOT_KINDS
    kinds = tuple(k.strip() for k in text.split(",") if k.strip())
    bad = [k for k in kinds if k not in PLOT_KINDS]
    if bad or not kinds:
        raise ValueError(f"--plots {text!r}: not a plot kind ({', '.join(bad) or 'none given'}); "
                         f"'key', 'all' or some of {', '.join(PLOT_KINDS)}")
    return kinds


def _save_named(fig: Figure, name: str, path: Path, dpi: int | None) -> Path:
    """Save a figure of plot_all with its title naming the run: its overall title, else the
    first panel's ("building5_dampers: peak inter-storey drift")."""
    sup = getattr(fig, "_suptitle", None)
    if sup is not None and sup.get_text():
        sup.set_text(f"{name}: {sup.get_text()}")
    else:
        for ax in fig.axes:
            if ax.get_title():
                ax.set_title(f"{name}: {ax.get_title()}")
                break
    return save(fig, path, dpi)


def plot_all(
    result: Result,
    directory: str | os.PathLike,
    stem: str,
    *,
    t_range: TRange = None,
    max_items: int = 10,
    units: Units | str | None = None,
    dpi: int | None = None,
    kinds: Sequence[str] | str = PLOT_KINDS,
) -> list[Path]:
    """Write PNGs of one result into ``directory`` and return their paths. ``kinds`` (from
    PLOT_KINDS, or "key"): ``<stem>_aabs<i>.png`` per DOF, ``<stem>_sdot<d>.png``,
    ``<stem>_hysteresis<d>.png`` and ``<stem>_phase<d>.png`` per device (the first
    ``max_items`` DOFs and devices), and with storeys ``<stem>_drift_profile.png``,
    ``<stem>_acceleration_profile.png``, ``<stem>_storey_loop<s>.png`` and
    ``<stem>_base_shear.png``, for a building of rigid floors ``<stem>_orbit.png`` and
    (with &floor_braces) ``<stem>_device_plan.png``, and with &bearings ``<stem>_bearings.png``. "key" is the last DOF's acceleration,
    the hysteresis of the device whose peak force is largest, with storeys the two profiles
    and the base shear, for rigid floors the orbit and the plan of the braces, and the
    bearings' orbits. Each title names the run (the deck's name, else ``stem``):
    "building5_dampers: peak inter-storey drift"."""
    directory = Path(directory)
    written: list[Path] = []
    name = default_label(result, 0) if (result.summary or {}).get("deck") else stem
    explicit = kinds != KEY_PLOTS and tuple(kinds) != PLOT_KINDS   # kinds named one by one
    kw = {"t_range": t_range, "units": units, "dpi": dpi}
    dofs = range(1, min(result.n_dof, max_items) + 1)
    devices = range(1, min(result.n_devices, max_items) + 1)
    chosen: dict[str, range | list[int]] = {k: (dofs if k == "aabs" else devices) for k in PLOT_KINDS}
    if kinds == KEY_PLOTS:
        kinds = ("aabs", "hysteresis", "drift_profile", "acceleration_profile", "base_shear", "orbit",
                 "device_plan", "bearings")
        chosen["aabs"] = [result.n_dof] if result.n_dof else []
        forces = result.summary.get("peak_force_N") or []
        chosen["hysteresis"] = [1 + int(np.argmax(forces))] if len(forces) else []
    storeys = bool(result.n_storeys) and "drift1" in result
    funcs = {"aabs": plot_acceleration, "sdot": plot_relative_velocity,
             "hysteresis": plot_hysteresis, "phase": plot_phase}
    for kind in ("aabs", "sdot", "hysteresis", "phase"):
        if kind not in kinds:
            continue
        for k in chosen[kind]:
            p = directory / f"{stem}_{kind}{k}.png"
            opts = {"t_range": t_range, "dpi": dpi} if kind == "phase" else kw
            written.append(_save_named(funcs[kind](result, k, None, **opts), name, p, dpi))
    if storeys:
        for kind, func in (("drift_profile", plot_drift_profile),
                           ("acceleration_profile", plot_acceleration_profile)):
            if kind in kinds:
                p = directory / f"{stem}_{kind}.png"
                written.append(_save_named(func(result, None, units=units, dpi=dpi), name, p, dpi))
        if "storey_loop" in kinds:
            for s_ in range(1, min(result.n_storeys, max_items) + 1):
                p = directory / f"{stem}_storey_loop{s_}.png"
                written.append(_save_named(plot_storey_loop(result, s_, None, **kw), name, p, dpi))
        if "base_shear" in kinds and "Vb" in result:
            p = directory / f"{stem}_base_shear.png"
            written.append(_save_named(plot_base_shear(result, None, **kw), name, p, dpi))
    floors = (result.summary or {}).get("floor_cm_x_m")
    asked = [k for k in ("orbit", "device_plan") if k in kinds] if explicit else []
    if asked and not floors:
        raise ValueError(f"plots {', '.join(asked)}: {default_label(result, 0)} is not a building of rigid "
                         "floors (&floors)")
    if floors and "orbit" in kinds and f"u{3 * len(floors)}" in result:
        p = directory / f"{stem}_orbit.png"
        written.append(_save_named(plot_orbit(result, None, units=units, dpi=dpi), name, p, dpi))
    if floors and "device_plan" in kinds and any(st > 0 for st in result.summary["device_storey"]):
        p = directory / f"{stem}_device_plan.png"
        written.append(_save_named(plot_device_plan(result, None, units=units, dpi=dpi), name, p, dpi))
    has_bearings = bool((result.summary or {}).get("bearing_labels"))
    if explicit and "bearings" in kinds and not has_bearings:
        raise ValueError(f"plots bearings: {default_label(result, 0)} has no planar bearing (&bearings)")
    if has_bearings and "bearings" in kinds:
        p = directory / f"{stem}_bearings.png"
        written.append(_save_named(plot_bearings(result, None, units=units, dpi=dpi), name, p, dpi))
    return written
