"""Plots of one or several Results (matplotlib Figures on the Agg canvas; no pyplot state).

Every function takes a Result or a sequence of Results (overlaid, one line each), an
optional output ``path`` (a PNG is written when given) or an ``ax`` to draw into, and
returns the Figure. Axis labels carry the units, from ``Result.label``. ``t_range``
restricts the plot to ``t0 <= t <= t1``; ``labels`` name the results in the legend
(default: the deck's name from the summary).

- ``plot_acceleration``: absolute acceleration of a DOF vs time (the paper's Figs. 3a, 4a, 4b)
- ``plot_relative_velocity``: relative velocity difference of a device vs time (Fig. 3b)
- ``plot_hysteresis``: friction force vs relative displacement of a device (Fig. 2)
- ``plot_phase``: stick (0) / slip (+-1) phase of a device vs time
- ``plot_columns``: any column against another (generic overlay)
- ``plot_compare``: one panel per DOF (absolute acceleration) and per device (force loop)
- ``plot_all``: the standard set of PNGs for one Result (used by the command line)
"""

from __future__ import annotations

import os
from collections.abc import Sequence
from pathlib import Path

import numpy as np
from matplotlib.axes import Axes
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure

from ._api import Result

__all__ = [
    "plot_acceleration",
    "plot_all",
    "plot_columns",
    "plot_compare",
    "plot_hysteresis",
    "plot_phase",
    "plot_relative_velocity",
]

Results = Result | Sequence[Result]
TRange = tuple[float, float] | None
PathLike = str | os.PathLike | None

_SIZE = (8.0, 4.0)
_DPI = 120


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


def window(result: Result, t_range: TRange) -> np.ndarray:
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


def _figure(size: tuple[float, float]) -> Figure:
    """A Figure on the Agg canvas, outside pyplot (no global state, safe in threads)."""
    fig = Figure(figsize=size, layout="constrained")
    FigureCanvasAgg(fig)
    return fig


def _axes(ax: Axes | None, size: tuple[float, float] = _SIZE) -> tuple[Figure, Axes]:
    if ax is not None:
        return ax.figure, ax
    fig = _figure(size)
    return fig, fig.add_subplot()


def _finish(fig: Figure, path: PathLike) -> Figure:
    if path is not None:
        fig.savefig(os.fspath(path), dpi=_DPI)
    return fig


def _check_column(results: list[Result], name: str) -> None:
    for i, r in enumerate(results):
        if name not in r:
            raise KeyError(
                f"result {i + 1} has no column {name!r}; its columns are {', '.join(r.names)}"
            )


def _overlay(
    ax: Axes,
    results: list[Result],
    names: list[str],
    x: str,
    y: str,
    t_range: TRange,
    drawstyle: str = "default",
) -> None:
    _check_column(results, x)
    _check_column(results, y)
    for r, name in zip(results, names, strict=True):
        m = window(r, t_range)
        ax.plot(r[x][m], r[y][m], label=name, linewidth=1.0, drawstyle=drawstyle)
    ax.set_xlabel(results[0].label(x))
    ax.set_ylabel(results[0].label(y))
    ax.grid(True, linewidth=0.3)
    if len(results) > 1:
        ax.legend(fontsize="small")


def plot_columns(
    results: Results,
    y: str,
    path: PathLike = None,
    *,
    x: str = "t",
    ax: Axes | None = None,
    t_range: TRange = None,
    labels: Sequence[str] | None = None,
    title: str | None = None,
) -> Figure:
    """Column ``y`` against column ``x`` (default time) of each result, overlaid."""
    rs = _as_list(results)
    fig, ax = _axes(ax)
    _overlay(ax, rs, _labels(rs, labels), x, y, t_range)
    ax.set_title(title if title is not None else f"{y} vs {x}")
    return _finish(fig, path)


def plot_acceleration(
    results: Results,
    dof: int,
    path: PathLike = None,
    *,
    ax: Axes | None = None,
    t_range: TRange = None,
    labels: Sequence[str] | None = None,
) -> Figure:
    """Absolute acceleration of DOF ``dof`` (1-based) vs time, one line per result."""
    rs = _as_list(results)
    fig, ax = _axes(ax)
    _overlay(ax, rs, _labels(rs, labels), "t", f"aabs{dof}", t_range)
    ax.set_title(f"absolute acceleration, DOF {dof}")
    return _finish(fig, path)


