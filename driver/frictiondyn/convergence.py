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

With three levels or more (the default: n1, 2 n1, 4 n1) it also estimates the error of the
quantities a design reads (peak displacements, drifts, absolute accelerations, device forces
and the friction energy) a posteriori, with the estimator a tolerance run stands on
(``sound_estimate``: the order of convergence measured from the last three levels, capped at
the technique's theoretical one, and Richardson extrapolation where that order is consistent;
a plain difference, flagged as such and no claim of convergence, where it is not), each
quantity's method named (``methods_text``) as a tolerance run names it. Under a
regularized law the step levels converge to the law's solution, not to Coulomb's: law levels
(the finest step with eps, or f and eps1, divided) estimate the law's error too
(docs/theory.md, section 16).
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

__all__ = ["ConvergenceReport", "Estimate", "Quantity", "estimate_error", "ladder_estimate",
           "method_text", "methods_text", "sound_estimate", "step_convergence"]

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
#: the quantities whose error is estimated: what a design reads from a run
ESTIMATED = ("peak_u_m", "peak_drift_m", "peak_aabs_mps2", "peak_force_N", "energy_friction_J")
#: a measured order is consistent in [ORDER_MIN, ORDER_MAX]: the techniques converge at order 1
#: to 2 (Newmark's across the events the correctness condition locates, Moreau-Jean's first
#: order, second where the events are velocity zeros), a resonant amplitude, quadratic in
#: Newmark's frequency error, at up to 4, a regularized law's peaks in eps or f at about 1;
#: a ratio of changes outside this range is not the asymptotic behaviour of an error
ORDER_MIN, ORDER_MAX = 0.5, 4.0
#: changes between levels below UNCHANGED times the quantity's scale are round-off: the
#: quantity does not depend on the step
UNCHANGED = 1e-9
#: a plain difference from three levels stands for the error only when every change stays
#: below NOISE times the tolerance
NOISE = 0.1
#: safety factors on the distance to the limit (Roache's grid convergence index: 1.25 with a
#: measured, consistent order, 3 without one), so that an estimate is a bound more often than
#: not: the extrapolated limit is a best guess, and the order at finer steps may differ
SAFETY_RICHARDSON, SAFETY_DIFFERENCE = 1.25, 3.0
#: the theoretical order of each technique's step error, and of the regularized laws' error in
#: eps and f: a measured order above it is capped (``sound_estimate``; docs/theory.md, section 16)
STEP_ORDER = {"newmark": 2.0, "moreau_jean": 1.0}
LAW_ORDER = 1.0


@dataclass
class Estimate:
    """An a-posteriori estimate of a quantity's error from its values at levels of one
    refined parameter: the step (n1), or a regularized law's eps or f.

    ``method``: ``"richardson"`` (the order measured from the last three levels is
    consistent: the limit is extrapolated and each level's error is its distance to it, times
    SAFETY_RICHARDSON), ``"difference"`` (no consistent order: each level's error is its
    distance to the finest level's value, the finest level's the last change, times
    SAFETY_DIFFERENCE; a plain difference, not a bound, and from three levels no claim of
    convergence unless every change is noise, ``_claims``) or ``"unchanged"`` (the levels
    agree to round-off).
    ``reason`` says why a difference was used."""

    method: str
    errors: list[float]  #: estimated absolute error of each level's value
    order: float | None = None  #: measured order (from the last three levels)
    extrapolated: float | None = None  #: Richardson's limit
    reason: str = ""
    changes: list[float] = field(default_factory=list)  #: |change| between consecutive levels
    #: the order measured, when ``order`` is capped below it (``sound_estimate``)
    measured: float | None = None

    @property
    def error(self) -> float:
        """The estimated error of the deck's own level (the first)."""
        return self.errors[0]


