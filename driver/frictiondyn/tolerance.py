"""Tolerance runs: the user states a tolerance on the reported peaks; the run chooses the
technique and its parameters, refines them until the estimated error of every estimated
quantity is below it, and reports the error it achieved.

``tolerance_run(deck, tolerance)`` (``frictiondyn.run(deck, tolerance=...)``, ``python -m
frictiondyn run DECK --tolerance T``, or ``tolerance`` in the deck's ``&integration``):

- Coulomb devices (a deck of ``technique = 'event_driven'`` or ``'moreau_jean'``): the exact
  event-driven technique when there are at most ``EXACT_DEVICES`` devices, all between two
  nodes (its peaks are exact: the estimate is round-off); otherwise Moreau-Jean, whose n1 is
  refined from the step levels' estimate (its next level the one their order predicts).
- The paper's regularized laws (``technique = 'newmark'``): where the deck has numerical eps or
  f (the velocity and hysteretic devices of ``&friction`` and ``&isolators``; a brace's f is
  physical), the combined ladder refines n1 and eps and f together; where it cannot measure an
  order, the step levels estimate the step's error and the law levels the law's.

The levels start from the model, not the deck's n1: a probe of one record step gives the
modes and dt_record, and the first round's finest step resolves the highest reported frequency
to the tolerance (``_probe_start``). Under a regularized law the combined ladder comes first
(``_combined``): n1 = n_c, 2 n_c, 4 n_c with eps and f divided by 0.5, 2 and 8 (eps and f fall
as the step squared, so that the law's first-order error falls as Newmark's second-order step
error does, and one order measured from three levels covers both), then the one level the
measured order predicts meets the tolerance, its estimate from the last three levels (their
order confirmed across the jump, ``ladder_estimate``); one extra level, 8 n_c, when the first
three measure no order. Where the combined order cannot be measured (the changes alternate,
do not shrink, or the order is below the range, above the noise; changes of one sign that
shrink faster than order 4 settle, ``_settles``, and their difference stands), or its next
level is beyond the cost limit, the separate ladders take over, reusing its runs, and the
report's ``why`` says so. The separate ladders: the law levels first, at the first round's
finest step: eps and f divided by 0.5, 2 and 8, then 4 times finer a level at a time, until
the law's estimate is within half the budget; then the step levels at that eps and f, n1 =
n_c, 2 n_c, 4 n_c, then one finer level a round, each round reusing the runs before. Each
estimate is Richardson's at the measured order capped at the theoretical one (``STEP_ORDER``,
``LAW_ORDER``), from the larger of the last two changes' predictions; a plain difference (times
3) where no order is consistent, or Richardson's over every other level (a ratio of 4) when five
levels exist; the step's difference stands for its error (a technique that converges), the
law's only below the noise (a regularized law's error need not vanish). The run returned, the
finest, is the first whose every estimate, step's plus law's, is below ``MARGIN`` times its
allowed error. When that would need more than ``MAX_REFINEMENT``
times the deck's n1 (or eps and f divided by more), ``ToleranceError`` is raised naming the
quantity, its estimate and why: no unmet tolerance is ever returned.

The allowed error of a quantity is tolerance x max(|q|, tolerance_floor x the largest |q| of
its kind) (the friction energy against the energy input): ``tolerance_floor`` keeps a DOF that
hardly moves from asking for a relative accuracy the structure's motion does not need.
"""

from __future__ import annotations

import hashlib
import json
import math
import os
import re
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass, field
from pathlib import Path

import f90nml

from ._api import _SUMMARY, DeckError, Result, Session, SolverError
from ._nml import copy_namelist, read_namelist, write_namelist
from .convergence import (
    DEFAULT_N1,
    ESTIMATED,
    LAW_ORDER,
    NOISE,
    ORDER_MAX,
    STEP_ORDER,
    Estimate,
    Quantity,
    _claims,
    _compare,
    _cpus,
    _law_text,
    ladder_estimate,
    method_text,
    methods_text,
)

__all__ = ["DEFAULT_FLOOR", "EXACT_DEVICES", "MAX_REFINEMENT", "ToleranceError",
           "ToleranceReport", "tolerance_run"]

