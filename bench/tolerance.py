"""Tolerance runs over the verification battery: the four figures of docs/validation.md, section 7.

    .venv/bin/python bench/tolerance.py              # both tolerances (20 to 30 s)
    .venv/bin/python bench/tolerance.py --tol 1e-2   # one
    .venv/bin/python bench/tolerance.py --split      # and every run each case made (and why
                                                     # a combined ladder fell back)

Each case has an exact answer: Den Hartog's steady state (closed form: amplitude A, peak
absolute acceleration (k A + F) / m; the friction energy of the exact technique), free
vibration with Coulomb friction (peak acceleration k (u0 - a) / m, energy 53 k a^2), the
paper's test 4 and shear buildings of 3 and 8 storeys with a rigid-plastic damper in every
storey under the synthetic record (the exact technique's peaks). For each case and tolerance
the tolerance run (``frictiondyn.tolerance``) either returns, and every estimated quantity
(peak displacements, drifts, absolute accelerations, device forces, friction energy) is
compared with the exact answer, or refuses (ToleranceError), which is counted apart.

The four figures, over the quantities of the runs that returned: the share whose true error is
within the tolerance (of the quantity's scale, the run's own allowed error), the share whose
estimate is at least the true error, the median of estimate / true error (quantities whose
true error is below 1e-9 of the scale, round-off, left out), and per case the cost (steps
solved, every run of the tolerance run) over the cheapest manual setting that meets the
tolerance against the exact answer (a grid of n1 and of eps and f divided by 2^k); a tolerance
run's steps include its probe (one step) and every level it made, each once.
Nothing is asserted here: it is measured (tests/test_tolerance.py asserts the short cases).
"""

from __future__ import annotations

import argparse
import math
import statistics
import sys
import warnings
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "tests"))

import frictiondyn as fd  # noqa: E402
from conftest import deck_text  # noqa: E402
from frictiondyn import tolerance as tm  # noqa: E402
from frictiondyn.convergence import ESTIMATED, _law_text  # noqa: E402
from oracles import den_hartog  # noqa: E402
from test_verification import (  # noqa: E402
    F0, FF, FV_A, FV_K, FV_M, FV_U0, K, M, W, den_hartog_groups,
)

INPUTS = ROOT / "inputs"


def building_text(storeys: int, law: str, technique: str, duration: float = 8.0) -> str:
    """A shear building: floors of 300 t (roof 250 t), storeys 400 MN/m falling to 200 MN/m at
    the top, a rigid-plastic damper in every storey slipping at 5 % of the weight above it."""
    mass = [300e3] * (storeys - 1) + [250e3]
    k = [400e6 - 200e6 * i / max(storeys - 1, 1) for i in range(storeys)]
    slip = [0.05 * 9.81 * sum(mass[i:]) for i in range(storeys)]
    nodes = list(range(1, storeys + 1))
    return deck_text({
        "model": {"n_dof": storeys, "mass": mass},
        "springs": {"n_springs": storeys, "node_i": nodes, "node_j": [n - 1 for n in nodes],
                    "k": k},
        "damping": {"damping_type": "rayleigh", "rayleigh_a0": 0.3, "rayleigh_a1": 8e-4},
        "friction": {"n_devices": storeys, "node_i": nodes, "node_j": [n - 1 for n in nodes],
                     "law": [law] * storeys, "mu": [0.3] * storeys, "p": [s / 0.3 for s in slip],
                     "f": [1e-5] * storeys, "eps1": [1e-3] * storeys, "eps": [1e-3] * storeys},
        "storeys": {"n_storeys": storeys, "node_i": nodes, "node_j": [n - 1 for n in nodes]},
        "excitation": {"excitation_type": "record",
                       "record_file": str(INPUTS / "synthetic_pga035.AT2"), "duration": duration},
        "integration": {"technique": technique, "n1": 20},
    })


def free_vibration_text(law: str, technique: str) -> str:
    friction = {"n_devices": 1, "node_i": 1, "node_j": 0, "law": law, "p": FV_K * FV_A, "mu": 1.0}
    if law == "hysteretic":
        friction.update(f=1e-6, eps1=1e-4)
    integration = {"technique": technique, "n1": 10}
    if technique == "newmark":
        integration["n2"] = 50
    return deck_text({
        "model": {"n_dof": 1, "mass": [FV_M], "u0": [FV_U0]},
        "springs": {"n_springs": 1, "node_i": [1], "node_j": [0], "k": [FV_K]},
        "damping": {"damping_type": "none"},
        "friction": friction,
        "excitation": {"excitation_type": "none", "dt_record": 0.01, "duration": 4.0},
        "integration": integration,
    })