def estimate_error(values: Sequence[float], factor: int = 2, scale: float = 0.0) -> Estimate:
    """The error of ``values``, a quantity at a parameter (the step, eps, f) h, h/factor,
    h/factor**2, ...

    From the last three levels: the changes d1 = q1 - q0, d2 = q2 - q1 (q2 finest) give the
    order p = log(d1 / d2) / log(factor) when they have one sign and shrink; when p lies in
    [ORDER_MIN, ORDER_MAX] (and, with four levels or more, every earlier triple's order too)
    the limit is q2 + d2 / (factor**p - 1) (Richardson). Otherwise a plain difference, with
    the reason. Changes below UNCHANGED * ``scale`` are round-off. ``Estimate`` says how each
    level's error follows."""
    q = [float(v) for v in values]
    if len(q) < 2:
        raise ValueError("an error estimate needs two levels or more")
    d = [b - a for a, b in zip(q, q[1:])]
    changes = [abs(x) for x in d]
    if max(changes) <= UNCHANGED * scale:
        return Estimate("unchanged", [max(changes)] * len(q), changes=changes)

    def plain(reason: str) -> Estimate:
        last, fs = q[-1], SAFETY_DIFFERENCE
        return Estimate("difference", [fs * abs(v - last) for v in q[:-1]] + [fs * changes[-1]],
                        reason=reason, changes=changes)

    if len(q) < 3:
        return plain("two levels: no order can be measured")
    orders = []
    for d1, d2 in zip(d, d[1:]):
        if d1 * d2 <= 0 or d2 == 0:
            return plain("the changes between levels alternate in sign" if d1 * d2 < 0
                         else "a change between levels is zero")
        if abs(d2) >= abs(d1):
            return plain("the changes between levels do not shrink as the step does")
        orders.append(math.log(d1 / d2) / math.log(factor))
    p = orders[-1]
    bad = [x for x in orders if not ORDER_MIN <= x <= ORDER_MAX]
    if bad:
        return plain(f"measured order {bad[0]:.2g} outside [{ORDER_MIN:g}, {ORDER_MAX:g}]")
    limit = q[-1] + d[-1] / (factor**p - 1)
    return Estimate("richardson", [SAFETY_RICHARDSON * abs(v - limit) for v in q], order=p,
                    extrapolated=limit, changes=changes)


def sound_estimate(values: Sequence[float], factor: int, scale: float, cap: float) -> Estimate:
    """The estimate ``converge`` reports and a tolerance run stands on: the error of each of
    ``values``, a quantity at a parameter h, h/factor, h/factor**2, ... whose error is of
    theoretical order ``cap`` (``STEP_ORDER``, ``LAW_ORDER``).

    From the last three levels (``estimate_error``), with three rules on the finest level's
    error: Richardson's at the measured order p, but never above ``cap`` (a measured order
    above it, the peaks of a sampled history falling at 3 or 4 before their asymptotic 1 or 2,
    extrapolates too little); from the larger of the two changes' predictions, |d2| and
    |d1| / factor^p (a ladder whose changes come in steps, a sampled peak or an event that
    moves to the next step, has one small change beside a large one, and the small one alone
    says the error is smaller than it is); without an order, SAFETY_DIFFERENCE times the
    larger change. With five levels or more and no order in the last three, Richardson's over
    every other one of the last five (a ratio factor**2, where the steps of such a ladder
    average out) stands for it if that has an order. A coarser level's error is its distance
    to the finest level's value plus the finest's error (Richardson's: SAFETY_RICHARDSON times
    the distance; a difference: the larger of SAFETY_DIFFERENCE times the distance and the
    finest's error)."""
    q = [float(v) for v in values]
    e = estimate_error(q[-3:], factor, scale)
    changes = [abs(b - a) for a, b in zip(q, q[1:])]
    used, ratio, suffix = q[-3:], factor, ""
    if e.method == "difference" and len(q) >= 5:
        wide = estimate_error(q[-5::2], factor**2, scale)
        if wide.method == "richardson":
            e, used, ratio, suffix = wide, q[-5::2], factor**2, "every other level"
    if e.method == "unchanged":
        last = max(changes[-2:])
        errors = [max(abs(v - q[-1]), last) for v in q[:-1]] + [last]
        return Estimate("unchanged", errors, changes=changes, reason=suffix)
    if e.method == "difference":
        last = SAFETY_DIFFERENCE * max(changes[-2:])
        errors = [max(SAFETY_DIFFERENCE * abs(v - q[-1]), last) for v in q[:-1]] + [last]
        return Estimate("difference", errors, reason=e.reason, changes=changes)
    d1, d2 = abs(used[-2] - used[-3]), abs(used[-1] - used[-2])
    p = min(e.order, cap)
    gain = ratio**p - 1
    limit = q[-1] + (used[-1] - used[-2]) / gain
    last = SAFETY_RICHARDSON * max(d2, d1 / ratio**p) / gain
    errors = [SAFETY_RICHARDSON * abs(v - q[-1]) + last for v in q[:-1]] + [last]
    return Estimate("richardson", errors, order=p, extrapolated=limit, reason=suffix,
                    changes=changes, measured=e.order if e.order > cap else None)


