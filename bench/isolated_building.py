"""frictiondyn against OpenSeesPy on an isolated building of rigid floors, side by side.

    .venv/bin/python bench/isolated_building.py           # 10 storeys, 40 bearings, three 30 s components
    .venv/bin/python bench/isolated_building.py --vertical 0 --k-init 5e7    # two components
    .venv/bin/python bench/isolated_building.py --storeys 3 --bearings 4 2 --duration 5   # smoke
    .venv/bin/python bench/isolated_building.py --friction veldep   # velocity-dependent friction

The model is bench/opensees_models.py's ``IsolatedBuildingCase``: an eccentric building of
rigid floors (ux, uy, rz at each centre of mass) on a rigid base mat carried by friction
pendulum bearings on a grid (Coulomb friction, a concave surface, the gravity share as normal
force), three synthetic ground components (x, y scaled by 0.7, and the vertical scaled by
--vertical, 2/3), Newmark's average acceleration at the same dt1 in both codes. frictiondyn runs the deck's &bearings with the
hysteretic law in the plane (a circular yield surface with radial return, as OpenSees's
singleFPBearing) and ``refinement = 'implicit'``; OpenSees a 3D model with rigidDiaphragm
floors on singleFPBearing elements (docs/performance.md, "An isolated building").

The vertical component: frictiondyn's vertical support is rigid, N = p (1 + a_z / g). OpenSees's
singleFPBearing takes N from its axial force, so each bearing's top node carries the vertical
mass p / g (g = 9.80665 m/s2) on an axial spring kv (--kv), under the vertical base motion:
kv = 1e13 N/m puts the vertical period 2 pi sqrt(p / (g kv)) at 0.5 ms, a twentieth of the
record step (0.01 s) and half of dt1, the rigid limit to 0.4 % in N. Under a varying N the two
codes' regularized friction differ in proportion to the sticking displacement f: frictiondyn
keeps f and scales the sticking stiffness P mu / f with N, OpenSees keeps k_init - N/R and
scales the yield displacement; --k-init 5e8 (f = 65 um) makes that difference small.

--friction veldep: mu(v) = 0.10 - 0.06 exp(-20 |v|), frictiondyn's velocity law (band 1e-4 m/s,
mu_law 'exponential') against OpenSees's frictionModel VelDependent; OpenSees's elastic-plastic
friction approaches the velocity law's rigid-plastic limit as k_init grows (default 1e11 N/m).
At dt1 = 1 ms the velocity law's force alternates in the band on some bearings (frictiondyn's
band-alternation warning, printed; also at 3e-4 m/s); a band of 1e-3 m/s, without it, leaves
the peaks within 0.9 % of OpenSees's. Smoke size (3 storeys, 8 bearings, 4 s, three components): bearings within
0.16 %, drifts within 0.33 %.

Both codes' peaks (each bearing's resultant displacement, each storey's drift along x and y
between the centres of mass) must agree within --peak-tol (2 %), else the exit status is 1.
frictiondyn runs --repeats times (the median is printed: the whole run of the deck, read,
set-up, integration, summary); OpenSees's analyze() once (minutes at full size; its model
build and gravity step printed apart). Installs openseespy from PyPI when it is missing.
"""

from __future__ import annotations

import argparse
import json
import math
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
    p.add_argument("--vertical", type=float, default=2 / 3,
                   help="the vertical component's PGA over the horizontal's (0: two components)")
    p.add_argument("--kv", type=float, default=1.0e13, help="OpenSees: a bearing's axial stiffness [N/m]")
    p.add_argument("--k-init", type=float, default=None,
                   help="a bearing's initial (sticking) stiffness [N/m]; f = mu N / (k_init - N/R); "
                        "default 5e8, 1e11 with --friction veldep")
    p.add_argument("--friction", choices=("coulomb", "veldep"), default="coulomb",
                   help="veldep: mu(v) = 0.10 - 0.06 exp(-20 |v|) (frictiondyn's velocity law, band "
                        "1e-4 m/s; OpenSees's VelDependent), with --k-init 1e11 unless given")
    p.add_argument("--repeats", type=int, default=3, help="frictiondyn's runs (OpenSees: one)")
    p.add_argument("--peak-tol", type=float, default=0.02)
    p.add_argument("--out", type=Path, default=Path("out/bench"))
    return p.parse_args(argv)