def den_hartog_exact() -> dict:
    """The closed form's peaks; the friction energy of the exact technique (the run ends on
    its last step, not on the fourth period's end: 16 A F is 5e-5 above it)."""
    amplitude = float(den_hartog(np.array([0.0]), M, K, FF, F0, W)[2])
    exact = exact_summary(deck_text(den_hartog_groups("coulomb", "event_driven", 20)))
    return {"peak_u_m": [amplitude], "peak_aabs_mps2": [(K * amplitude + FF) / M],
            "peak_force_N": [FF], "energy_friction_J": exact["energy_friction_J"]}


FV_EXACT = {"peak_u_m": [FV_U0], "peak_aabs_mps2": [FV_K * (FV_U0 - FV_A) / FV_M],
            "peak_force_N": [FV_K * FV_A], "energy_friction_J": 53 * FV_K * FV_A**2}


def exact_summary(text: str) -> dict:
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", fd.FrictiondynWarning)
        return fd.run_text(text, name="exact.nml").summary


def cases() -> list[tuple[str, str, dict, bool]]:
    """(name, deck text, exact values by summary key, Moreau-Jean forced)."""
    dh = den_hartog_exact()
    def dh_text(law: str, technique: str, **friction) -> str:
        return deck_text(den_hartog_groups(law, technique, 20, **friction))

    out = [
        ("Den Hartog, velocity law", dh_text("velocity", "newmark", eps=1e-3), dh, False),
        ("Den Hartog, hysteretic law", dh_text("hysteretic", "newmark", f=1e-5, eps1=1e-3), dh,
         False),
        ("Den Hartog, Coulomb (auto)", dh_text("coulomb", "moreau_jean"), dh, False),
        ("Den Hartog, Coulomb, Moreau-Jean", dh_text("coulomb", "moreau_jean"), dh, True),
    ]
    for law, technique in (("velocity", "newmark"), ("hysteretic", "newmark")):
        out.append((f"free vibration, {law} law", free_vibration_text(law, technique), FV_EXACT,
                    False))
    coulomb = free_vibration_text("coulomb", "moreau_jean")
    out.append(("free vibration, Coulomb (auto)", coulomb, FV_EXACT, False))
    out.append(("free vibration, Coulomb, Moreau-Jean", coulomb, FV_EXACT, True))
    test4 = fd.run(INPUTS / "test4_coulomb.nml").summary
    for law in ("velocity", "hysteretic"):
        out.append((f"Table 1 test 4, {law} law", (INPUTS / f"test4_{law}.nml").read_text(), test4,
                    False))
    for storeys in (3, 8):
        exact = exact_summary(building_text(storeys, "coulomb", "event_driven"))
        for law in ("velocity", "hysteretic"):
            out.append((f"{storeys}-storey building, {law} law",
                        building_text(storeys, law, "newmark"), exact, False))
        out.append((f"{storeys}-storey building, Coulomb, Moreau-Jean",
                    building_text(storeys, "coulomb", "moreau_jean"), exact, True))
    return out


def true_errors(summary: dict, exact: dict, rows: list[dict]) -> list[tuple[dict, float]]:
    out = []
    for row in rows:
        ref = exact.get(row["key"])
        if ref is None:
            continue
        ref = float(ref[row["index"]]) if isinstance(ref, list) else float(ref)
        out.append((row, abs(row["value"] - ref)))
    return out


def meets(summary: dict, exact: dict, tol: float, scales: dict) -> bool:
    for key, ref in exact.items():
        values = summary[key] if isinstance(summary[key], list) else [summary[key]]
        refs = ref if isinstance(ref, list) else [ref]
        for i, (v, r) in enumerate(zip(values, refs)):
            if abs(v - r) > tol * scales.get((key, i), abs(r)):
                return False
    return True