def _order_between(d1: float, d2: float, r1: float, r2: float) -> float | None:
    """The order p of two changes d1, d2 (one sign) between levels whose parameter falls by
    r1 and then r2: d1 / d2 = r2^p (r1^p - 1) / (r2^p - 1), increasing in p; None outside
    [ORDER_MIN, ORDER_MAX]."""
    def g(p: float) -> float:
        return r2**p * (r1**p - 1) / (r2**p - 1)

    target = d1 / d2
    lo, hi = ORDER_MIN, ORDER_MAX
    if not g(lo) <= target <= g(hi):
        return None
    for _ in range(60):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if g(mid) < target else (lo, mid)
    return 0.5 * (lo + hi)


def ladder_estimate(values: Sequence[float], ratios: Sequence[float], scale: float,
                    cap: float) -> Estimate:
    """``sound_estimate`` on a ladder whose parameter falls by ``ratios[i]`` from level i to
    i + 1 (one ratio fewer than values): with one ratio throughout, ``sound_estimate`` itself;
    with the last two equal, ``sound_estimate`` of the last three levels; otherwise the order
    of the last three levels solves d1 / d2 = r2^p (r1^p - 1) / (r2^p - 1) (a ladder that jumps
    to a level predicted from the order the levels before it measured confirms that order
    across the jump, or has none), and the same rules follow: the order capped at ``cap``, the
    finest level's error 1.25 max(|d2|, the d2 that d1 predicts at that order) / (r2^p - 1), a
    plain difference (3 times the larger of the last two changes) without a consistent
    order."""
    q = [float(v) for v in values]
    r = [float(x) for x in ratios]
    if len(r) != len(q) - 1:
        raise ValueError("a ladder's ratios are one fewer than its values")
    if len(set(r)) == 1:
        return sound_estimate(q, r[0], scale, cap)
    if r[-1] == r[-2]:
        return sound_estimate(q[-3:], r[-1], scale, cap)
    changes = [abs(b - a) for a, b in zip(q, q[1:])]
    d1, d2 = q[-2] - q[-3], q[-1] - q[-2]
    if max(changes[-2:]) <= UNCHANGED * scale:
        last = max(changes[-2:])
        errors = [max(abs(v - q[-1]), last) for v in q[:-1]] + [last]
        return Estimate("unchanged", errors, changes=changes)
    p = None
    if d1 * d2 < 0:
        reason = "the changes between levels alternate in sign"
    elif d1 * d2 == 0:
        reason = "a change between levels is zero"
    else:
        p = _order_between(d1, d2, r[-2], r[-1])
        reason = f"no order in [{ORDER_MIN:g}, {ORDER_MAX:g}] fits the changes across the jump"
    if p is None:
        last = SAFETY_DIFFERENCE * max(changes[-2:])
        errors = [max(SAFETY_DIFFERENCE * abs(v - q[-1]), last) for v in q[:-1]] + [last]
        return Estimate("difference", errors, reason=reason, changes=changes)
    pc = min(p, cap)
    gain = r[-1]**pc - 1
    predicted = abs(d1) * gain / (r[-1]**pc * (r[-2]**pc - 1))
    last = SAFETY_RICHARDSON * max(abs(d2), predicted) / gain
    errors = [SAFETY_RICHARDSON * abs(v - q[-1]) + last for v in q[:-1]] + [last]
    return Estimate("richardson", errors, order=pc, extrapolated=q[-1] + d2 / gain,
                    reason=f"ratios {r[-2]:g} and {r[-1]:g}", changes=changes,
                    measured=p if p > cap else None)