#: tolerance_floor when neither the deck nor the caller gives it
DEFAULT_FLOOR = 0.01
#: Coulomb devices up to this count are run by the exact event-driven technique
EXACT_DEVICES = 10
#: the cost limit: the run returned has n1 at most this times the deck's, eps and f at least
#: the deck's / this
MAX_REFINEMENT = 128
#: a run is returned when every estimate is below MARGIN times its allowed error (the law's
#: below half of that, the step taking the rest): as soon as it is within it, the estimate
#: carrying its own safety factors (a margin of 0.8 cost up to 1.8 times the steps and bounded
#: no more quantities over the battery: docs/validation.md, section 7)
MARGIN = 1.0
#: the law levels: eps and f divided by LAW_START in the first round, each level LAW_RATIO
#: times finer than the one before (0.5, 2, 8, then 32 and 128, the cost limit)
LAW_START = (0.5, 2, 8)
LAW_RATIO = 4
#: the combined ladder ties eps and f to the step as its TIE-th power: the law's error, first
#: order in eps and f, then falls at Newmark's second order in the step, as the step's does
TIE = 2
#: the techniques whose step ladder jumps to the level the measured order predicts (the
#: smallest integer multiple of the finest, at most JUMP_MAX), filling in the level twice the
#: one it jumped from when the order is not confirmed across the jump
JUMPS = ("moreau_jean",)
JUMP_MAX = 8
#: the combined ladder's coarsest eps and f: the deck's divided by this
COMBINED_START = 0.5
#: levels the combined ladder adds, one a round, before it falls back when its order is not measured
COMBINED_EXTRA = 1
#: the method of a combined ladder's estimate
COMBINED = "step and law together (eps and f / the step squared)"
#: the estimate of an exact technique's peaks, relative to the quantity (round-off)
ROUND_OFF = 1e-9
#: the two deck variables of a tolerance run (&integration)
VARIABLES = ("tolerance", "tolerance_floor")


class ToleranceError(SolverError):
    """A tolerance run cannot meet its tolerance (an error that does not vanish, or a cost
    beyond the limit); its message names the quantity, its estimate and why."""


@dataclass
class ToleranceReport:
    """What a tolerance run chose and achieved (the summary's ``tolerance_run`` block)."""

    tolerance: float
    floor: float
    technique: str
    why: str
    n1: int
    law_divisor: int  #: eps and f of the regularized devices divided by this (1: the deck's)
    runs: int
    rounds: int
    steps: int  #: the steps of every run made (newmark_steps of each summary)
    quantities: list[dict] = field(default_factory=list)
    #: every run made, in order: (what it was, its steps), the split of ``steps``
    made: list[tuple[str, int]] = field(default_factory=list)

    def block(self) -> dict:
        errors: dict[str, list[float]] = {}
        methods: dict[str, list[str]] = {}
        for q in self.quantities:
            errors.setdefault(q["key"], []).append(q["estimated_error"])
            methods.setdefault(q["key"], []).append(q["method"])
        return {
            "tolerance": self.tolerance, "tolerance_floor": self.floor, "technique": self.technique,
            "why": self.why, "n1": self.n1, "law_divisor": self.law_divisor, "runs": self.runs,
            "rounds": self.rounds, "steps": self.steps, "met": True,
            "estimated_error": errors, "estimate_method": methods,
        }

    def __str__(self) -> str:
        head = (f"tolerance run: {self.tolerance:g} (floor {self.floor:g}): {self.technique}, "
                f"n1 = {self.n1}")
        if self.law_divisor > 1:
            head += f", eps and f / {self.law_divisor}"
        rounds = f"{self.rounds} round{'s' * (self.rounds != 1)}"
        runs = f"{self.runs} run{'s' * (self.runs != 1)}"
        lines = [f"{head} ({runs}, {rounds}): {self.why}"]
        worst: dict[str, dict] = {}
        for q in self.quantities:
            if q["key"] not in worst or q["relative_error"] > worst[q["key"]]["relative_error"]:
                worst[q["key"]] = q
        for q in worst.values():
            name = f"{q['what']} {q['item']}".strip()
            lines.append(f"  {name}: {q['value']:.6g} {q['unit']} +- {q['estimated_error']:.3g} "
                         f"({100 * q['relative_error']:.3g} % of its scale; {q['method']})")
        return "\n".join(lines)


def _strip(text: str, path: Path) -> tuple[str, float | None, float | None]:
    """The deck without its tolerance variables, and their values (None: not given). The
    library reads the deck first: a bad value gets its message; a deck that gives either
    is refused there as one setting, which is what this run is for."""
    try:
        with Session.from_text(text, path.name, path.parent):
            pass
    except DeckError as exc:
        if "is a tolerance run" not in str(exc):
            raise
    match = re.search(r"&integration\b", text, re.IGNORECASE)
    values: list[float | None] = [None, None]
    if match is None:
        return text, None, None
    end = text.find("&", match.end())
    end = len(text) if end < 0 else end
    group = text[match.end():end]
    for k, var in enumerate(VARIABLES):
        pattern = re.compile(rf"\b{var}\s*=\s*([^\s,/!]+)\s*,?", re.IGNORECASE)
        found = pattern.search(group)
        if found is not None:
            values[k] = float(found.group(1).lower().replace("d", "e"))
            group = pattern.sub("", group)
    return text[:match.end()] + group + text[end:], values[0], values[1]


