"""Tolerance runs: the user states a tolerance on the reported peaks; the run chooses the
technique and its parameters, refines them until the estimated error of every estimated
quantity is below it, and reports the error it achieved.

``tolerance_run(deck, tolerance)`` (``frictiondyn.run(deck, tolerance=...)``, ``python -m
frictiondyn run DECK --tolerance T``, or ``tolerance`` in the deck's ``&integration``):

- Coulomb devices (a deck of ``technique = 'event_driven'`` or ``'moreau_jean'``): the exact
  event-driven technique when there are at most ``EXACT_DEVICES`` devices, all between two
  nodes (its peaks are exact: the estimate is round-off); otherwise Moreau-Jean, whose n1 is
  refined from the step levels' estimate.
- The paper's regularized laws (``technique = 'newmark'``): the step levels estimate the step's
  error and, where the deck has numerical eps or f (the velocity and hysteretic devices of
  ``&friction`` and ``&isolators``; a brace's f is physical), the law levels the law's.

The run returned is the finest level: n1 = N (the deck's n1 in the first round, rounded up to
a multiple of 4) with eps and f divided by D (1 in the first round). The step levels are N / 4,
N / 2 and N; the law levels are the coarsest step, N / 4, with eps and f times 4 and 2, and
with them (the law's error is taken apart from the step's, which the levels at one step cancel).
Each level's estimate is that of ``frictiondyn converge`` (``frictiondyn.convergence``,
docs/theory.md, section 16): Richardson extrapolation at the measured order where it is
consistent, a plain difference (times 3) otherwise; the finest level's error, the step's plus
the law's, is its estimate. While that is above the allowed error of a quantity, N (and D) are
multiplied by the power of 2 its measured order asks for; a plain difference above the noise
claims nothing and doubles them. When the returned run would need more than ``MAX_REFINEMENT``
times the deck's n1 (or eps and f divided by more), or ``MAX_ROUNDS`` rounds do not meet it,
``ToleranceError`` is raised naming the quantity, its estimate and why: no unmet tolerance is
ever returned. A run costs the finest level and 1.25 times it (1 / 4 + 1 / 2 for the coarser
step levels, and 1 / 2 for the two law levels at the coarsest step) in each round.

The allowed error of a quantity is tolerance x max(|q|, tolerance_floor x the largest |q| of
its kind) (the friction energy against the energy input): ``tolerance_floor`` keeps a DOF that
hardly moves from asking for a relative accuracy the structure's motion does not need.
"""

from __future__ import annotations

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
    Estimate,
    Quantity,
    estimate_error,
    _claims,
    _compare,
    _cpus,
    _law_text,
)

__all__ = ["DEFAULT_FLOOR", "EXACT_DEVICES", "MAX_REFINEMENT", "MAX_ROUNDS", "ToleranceError",
           "ToleranceReport", "tolerance_run"]

#: tolerance_floor when neither the deck nor the caller gives it
DEFAULT_FLOOR = 0.01
#: Coulomb devices up to this count are run by the exact event-driven technique
EXACT_DEVICES = 10
#: the cost limit: the run returned has n1 at most this times the deck's, eps and f at least
#: the deck's / this
MAX_REFINEMENT = 128
#: refinement rounds at most (each runs the step levels and, under a regularized law, the law levels)
MAX_ROUNDS = 4
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
        lines = [f"tolerance run: {self.tolerance:g} (floor {self.floor:g}): {self.technique}, n1 = {self.n1}"
                 + (f", eps and f / {self.law_divisor}" if self.law_divisor > 1 else "")
                 + f" ({self.runs} runs, {self.rounds} round{'s' * (self.rounds != 1)}): {self.why}"]
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
    if isinstance(tolerance, bool) or not isinstance(tolerance, (int, float)) or not 0 < tolerance < 1:
        raise DeckError(f"{path}, group &integration: tolerance = {tolerance!r} is invalid: must be in (0, 1)")
    if isinstance(floor, bool) or not isinstance(floor, (int, float)) or not 0 <= floor <= 1:
        raise DeckError(f"{path}, group &integration: tolerance_floor = {floor!r} is invalid: must be in [0, 1]")


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

    def run(self, texts: list[str], keep: str | None) -> list[dict]:
        todo = [t for t in dict.fromkeys(texts) if t not in self.summaries]
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
    keys = ("steps_dt1", "steps_nested", "steps_dt2", "steps_finer", "steps_implicit", "implicit_redos")
    return int(sum(summary.get(k, 0) for k in keys))


def _error_of(q: Quantity) -> tuple[float, float]:
    """(step, law) estimated errors of the finest run of the levels."""
    step = q.estimate.errors[-1] if q.estimate is not None else 0.0
    law = q.law_estimate.errors[-1] if q.law_estimate is not None else 0.0
    return step, law


def _method(e: Estimate | None, what: str) -> str:
    if e is None:
        return ""
    if e.method == "richardson":
        return f"{what}: Richardson at order {e.order:.2f}"
    if e.method == "unchanged":
        return f"{what}: unchanged (round-off)"
    return f"{what}: difference ({e.reason})"