def method_text(e: Estimate | None) -> str:
    """How ``e`` was made, as ``converge`` prints it and a tolerance run's ``estimate_method``
    names it."""
    if e is None:
        return ""
    if e.method == "richardson":
        text = (f"Richardson at order {e.order:g}, the theoretical ({e.measured:.2f} measured)"
                if e.measured is not None else f"Richardson at order {e.order:.2f}")
        return text + (f" ({e.reason})" if e.reason else "")
    if e.method == "unchanged":
        return "unchanged (round-off)"
    return f"difference ({e.reason})"


def methods_text(step: Estimate | None, law: Estimate | None) -> str:
    """The methods of a quantity's step and law estimates: ``"step: ...; law: ..."``."""
    return "; ".join(f"{what}: {method_text(e)}" for what, e in (("step", step), ("law", law))
                     if e is not None)


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
    agrees: bool  #: the changes and the estimated error within the tolerance
    estimate: Estimate | None = None  #: its step error (the quantities of ESTIMATED)
    #: the error of a regularized law's eps or f, from the law levels (at the finest step)
    law_estimate: Estimate | None = None
    index: int = 0  #: the item's place in the summary's list (0 for a scalar)

    @property
    def error(self) -> float | None:
        """The estimated error of the deck's own level: the step's plus the law's."""
        if self.estimate is None:
            return None
        return self.estimate.error + (self.law_estimate.error if self.law_estimate else 0.0)

    @property
    def relative_error(self) -> float | None:
        """The estimated error of the deck's own level over the quantity's scale."""
        error = self.error
        if error is None:
            return None
        return error / self.scale if self.scale > 0 else (math.inf if error else 0.0)

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
    #: the law levels (the finest step, eps and f divided by factor, factor**2, ...), if any
    law_summaries: list[dict] = field(default_factory=list)
    factor: int = 2
    law_warnings: list[list[str]] = field(default_factory=list)

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
            "factor": self.factor,
            "law_levels": len(self.law_summaries),
            "converged": self.converged,
            "warnings": self.warnings,
            "quantities": [
                {
                    "key": q.key, "item": q.item, "unit": q.unit, "values": q.values,
                    "scale": q.scale, "tolerance": q.tolerance, "agrees": q.agrees,
                    **_estimate_dict(q),
                }
                for q in self.quantities
            ],
        }

    def estimated(self) -> list[Quantity]:
        """For each kind of quantity whose error is estimated, the one with the largest
        estimated relative error (a plain difference from three levels or more first)."""
        out: dict[str, Quantity] = {}
        for q in self.quantities:
            if q.estimate is None:
                continue
            if q.key not in out or _rank(q) > _rank(out[q.key]):
                out[q.key] = q
        return list(out.values())

    def __str__(self) -> str:
        levels = ", ".join(str(n) for n in self.n1)
        lines = [f"step convergence of {self.deck}: n1 = {levels} (dt1 = " + ", ".join(
            f"{s['dt1_s']:.4g}" for s in self.summaries) + " s)"]
        for n, w in zip(self.n1, self.warnings):
            for text in w:
                lines.append(f"  n1 = {n}: warning: {text}")
        for k, w in enumerate(self.law_warnings, start=1):
            for text in w:
                lines.append(f"  n1 = {self.n1[-1]}, eps and f / {self.factor**k}: warning: {text}")
        lines.append(
            f"  the quantity of each kind that moves most (tolerance {100 * self.rtol:g} % of the "
            "quantity, or of the largest of its kind; counts max(2, 10 %)):"
        )
        for q in self.worst():
            name = f"{q.what} {q.item}".strip()
            vals = " -> ".join(f"{v:.6g}" for v in q.values)
            unit = f" {q.unit}" if q.unit else ""
            mark = "agrees" if q.agrees else ("MOVES" if q.change > 1 else "ESTIMATED ERROR ABOVE IT")
            lines.append(f"    {name}: {vals}{unit}  {mark}")
        estimated = self.estimated()
        if estimated:
            lines.append(f"  estimated error of the results at n1 = {self.n1[0]} (the largest of each kind):")
            for q in estimated:
                lines.append("    " + _estimate_line(q))
            if self.law_summaries:
                lines.append(
                    "  step: the deck's n1 against n1 refined; law: eps and f refined at the finest step "
                    "(the law's error does not vanish with the step; docs/theory.md, section 16)"
                )
            elif any(x in ("velocity", "hysteretic") for x in self.summaries[0].get("device_law", [])):
                lines.append(
                    "  these are the step's errors alone: the error of a regularized law (eps, f) does not "
                    "vanish with the step and is not included (docs/theory.md, section 16)"
                )
        moved = self.moved
        if not moved:
            lines.append(
                "  converged: every quantity agrees between consecutive levels within its "
                f"tolerance; the results at n1 = {self.n1[0]} do not depend on the step at that tolerance"
            )
        else:
            erratic = [q for q in moved if q.estimate is not None and not _claims(q.estimate, q.tolerance)]
            law = [q for q in moved if _law_bound(q)]
            lines.append(
                f"  NOT converged: {len(moved)} quantit{'y moves' if len(moved) == 1 else 'ies move'} "
                f"by more than the tolerance or {'has' if len(moved) == 1 else 'have'} an estimated "
                "error above it"
                + ("" if len(law) == len(moved) else
                   f"; the results at n1 = {self.n1[0]} depend on the step (raise n1 and check again)")
            )
            if erratic:
                lines.append(
                    f"  {len(erratic)} of them do not converge with the step at a measurable order (a plain "
                    "difference, not an error bound): their error may not vanish with the step"
                )
            if law:
                lines.append(
                    f"  {len(law)} of them carry the law's error (eps or f) more than the step's: a smaller "
                    "eps or f, or the exact technique, not a finer step, reduces it"
                )
        return "\n".join(lines)