def _check(tolerance: float, floor: float, path: Path) -> None:
    def number(x) -> bool:
        return isinstance(x, (int, float)) and not isinstance(x, bool)

    if not number(tolerance) or not 0 < tolerance < 1:
        raise DeckError(f"{path}, group &integration: tolerance = {tolerance!r} is invalid: "
                        "must be in (0, 1)")
    if not number(floor) or not 0 <= floor <= 1:
        raise DeckError(f"{path}, group &integration: tolerance_floor = {floor!r} is invalid: "
                        "must be in [0, 1]")


def _with(nml: f90nml.Namelist, n1: int, technique: str | None = None) -> f90nml.Namelist:
    out = copy_namelist(nml)
    integ = out.setdefault("integration", f90nml.Namelist())
    base = integ.get("n1")
    base = DEFAULT_N1 if base is None else int(base)
    factor = n1 / base
    integ["n1"] = n1
    if technique is not None:
        integ["technique"] = technique
    if integ.get("dt_min") and factor > 1:  # a coarser step keeps the deck's (below its bound)
        integ["dt_min"] = float(integ["dt_min"]) / factor
    output = out.get("output")
    if output is not None and output.get("output_every"):  # a row every dt_record x output_every
        output["output_every"] = max(1, round(int(output["output_every"]) * factor))
    return out


class _Runner:
    """Runs deck texts side by side, each once; keeps the session of the one asked for."""

    def __init__(self, path: Path, threads: int | None, select=(None, None)) -> None:
        self.path, self.threads, self.select = path, threads, select
        self.summaries: dict[str, dict] = {}
        self.kept: dict[str, Session] = {}
        self.steps = 0
        self.labels: dict[str, str] = {}  #: what each deck text is (the report's ``made``)
        self.made: list[tuple[str, int]] = []

    def run(self, texts: list[str], keep: str | None, labels: list[str] | None = None
            ) -> list[dict]:
        for t, label in zip(texts, labels or []):
            self.labels.setdefault(t, label)
        # a run made before and closed is made again if it is the one to keep
        todo = [t for t in dict.fromkeys(texts)
                if t not in self.summaries or (t == keep and t not in self.kept)]
        sessions = []
        try:
            for t in todo:
                s = Session.from_text(t, self.path.name, self.path.parent)
                sessions.append(s)
                if t != keep:
                    s.select([], [])
                elif self.select != (None, None):
                    s.select(*self.select)
            workers = max(1, self.threads or min(len(todo), _cpus()))
            with ThreadPoolExecutor(max_workers=workers) as pool:
                futures = [pool.submit(s.solve, None, t == keep) for s, t in zip(sessions, todo)]
                try:
                    for f in futures:
                        f.result()
                except BaseException:
                    for s in sessions:
                        s.cancel()
                    raise
            for s, t in zip(sessions, todo):
                summary = json.loads(s._text(_SUMMARY))
                self.summaries[t] = summary
                self.steps += _cost(summary)
                self.made.append((self.labels.get(t, "run"), _cost(summary)))
                if t == keep:
                    self.kept[t] = s
        finally:
            for s, t in zip(sessions, todo):
                if t != keep or t not in self.kept:
                    s.close()
        return [self.summaries[t] for t in texts]

    def close(self, but: str | None = None) -> None:
        for t, s in list(self.kept.items()):
            if t != but:
                s.close()
                del self.kept[t]


def _cost(summary: dict) -> int:
    """The steps a run solved (an exact run: its events and sampled intervals)."""
    keys = ("steps_dt1", "steps_nested", "steps_dt2", "steps_finer", "steps_implicit",
            "implicit_redos")
    return int(sum(summary.get(k, 0) for k in keys))


def _error_of(q: Quantity) -> tuple[float, float]:
    """(step, law) estimated errors of the finest run of the levels."""
    step = q.estimate.errors[-1] if q.estimate is not None else 0.0
    law = q.law_estimate.errors[-1] if q.law_estimate is not None else 0.0
    return step, law


def _factor(error: float, allowed: float, order: float | None) -> int:
    """The power of 2 by which to divide a parameter so that an error at ``order`` falls
    below ``allowed`` (with a margin of 1.5)."""
    p = order if order else 1.0
    need = (1.5 * error / allowed) ** (1.0 / p) if allowed > 0 else math.inf
    if not math.isfinite(need):
        return 2 ** 30
    return max(2, 2 ** math.ceil(math.log2(max(need, 1.0))))


def _multiple(error: float, allowed: float, order: float) -> int:
    """The smallest integer by which to divide a parameter so that an error at ``order`` falls
    below ``allowed`` (with a margin of 1.5), at least 2: the level a jump predicts, no finer
    than the order asks (a power of 2 costs up to twice as many steps)."""
    need = (1.5 * error / allowed) ** (1.0 / order) if allowed > 0 else math.inf
    if not math.isfinite(need):
        return 2 ** 30
    return max(2, math.ceil(need - 1e-9))


