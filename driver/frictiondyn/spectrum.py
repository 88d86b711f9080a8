"""Elastic response spectra of a ground-motion record: the peak response of linear
oscillators of period T and damping ratio xi from rest, computed by the library
(fortran/model/fd_spectrum.f90: the motion linear between samples, each oscillator stepped
exactly). The record is read by the library's own reader, with the same format, units and
scale settings as a deck's ``&excitation``, so a spectrum is of exactly the motion a run
would see; a deck may be given instead of a record (its table motion, as read).
"""

from __future__ import annotations

import csv
import math
import os
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ._api import DeckError, Session, _core

__all__ = ["Spectrum", "default_periods", "response_spectrum"]

G = 9.80665  # standard gravity [m/s2]


def default_periods() -> np.ndarray:
    """T = 0 and 120 periods from 0.01 s to 10 s, evenly spaced in log T."""
    return np.concatenate([[0.0], np.logspace(-2.0, 1.0, 120)])


@dataclass(frozen=True)
class Spectrum:
    """A response spectrum: for each period [s] the peak relative displacement ``sd`` [m],
    the pseudo-velocity ``psv`` = w sd [m/s], the pseudo-acceleration ``psa`` = w^2 sd
    [m/s2] and the peak absolute acceleration ``sa`` [m/s2]; ``xi`` the damping ratio and
    ``source`` the record or deck it is of."""

    periods: np.ndarray
    sd: np.ndarray
    psv: np.ndarray
    psa: np.ndarray
    sa: np.ndarray
    xi: float
    source: str

    def at(self, period: float) -> float:
        """The pseudo-acceleration at ``period`` [s] (linear in log T between the periods
        computed; a period outside them is an error)."""
        t = self.periods
        if not (t[0] <= period <= t[-1]):
            raise ValueError(f"period {period} s is outside the spectrum's {t[0]}..{t[-1]} s")
        if period in t:
            return float(self.psa[np.searchsorted(t, period)])
        pos = t > 0
        return float(np.interp(math.log(period), np.log(t[pos]), self.psa[pos]))

    def to_csv(self, path: str | os.PathLike) -> Path:
        """Write period_s, sd_m, psv_mps, psa_mps2, psa_g, sa_mps2 columns."""
        path = Path(path)
        with open(path, "w", newline="") as f:
            w = csv.writer(f)
            w.writerow(["period_s", "sd_m", "psv_mps", "psa_mps2", "psa_g", "sa_mps2"])
            for row in zip(self.periods, self.sd, self.psv, self.psa, self.psa / G, self.sa):
                w.writerow([f"{x:.10g}" for x in row])
        return path


def _quoted(text: str) -> str:
    return "'" + text.replace("'", "''") + "'"


def _record_deck(record: Path, fmt: str, units: str | None, scale: float,
                 dt: float | None, kind: str) -> str:
    """A one-oscillator deck whose table motion is the record (its spectrum is all it is
    read for)."""
    lines = [
        "&model", "  n_dof = 1", "  mass = 1.0", "/",
        "&springs", "  n_springs = 1", "  node_i = 1", "  node_j = 0", "  k = 1.0", "/",
        "&damping", "  damping_type = 'none'", "/",
        "&excitation", "  excitation_type = 'record'",
        f"  record_file = {_quoted(os.fspath(record))}",
        f"  record_format = {_quoted(fmt)}",
        f"  record_kind = {_quoted(kind)}",
        f"  record_scale = {float(scale)!r}",
    ]
    if units is not None:
        lines.append(f"  record_units = {_quoted(units)}")
    if dt is not None:
        lines.append(f"  dt_record = {float(dt)!r}")
    lines += ["/", "&output", "  write_history = .false.", "/", ""]
    return "\n".join(lines)


def response_spectrum(
    source: str | os.PathLike,
    *,
    periods=None,
    xi: float = 0.05,
    format: str = "auto",
    units: str | None = None,
    scale: float = 1.0,
    dt: float | None = None,
    kind: str = "acceleration",
) -> Spectrum:
    """The elastic response spectrum of a record file (PEER AT2, one value a line, or time
    and value: ``format``, ``units``, ``scale``, ``dt`` and ``kind`` as ``record_format``,
    ``record_units``, ``record_scale``, ``dt_record`` and ``record_kind`` of a deck), or of
    a deck's (.nml) table motion. ``periods`` [s] default to ``default_periods()``; ``xi``
    is the damping ratio (0 <= xi < 1). A bad record or deck raises DeckError with the
    library's message."""
    src = Path(source)
    t = default_periods() if periods is None else np.asarray(periods, dtype=np.float64).ravel()
    if t.size == 0:
        raise ValueError("no periods given")
    if np.any(np.diff(t) <= 0):
        raise ValueError("the periods must increase")
    if src.suffix.lower() == ".nml":
        session = Session(src)
    else:
        if not src.is_file():
            raise DeckError(f"{src}: no such record file")
        text = _record_deck(src.resolve(), format, units, scale, dt, kind)
        session = Session.from_text(text, f"spectrum of {src.name}", ".")
    with session:
        sd, psv, psa, sa, status = _core.fd_session_spectrum(session._live(), t, float(xi))
        session._check(status)
    return Spectrum(t, np.asarray(sd), np.asarray(psv), np.asarray(psa), np.asarray(sa),
                    float(xi), os.fspath(source))


def plot_spectra(spectra: list[Spectrum], path: str | os.PathLike, *, dpi: int = 150,
                 labels: list[str] | None = None) -> Path:
    """Pseudo-acceleration [g] against period [s] of one or several spectra, one curve
    each, saved to ``path``."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    fig = Figure(figsize=(7.0, 4.5))
    FigureCanvasAgg(fig)
    ax = fig.add_subplot(1, 1, 1)
    names = labels or [Path(s.source).name for s in spectra]
    for s, name in zip(spectra, names):
        pos = s.periods > 0
        ax.plot(s.periods[pos], s.psa[pos] / G, label=name)
    ax.set_xscale("log")
    ax.set_xlabel("period T [s]")
    ax.set_ylabel("pseudo-acceleration PSA [g]")
    xis = sorted({s.xi for s in spectra})
    ax.set_title("elastic response spectrum, xi = " + ", ".join(f"{100 * x:g} %" for x in xis))
    ax.grid(True, which="both", alpha=0.3)
    ax.legend()
    fig.tight_layout()
    path = Path(path)
    fig.savefig(path, dpi=dpi)
    return path