def _law_bound(q: Quantity) -> bool:
    """Whether the law's error governs a quantity's estimate."""
    e, law = q.estimate, q.law_estimate
    if e is None or law is None:
        return False
    return law.error >= e.error or not _claims(law, q.tolerance)


def _rank(q: Quantity) -> tuple[int, float]:
    flagged = any(e is not None and not _claims(e, q.tolerance) for e in (q.estimate, q.law_estimate))
    return (int(flagged), q.relative_error or 0.0)


def _estimate_part(e: Estimate) -> dict:
    return {"method": e.method, "order": e.order, "measured_order": e.measured,
            "extrapolated": e.extrapolated, "error": e.error, "errors": e.errors,
            "reason": e.reason}


def _estimate_dict(q: Quantity) -> dict:
    if q.estimate is None:
        return {}
    return {
        "estimated_error": q.error, "relative_error": q.relative_error,
        "estimate_method": methods_text(q.estimate, q.law_estimate),
        "step": _estimate_part(q.estimate),
        "law": None if q.law_estimate is None else _estimate_part(q.law_estimate),
    }


def _describe(e: Estimate, what: str, unit: str) -> str:
    text = f"{what} {e.error:.3g}: {method_text(e)}"
    if e.method == "richardson":
        text += f", limit {e.extrapolated:.6g}{unit}"
    return text


def _estimate_line(q: Quantity) -> str:
    assert q.estimate is not None
    name = f"{q.what} {q.item}".strip()
    unit = f" {q.unit}" if q.unit else ""
    head = f"{name}: {q.values[0]:.6g}{unit} +- {q.error:.3g} ({100 * (q.relative_error or 0.0):.3g} %): "
    parts = [_describe(q.estimate, "step", unit)]
    if q.law_estimate is not None:
        parts.append(_describe(q.law_estimate, "law", unit))
    return head + "; ".join(parts)


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


