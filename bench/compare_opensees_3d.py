"""frictiondyn against OpenSeesPy on an eccentric building of rigid floors, side by side.

    .venv/bin/python bench/compare_opensees_3d.py                 # 20 storeys, 30 s, 3 repeats
    .venv/bin/python bench/compare_opensees_3d.py --storeys 5 --duration 5 --repeats 1   # smoke

The model is bench/opensees_models.py's ``Building3DCase``: floors with three DOFs at their
centre of mass (ux, uy, rz; 60 DOFs for 20 storeys), stiffness eccentric along x and centres
of mass moving east with height, four braces with friction dampers a storey (two along x, two
along y; frictiondyn's hysteretic law, OpenSees's ElasticPP zeroLength links), two synthetic
ground components (x, and y scaled by 0.7), Newmark's average acceleration at the same dt1.
frictiondyn runs the deck with ``refinement = 'implicit'`` (a step with a phase change is
taken again in the phases it ends in: OpenSees's return mapping) and a narrow end-of-sliding
band eps1; OpenSees a 3D model with rigidDiaphragm floors (docs/performance.md).

Each code runs once and both codes' peaks (|ux|, |uy|, |rz| of every floor, |drift| of every
storey along x and y, |deformation| and |force| of every brace) must agree within --peak-tol
(0.5 %), else the exit status is 1. Then each runs --repeats times, interleaved, and the
median wall-clock and processor times are printed: frictiondyn's whole run of the deck (read,
set-up, integration, summary), OpenSees's analyze() alone (its model build is printed apart).
Installs openseespy from PyPI when it is missing (as bench/compare_opensees.py does).
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))

import opensees_models as om  # noqa: E402


def ensure_openseespy() -> str:
    try:
        import openseespy.opensees  # noqa: F401
    except ImportError:
        print(f"compare_opensees_3d: installing openseespy from PyPI into {sys.prefix}", flush=True)
        subprocess.run([sys.executable, "-m", "pip", "install", "-q", "openseespy"], check=True)
        import openseespy.opensees  # noqa: F401
    from importlib.metadata import version

    return version("openseespy")


def parse_args(argv=None):
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--storeys", type=int, default=20)
    p.add_argument("--duration", type=float, default=30.0, help="seconds of each component")
    p.add_argument("--n1", type=int, default=10, help="dt1 = 0.01 s / n1 in both codes")
    p.add_argument("--eps1", type=float, default=1e-6, help="frictiondyn's end-of-sliding band")
    p.add_argument("--refinement", default="implicit", choices=("implicit", "step", "nested"))
    p.add_argument("--repeats", type=int, default=3)
    p.add_argument("--peak-tol", type=float, default=0.005)
    p.add_argument("--ops-tol", type=float, default=1e-8, help="OpenSees NormDispIncr [m]")
    p.add_argument("--out", type=Path, default=Path("out/bench"))
    return p.parse_args(argv)


def main(argv=None) -> int:
    args = parse_args(argv)
    version = ensure_openseespy()
    case = om.Building3DCase(args.storeys, duration=args.duration, n1=args.n1,
                             eps1=args.eps1, refinement=args.refinement)
    settings = om.OpenSeesSettings(tol=args.ops_tol, constraints="Transformation")
    print(f"{case.name}: {case.n_dof} DOFs, {len(case.braces)} braces, {case.n_steps} steps of "
          f"{case.dt:g} s, two components; frictiondyn refinement '{args.refinement}', "
          f"eps1 {args.eps1:g}; OpenSeesPy {version}: {settings.describe()}", flush=True)

    fd_result = case.run_frictiondyn()
    fd_peaks = om.frictiondyn_peaks_3d(fd_result)
    ops_run = om.run_opensees_3d(case, settings)
    diff = om.compare_peaks_3d(fd_peaks, ops_run.peaks)
    slipping = int((fd_peaks["F"] >= 0.999 * case.slip).sum())
    print(f"braces reaching their slip load: frictiondyn {slipping}, OpenSees "
          f"{int((ops_run.peaks['F'] >= 0.999 * case.slip).sum())} of {len(case.braces)}")
    print("peak difference |fd - ops| / |ops| (largest over DOFs, storeys or braces):")
    names = {"u": "ux, uy, rz of the floors", "drift": "storey drifts x, y",
             "s": "brace deformations", "F": "brace forces"}
    for q, (d, i) in diff.items():
        print(f"  {names[q]:28s} {100 * d:9.4f} %  (at {i}: {fd_peaks[q][i]:.6g} against "
              f"{ops_run.peaks[q][i]:.6g})")
    worst = max(d for d, _ in diff.values())
    agree = worst <= args.peak_tol

    fd_wall, fd_cpu, ops_wall, ops_cpu, ops_build = [], [], [], [], []
    for _ in range(args.repeats):
        t0, c0 = time.perf_counter(), time.process_time()
        r = case.run_frictiondyn()
        fd_wall.append(time.perf_counter() - t0)
        fd_cpu.append(time.process_time() - c0)
        o = om.run_opensees_3d(case, settings)
        ops_wall.append(o.seconds)
        ops_cpu.append(o.cpu_seconds)
        ops_build.append(o.build_seconds)
        again = om.compare_peaks_3d(om.frictiondyn_peaks_3d(r), o.peaks)
        agree = agree and max(d for d, _ in again.values()) <= args.peak_tol
    med = statistics.median
    ratio_cpu, ratio_wall = med(ops_cpu) / med(fd_cpu), med(ops_wall) / med(fd_wall)
    load = os.getloadavg()
    print(f"time per run, median of {args.repeats} (load average {load[0]:.2f}):")
    print("| code | wall s | CPU s |")
    print("|---|---|---|")
    print(f"| frictiondyn (whole run of the deck) | {med(fd_wall):.3f} | {med(fd_cpu):.3f} |")
    print(f"| OpenSeesPy analyze() | {med(ops_wall):.3f} | {med(ops_cpu):.3f} |")
    print(f"| OpenSeesPy model build (not in the ratio) | {med(ops_build):.3f} | |")
    print(f"frictiondyn is {ratio_cpu:.1f}x faster (CPU), {ratio_wall:.1f}x (wall)")
    args.out.mkdir(parents=True, exist_ok=True)
    out = args.out / f"compare_opensees_3d_{args.storeys}.json"
    out.write_text(json.dumps({
        "case": case.name, "n_dof": case.n_dof, "braces": len(case.braces), "steps": case.n_steps,
        "dt": case.dt, "duration": case.duration, "refinement": args.refinement, "eps1": args.eps1,
        "openseespy": version, "opensees_settings": settings.describe(),
        "peak_difference": {q: d for q, (d, _) in diff.items()},
        "frictiondyn": {"wall_s": fd_wall, "cpu_s": fd_cpu},
        "opensees": {"wall_s": ops_wall, "cpu_s": ops_cpu, "build_s": ops_build},
        "ratio_cpu": ratio_cpu, "ratio_wall": ratio_wall, "loadavg": load,
    }, indent=1))
    print(f"written {out}")
    if not agree:
        print(f"peaks differ by more than {100 * args.peak_tol:g} %", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