def _quantity_rows(quantities: list[Quantity], tol: float, values_of) -> list[dict]:
    rows = []
    for q in quantities:
        if q.key not in ESTIMATED:
            continue
        step, law = _error_of(q)
        error = max(step + law, ROUND_OFF * q.scale)  # no estimate below round-off
        method = methods_text(q.estimate, q.law_estimate)
        rows.append({"key": q.key, "index": q.index, "what": q.what, "item": q.item, "unit": q.unit,
                     "value": values_of(q), "estimated_error": error,
                     "relative_error": error / q.scale if q.scale > 0 else 0.0,
                     "allowed": tol * q.scale, "method": method})
    return rows


def _exact(runner: _Runner, nml, n1: int, tol: float, floor: float,
           why: str) -> tuple[ToleranceReport, str]:
    text = write_namelist(_with(nml, n1, "event_driven"))
    (summary,) = runner.run([text], keep=text, labels=[f"exact, n1 = {n1}"])
    qs = _compare([summary, summary], tol, 2, (), floor)
    rows = []
    for q in qs:
        if q.key in ESTIMATED:
            err = ROUND_OFF * q.scale
            rows.append({"key": q.key, "index": q.index, "what": q.what, "item": q.item,
                         "unit": q.unit, "value": q.values[0], "estimated_error": err,
                         "relative_error": ROUND_OFF, "allowed": tol * q.scale,
                         "method": "exact: event-driven technique (round-off)"})
    report = ToleranceReport(tol, floor, "event_driven", why, n1, 1, len(runner.summaries), 1,
                             runner.steps, rows, list(runner.made))
    return report, text


def _measured(e: Estimate) -> float | None:
    """The measured order of a Richardson estimate (before any cap), to predict the refinement
    a quantity needs; None for a difference."""
    if e.method != "richardson":
        return None
    return e.measured if e.measured is not None else e.order