#: the numerical parameter of each regularized law, refined by the law levels: the velocity
#: law's band eps; the hysteretic law's sticking displacement f with its end-of-slide band
#: eps1 (docs/namelist.md defaults)
_LAW_PARAMETERS = {"velocity": (("eps", 1.0e-3),), "hysteretic": (("f", 1.0e-5), ("eps1", 1.0e-3))}
#: the groups whose devices' eps and f are numerical (a brace's f is its stiffness: physical)
_LAW_GROUPS = (("friction", "n_devices"), ("isolators", "n_isolators"))


def _law_text(text: str, factor: int) -> str | None:
    """The deck (a level's text) with the numerical parameter of every regularized device of
    ``&friction`` and ``&isolators`` divided by ``factor``; None when it has none."""
    out = f90nml.reads(text)
    changed = False
    for name, count in _LAW_GROUPS:
        group = out.get(name)
        if group is None or not int(group.get(count) or 0):
            continue
        n = int(group[count])
        laws = group.get("law")
        laws = laws if isinstance(laws, list) else [laws]
        laws = [str(x).strip().lower() if x is not None else "" for x in laws] + [""] * n
        for var, default in {v for law in laws[:n] for v in _LAW_PARAMETERS.get(law, ())}:
            given = group.get(var)
            given = given if isinstance(given, list) else [given]
            given = list(given) + [None] * (n - len(given))
            values = [default if v is None else float(v) for v in given[:n]]
            for i in range(n):
                if any(var == v for v, _ in _LAW_PARAMETERS.get(laws[i], ())):
                    values[i] /= factor
                    changed = True
            group[var] = values
    return write_namelist(out) if changed else None


def _items(kind: str, summary: dict, n: int) -> list[str]:
    if not kind:
        return [""]
    labels = {
        "dof": summary.get("dof_labels"),
        "device": summary.get("device_labels"),
        "storey": summary.get("storey_labels"),
    }[kind]
    return [labels[i] if labels and i < len(labels) and labels[i] else f"{kind} {i + 1}" for i in range(n)]


def _claims(estimate: Estimate, tol: float) -> bool:
    """Whether an estimate may stand for the error: Richardson's, or no change beyond
    round-off; a plain difference from three levels or more only when every change stays
    below NOISE times ``tol`` (the scatter of sampled peaks and located events). Otherwise its
    changes do not shrink at an order and nothing says that the error vanishes with the
    step: no convergence is claimed. (Two levels give no order: their change is judged
    against the tolerance as it is.)"""
    if estimate.method != "difference" or len(estimate.errors) < 3:
        return True
    return max(estimate.changes) <= NOISE * tol