def cheapest_manual(text: str, exact: dict, tol: float, scales: dict, mj: bool,
                    cache: dict) -> int | None:
    """The fewest steps of a setting that meets ``tol`` against the exact answer: n1 from 5 to
    1280, and under a regularized law eps and f divided by 1 to 128."""
    base = text
    if mj:
        base = base.replace("'event_driven'", "'moreau_jean'")
    regularized = (not any(t in base for t in ("moreau_jean", "event_driven"))
                   and _law_text(base, 2) is not None)
    best, per_n1 = None, None
    for n1 in (5, 10, 20, 40, 80, 160, 320, 640, 1280):
        if best is not None and per_n1 is not None and n1 * per_n1 >= best:
            break  # its dt1 steps alone cost more than the best found
        for divisor in ((1, 2, 4, 8, 16, 32, 64, 128) if regularized else (1,)):
            key = (n1, divisor)
            if key not in cache:
                deck = base.replace("n1 = 20", f"n1 = {n1}").replace("n1 = 10", f"n1 = {n1}")
                if divisor > 1:
                    deck = _law_text(deck, divisor)
                try:
                    s = fd.run_text(deck, name="manual.nml").summary
                    cache[key] = (tm._cost(s), s)
                except fd.FrictiondynError:
                    cache[key] = (None, None)
            cost, s = cache[key]
            if s is not None:
                per_n1 = s["steps_dt1"] / n1
            if cost is not None and meets(s, exact, tol, scales) and (best is None or cost < best):
                best = cost
    return best


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--tol", type=float, action="append",
                        help="tolerance (default: 1e-2 and 1e-3)")
    parser.add_argument("--split", action="store_true",
                        help="also print every run a tolerance run made, with its steps")
    args = parser.parse_args(argv)
    warnings.simplefilter("ignore", fd.FrictiondynWarning)
    battery = cases()
    manual_cache: dict[str, dict] = {}
    for tol in args.tol or [1e-2, 1e-3]:
        print(f"\ntolerance {tol:g}")
        within = bounded = total = 0
        ratios, costs, refused, split = [], [], [], []
        for name, text, exact, mj in battery:
            saved = tm.EXACT_DEVICES
            tm.EXACT_DEVICES = 0 if mj else saved
            try:
                result, report, session = tm.tolerance_run(text=text, tolerance=tol,
                                                           name="case.nml")
                session.close()
            except fd.ToleranceError as exc:
                refused.append(name)
                print(f"  {name}: REFUSED: {str(exc)[:200]}...")
                continue
            finally:
                tm.EXACT_DEVICES = saved
            pairs = true_errors(result.summary, exact, report.quantities)
            scales = {(r["key"], r["index"]): r["allowed"] / tol for r, _ in pairs}
            case_in = case_bound = 0
            for row, true in pairs:
                total += 1
                case_in += true <= row["allowed"]
                case_bound += row["estimated_error"] >= true
                if true > 1e-9 * row["allowed"] / tol:
                    ratios.append(row["estimated_error"] / true)
            within += case_in
            bounded += case_bound
            if report.technique == "event_driven":  # one exact run: no cheaper setting
                manual = report.steps
            else:
                estimated = {k: exact[k] for k in ESTIMATED if k in exact}
                manual = cheapest_manual(text, estimated, tol, scales, mj,
                                         manual_cache.setdefault(name, {}))
            ratio = report.steps / manual if manual else math.nan
            costs.append(ratio)
            print(f"  {name}: {report.technique}, n1 = {report.n1}, eps and f / "
                  f"{report.law_divisor}, {report.runs} runs; within {case_in}/{len(pairs)}, "
                  f"estimate >= true {case_bound}/{len(pairs)}; cost {report.steps} steps, "
                  f"cheapest manual {manual} ({ratio:.2f} x)")
            if args.split:
                if "measured no order" in report.why:  # the combined ladder fell back
                    reason = report.why.split("measured no order (", 1)[1].split("): ", 1)[0]
                    print(f"      the combined ladder fell back: {reason}")
                for label, steps in report.made:
                    print(f"      {label}: {steps} steps")
                finest = f"n1 = {report.n1}" + (f", eps and f / {report.law_divisor:g}"
                                                 if report.law_divisor != 1 else "")
                returned = [s for label, s in report.made if label.split(": ", 1)[-1] == finest
                            or label == f"exact, {finest}"]
                split.append((name, report.steps, manual, report.runs, returned[-1]))
        if args.split and split:
            print("  cost split (all runs / cheapest manual; the run returned / cheapest manual):")
            for name, steps, manual, runs, returned in split:
                if manual:
                    print(f"    {name}: {steps / manual:.2f} x in {runs} runs; the run returned "
                          f"{returned / manual:.2f} x")
        finite = [c for c in costs if math.isfinite(c)]
        print(f"  quantities {total} in {len(battery) - len(refused)} runs "
              f"({len(refused)} refused: "
              f"{', '.join(refused) or 'none'})")
        print(f"  within tolerance: {100 * within / max(total, 1):.1f} %")
        print(f"  estimate >= true error: {100 * bounded / max(total, 1):.1f} %")
        if ratios:
            print(f"  median estimate / true error: {statistics.median(ratios):.2f} "
                  f"(of {len(ratios)} above round-off)")
        if finite:
            print(f"  cost / cheapest manual: median {statistics.median(finite):.2f}, "
                  f"max {max(finite):.2f} "
                  f"(of {len(finite)} cases)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