def _probe_start(runner: _Runner, nml, technique: str, tol: float) -> tuple[int, str]:
    """The coarsest step level chosen from the model: the finest level of the first round,
    n1 = 4 n_c, resolves the highest frequency that carries the response, omega (the reported
    modes, stuck and free (free only under a hysteretic law), and a harmonic table motion's),
    to the tolerance: Newmark's (the
    trapezoidal rule's) relative period error (omega dt1)^2 / 12 at most the tolerance. The
    model's modes come from a probe of one record step (dt1 = dt_record)."""
    probe = _with(nml, 1, technique)
    if "excitation" in probe:
        probe["excitation"]["duration"] = 1e-9  # one step: the modes and dt_record, no response
    try:
        (summary,) = runner.run([write_namelist(probe)], keep=None, labels=["probe"])
    except (SolverError, DeckError):
        summary = {}
    # the stuck system of a hysteretic device holds its sticking spring, k = P mu / f: a
    # numerical stiffness whose ringing the paper's dt2 steps resolve (stick_resolution)
    keys = ("periods_free_s",) if "hysteretic" in (summary.get("device_law") or []) else (
        "periods_free_s", "periods_stuck_s")
    periods = [float(t) for key in keys for t in summary.get(key) or [] if t is not None]
    periods = [t for t in periods if math.isfinite(t) and t > 0]
    omegas = [2 * math.pi / t for t in periods]
    if summary.get("excitation_frequency_Hz"):
        omegas.append(2 * math.pi * float(summary["excitation_frequency_Hz"]))
    if not omegas or not summary.get("dt1_s"):
        n_c = max(1, int(nml.get("integration", {}).get("n1") or DEFAULT_N1) // 4)
        return n_c, (f"n1 = {n_c}, {2 * n_c}, {4 * n_c} from the deck's n1 (no mode or record step "
                     "known)")
    omega, dt_record = max(omegas), float(summary["dt1_s"])
    n_fine = max(1, math.ceil(dt_record * omega / math.sqrt(12 * tol)))
    n_c = 2 ** max(0, math.ceil(math.log2(n_fine)) - 2)
    return n_c, (f"n1 = {n_c}, {2 * n_c}, {4 * n_c} first (omega = {omega:.4g} rad/s, dt_record = "
                 f"{dt_record:g} s: (omega dt1)^2 / 12 <= {tol:g} at n1 = {n_fine})")


def _text_at(nml, technique: str, n: int, divisor: float) -> str:
    """The deck at n1 = n with eps and f of the regularized devices divided by ``divisor``."""
    text = write_namelist(_with(nml, n, technique))
    return text if divisor == 1 else _law_text(text, divisor)


def _label(kind: str, n: int, divisor: float) -> str:
    return f"{kind}: n1 = {n}" + (f", eps and f / {divisor:g}" if divisor != 1 else "")


def _law_levels(runner: _Runner, nml, technique: str, n: int, tol: float, floor: float,
                divisors: list[float]) -> dict[tuple[str, int], Quantity]:
    """The law's estimate per quantity, from the last three law levels at step n1 = n."""
    texts = [_text_at(nml, technique, n, d) for d in divisors[-3:]]
    runner.close(but=texts[-1])  # the combined ladder's finest level may be the law's
    labels = [_label("law level", n, d) for d in divisors[-3:]]
    runs = runner.run(texts, keep=texts[-1], labels=labels)  # its finest may be the run returned
    return {(q.key, q.index): q for q in _compare(runs, tol, LAW_RATIO, (), floor, LAW_ORDER)
            if q.estimate is not None}


def _measures(e: Estimate, allowed: float) -> bool:
    """Whether a combined ladder's estimate may stand for the error: Richardson's, unchanged,
    or a plain difference whose last two changes are below NOISE times the allowed error (the
    scatter of sampled peaks; ``_claims`` on the levels the estimate stands on)."""
    return e.method != "difference" or max(e.changes[-2:]) <= NOISE * allowed


def _settles(values: list[float], ratios: list[float]) -> bool:
    """Whether the last three levels' changes have one sign and shrink faster than any order
    of the range (ORDER_MAX), or the last is zero: a quantity that settles before the
    asymptotic order shows, whose plain difference (3 times the larger change) is then an
    upper estimate, not a guess."""
    d1, d2 = values[-2] - values[-3], values[-1] - values[-2]
    if d1 == 0:
        return False
    if d2 == 0:
        return True
    r1, r2 = ratios[-2], ratios[-1]
    fastest = r2**ORDER_MAX * (r1**ORDER_MAX - 1) / (r2**ORDER_MAX - 1)
    return d1 * d2 > 0 and d1 / d2 > fastest


def _tied(start: int, s: int) -> tuple[int, float]:
    """The combined ladder's level of scale ``s``: n1 = s start, and eps and f divided by
    COMBINED_START s^TIE."""
    return start * s, COMBINED_START * s**TIE


def _combined(runner: _Runner, nml, path: Path, n1: int, technique: str, tol: float,
              floor: float, start: int, why: str) -> tuple[ToleranceReport, str] | str:
    """The combined ladder of a regularized law: the step and the law's eps and f refined
    together (``_tied``), so that one ratio moves both error sources and three levels measure
    one order (capped at the step's theoretical one: the law's first order in eps and f is
    order TIE in the step). From scales 1, 2 and 4, each round adds the one level the measured
    order predicts meets the tolerance (a power of 2 times the finest, with a margin of 1.5),
    every run made once; the estimate of the finest level then stands on the last three levels,
    whose order confirms the prediction across the jump (``ladder_estimate``). Returns the
    report and the text of the run returned, or, where a quantity's combined order cannot be
    measured (no consistent order, changes above the noise) or the next level is beyond the
    cost limit, the reason, for the separate ladders to take over."""
    scales = [1, 2, 4]
    cap = STEP_ORDER[technique]
    rounds = extra = 0
    while True:
        rounds += 1
        texts = [_text_at(nml, technique, *_tied(start, s)) for s in scales]
        labels = [_label("combined level", *_tied(start, s)) for s in scales]
        runner.close()
        summaries = runner.run(texts, keep=texts[-1], labels=labels)
        ratios = [b / a for a, b in zip(scales, scales[1:])]
        qs = _compare(summaries, tol, 2, (), floor, cap)
        last = summaries[-1]
        _initial_peaks(path, tol, last, qs)
        need, worst, unmeasured = 1, None, None
        for q in qs:
            if q.key not in ESTIMATED:
                continue
            q.estimate = ladder_estimate(q.values, ratios, q.scale, cap)
            allowed = tol * q.scale
            error = q.estimate.errors[-1]
            if not (_measures(q.estimate, allowed) or _settles(q.values, ratios)):
                unmeasured = q
                break
            if error <= MARGIN * allowed:
                continue
            p = q.estimate.order or cap
            factor = (1.5 * error / allowed) ** (1.0 / p)
            need = max(need, 2 ** max(1, math.ceil(math.log2(factor))))
            if worst is None or error / allowed > worst[1]:
                worst = (q, error / allowed)
        if unmeasured is not None:
            if extra < COMBINED_EXTRA and len(scales) == 3 + extra:  # the coarsest level may
                # come before the asymptotic order: one more level, the coarsest then left out
                extra += 1
                scales.append(2 * scales[-1])
                continue
            name = f"{unmeasured.what} {unmeasured.item}".strip()
            return (f"{name}: the combined levels n1 = "
                    f"{', '.join(str(_tied(start, s)[0]) for s in scales[-3:])} give "
                    f"{method_text(unmeasured.estimate)}")
        if worst is None:
            rows = []
            for q in qs:
                if q.key not in ESTIMATED:
                    continue
                error = max(q.estimate.errors[-1], ROUND_OFF * q.scale)
                rows.append({"key": q.key, "index": q.index, "what": q.what, "item": q.item,
                             "unit": q.unit, "value": _value(last, q), "estimated_error": error,
                             "relative_error": error / q.scale if q.scale > 0 else 0.0,
                             "allowed": tol * q.scale,
                             "method": f"{COMBINED}: {method_text(q.estimate)}"})
            n_final, divisor = _tied(start, scales[-1])
            levels = "; ".join(f"n1 = {n}, eps and f / {d:g}"
                               for n, d in (_tied(start, s) for s in scales))
            report = ToleranceReport(tol, floor, technique, f"{why}; the combined ladder: {levels}",
                                     n_final, int(divisor), len(runner.summaries), rounds,
                                     runner.steps, rows, list(runner.made))
            return report, texts[-1]
        s_next = scales[-1] * need
        n_next, d_next = _tied(start, s_next)
        if n_next > MAX_REFINEMENT * n1 or d_next > MAX_REFINEMENT:
            q = worst[0]
            return (f"{q.what} {q.item}".strip() + f": the combined ladder's next level, n1 = "
                    f"{n_next} with eps and f / {d_next:g}, is beyond the cost limit")
        scales.append(s_next)


def _refine(runner: _Runner, nml, path: Path, n1: int, technique: str, tol: float, floor: float,
            why: str) -> tuple[ToleranceReport, str]:
    """Under a regularized law, the combined ladder (``_combined``); where it cannot measure
    an order, the separate ladders, saying so: the law levels refined until the law's
    estimate is within half the budget, then the step levels until every estimate, step's
    plus law's, is within it (MARGIN times the allowed error): each round adds one level to a
    ladder and reuses the runs of the rounds before (the runner makes each deck text once).
    Moreau-Jean's step ladder (JUMPS) adds the level the order its estimate stands on
    predicts (the smallest integer multiple of the finest, at most JUMP_MAX), and, where the
    changes across that jump show no order, the level twice the one it jumped from."""
    regularized = (technique == "newmark"
                   and _law_text(write_namelist(_with(nml, n1)), 2) is not None)
    start, start_why = _probe_start(runner, nml, technique, tol)
    if regularized:
        got = _combined(runner, nml, path, n1, technique, tol, floor, start,
                        f"{why}; {start_why}")
        if not isinstance(got, str):
            return got
        why = (f"{why}; the combined ladder (eps and f tied to the step) measured no order "
               f"({got}): the separate step and law ladders")
    steps = [start, 2 * start, 4 * start]
    divisors = list(LAW_START) if regularized else [1]
    laws: dict[tuple[str, int], Quantity] = {}
    rounds = 0
    while regularized:  # the law levels, at the first round's finest step
        rounds += 1
        laws = _law_levels(runner, nml, technique, steps[-1], tol, floor, divisors)
        worst, need = None, 1
        for q in laws.values():
            if q.key not in ESTIMATED:
                continue
            allowed = tol * q.scale
            claims = _claims(q.estimate, allowed)
            if q.estimate.errors[-1] <= MARGIN * allowed / 2 and claims:
                continue
            ratio = q.estimate.errors[-1] / max(allowed, 1e-300)
            if worst is None or ratio > worst[1]:
                worst = (q, ratio)
            budget = MARGIN * allowed / 2
            need = max(need, _factor(q.estimate.errors[-1], budget, _measured(q.estimate))
                       if claims else 2)
        if worst is None:
            break
        if divisors[-1] * need > MAX_REFINEMENT or divisors[-1] * LAW_RATIO > MAX_REFINEMENT:
            q = worst[0]
            what = _what(q, q.values[-1], 0.0, q.estimate.errors[-1], None, q.estimate)
            why = (f"meeting it needs more than eps and f / {MAX_REFINEMENT}, the cost limit "
                   f"({MAX_REFINEMENT} times the deck's setting)")
            raise ToleranceError(_unmet(path, tol, what, q.estimate, why))
        divisors.append(divisors[-1] * LAW_RATIO)
    divisor = divisors[-1]
    filled: set[int] = set()  # the jumps whose order a level filled in below them confirms
    while True:
        rounds += 1
        levels = [_text_at(nml, technique, n, divisor) for n in steps[-5:]]
        final = levels[-1]
        labels = [_label("step level", n, divisor) for n in steps[-5:]]
        summaries = runner.run(levels, keep=final, labels=labels)
        qs = _compare(summaries, tol, 2, (), floor, STEP_ORDER[technique])
        ratios = [b / a for a, b in zip(steps[-5:], steps[-5:][1:])]
        for q in qs:
            if q.estimate is not None:
                q.estimate = ladder_estimate(q.values, ratios, q.scale, STEP_ORDER[technique])
                law = laws.get((q.key, q.index))
                q.law_estimate = law.estimate if law is not None else None
        last = summaries[-1]

        def value(q: Quantity, last=last) -> float:
            return _value(last, q)

        if regularized:
            _initial_peaks(path, tol, last, qs)
        rows = _quantity_rows(qs, tol, value)
        worst, need, jump = None, 1, 2
        for q in qs:
            if q.key not in ESTIMATED:
                continue
            step, law = _error_of(q)
            allowed = tol * q.scale
            # the step's: a technique that converges, whose difference times 3 stands for its
            # error without an order (the law's must show one, or changes below the noise)
            claims = True
            if step + law <= MARGIN * allowed:
                continue
            ratio = (step + law) / max(allowed, 1e-300)
            if worst is None or ratio > worst[1]:
                worst = (q, ratio, step, law)
            budget = MARGIN * allowed - law
            need = max(need, _factor(step, budget, _measured(q.estimate)) if claims else 2)
            # the level the order the estimate stands on predicts; none without an order
            jump = (max(jump, _multiple(step, budget, q.estimate.order)) if jump
                    and q.estimate.method == "richardson" else 0)
        if worst is None:
            report = ToleranceReport(tol, floor, technique, f"{why}; {start_why}", steps[-1],
                                     int(divisor), len(runner.summaries), rounds, runner.steps,
                                     rows, list(runner.made))
            return report, final
        runner.close(but=final)  # a level filled in below keeps the finest
        q, _, step, law = worst
        if steps[-1] * need > MAX_REFINEMENT * n1 or 2 * steps[-1] > MAX_REFINEMENT * n1:
            what = _what(q, value(q), step, law, q.estimate, q.law_estimate)
            why = (f"meeting it needs more than n1 = {MAX_REFINEMENT * n1}, the cost limit "
                   f"({MAX_REFINEMENT} times the deck's n1)")
            raise ToleranceError(_unmet(path, tol, what, None, why))
        if technique not in JUMPS:
            steps.append(2 * steps[-1])
        elif steps[-1] > 2 * steps[-2] and not jump and steps[-1] not in filled:
            # the jump's order not confirmed: the level twice the one it jumped from, the
            # cheapest level between them, so the finest's estimate stands on ratios 2 and r / 2
            filled.add(steps[-1])
            steps.insert(len(steps) - 1, 2 * steps[-2])
        else:
            jump = min(max(jump, 2), JUMP_MAX, MAX_REFINEMENT * n1 // steps[-1])
            steps.append(steps[-1] * jump)


def _what(q: Quantity, value: float, step: float, law: float, step_e: Estimate | None,
          law_e: Estimate | None) -> str:
    name = f"{q.what} {q.item}".strip()
    return (f"{name} = {value:.6g} {q.unit}: estimated error {step + law:.3g} {q.unit} "
            f"({100 * (step + law) / q.scale:.3g} % of its scale {q.scale:.6g}; "
            f"{methods_text(step_e, law_e)})")


def _initial_peaks(path: Path, tol: float, summary: dict, qs: list[Quantity]) -> None:
    """A peak absolute acceleration at t = 0 under a regularized law is the law's initial
    state, a device that starts unloaded (its force 0 at rest, whatever eps or f), where
    Coulomb's force takes any value up to P mu: no level changes it, so no estimate sees it."""
    times = summary.get("peak_aabs_time_s") or []
    for q in qs:
        if q.key == "peak_aabs_mps2" and q.index < len(times) and times[q.index] == 0.0:
            raise ToleranceError(
                f"{path}: tolerance {tol:g} cannot be met: {q.what} {q.item} = "
                f"{_value(summary, q):.6g} {q.unit} is reached at t = 0, where a regularized "
                "device starts unloaded (no force at rest, whatever eps or f; Coulomb's force up "
                "to P mu): no refinement changes it and no estimate sees it; give the devices "
                "law = 'coulomb' (the exact technique or Moreau-Jean)")


def _unmet(path: Path, tol: float, what: str, law: Estimate | None, why: str) -> str:
    """The refusal: ``law`` is the law's estimate when the law governs (None: the step)."""
    if law is not None:
        rate = (f"it falls at order {law.order:.2f} in eps or f" if law.method == "richardson"
                else "it falls at no measurable order in eps or f")
        hint = (f"the regularized law's error governs and {rate} (the hysteretic law's peaks at "
                "about 1/2 in f, and its accelerations where the exact force jumps not at all: "
                "docs/theory.md, section 16); give the devices law = 'coulomb' (the exact "
                "technique or Moreau-Jean), or a larger tolerance")
    else:
        hint = ("the step's error governs: a larger tolerance, or a shorter or smaller model, is "
                "needed")
    return f"{path}: tolerance {tol:g} cannot be met: {what}; {why}; {hint}"


def _value(summary: dict, q: Quantity) -> float:
    v = summary[q.key]
    return float(v[q.index]) if isinstance(v, list) else float(v)


def _summary_block(report: ToleranceReport) -> dict:
    block = report.block()
    return {"estimated_error": block.pop("estimated_error"),
            "estimate_method": block.pop("estimate_method"), "tolerance_run": block}


def tolerance_run(
    deck: str | os.PathLike | None = None,
    tolerance: float | None = None,
    tolerance_floor: float | None = None,
    threads: int | None = None,
    text: str | None = None,
    name: str = "deck.nml",
    base_dir: str | os.PathLike = ".",
    dofs=None,
    devices=None,
) -> tuple[Result, ToleranceReport, Session]:
    """Run ``deck`` (a file, or ``text`` named ``name`` in ``base_dir``) to ``tolerance``
    (relative, on the estimated peaks; the deck's ``&integration`` tolerance when None) with
    ``tolerance_floor`` (the deck's, else DEFAULT_FLOOR). Returns the chosen run's Result,
    whose summary carries ``estimated_error``, ``estimate_method`` and ``tolerance_run``,
    the report, and the chosen run's open Session (for ``write``; the caller closes it).
    ``dofs``, ``devices``: the history's selection, as for ``frictiondyn.run``.
    Raises ToleranceError when the tolerance cannot be met, DeckError for a bad deck."""
    if text is None:
        if deck is None:
            raise TypeError("tolerance_run needs a deck or its text")
        path = Path(deck)
        try:
            text = path.read_bytes().decode("utf-8", "surrogateescape")
        except FileNotFoundError:
            raise DeckError(f"{path}: no such deck") from None
        except (OSError, UnicodeDecodeError) as exc:
            raise DeckError(f"{path}: cannot read the deck ({exc})") from None
    else:
        path = Path(base_dir) / name
    stripped, deck_tol, deck_floor = _strip(text, path)
    tol = tolerance if tolerance is not None else deck_tol
    if tol is None:
        raise DeckError(f"{path}: no tolerance: give &integration tolerance, or tolerance=")
    floor = tolerance_floor if tolerance_floor is not None else (
        deck_floor if deck_floor is not None else DEFAULT_FLOOR)
    _check(tol, floor, path)
    nml = read_namelist(stripped, path)
    integ = nml.get("integration", {})
    technique = str(integ.get("technique") or "newmark").strip().lower()
    n1 = integ.get("n1")
    n1 = DEFAULT_N1 if n1 is None else int(n1)
    runner = _Runner(path, threads, (dofs, devices))
    try:
        if technique == "newmark":
            why = ("the paper's regularized laws: n1, eps and f refined together by the combined "
                   "ladder" if _law_text(stripped, 2) is not None else
                   "Newmark without a numerical eps or f (no velocity or hysteretic device of "
                   "&friction or &isolators): n1 refined by the step levels")
            report, final = _refine(runner, nml, path, n1, "newmark", tol, floor, why)
        else:
            with Session.from_text(stripped, path.name, path.parent) as s:
                n_dev = s._sizes()[1]
            exact_ok = n_dev <= EXACT_DEVICES
            if exact_ok:
                try:
                    exact = write_namelist(_with(nml, n1, "event_driven"))
                    with Session.from_text(exact, path.name, path.parent):
                        pass
                except DeckError:
                    exact_ok = False  # a device the exact technique cannot take (not a pair's)
            report = final = None
            if exact_ok:
                try:
                    why = (f"{n_dev} Coulomb device{'s' * (n_dev != 1)} (at most {EXACT_DEVICES}): "
                           "the exact event-driven technique, whose peaks are exact")
                    report, final = _exact(runner, nml, n1, tol, floor, why)
                except SolverError as exc:
                    why = f"the exact technique failed ({exc}); "
                else:
                    why = ""
            if report is None:
                if not exact_ok:
                    why = (f"{n_dev} Coulomb devices (more than {EXACT_DEVICES}, or one not "
                           "between two nodes): ")
                report, final = _refine(runner, nml, path, n1, "moreau_jean", tol, floor,
                                        why + "Moreau-Jean with n1 refined by its step levels")
        session = runner.kept.pop(final)
        runner.close()
        result = session.result()
        result.summary.update(_summary_block(report))
        # the deck given, as sha256sum reads it (the run chosen is of a deck written from it)
        result.summary["deck_sha256"] = hashlib.sha256(
            text.encode("utf-8", "surrogateescape")).hexdigest()
        return result, report, session
    finally:
        runner.close()
