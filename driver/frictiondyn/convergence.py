"""A time-step convergence study of one deck: the same deck at n1, factor·n1, ...

No single run can tell whether its step is small enough for the stick-slip history it
computed: the reports of a run (correctness violations, ``mode_resolution``,
``stick_resolution``, ``harmonic_resolution``, ``record_resolution``, ``energy_balance``)
each catch one mechanism, and in a fuzz campaign of random decks about
one run in eight had stick-slip counts that moved with the step with none of them raised
(docs/theory.md, section 6). The general check is the engineer's: run again with a smaller
step and see whether the answer moves. ``step_convergence(deck)`` does that: it runs the deck
at its own n1 and at ``factor`` times n1 (``levels`` times over, the runs side by side in
threads), everything else unchanged (dt_min, when given, and output_every scale with the
step), and compares what a design check reads from the summary: the peaks of every DOF,
device and storey, the residual drifts and slips, the energy dissipated by friction, and the
stick-slip counts. ``python -m frictiondyn converge DECK`` prints it (exit status 3 when the
answer moves). docs/python.md documents both.
"""

from __future__ import annotations

import json
import math
import os
from collections.abc import Sequence
from concurrent.futures import FIRST_EXCEPTION, ThreadPoolExecutor, wait
from dataclasses import dataclass, field
from pathlib import Path

import f90nml

from ._api import _SUMMARY, DeckError, FrictiondynError, Session, summary_warnings
from ._nml import copy_namelist, read_namelist, write_namelist

DEFAULT_N1 = 20  # n1 when a deck does not give it (fortran/model/fd_names.f90, default_n1)

__all__ = ["ConvergenceReport", "Quantity", "step_convergence"]

#: (summary key, what, unit, item kind, peak key): a quantity is judged relative to its own
#: size, but not below FLOOR times the largest of its kind (a DOF that hardly moves is judged
#: against the structure's motion); a residual relative to the peak of the same device or
#: storey (peak key), the friction energy relative to the energy input.
_GROUPS = (
    ("peak_u_m", "peak |u|", "m", "dof", None),
    ("peak_v_mps", "peak |v|", "m/s", "dof", None),
    ("peak_aabs_mps2", "peak |a_abs|", "m/s2", "dof", None),
    ("peak_s_m", "peak |s|", "m", "device", None),
    ("peak_force_N", "peak |F|", "N", "device", None),
    ("residual_s_m", "residual s", "m", "device", "peak_s_m"),
    ("peak_drift_m", "peak drift", "m", "storey", None),
    ("residual_drift_m", "residual drift", "m", "storey", "peak_drift_m"),
    ("peak_storey_shear_N", "peak storey shear", "N", "storey", None),
    ("peak_base_shear_N", "peak base shear", "N", "", None),
    ("energy_friction_J", "energy dissipated by friction", "J", "", "energy_input_J"),
)
#: the stick-slip counts, judged as counts
_COUNTS = (
    ("stick_to_slip", "stick-to-slip transitions"),
    ("slip_reversals", "slip reversals"),
)
#: a quantity smaller than FLOOR times the largest of its group is judged against that
FLOOR = 0.01


@dataclass
class Quantity:
    """One compared quantity: its values at each level and whether consecutive levels agree."""

    key: str  #: summary key
    what: str  #: what it is, e.g. "peak |u|"
    item: str  #: "dof 2", "device 1", "storey 3" or "" for a scalar
    unit: str
    values: list[float]  #: at n1, factor·n1, ...
    scale: float  #: a change is judged relative to this (0 for a count)
    tolerance: float  #: the largest change allowed between consecutive levels
    agrees: bool

    @property
    def change(self) -> float:
        """The largest change between consecutive levels over the change allowed (above 1:
        the quantity moves)."""
        steps = [abs(b - a) for a, b in zip(self.values, self.values[1:])]
        return max(steps) / self.tolerance if self.tolerance > 0 else (math.inf if max(steps) else 0.0)


