"""Benchmark of the Moreau-Jean technique on tall buildings: cost per step against N.

    .venv/bin/python bench/moreau_jean.py                    # N = 10 ... 1000, 20 s of record
    .venv/bin/python bench/moreau_jean.py --sizes 10,100,1000,3000 --repeats 7
    .venv/bin/python bench/moreau_jean.py alloc              # valgrind: the loop allocates nothing

The building is the OpenSeesPy comparison's (bench/opensees_models.BuildingCase: 1000 t
shared by N floors, first period 1 s, storey stiffness and slip load proportional to the
weight carried, slip at 5 % of it, Rayleigh 2 % on modes 1 and 3, 20 s of the synthetic
ground motion, PGA 0.3 g, dt_r = 10 ms, dt1 = dt_r / 10), with a rigid Coulomb damper in
every storey (law 'coulomb', technique 'moreau_jean', theta = 1/2): proportional slip loads,
the case in which every storey starts and stops sliding together.

Cost per step: (run of the whole record - run of one record interval) / (difference in
steps), so that reading the deck and setting up is left out; medians of --repeats runs,
interleaved over N; wall clock and processor time of this process (the machine may be
shared: the processor time is the steadier figure). The history is not kept (a row every
10^6 steps). Prints a table and the slope of log(cost) against log(N); writes
<out>/moreau_jean.json. Nothing is asserted here: it is measured.

`alloc` runs the executable under valgrind on the same building (N = 30) for two durations
and prints the heap allocation counts: counts that do not grow with the steps mean the
time-step loop allocates nothing.
"""

from __future__ import annotations

import argparse
import json
import math
import platform
import re
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))
import frictiondyn as fd
from opensees_models import BuildingCase

SIZES = [10, 30, 100, 300, 1000]


def analysis(case: BuildingCase, duration: float, every: int = 1_000_000) -> fd.Analysis:
    """The case's building with a rigid Coulomb damper per storey, Moreau-Jean."""
    n = case.n_storeys
    return fd.Analysis(
        masses=[case.m] * n,
        springs=[fd.Spring(i + 1, i, float(case.k[i])) for i in range(n)],
        damping=fd.Damping.rayleigh(case.a0, case.a1),
        devices=[fd.Device(i + 1, i, float(case.slip[i]), 1.0, law="coulomb") for i in range(n)],
        excitation=fd.Record(case.dt_record, values=case.record, duration=duration),
        integration=fd.Integration(technique="moreau_jean", n1=case.n1),
        output=fd.Output(output_every=every),
    )


def timed(an: fd.Analysis) -> tuple[float, float, fd.Result]:
    w0, c0 = time.perf_counter(), time.process_time()
    r = an.run()
    return time.perf_counter() - w0, time.process_time() - c0, r


def measure(sizes: list[int], repeats: int, duration: float) -> list[dict]:
    cases = {n: BuildingCase(n, duration=duration) for n in sizes}
    full = {n: analysis(c, duration) for n, c in cases.items()}
    short = {n: analysis(c, c.dt_record) for n, c in cases.items()}
    walls: dict[int, list[float]] = {n: [] for n in sizes}
    cpus: dict[int, list[float]] = {n: [] for n in sizes}
    results: dict[int, fd.Result] = {}
    for n in sizes:  # warm-up, and the run whose summary is reported
        results[n] = full[n].run()
    for _ in range(repeats):
        for n in sizes:
            w1, c1, r = timed(full[n])
            w0, c0, r0 = timed(short[n])
            steps = r.summary["steps_dt1"] - r0.summary["steps_dt1"]
            walls[n].append((w1 - w0) / steps)
            cpus[n].append((c1 - c0) / steps)
    rows = []
    for n in sizes:
        s = results[n].summary
        steps = s["steps_dt1"]
        rows.append(
            {
                "storeys": n,
                "steps": steps,
                "us_per_step_wall": 1e6 * statistics.median(walls[n]),
                "us_per_step_cpu": 1e6 * statistics.median(cpus[n]),
                "us_per_step_cpu_all": [1e6 * x for x in cpus[n]],
                "patterns_per_step": s["patterns_solved"] / steps,
                "factorizations_per_step": s["factorizations"] / steps,
                "lcp_fallbacks": s["lcp_fallbacks"],
                "transitions": int(sum(s["stick_to_slip"]) + sum(s["slip_to_stick"])),
                "energy_residual_rel": s["energy_residual_J"] / s["energy_input_J"],
                "friction_share": s["energy_friction_J"] / s["energy_input_J"],
                "peak_aabs_max_mps2": max(s["peak_aabs_mps2"]),
                "peak_drift_max_m": max(s["peak_s_m"]),
            }
        )
    return rows


