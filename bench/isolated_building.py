"""frictiondyn against OpenSeesPy on an isolated building of rigid floors, side by side.

    .venv/bin/python bench/isolated_building.py           # 10 storeys, 40 bearings, 30 s
    .venv/bin/python bench/isolated_building.py --storeys 3 --bearings 4 2 --duration 5   # smoke

The model is bench/opensees_models.py's ``IsolatedBuildingCase``: an eccentric building of
rigid floors (ux, uy, rz at each centre of mass) on a rigid base mat carried by friction
pendulum bearings on a grid (Coulomb friction, a concave surface, the gravity share as normal
force), two synthetic ground components (x, and y scaled by 0.7), Newmark's average
acceleration at the same dt1 in both codes. frictiondyn runs the deck's &bearings with the
hysteretic law in the plane (a circular yield surface with radial return, as OpenSees's
singleFPBearing) and ``refinement = 'implicit'``; OpenSees a 3D model with rigidDiaphragm
floors on singleFPBearing elements (docs/performance.md, "An isolated building").

Both codes' peaks (each bearing's resultant displacement, each storey's drift along x and y
between the centres of mass) must agree within --peak-tol (2 %), else the exit status is 1.
frictiondyn runs --repeats times (the median is printed: the whole run of the deck, read,
set-up, integration, summary); OpenSees's analyze() once (minutes at full size; its model
build and gravity step printed apart). Installs openseespy from PyPI when it is missing.
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import sys
import time
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))

import opensees_models as om  # noqa: E402
from compare_opensees_3d import ensure_openseespy  # noqa: E402


def parse_args(argv=None):
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--storeys", type=int, default=10, help="storeys above the base mat")
    p.add_argument("--bearings", type=int, nargs=2, default=(8, 5), metavar=("NX", "NY"),
                   help="the grid of bearings under the base mat")
    p.add_argument("--duration", type=float, default=30.0, help="seconds of each component")
    p.add_argument("--n1", type=int, default=10, help="dt1 = 0.01 s / n1 in both codes")
    p.add_argument("--repeats", type=int, default=3, help="frictiondyn's runs (OpenSees: one)")
    p.add_argument("--peak-tol", type=float, default=0.02)
    p.add_argument("--out", type=Path, default=Path("out/bench"))
    return p.parse_args(argv)


def main(argv=None) -> int:
    args = parse_args(argv)
    version = ensure_openseespy()
    case = om.IsolatedBuildingCase(args.storeys, bearings_x=args.bearings[0], bearings_y=args.bearings[1],
                                   duration=args.duration, n1=args.n1)
    nb = len(case.bearings)
    print(f"{case.name}: {case.n_floors} floors ({3 * case.n_floors} DOFs), {nb} friction pendulum "
          f"bearings (mu {case.mu:g}, R {case.radius:g} m, N {case.p:.4g} N), {case.n_steps} steps of "
          f"{case.dt:g} s, two components; OpenSeesPy {version}: singleFPBearing, Newmark(0.5, 0.25), "
          f"Newton, BandGeneral, RCM, NormDispIncr 1e-8, Transformation", flush=True)

    fd_wall, fd_cpu = [], []
    for _ in range(args.repeats):
        t0, c0 = time.perf_counter(), time.process_time()
        r = case.run_frictiondyn()
        fd_wall.append(time.perf_counter() - t0)
        fd_cpu.append(time.process_time() - c0)
    fd = case.frictiondyn_peaks(r)
    ops = case.run_opensees()
    diff = {}
    for q, name in (("bearing", "bearings' peak displacement"), ("drift", "storey drifts x, y")):
        rel = np.abs(fd[q] - ops.peaks[q]) / ops.peaks[q]
        i = int(rel.argmax())
        diff[q] = float(rel[i])
        print(f"  {name:28s} {100 * rel[i]:8.4f} %  (at {i}: {fd[q][i]:.6g} m against {ops.peaks[q][i]:.6g} m; "
              f"largest {fd[q].max():.4g} m)")
    normal = ops.peaks["normal"] / case.p - 1
    print(f"  OpenSees's normal forces over the gravity share - 1: {normal.min():.2e} ... {normal.max():.2e}")
    agree = max(diff.values()) <= args.peak_tol
    med = statistics.median
    ratio_cpu, ratio_wall = ops.cpu_seconds / med(fd_cpu), ops.seconds / med(fd_wall)
    load = os.getloadavg()
    print(f"time per run (frictiondyn: median of {args.repeats}; load average {load[0]:.2f}):")
    print("| code | wall s | CPU s |")
    print("|---|---|---|")
    print(f"| frictiondyn (whole run of the deck) | {med(fd_wall):.3f} | {med(fd_cpu):.3f} |")
    print(f"| OpenSeesPy analyze() | {ops.seconds:.3f} | {ops.cpu_seconds:.3f} |")
    print(f"| OpenSeesPy model build and gravity (not in the ratio) | {ops.build_seconds:.3f} | |")
    print(f"frictiondyn is {ratio_cpu:.1f}x faster (CPU), {ratio_wall:.1f}x (wall)")
    args.out.mkdir(parents=True, exist_ok=True)
    out = args.out / f"isolated_building_{args.storeys}_{nb}.json"
    out.write_text(json.dumps({
        "case": case.name, "floors": case.n_floors, "bearings": nb, "steps": case.n_steps,
        "dt": case.dt, "duration": case.duration, "openseespy": version,
        "peak_difference": diff, "normal_force_ratio": [float(normal.min()), float(normal.max())],
        "frictiondyn": {"wall_s": fd_wall, "cpu_s": fd_cpu},
        "opensees": {"wall_s": ops.seconds, "cpu_s": ops.cpu_seconds, "build_s": ops.build_seconds},
        "ratio_cpu": ratio_cpu, "ratio_wall": ratio_wall, "loadavg": load,
    }, indent=1))
    print(f"written {out}")
    if not agree:
        print(f"peaks differ by more than {100 * args.peak_tol:g} %", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
