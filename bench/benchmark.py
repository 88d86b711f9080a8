"""Benchmark of frictiondyn: prints run times, step and event counts, and memory.

    python bench/benchmark.py [--repeat 5] [--quick]

Times are wall-clock medians over --repeat runs through the f2py extension (the
executable adds its file output on top, timed separately); the exact technique's
integration time is also given alone (the summary's run_time_s: the time-step loop, without
reading the deck or handing the history to Python). Nothing here is asserted: speed and
memory are measured, not tested.
"""

from __future__ import annotations

import argparse
import resource
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import frictiondyn as fd
from frictiondyn.model import Analysis, Damping, Device, Harmonic, Integration, Output, Spring
from frictiondyn.paper import paper_analysis

ROOT = Path(__file__).resolve().parent.parent


def timed(an: Analysis, repeat: int) -> tuple[float, fd.Result]:
    times, res = [], None
    for _ in range(repeat):
        t0 = time.perf_counter()
        res = an.run()
        times.append(time.perf_counter() - t0)
    return statistics.median(times), res


def exact_test4(repeat: int) -> None:
    """The exact technique on 40 s of the paper's test 4: integration time (median and best
    of `repeat`), its events, the patterns it built; the target is 20 ms of integration."""
    an = paper_analysis(4, "coulomb", output_every=20)
    loop, total, res = [], [], None
    for _ in range(repeat):
        t0 = time.perf_counter()
        res = an.run()
        total.append(time.perf_counter() - t0)
        loop.append(res.summary["run_time_s"])
    s = res.summary
    print(
        f"\nexact technique, test 4, 40 s (rows every 5 ms): integration "
        f"{1e3 * statistics.median(loop):.1f} ms median, {1e3 * min(loop):.1f} ms best "
        f"(target <= 20 ms); run {1e3 * statistics.median(total):.1f} ms; "
        f"{s['events']} events (every phase change located: {sum(s['stick_to_slip'])} stick->slip, "
        f"{sum(s['slip_to_stick'])} slip->stick, {sum(s['slip_reversals'])} reversals), "
        f"{s['factorizations']} phase patterns built"
    )


def chain(n: int, law: str, duration: float) -> Analysis:
    """n masses in a shear chain, a friction device in every storey but the first."""
    masses = [1000.0] * n
    springs = [Spring(i + 1, i, 2.0e6) for i in range(n)]
    devices = [Device(i + 1, i, 2000.0, 0.3, law=law) for i in range(1, n)]
    return Analysis(
        masses=masses,
        springs=springs,
        damping=Damping.rayleigh(0.2, 0.002),
        devices=devices,
        excitation=Harmonic(0.02, 2.0, 0.005, duration, ramp_cycles=2),
        integration=Integration(
            technique="event_driven" if law == "coulomb" else None, n1=10, n2=20
        ),
        output=Output(output_every=10),
    )


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--repeat", type=int, default=5)
    ap.add_argument("--quick", action="store_true", help="shorter chain runs")
    args = ap.parse_args()

    print("frictiondyn benchmark (median of %d runs, extension, no file output)" % args.repeat)
    print()
    print("Paper's test 4, 40 s of 4.104 Hz table motion, dt1 = 0.25 ms:")
    print(
        f"{'technique':<34}{'time [s]':>10}{'steps':>10}{'events':>8}{'fact/pat':>10}"
        f"{'transitions':>12}{'violations':>11}"
    )
    for label, an in [
        ("velocity law, eps = 1e-3", paper_analysis(4, "velocity", output_every=20)),
        ("hysteretic law, f = 1e-5", paper_analysis(4, "hysteretic", output_every=20)),
        (
            "Fig. 3 coarse (n1 = n2 = 2, off)",
            paper_analysis(4, "hysteretic", coarse=True, output_every=2),
        ),
        ("exact Coulomb (event-driven)", paper_analysis(4, "coulomb", output_every=20)),
    ]:
        t, r = timed(an, args.repeat)
        s = r.summary
        steps = fd.newmark_steps(s)
        print(
            f"{label:<34}{t:>10.4f}{steps:>10}{s['events']:>8}{s['factorizations']:>10}"
            f"{s['stick_to_slip'][0] + s['slip_to_stick'][0]:>12}{s['correctness_violations']:>11}"
        )

    exact_test4(max(args.repeat, 5))

    exe = fd.executable()
    deck = (ROOT / "inputs" / "test4_velocity.nml").read_text()
    with tempfile.TemporaryDirectory() as tmp:
        # the same run with and without the history file: the difference is its formatting
        # and writing (8001 rows x 12 values)
        quiet = Path(tmp) / "quiet.nml"
        quiet.write_text(deck.replace("&output", "&output\n  write_history = .false.", 1))
        times: dict[str, list[float]] = {"csv": [], "none": []}
        for _ in range(args.repeat):
            for key, path in (("csv", ROOT / "inputs" / "test4_velocity.nml"), ("none", quiet)):
                t0 = time.perf_counter()
                subprocess.run([exe, str(path)], cwd=tmp, check=True, capture_output=True)
                times[key].append(time.perf_counter() - t0)
        size = (Path(tmp) / "out" / "test4_velocity.csv").stat().st_size
    t_csv, t_none = statistics.median(times["csv"]), statistics.median(times["none"])
    print(
        f"\nexecutable on inputs/test4_velocity.nml (8001 x 12 CSV, {size / 1e6:.1f} MB): "
        f"{t_csv:.4f} s; without the history file {t_none:.4f} s: "
        f"{1e9 * (t_csv - t_none) / (8001 * 12):.0f} ns a value written"
    )

    # the fixed cost of a run through the extension: a deck of one record step (20 steps)
    short = paper_analysis(4, "hysteretic")
    short.excitation.duration = short.excitation.dt_record
    for _ in range(20):
        short.run()
    cpu = []
    for _ in range(200):
        c0 = time.process_time()
        short.run()
        cpu.append(time.process_time() - c0)
    print(
        f"fixed cost of Analysis.run() (test 4, one record step: deck, set-up, summary, "
        f"Result): {1e3 * statistics.median(cpu):.2f} ms CPU (median of 200)"
    )

    print(
        "\nShear chain of n masses, a device in every storey above the first, 2 Hz, dt1 = 0.5 ms:"
    )
    print(f"{'n':>5}{'law':>12}{'duration [s]':>14}{'time [s]':>10}{'events':>8}{'fact/pat':>10}")
    sizes = [2, 10, 50] if args.quick else [2, 10, 50, 200]
    for n in sizes:
        for law in ("velocity", "coulomb"):
            if law == "coulomb" and n > 50:
                continue
            dur = 5.0 if args.quick else 10.0
            t, r = timed(chain(n, law, dur), max(1, args.repeat // 2))
            s = r.summary
            print(f"{n:>5}{law:>12}{dur:>14.1f}{t:>10.3f}{s['events']:>8}{s['factorizations']:>10}")

    rss = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
    print(f"\npeak resident memory of this process: {rss:.0f} MB")


if __name__ == "__main__":
    sys.exit(main())