def slope(x, y) -> float:
    return float(np.polyfit(np.log(x), np.log(y), 1)[0])


def report(rows: list[dict]) -> str:
    lines = [
        (
            "| storeys N | steps | us/step CPU | us/step wall | patterns/step | factorizations/step | "
            "Lemke fallbacks | transitions | residual / input | friction / input |"
        ),
        "|---|---|---|---|---|---|---|---|---|---|",
    ]
    for r in rows:
        lines.append(
            f"| {r['storeys']} | {r['steps']} | {r['us_per_step_cpu']:.1f} | {r['us_per_step_wall']:.1f} | "
            f"{r['patterns_per_step']:.2f} | {r['factorizations_per_step']:.2f} | {r['lcp_fallbacks']} | "
            f"{r['transitions']} | {r['energy_residual_rel']:.1e} | {r['friction_share']:.3f} |"
        )
    n = [r["storeys"] for r in rows]
    c = [r["us_per_step_cpu"] for r in rows]
    lines.append("")
    lines.append(f"cost per step (CPU) ~ N^{slope(n, c):.2f} over N = {n[0]} ... {n[-1]}")
    for i in range(1, len(rows)):
        lines.append(
            f"  N = {n[i - 1]} -> {n[i]}: exponent {math.log(c[i] / c[i - 1]) / math.log(n[i] / n[i - 1]):.2f}"
        )
    return "\n".join(lines)


def alloc(n: int, durations: tuple[float, float]) -> int:
    """Heap allocations of the executable for two durations (valgrind): counts that do
    not grow with the number of steps mean nothing is allocated per step."""
    if shutil.which("valgrind") is None:
        print("alloc: valgrind is required (apt-get install valgrind)", file=sys.stderr)
        return 1
    exe = fd.executable()
    counts, steps_run = [], []
    with tempfile.TemporaryDirectory() as tmp:
        for dur in durations:
            case = BuildingCase(n, duration=dur)
            # one history row at each end: the writer's allocations do not scale with the run
            deck = analysis(case, dur).write_deck(Path(tmp) / f"b{n}_{dur:g}.nml")
            out = subprocess.run(
                ["valgrind", exe, str(deck)], cwd=tmp, capture_output=True, text=True, check=True
            ).stderr
            m = re.search(r"total heap usage: ([\d,]+) allocs, ([\d,]+) frees, ([\d,]+) bytes", out)
            allocs, frees, nbytes = (int(x.replace(",", "")) for x in m.groups())
            steps = round(dur / (case.dt_record / case.n1))
            counts.append(allocs)
            steps_run.append(steps)
            print(
                f"N = {n}, {dur:g} s ({steps} steps): {allocs} allocs, {frees} frees, {nbytes} bytes"
            )
    per_step = (counts[1] - counts[0]) / (steps_run[1] - steps_run[0])
    # set-up and output (the deck's duration, the record's samples kept) may differ by a
    # few allocations; one in the loop would add one per step at least
    grows = abs(counts[1] - counts[0]) >= 0.01 * (steps_run[1] - steps_run[0])
    print(
        f"allocations per additional step: {per_step:.4f}: "
        + ("they grow with the duration" if grows else "the time-step loop allocates nothing")
    )
    return 1 if grows else 0


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("mode", nargs="?", default="cost", choices=["cost", "alloc"])
    ap.add_argument(
        "--sizes", default=",".join(map(str, SIZES)), help="storey counts, comma-separated"
    )
    ap.add_argument("--repeats", type=int, default=5)
    ap.add_argument("--duration", type=float, default=20.0, help="seconds of record (<= 20)")
    ap.add_argument("--out", default="out/bench", help="directory of moreau_jean.json")
    args = ap.parse_args(argv)
    if args.mode == "alloc":
        return alloc(30, (2.0, 4.0))
    sizes = [int(x) for x in args.sizes.split(",")]
    print(
        f"Moreau-Jean on the benchmark's building, {args.duration:g} s of record, dt1 = 1 ms, "
        f"median of {args.repeats} runs",
        flush=True,
    )
    rows = measure(sizes, args.repeats, args.duration)
    text = report(rows)
    print(text)
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    meta = {
        "machine": platform.platform(),
        "processor": platform.processor(),
        "python": platform.python_version(),
        "frictiondyn": fd.__version__,
        "duration_s": args.duration,
        "repeats": args.repeats,
    }
    (out / "moreau_jean.json").write_text(json.dumps({"meta": meta, "rows": rows}, indent=1))
    print(f"wrote {out / 'moreau_jean.json'}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