def _factor(error: float, allowed: float, order: float | None) -> int:
    """The power of 2 by which to divide a parameter so that an error at ``order`` falls
    below ``allowed`` (with a margin of 1.5)."""
    p = order if order else 1.0
    need = (1.5 * error / allowed) ** (1.0 / p) if allowed > 0 else math.inf
    if not math.isfinite(need):
        return 2 ** 30
    return max(2, 2 ** math.ceil(math.log2(max(need, 1.0))))


def _quantity_rows(quantities: list[Quantity], tol: float, values_of) -> list[dict]:
    rows = []
    for q in quantities:
        if q.key not in ESTIMATED:
            continue
        step, law = _error_of(q)
        error = max(step + law, ROUND_OFF * q.scale)  # no estimate below round-off
        method = "; ".join(x for x in (_method(q.estimate, "step"), _method(q.law_estimate, "law")) if x)
        rows.append({"key": q.key, "index": q.index, "what": q.what, "item": q.item, "unit": q.unit,
                     "value": values_of(q), "estimated_error": error,
                     "relative_error": error / q.scale if q.scale > 0 else 0.0,
                     "allowed": tol * q.scale, "method": method})
    return rows


def _exact(runner: _Runner, nml, n1: int, tol: float, floor: float, why: str) -> tuple[ToleranceReport, str]:
    text = write_namelist(_with(nml, n1, "event_driven"))
    (summary,) = runner.run([text], keep=text)
    qs = _compare([summary, summary], tol, 2, (), floor)
    rows = []
    for q in qs:
        if q.key in ESTIMATED:
            err = ROUND_OFF * q.scale
            rows.append({"key": q.key, "index": q.index, "what": q.what, "item": q.item, "unit": q.unit,
                         "value": q.values[0], "estimated_error": err, "relative_error": ROUND_OFF, "allowed": tol * q.scale,
                         "method": "exact: event-driven technique (round-off)"})
    report = ToleranceReport(tol, floor, "event_driven", why, n1, 1, len(runner.summaries), 1, runner.steps, rows)
    return report, text