def _compare(
    summaries: list[dict], rtol: float, factor: int = 2, law_summaries: Sequence[dict] = (),
    floor_share: float = FLOOR, cap: float = STEP_ORDER["newmark"],
) -> list[Quantity]:
    """The quantities of ``summaries`` (levels a ratio ``factor`` apart); the estimated ones
    with ``sound_estimate`` at the step's theoretical order ``cap`` and, from the law levels
    (``law_summaries``, below the last of ``summaries``), at the law's (LAW_ORDER)."""
    out = []
    for key, what, unit, kind, peak_key in _GROUPS:
        if any(key not in s for s in summaries):
            continue
        law_rows = [s[key] if isinstance(s[key], list) else [s[key]] for s in law_summaries]
        if key == "energy_friction_J" and not summaries[0].get("n_devices"):
            continue  # no device: nothing to compare (the per-device lists are empty)
        rows = [s[key] if isinstance(s[key], list) else [s[key]] for s in summaries]
        n = len(rows[0])
        if n == 0 or any(len(r) != n for r in rows):
            continue
        floor = floor_share * max(abs(x) for r in rows for x in r)
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
            estimate = law = None
            if key in ESTIMATED:
                estimate = sound_estimate(values, factor, size, cap)
                if law_rows:
                    law = sound_estimate([values[-1]] + [float(r[i]) for r in law_rows], factor,
                                         size, LAW_ORDER)
                error = estimate.error + (law.error if law else 0.0)
                if len(values) >= 3:  # from two levels, the change is all there is to judge
                    agrees = agrees and error <= tol and _claims(estimate, tol) and (
                        law is None or _claims(law, tol))
            out.append(Quantity(key, what, item, unit, values, size, tol, agrees, estimate, law, i))
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
    levels: int = 2,
    rtol: float = 0.01,
    threads: int | None = None,
    law: bool = True,
) -> ConvergenceReport:
    """Run ``deck`` at its n1 and at n1·factor**k, k = 1..levels, and compare the results.

    ``rtol``: the largest change allowed between consecutive levels, relative to the
    quantity (and not below ``FLOOR`` times the largest of its kind, so that a DOF that
    hardly moves is judged against the structure's motion); a residual drift or slip is
    judged against the largest peak drift or slip, the friction energy against the energy
    input; a stick-slip count may move by max(2, 10 %). The quantities of ``ESTIMATED`` also
    get an estimate of their error (``Estimate``): from the step levels, and with ``law``
    (the default), for the devices of ``&friction`` and ``&isolators`` under a regularized
    law, from law levels: the finest step with their eps (velocity law) or f and eps1
    (hysteretic law) divided by factor**k, k = 1..levels; such a quantity agrees when its
    estimated error (the step's plus the law's) is within the tolerance and its estimates
    may stand for the error (``_claims``). ``threads``: runs side by side (default: as many
    as there are runs, at most the CPUs this process may use). Raises DeckError for a bad
    deck, or for the event-driven technique (exact: its n1 only samples the history).
    """
    if isinstance(factor, bool) or not isinstance(factor, int) or factor < 2:
        raise ValueError(f"factor = {factor!r}: must be an integer >= 2")
    if isinstance(levels, bool) or not isinstance(levels, int) or not 1 <= levels <= 6:
        raise ValueError(f"levels = {levels!r}: must be an integer 1..6")
    if not (isinstance(rtol, (int, float)) and 0 < rtol < 1):
        raise ValueError(f"rtol = {rtol!r}: must be in (0, 1)")
    nml, path = _deck(deck)
    technique = str(nml.get("integration", {}).get("technique") or "newmark").strip().lower()
    if technique == "event_driven":
        raise DeckError(
            f"{path}: &integration technique = 'event_driven' is exact: its events, peaks and "
            "energies do not depend on n1 (it only samples the history), so there is no step "
            "to converge"
        )
    factors = [factor**k for k in range(levels + 1)]
    texts = [_level_text(nml, f) for f in factors]
    n1 = [int(f90nml.reads(t)["integration"]["n1"]) for t in texts]
    names = [f"n1 = {n}" for n in n1]
    law_texts = [_law_text(texts[-1], f) for f in factors[1:]] if law else []
    if law_texts and law_texts[0] is not None:
        texts += law_texts
        names += [f"n1 = {n1[-1]} with eps and f / {f}" for f in factors[1:]]
    workers = max(1, threads or min(len(texts), _cpus()))
    sessions: list[Session] = []
    level = names[0]
    try:
        for text, level in zip(texts, names):
            sessions.append(Session.from_text(text, path.name, path.parent))
            sessions[-1].select([], [])  # the summary has every peak; no history is kept
        with ThreadPoolExecutor(max_workers=workers) as pool:
            futures = [pool.submit(s.solve, None, False) for s in sessions]
            try:
                # a failed level stops the others at once
                wait(futures, return_when=FIRST_EXCEPTION)
                for f, level in zip(futures, names):
                    if f.done() and f.exception() is not None:
                        f.result()  # raises it
                for f, level in zip(futures, names):
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
        hint = "; --no-law (law=False) leaves the law levels out" if "eps and f" in level else ""
        raise type(exc)(f"{exc} (in the step convergence study, the level {level}{hint})") from None
    finally:
        for s in sessions:
            s.close()
    steps, laws = summaries[: len(n1)], summaries[len(n1):]
    report = ConvergenceReport(
        deck=str(path), n1=n1, rtol=float(rtol), summaries=steps,
        warnings=[summary_warnings(s) for s in steps], law_summaries=laws,
        law_warnings=[summary_warnings(s) for s in laws], factor=factor,
    )
    report.quantities = _compare(steps, rtol, factor, laws, cap=STEP_ORDER.get(technique, STEP_ORDER["newmark"]))
    return report