def main(argv=None) -> int:
    args = parse_args(argv)
    version = ensure_openseespy()
    veldep = args.friction == "veldep"
    if args.k_init is None:
        args.k_init = 1.0e11 if veldep else 5.0e8
    friction = {"mu": 0.10, "mu_min": 0.04, "mu_rate": 20.0, "eps": 1.0e-4} if veldep else {}
    case = om.IsolatedBuildingCase(args.storeys, bearings_x=args.bearings[0], bearings_y=args.bearings[1],
                                   duration=args.duration, n1=args.n1, vertical=args.vertical, kv=args.kv,
                                   k_init=args.k_init, **friction)
    nb = len(case.bearings)
    three = len(case.records) > 2
    print(f"{case.name}: {case.n_floors} floors ({3 * case.n_floors} DOFs), {nb} friction pendulum "
          f"bearings ({'mu' if case.mu_min is None else f'mu {case.mu_min:g} ... '}{case.mu:g}, R {case.radius:g} m, N {case.p:.4g} N, k_init {case.k_init:.3g} N/m, "
          f"f {case.f:.3g} m), {case.n_steps} steps of {case.dt:g} s, {len(case.records)} components; "
          f"OpenSeesPy {version}: singleFPBearing, Newmark(0.5, 0.25), Newton, BandGeneral, RCM, "
          "NormDispIncr 1e-8, Transformation", flush=True)
    if three:
        tv = 2 * math.pi * math.sqrt(case.p / om.G_FD / case.kv)
        print(f"vertical: PGA {np.abs(case.records[2]).max() / om.G_FD:.3f} g; OpenSees's vertical mass "
              f"p/g {case.p / om.G_FD:.4g} kg a bearing on kv {case.kv:.3g} N/m: period {1e3 * tv:.3f} ms "
              f"({tv / case.dt_record:.3f} of the record step, {tv / case.dt:.3f} of dt1)", flush=True)

    fd_wall, fd_cpu = [], []
    for _ in range(args.repeats):
        t0, c0 = time.perf_counter(), time.process_time()
        r = case.run_frictiondyn()
        fd_wall.append(time.perf_counter() - t0)
        fd_cpu.append(time.process_time() - c0)
    fd = case.frictiondyn_peaks(r)
    ops = case.run_opensees()
    diff = {}
    print("peaks side by side (largest difference of each kind):")
    print("| quantity | item | frictiondyn | OpenSeesPy | difference |")
    print("|---|---|---|---|---|")
    kinds = [("bearing", "bearing peak resultant displacement [mm]", 1e3),
             ("drift", "storey peak drift (x, y) [mm]", 1e3)]
    if three:
        kinds += [("normal_min", "bearing min N [kN]", 1e-3), ("normal_max", "bearing max N [kN]", 1e-3)]
    for q, name, unit in kinds:
        rel = np.abs(fd[q] - ops.peaks[q]) / ops.peaks[q]
        i = int(rel.argmax())
        if q in ("bearing", "drift"):
            diff[q] = float(rel[i])
        item = f"{i + 1}" if q != "drift" else f"storey {i // 2 + 1} {'xy'[i % 2]}"
        print(f"| {name} | {item} | {unit * fd[q][i]:.4f} | {unit * ops.peaks[q][i]:.4f} | {100 * rel[i]:.3f} % |")
    print(f"| largest bearing displacement [mm] | | {1e3 * fd['bearing'].max():.4f} | "
          f"{1e3 * ops.peaks['bearing'].max():.4f} | |")
    print("storey drifts [mm], x then y, storey 1 (the base mat) first:")
    print("  frictiondyn: " + " ".join(f"{1e3 * x:.3f}" for x in fd["drift"]))
    print("  OpenSeesPy:  " + " ".join(f"{1e3 * x:.3f}" for x in ops.peaks["drift"]))
    normal = ops.peaks["normal"] / case.p - 1
    print(f"  OpenSees's normal forces at the end over the gravity share - 1: {normal.min():.2e} ... {normal.max():.2e}")
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
    out = args.out / f"isolated_building_{args.storeys}_{nb}_{len(case.records)}c{'_veldep' * veldep}.json"
    out.write_text(json.dumps({
        "case": case.name, "floors": case.n_floors, "bearings": nb, "steps": case.n_steps,
        "dt": case.dt, "duration": case.duration, "openseespy": version, "components": len(case.records),
        "vertical": args.vertical, "kv": case.kv, "k_init": case.k_init, "friction": args.friction,
        "peaks": {q: {"frictiondyn": np.asarray(fd[q]).tolist(), "opensees": np.asarray(ops.peaks[q]).tolist()}
                  for q in fd},
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