@dataclass
class ConvergenceReport:
    """What ``step_convergence`` found: the n1 of each level, each run's summary and
    warnings, and every compared quantity; ``converged`` when every consecutive pair of
    levels agrees within the tolerances."""

    deck: str
    n1: list[int]
    rtol: float
    summaries: list[dict]
    warnings: list[list[str]]
    quantities: list[Quantity] = field(default_factory=list)

    @property
    def converged(self) -> bool:
        return all(q.agrees for q in self.quantities)

    @property
    def moved(self) -> list[Quantity]:
        """The quantities that move by more than their tolerance, the worst first."""
        return sorted((q for q in self.quantities if not q.agrees), key=lambda q: -q.change)

    def worst(self) -> list[Quantity]:
        """For each kind of quantity, the one that moves most (relative to its tolerance)."""
        out: dict[str, Quantity] = {}
        for q in self.quantities:
            if q.key not in out or q.change > out[q.key].change:
                out[q.key] = q
        return list(out.values())

    def to_dict(self) -> dict:
        return {
            "deck": self.deck,
            "n1": self.n1,
            "rtol": self.rtol,
            "converged": self.converged,
            "warnings": self.warnings,
            "quantities": [
                {
                    "key": q.key, "item": q.item, "unit": q.unit, "values": q.values,
                    "scale": q.scale, "tolerance": q.tolerance, "agrees": q.agrees,
                }
                for q in self.quantities
            ],
        }

    def __str__(self) -> str:
        levels = ", ".join(str(n) for n in self.n1)
        lines = [f"step convergence of {self.deck}: n1 = {levels} (dt1 = " + ", ".join(
            f"{s['dt1_s']:.4g}" for s in self.summaries) + " s)"]
        for n, w in zip(self.n1, self.warnings):
            for text in w:
                lines.append(f"  n1 = {n}: warning: {text}")
        lines.append(
            f"  the quantity of each kind that moves most (tolerance {100 * self.rtol:g} % of the "
            "quantity, or of the largest of its kind; counts max(2, 10 %)):"
        )
        for q in self.worst():
            name = f"{q.what} {q.item}".strip()
            vals = " -> ".join(f"{v:.6g}" for v in q.values)
            unit = f" {q.unit}" if q.unit else ""
            mark = "agrees" if q.agrees else "MOVES"
            lines.append(f"    {name}: {vals}{unit}  {mark}")
        moved = self.moved
        if not moved:
            lines.append(
                "  converged: every quantity agrees between consecutive levels within its "
                f"tolerance; the results at n1 = {self.n1[0]} do not depend on the step at that tolerance"
            )
        else:
            lines.append(
                f"  NOT converged: {len(moved)} quantit{'y moves' if len(moved) == 1 else 'ies move'} "
                f"by more than the tolerance; the results at n1 = {self.n1[0]} depend on the step "
                "(raise n1 and check again)"
            )
        return "\n".join(lines)


def _deck(deck: str | os.PathLike) -> tuple[f90nml.Namelist, Path]:
    path = Path(deck)
    try:  # the deck's bytes as the library reads them (a Latin-1 comment is no error)
        text = path.read_bytes().decode("utf-8", "surrogateescape")
    except FileNotFoundError:
        raise DeckError(f"{path}: no such deck") from None
    except (OSError, UnicodeDecodeError) as exc:
        raise DeckError(f"{path}: cannot read the deck ({exc})") from None
    return read_namelist(text, path), path


def _level_text(nml: f90nml.Namelist, factor: int) -> str:
    """The deck with its step divided by ``factor``: n1, and dt_min and output_every (given
    in seconds and in dt1 steps) with it."""
    out = copy_namelist(nml)
    integ = out.setdefault("integration", f90nml.Namelist())
    n1 = integ.get("n1")  # absent, or an empty value (n1 = ,): the library's default
    integ["n1"] = (DEFAULT_N1 if n1 is None else int(n1)) * factor
    if integ.get("dt_min"):
        integ["dt_min"] = float(integ["dt_min"]) / factor
    output = out.get("output")
    if output is not None and output.get("output_every"):
        output["output_every"] = int(output["output_every"]) * factor
    return write_namelist(out)


def _items(kind: str, summary: dict, n: int) -> list[str]:
    if not kind:
        return [""]
    labels = {
        "dof": summary.get("dof_labels"),
        "device": summary.get("device_labels"),
        "storey": summary.get("storey_labels"),
    }[kind]
    return [labels[i] if labels and i < len(labels) and labels[i] else f"{kind} {i + 1}" for i in range(n)]


