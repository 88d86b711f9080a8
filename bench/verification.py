"""The verification battery, long version: cases with exact answers, every technique and law.

    .venv/bin/python bench/verification.py                 # all three tables (about a minute)
    .venv/bin/python bench/verification.py --duration 20   # the building under 20 s of record

1. Den Hartog's steady state of a harmonically forced oscillator with Coulomb friction
   (closed form): amplitude and phase errors of the exact technique, Moreau-Jean at n1 = 10
   ... 160, the velocity law at eps = 1e-3 ... 1e-5 m/s and the hysteretic law at f = 1e-5 ...
   1e-7 m (eps1 = 100 f), with the order observed between consecutive rows.
2. Free vibration with Coulomb friction (closed form: extremes (-1)^n (u0 - 2 n F/k) every
   half period, stop at -0.3 F/k): the largest error of the extremes and the position at the
   end, every technique.
3. ``frictiondyn converge`` against the exact technique: for the paper's test 4 (both laws)
   and the 3-storey building of tests/test_convergence.py (both laws and Moreau-Jean), each
   estimated quantity's value at the deck's n1, its true error against the event-driven
   technique, the estimate (step + law) and its methods, the ratio of the two; then per deck
   the share of estimates at least the true error and the median ratio (round-off quantities,
   whose true error is below 1e-9 of the quantity, left out).

The short versions, with the measured values asserted, are tests/test_verification.py and
tests/test_convergence.py; docs/theory.md, section 16, gives the findings. Nothing is
asserted here: it is measured.
"""

from __future__ import annotations

import argparse
import math
import statistics
import sys
import tempfile
import time
import warnings
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "tests"))

import frictiondyn as fd  # noqa: E402
from frictiondyn.convergence import methods_text, step_convergence  # noqa: E402
from test_convergence import BUILDING  # noqa: E402
from test_verification import (  # noqa: E402
    FV_A,
    FV_U0,
    den_hartog_errors,
    free_vibration,
)

INPUTS = ROOT / "inputs"


def order(a: float, b: float, ratio: float) -> str:
    return f"{math.log(a / b) / math.log(ratio):.2f}" if a > 0 and b > 0 else "-"


def den_hartog_table() -> None:
    print("1. Den Hartog (w / wn = 0.7, F = 0.3 f0): amplitude and phase errors, last two cycles")
    print(f"  {'case':<34} {'amplitude':>10} {'phase [rad]':>12} {'order':>6}")
    rows = [("exact technique, n1 = 10", ("coulomb", "event_driven", 10), {}, None)]
    rows += [(f"Moreau-Jean, n1 = {n}", ("coulomb", "moreau_jean", n), {}, 2.0) for n in (10, 20, 40, 80, 160)]
    rows += [(f"velocity law, eps = {e:g} m/s", ("velocity", "newmark", 20), {"eps": e}, 10.0)
             for e in (1e-3, 1e-4, 1e-5)]
    rows += [(f"hysteretic law, f = {f:g} m", ("hysteretic", "newmark", 20), {"f": f, "eps1": 100 * f}, 10.0)
             for f in (1e-5, 1e-6, 1e-7)]
    previous = None
    for name, args, friction, ratio in rows:
        amp, phase = den_hartog_errors(*args, **friction)
        observed = order(previous, amp, ratio) if previous is not None and ratio else ""
        print(f"  {name:<34} {amp:10.3e} {phase:12.3e} {observed:>6}")
        previous = amp if ratio else None
        if name.startswith(("Moreau-Jean, n1 = 160", "velocity law, eps = 1e-05")):
            previous = None


def free_vibration_table() -> None:
    print("\n2. Free vibration, u0 = 10.3 F/k: extremes every half period, stop at -0.3 F/k")
    print(f"  {'case':<40} {'extremes / (F/k)':>16} {'end / (F/k)':>12}")
    for name, args, friction in (
        ("exact technique", ("coulomb", "event_driven"), {}),
        ("Moreau-Jean, n1 = 10", ("coulomb", "moreau_jean"), {}),
        ("velocity law, eps = 1e-4 m/s", ("velocity", "newmark"), {"eps": 1e-4}),
        ("hysteretic law, f = 1e-6 m", ("hysteretic", "newmark"), {"f": 1e-6, "eps1": 1e-4}),
    ):
        r = free_vibration(*args, **friction)
        t, u = np.asarray(r["t"]), np.asarray(r["u1"])
        worst = 0.0
        for n in range(1, 6):
            i = int(np.argmin(np.abs(t - n / 2)))
            worst = max(worst, abs(u[i] - (-1) ** n * (FV_U0 - 2 * n * FV_A)))
        print(f"  {name:<40} {worst / FV_A:16.2e} {u[-1] / FV_A:12.5f}")


def building_deck(directory: Path, law: str, technique: str, duration: float) -> Path:
    text = BUILDING.replace("LAW", law).replace("TECHNIQUE", technique)
    text = text.replace("RECORD", str(INPUTS / "synthetic_pga035.AT2"))
    text = text.replace("duration = 8.0", f"duration = {duration!r}")
    path = directory / f"building_{law}_{technique}.nml"
    path.write_text(text)
    return path


def estimate_table(duration: float) -> None:
    print("\n3. converge's estimates (deck's n1; step + law) against the exact technique")
    with tempfile.TemporaryDirectory() as tmp:
        work = Path(tmp)
        decks = [
            ("test 4, velocity law", INPUTS / "test4_velocity.nml", INPUTS / "test4_coulomb.nml"),
            ("test 4, hysteretic law", INPUTS / "test4_hysteretic.nml", INPUTS / "test4_coulomb.nml"),
        ]
        exact_building = building_deck(work, "coulomb", "event_driven", duration)
        for law, technique in (("hysteretic", "newmark"), ("velocity", "newmark"), ("coulomb", "moreau_jean")):
            decks.append((f"building, {law} ({technique})", building_deck(work, law, technique, duration),
                          exact_building))
        for name, deck, exact_deck in decks:
            exact = fd.run(exact_deck).summary
            start = time.perf_counter()
            report = step_convergence(deck)
            seconds = time.perf_counter() - start
            print(f"  {name}: converged = {report.converged} ({seconds:.1f} s, "
                  f"{len(report.summaries) + len(report.law_summaries)} runs)")
            ratios = []
            for q in report.quantities:
                if q.estimate is None:
                    continue
                ref = exact[q.key]
                ref = float(ref) if not isinstance(ref, list) else float(ref[int(q.item.split()[-1]) - 1])
                true = abs(q.values[0] - ref)
                methods = methods_text(q.estimate, q.law_estimate)
                if true <= 1e-9 * abs(ref):
                    print(f"    {q.key:<18} {q.item:<9} round-off (true {true:.1e})")
                    continue
                ratios.append(q.error / true)
                print(f"    {q.key:<18} {q.item:<9} true {true / abs(ref):8.2e} est {q.error / abs(ref):8.2e} "
                      f"ratio {q.error / true:6.2f}  {methods}")
            if ratios:
                share = sum(r >= 1 for r in ratios) / len(ratios)
                print(f"    estimate >= true error: {100 * share:.0f} % of {len(ratios)}; "
                      f"median ratio {statistics.median(ratios):.2f}")


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--duration", type=float, default=8.0, help="seconds of record for the building")
    args = parser.parse_args(argv)
    warnings.simplefilter("ignore", fd.FrictiondynWarning)
    den_hartog_table()
    free_vibration_table()
    estimate_table(args.duration)
    return 0


if __name__ == "__main__":
    sys.exit(main())
