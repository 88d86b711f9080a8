"""Modal damping at scale: the time per Newmark step of a chain of n masses under
damping_type = 'modal' (10 kept modes, C kept low-rank beside the banded K) against
Rayleigh damping (C banded like K), for growing n. With C low-rank, the step costs
O(n * (bandwidth + kept modes)): doubling n about doubles the time per step.

    .venv/bin/python bench/modal_damping.py                   # n = 1000 ... 8000
    .venv/bin/python bench/modal_damping.py --sizes 500,1000  # a quick look

The set-up (reading, ordering, modes by subspace iteration) is removed by timing a short and
a long run of the same model and dividing the difference by the difference in steps. CPU
time of this process (the machine may be shared); the better of --repeat tries. Nothing here
asserts a speed; the structure (no n x n matrix) is asserted by tests/test_modal_damping.py.
"""

from __future__ import annotations

import argparse
import time
import warnings

import frictiondyn as fd


def chain(n: int, duration: float, damping: fd.Damping) -> fd.Analysis:
    return fd.Analysis(
        masses=[2.0e5] * n,
        springs=[fd.Spring(i + 1, i, 3.0e8) for i in range(n)],
        damping=damping,
        excitation=fd.FreeVibration(dt_record=0.01, duration=duration),
        integration=fd.Integration(n1=2),
        output=fd.Output(output_every=100, n_modes=1),
        u0=[0.01 * (i + 1) / n for i in range(n)],
    )


def per_step(n: int, damping: fd.Damping, repeat: int) -> float:
    """CPU seconds per dt1 step, set-up removed (see the module docstring)."""
    short, long = 0.02, 2.0
    steps = round((long - short) / 0.005)
    best = float("inf")
    for _ in range(repeat):
        t0 = time.process_time()
        chain(n, long, damping).run()
        t1 = time.process_time()
        chain(n, short, damping).run()
        t2 = time.process_time()
        best = min(best, ((t1 - t0) - (t2 - t1)) / steps)
    return best


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--sizes", default="1000,2000,4000,8000")
    ap.add_argument("--repeat", type=int, default=2)
    args = ap.parse_args()
    # a long chain's first period is far beyond a building's: the plausibility warning is noise here
    warnings.simplefilter("ignore", fd.FrictiondynWarning)
    sizes = [int(s) for s in args.sizes.split(",")]
    cases = {
        "modal (10 modes)": fd.Damping.modal(0.05, 10),
        "rayleigh": fd.Damping("rayleigh", rayleigh_a0=0.1, rayleigh_a1=1e-3),
    }
    print(f"{'n':>6}  " + "  ".join(f"{k + ' [us/step]':>26}" for k in cases)
          + "  modal/rayleigh")
    previous = None
    for n in sizes:
        t = {k: per_step(n, d, args.repeat) for k, d in cases.items()}
        ratio = t["modal (10 modes)"] / t["rayleigh"]
        growth = "" if previous is None else (
            f"  (x{t['modal (10 modes)'] / previous:.2f} against the size before)")
        print(f"{n:>6}  " + "  ".join(f"{v * 1e6:>26.1f}" for v in t.values())
              + f"  {ratio:>14.2f}{growth}")
        previous = t["modal (10 modes)"]


if __name__ == "__main__":
    main()