def plot_relative_velocity(
    results: Results,
    device: int,
    path: PathLike = None,
    *,
    ax: Axes | None = None,
    t_range: TRange = None,
    labels: Sequence[str] | None = None,
    band: float | None = None,
) -> Figure:
    """Relative velocity difference s' of device ``device`` vs time, one line per result.
    ``band`` (eps or eps1 [m/s]) adds two dashed lines at +-band."""
    rs = _as_list(results)
    fig, ax = _axes(ax)
    _overlay(ax, rs, _labels(rs, labels), "t", f"sdot{device}", t_range)
    if band is not None:
        for sign in (1.0, -1.0):
            ax.axhline(sign * band, color="0.4", linestyle="--", linewidth=0.7)
    ax.set_title(f"relative velocity difference, device {device}")
    return _finish(fig, path)


def plot_hysteresis(
    results: Results,
    device: int,
    path: PathLike = None,
    *,
    ax: Axes | None = None,
    t_range: TRange = None,
    labels: Sequence[str] | None = None,
) -> Figure:
    """Friction force F vs relative displacement s of device ``device``: the loops."""
    rs = _as_list(results)
    fig, ax = _axes(ax, (6.0, 4.5))
    _overlay(ax, rs, _labels(rs, labels), f"s{device}", f"F{device}", t_range)
    ax.set_title(f"friction force vs relative displacement, device {device}")
    return _finish(fig, path)


def plot_phase(
    results: Results,
    device: int,
    path: PathLike = None,
    *,
    ax: Axes | None = None,
    t_range: TRange = None,
    labels: Sequence[str] | None = None,
) -> Figure:
    """Phase of device ``device`` vs time: -1 slip -, 0 stick, +1 slip + (steps)."""
    rs = _as_list(results)
    fig, ax = _axes(ax, (8.0, 3.0))
    _overlay(ax, rs, _labels(rs, labels), "t", f"phase{device}", t_range, drawstyle="steps-post")
    ax.set_yticks([-1, 0, 1], ["slip \u2212", "stick", "slip +"])
    ax.set_ylim(-1.3, 1.3)
    ax.set_title(f"stick/slip phase, device {device}")
    return _finish(fig, path)


def _common(results: list[Result], attr: str) -> int:
    return min(getattr(r, attr) for r in results)


def plot_compare(
    results: Results,
    path: PathLike = None,
    *,
    t_range: TRange = None,
    labels: Sequence[str] | None = None,
    max_panels: int = 8,
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
            plot_acceleration(rs, k, ax=ax, t_range=t_range, labels=names)
        else:
            plot_hysteresis(rs, k, ax=ax, t_range=t_range, labels=names)
    return _finish(fig, path)


def plot_all(
    result: Result,
    directory: str | os.PathLike,
    stem: str,
    *,
    t_range: TRange = None,
    max_items: int = 10,
) -> list[Path]:
    """Write the standard PNGs of one result into ``directory``: ``<stem>_aabs<i>.png`` per
    DOF, ``<stem>_sdot<d>.png``, ``<stem>_hysteresis<d>.png`` and ``<stem>_phase<d>.png`` per
    device (the first ``max_items`` DOFs and devices). Returns the paths written."""
    directory = Path(directory)
    written: list[Path] = []
    for i in range(1, min(result.n_dof, max_items) + 1):
        p = directory / f"{stem}_aabs{i}.png"
        plot_acceleration(result, i, p, t_range=t_range)
        written.append(p)
    for d in range(1, min(result.n_devices, max_items) + 1):
        for kind, func in (
            ("sdot", plot_relative_velocity),
            ("hysteresis", plot_hysteresis),
            ("phase", plot_phase),
        ):
            p = directory / f"{stem}_{kind}{d}.png"
            func(result, d, p, t_range=t_range)
            written.append(p)
    return written