def _refine(runner: _Runner, nml, path: Path, n1: int, technique: str, tol: float, floor: float,
            why: str) -> tuple[ToleranceReport, str]:
    """Step levels (and law levels) refined until every estimate is below the allowed error."""
    top, divisor = 4 * math.ceil(n1 / 4), 1  # the run returned: n1 = top, eps and f / divisor
    regularized = technique == "newmark" and _law_text(write_namelist(_with(nml, n1)), 2) is not None
    for rounds in range(1, MAX_ROUNDS + 1):
        levels = [write_namelist(_with(nml, top // f, technique)) for f in (4, 2, 1)]
        if regularized and divisor > 1:
            levels = [_law_text(t, divisor) for t in levels]
        # the law levels at the coarsest step, eps and f x 4 and x 2, with its own level last
        laws = [_law_text(levels[0], 1 / f) for f in (4, 2)] if regularized else []
        final = levels[-1]
        runs = runner.run(levels + laws, keep=final)
        summaries, law_sums = runs[:3], (runs[3:] + [runs[0]] if laws else [])
        qs = _compare(summaries, tol, 2, law_sums[1:], floor)
        if laws:  # the law's estimate from its three levels, coarse to fine (the step's own last)
            for q in qs:
                if q.estimate is not None:
                    q.law_estimate = estimate_error([_value(s, q) for s in law_sums], 2, q.scale)
        last = summaries[-1]

        def value(q: Quantity, last=last) -> float:
            return _value(last, q)

        if regularized:
            _initial_peaks(path, tol, last, qs)
        rows = _quantity_rows(qs, tol, value)
        step_need, law_need, worst = 1, 1, None
        for q in qs:
            if q.key not in ESTIMATED:
                continue
            step, law = _error_of(q)
            allowed = tol * q.scale
            step_claims = q.estimate is None or _claims(q.estimate, tol * q.scale)
            law_claims = q.law_estimate is None or _claims(q.law_estimate, tol * q.scale)
            if step + law <= allowed and step_claims and law_claims:
                continue
            if worst is None or (step + law) / max(allowed, 1e-300) > worst[1]:
                worst = (q, (step + law) / max(allowed, 1e-300), step, law, step_claims, law_claims)
            share = allowed / 2 if q.law_estimate is not None else allowed
            if step > share or not step_claims:
                order = q.estimate.order if q.estimate is not None and q.estimate.method == "richardson" else None
                step_need = max(step_need, _factor(step, share, order) if step_claims else 2)
            if q.law_estimate is not None and (law > share or not law_claims):
                e = q.law_estimate
                order = e.order if e.method == "richardson" else None
                law_need = max(law_need, _factor(law, share, order) if law_claims else 2)
        if worst is None:
            report = ToleranceReport(tol, floor, technique, why, top, divisor,
                                     len(runner.summaries), rounds, runner.steps, rows)
            return report, final
        runner.close()
        q, ratio, step, law, step_claims, law_claims = worst
        name = f"{q.what} {q.item}".strip()
        what = (f"{name} = {value(q):.6g} {q.unit}: estimated error {step + law:.3g} {q.unit} "
                f"({100 * (step + law) / q.scale:.3g} % of its scale {q.scale:.6g}, allowed {100 * tol:g} %; "
                f"{'; '.join(x for x in (_method(q.estimate, 'step'), _method(q.law_estimate, 'law')) if x)})")
        law_cause = q.law_estimate is not None and (law >= step or not law_claims)
        over_step = top * step_need > MAX_REFINEMENT * n1
        over_law = divisor * law_need > MAX_REFINEMENT
        if over_step or over_law:
            limit = (f"eps and f / {MAX_REFINEMENT}" if over_law else f"n1 = {MAX_REFINEMENT * n1}")
            raise ToleranceError(_unmet(path, tol, what, q, law_cause, f"meeting it needs more than {limit}, "
                                        f"the cost limit ({MAX_REFINEMENT} times the deck's setting)"))
        top *= step_need
        divisor *= law_need
    raise ToleranceError(_unmet(path, tol, what, q, law_cause, f"{MAX_ROUNDS} rounds of refinement did not meet it"))


def _initial_peaks(path: Path, tol: float, summary: dict, qs: list[Quantity]) -> None:
    """A peak absolute acceleration at t = 0 under a regularized law is the law's initial
    state, a device that starts unloaded (its force 0 at rest, whatever eps or f), where
    Coulomb's force takes any value up to P mu: no level changes it, so no estimate sees it."""
    times = summary.get("peak_aabs_time_s") or []
    for q in qs:
        if q.key == "peak_aabs_mps2" and q.index < len(times) and times[q.index] == 0.0:
            raise ToleranceError(
                f"{path}: tolerance {tol:g} cannot be met: {q.what} {q.item} = {_value(summary, q):.6g} "
                f"{q.unit} is reached at t = 0, where a regularized device starts unloaded (no force at rest, "
                "whatever eps or f; Coulomb's force up to P mu): no refinement changes it and no estimate "
                "sees it; give the devices law = 'coulomb' (the exact technique or Moreau-Jean)")


def _unmet(path: Path, tol: float, what: str, q: Quantity, law_cause: bool, why: str) -> str:
    if law_cause:
        e = q.law_estimate
        rate = (f"it falls at order {e.order:.2f} in eps or f" if e.method == "richardson"
                else "it falls at no measurable order in eps or f")
        hint = (f"the regularized law's error governs and {rate} (the hysteretic law's peaks at about 1/2 in "
                "f, and its accelerations where the exact force jumps not at all: docs/theory.md, section 16); "
                "give the devices law = 'coulomb' (the exact technique or Moreau-Jean), or a larger tolerance")
    else:
        hint = "the step's error governs: a larger tolerance, or a shorter or smaller model, is needed"
    return f"{path}: tolerance {tol:g} cannot be met: {what}; {why}; {hint}"


def _value(summary: dict, q: Quantity) -> float:
    v = summary[q.key]
    return float(v[q.index]) if isinstance(v, list) else float(v)


def _summary_block(report: ToleranceReport) -> dict:
    block = report.block()
    return {"estimated_error": block.pop("estimated_error"), "estimate_method": block.pop("estimate_method"),
            "tolerance_run": block}


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
            why = ("the paper's regularized laws: n1 refined by the step levels, and eps and f by the law "
                   "levels" if _law_text(stripped, 2) is not None else
                   "Newmark without a numerical eps or f (no velocity or hysteretic device of &friction or "
                   "&isolators): n1 refined by the step levels")
            report, final = _refine(runner, nml, path, n1, "newmark", tol, floor, why)
        else:
            with Session.from_text(stripped, path.name, path.parent) as s:
                n_dev = s._sizes()[1]
            exact_ok = n_dev <= EXACT_DEVICES
            if exact_ok:
                try:
                    with Session.from_text(write_namelist(_with(nml, n1, "event_driven")), path.name, path.parent):
                        pass
                except DeckError:
                    exact_ok = False  # a device the exact technique cannot take (not between two nodes)
            report = final = None
            if exact_ok:
                try:
                    report, final = _exact(runner, nml, n1, tol, floor,
                                           f"{n_dev} Coulomb device{'s' * (n_dev != 1)} (at most {EXACT_DEVICES}): "
                                           "the exact event-driven technique, whose peaks are exact")
                except SolverError as exc:
                    why = f"the exact technique failed ({exc}); "
                else:
                    why = ""
            if report is None:
                if not exact_ok:
                    why = (f"{n_dev} Coulomb devices (more than {EXACT_DEVICES}, or one not between two nodes): ")
                report, final = _refine(runner, nml, path, n1, "moreau_jean", tol, floor,
                                        why + "Moreau-Jean with n1 refined by its step levels")
        session = runner.kept.pop(final)
        runner.close()
        result = session.result()
        result.summary.update(_summary_block(report))
        return result, report, session
    finally:
        runner.close()