def _compare(summaries: list[dict], rtol: float) -> list[Quantity]:
    out = []
    for key, what, unit, kind, peak_key in _GROUPS:
        if any(key not in s for s in summaries):
            continue
        if key == "energy_friction_J" and not summaries[0].get("n_devices"):
            continue  # no device: nothing to compare (the per-device lists are empty)
        rows = [s[key] if isinstance(s[key], list) else [s[key]] for s in summaries]
        n = len(rows[0])
        if n == 0 or any(len(r) != n for r in rows):
            continue
        floor = FLOOR * max(abs(x) for r in rows for x in r)
        peaks = None
        if peak_key is not None:  # a residual: judged against the peak of the same item
            peaks = [p if isinstance(p, list) else [p] for p in (s[peak_key] for s in summaries)]
        for i, item in enumerate(_items(kind, summaries[0], n)):
            values = [float(r[i]) for r in rows]
            size = max(max(abs(v) for v in values), floor)
            if peaks is not None:
                size = max(size, max(abs(float(p[i])) for p in peaks))
            tol = rtol * size
            agrees = all(abs(b - a) <= tol for a, b in zip(values, values[1:]))
            out.append(Quantity(key, what, item, unit, values, size, tol, agrees))
    for key, what in _COUNTS:
        if any(key not in s for s in summaries):
            continue
        rows = [s[key] for s in summaries]
        for i, item in enumerate(_items("device", summaries[0], len(rows[0]))):
            values = [float(r[i]) for r in rows]
            tol = max(2.0, 0.1 * max(values))
            agrees = all(abs(b - a) <= tol for a, b in zip(values, values[1:]))
            out.append(Quantity(key, what, item, "", values, 0.0, tol, agrees))
    return out


def _cpus() -> int:
    """The CPUs this process may use (its affinity: taskset, a Slurm allocation)."""
    try:
        return len(os.sched_getaffinity(0))
    except (AttributeError, OSError):
        return os.cpu_count() or 1


def step_convergence(
    deck: str | os.PathLike,
    factor: int = 2,
    levels: int = 1,
    rtol: float = 0.01,
    threads: int | None = None,
) -> ConvergenceReport:
    """Run ``deck`` at its n1 and at n1·factor**k, k = 1..levels, and compare the results.

    ``rtol``: the largest change allowed between consecutive levels, relative to the
    quantity (and not below ``FLOOR`` times the largest of its kind, so that a DOF that
    hardly moves is judged against the structure's motion); a residual drift or slip is
    judged against the largest peak drift or slip, the friction energy against the energy
    input; a stick-slip count may move by max(2, 10 %). ``threads``: runs side by side
    (default: as many as there are levels, at most the CPUs this process may use). Raises
    DeckError for a bad deck, or for the event-driven technique (exact: its n1 only samples
    the history).
    """
    if isinstance(factor, bool) or not isinstance(factor, int) or factor < 2:
        raise ValueError(f"factor = {factor!r}: must be an integer >= 2")
    if isinstance(levels, bool) or not isinstance(levels, int) or not 1 <= levels <= 6:
        raise ValueError(f"levels = {levels!r}: must be an integer 1..6")
    if not (isinstance(rtol, (int, float)) and 0 < rtol < 1):
        raise ValueError(f"rtol = {rtol!r}: must be in (0, 1)")
    nml, path = _deck(deck)
    technique = str(nml.get("integration", {}).get("technique", "newmark")).strip().lower()
    if technique == "event_driven":
        raise DeckError(
            f"{path}: &integration technique = 'event_driven' is exact: its events, peaks and "
            "energies do not depend on n1 (it only samples the history), so there is no step "
            "to converge"
        )
    factors = [factor**k for k in range(levels + 1)]
    texts = [_level_text(nml, f) for f in factors]
    n1 = [int(f90nml.reads(t)["integration"]["n1"]) for t in texts]
    workers = max(1, threads or min(len(texts), _cpus()))
    sessions: list[Session] = []
    level = n1[0]
    try:
        for text, level in zip(texts, n1):
            sessions.append(Session.from_text(text, path.name, path.parent))
            sessions[-1].select([], [])  # the summary has every peak; no history is kept
        with ThreadPoolExecutor(max_workers=workers) as pool:
            futures = [pool.submit(s.solve, None, False) for s in sessions]
            try:
                # a failed level stops the others at once
                wait(futures, return_when=FIRST_EXCEPTION)
                for f, level in zip(futures, n1):
                    if f.done() and f.exception() is not None:
                        f.result()  # raises it
                for f, level in zip(futures, n1):
                    f.result()
            except BaseException:  # Ctrl-C or a failed level: stop the others, then raise
                for f in futures:
                    f.cancel()
                while not all(f.done() for f in futures):
                    for s in sessions:  # again at each look: a cancel before a solve starts is lost
                        s.cancel()
                    wait(futures, timeout=0.05)
                raise
        summaries = [json.loads(s._text(_SUMMARY)) for s in sessions]
    except FrictiondynError as exc:  # say which level
        raise type(exc)(f"{exc} (in the step convergence study, the level n1 = {level})") from None
    finally:
        for s in sessions:
            s.close()
    report = ConvergenceReport(
        deck=str(path), n1=n1, rtol=float(rtol), summaries=summaries,
        warnings=[summary_warnings(s) for s in summaries],
    )
    report.quantities = _compare(summaries, rtol)
    return report
