"""&matrices at scale: a general linear structure of 1000 to 5000 DOFs from Matrix Market
files, with 200 friction devices, under Newmark with each regularized law, and under
Moreau-Jean with Coulomb's law (law `coulomb`).

    .venv/bin/python bench/matrix_scale.py                      # towers of 1080 to 5022 DOFs (about 15 min)
    .venv/bin/python bench/matrix_scale.py --family tower --storeys 20,40
    .venv/bin/python bench/matrix_scale.py --family plan --plans 4,6 --laws hysteretic
    .venv/bin/python bench/matrix_scale.py --laws coulomb --solvers dense   # Moreau-Jean's dense form
    .venv/bin/python bench/matrix_scale.py --family plan --plans 6,9 --solvers banded,sparse,auto \
        --laws hysteretic --durations 0.05,0.1          # the band's and CHOLMOD's paths side by side

The structure is a 3D reinforced-concrete frame: nx x ny columns 6 m apart, storeys of
3.5 m, columns fixed at the base, beams along x and y at every floor, each member a 3D
Euler-Bernoulli beam element (12 x 12 stiffness), so K has the sparsity of a real FE model:
six DOFs per node (ux, uy, uz, rx, ry, rz), each node coupled to its (at most six)
neighbours. M is lumped: 30 t on each translation of a node, 30 t x 1 m^2 on each rotation.
Two families: `tower`, a 3 x 3 plan (54 DOFs a floor) of growing height (the band after
reverse Cuthill-McKee about one floor, constant); `plan`, 10 storeys of a growing square plan
(the band grows with the plan's side). The 200 devices (velocity law, eps = 1 mm/s; or
hysteretic, f = 0.1 mm; slip load 150 kN) join ux (or uy, every other one) of a perimeter
node to the same translation of the node below (the table at the first floor): b = e_i - e_j,
an interstorey damper. The table moves along x, harmonic, 0.05 m at 1 Hz, dt_record = 10 ms,
dt1 = 1 ms (n1 = 10); Rayleigh damping (a0 = 0.3 /s, a1 = 1e-3 s); n_modes = 0 and no
history file, so that the run is the time-step loop.

Each case is run by the executable (.venv/bin/frictiondyn) for two durations and a short
one, each in a process of its own; its peak resident memory is its VmHWM, polled from /proc.
The time per step (per dt1 step, and per Newmark step taken: dt1, dt2 and finer) is the
difference of the two long runs over the difference of their steps; the set-up, the short
run (0.02 s, 20 dt1 steps) less its Newmark steps at that time per step. Processor time (user
+ system of the child): the machine may be shared. For each law the exponent p of time per
step ~ nnz(K)^p is fitted (least squares in logarithms) over the sizes; the phase changes'
cost is counted as the banded factor's rank-one updates and partial refactorizations per
dt1 step (the summary's factor_updates, partial_factorizations). With --solvers each case
runs once per `linear_system` (dense, banded, sparse: SuiteSparse's CHOLMOD; auto: the choice
the summary names), rows side by side. Law `coulomb` runs
technique = 'moreau_jean' (theta = 1/2, a step of dt1, its one-step problem in the form
--solvers chooses: 'auto', banded at this size, or 'dense'); its "Newmark steps" are
its steps. Writes
<out>/matrix_scale.json and prints the command and the table. Nothing here asserts a speed.
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent
EXE = Path(os.environ.get("FRICTIONDYN_EXE", ROOT / ".venv" / "bin" / "frictiondyn"))  # or another build's

E, G = 30.0e9, 12.5e9                       # concrete [Pa]
COLUMN = (0.36, 0.0108, 0.0108, 0.0182)     # 0.6 x 0.6 m: A, Iy, Iz, J
BEAM = (0.24, 0.0072, 0.0032, 0.0075)       # 0.4 x 0.6 m
BAY, STOREY = 6.0, 3.5                      # [m]
NODE_MASS, NODE_INERTIA = 3.0e4, 3.0e4      # [kg], [kg m^2]
N_DEVICES = 200
SETUP_DURATION = 0.02                       # [s]: the run that measures the set-up


def beam_stiffness(a: float, iy: float, iz: float, j: float, length: float) -> np.ndarray:
    """The 12 x 12 stiffness of a 3D Euler-Bernoulli beam in its local axes (x along it)."""
    L = length
    k = np.zeros((12, 12))
    k[0, 0] = k[6, 6] = E * a / L
    k[0, 6] = -E * a / L
    k[3, 3] = k[9, 9] = G * j / L
    k[3, 9] = -G * j / L
    for (u, r, sgn, inertia) in ((1, 5, 1.0, iz), (2, 4, -1.0, iy)):
        c = E * inertia
        k[u, u] = k[u + 6, u + 6] = 12 * c / L**3
        k[u, u + 6] = -12 * c / L**3
        k[u, r] = k[u, r + 6] = sgn * 6 * c / L**2
        k[u + 6, r] = k[u + 6, r + 6] = -sgn * 6 * c / L**2
        k[r, r] = k[r + 6, r + 6] = 4 * c / L
        k[r, r + 6] = 2 * c / L
    return k + k.T - np.diag(np.diag(k))   # each pair above was set once, in either triangle


def rotation(axis: np.ndarray) -> np.ndarray:
    """Rows: the element's local axes in global coordinates (x along the element)."""
    x = axis / np.linalg.norm(axis)
    ref = np.array([1.0, 0.0, 0.0]) if abs(x[2]) > 0.9 else np.array([0.0, 0.0, 1.0])
    y = np.cross(ref, x)
    y /= np.linalg.norm(y)
    return np.array([x, y, np.cross(x, y)])


def frame(nx: int, ny: int, nz: int):
    """K (entries on and below the diagonal: i, j, value), the node numbering and n DOFs."""
    node = {}
    for z in range(1, nz + 1):
        for iy in range(ny):
            for ix in range(nx):
                node[(ix, iy, z)] = len(node)
    n = 6 * len(node)
    ent: dict[tuple[int, int], float] = {}
    cols = [(ix, iy, z) for z in range(1, nz + 1) for iy in range(ny) for ix in range(nx)]
    members = [((ix, iy, z - 1), (ix, iy, z), COLUMN) for (ix, iy, z) in cols]
    members += [((ix, iy, z), (ix + 1, iy, z), BEAM) for (ix, iy, z) in cols if ix + 1 < nx]
    members += [((ix, iy, z), (ix, iy + 1, z), BEAM) for (ix, iy, z) in cols if iy + 1 < ny]
    cache = {}
    for a, b, sec in members:
        d = np.array([(b[0] - a[0]) * BAY, (b[1] - a[1]) * BAY, (b[2] - a[2]) * STOREY])
        key = (tuple(d), sec)
        if key not in cache:
            t = np.kron(np.eye(4), rotation(d))
            cache[key] = t.T @ beam_stiffness(*sec, float(np.linalg.norm(d))) @ t
        kg = cache[key]
        dofs = [6 * node[a] + i if a in node else -1 for i in range(6)]
        dofs += [6 * node[b] + i for i in range(6)]
        for p, dp in enumerate(dofs):
            if dp < 0:
                continue
            for q, dq in enumerate(dofs):
                if dq < 0 or dq > dp or kg[p, q] == 0.0:
                    continue
                ent[(dp, dq)] = ent.get((dp, dq), 0.0) + kg[p, q]
    return ent, node, n


def write_mtx(path: Path, n: int, ent: dict) -> None:
    lines = ["%%MatrixMarket matrix coordinate real symmetric", f"{n} {n} {len(ent)}"]
    lines += [f"{i + 1} {j + 1} {float(v)!r}" for (i, j), v in sorted(ent.items(), key=lambda e: (e[0][1], e[0][0]))]
    path.write_text("\n".join(lines) + "\n")


def devices(node: dict, nx: int, ny: int, nz: int) -> tuple[list[int], list[int]]:
    """N_DEVICES interstorey dampers at perimeter nodes, x and y in turn, floors in turn."""
    perim = [(ix, iy) for iy in range(ny) for ix in range(nx) if ix in (0, nx - 1) or iy in (0, ny - 1)]
    ni, nj, seen = [], [], set()
    k = 0
    while len(ni) < N_DEVICES:
        z = 1 + k % nz
        ix, iy = perim[(k // nz) % len(perim)]
        comp = (k // (nz * len(perim)) + k) % 2      # 0: ux, 1: uy
        k += 1
        if (ix, iy, z, comp) in seen:
            comp = 1 - comp
            if (ix, iy, z, comp) in seen:
                continue
        seen.add((ix, iy, z, comp))
        ni.append(6 * node[(ix, iy, z)] + comp + 1)
        nj.append(6 * node[(ix, iy, z - 1)] + comp + 1 if z > 1 else 0)
    return ni, nj


def fortran_list(values) -> str:
    return ", ".join(str(v) for v in values)


def make_case(work: Path, family: str, nx: int, ny: int, nz: int) -> dict:
    d = work / f"{family}_{nx}x{ny}x{nz}"
    d.mkdir(parents=True, exist_ok=True)
    ent, node, n = frame(nx, ny, nz)
    write_mtx(d / "K.mtx", n, ent)
    mass = {(i, i): (NODE_MASS if i % 6 < 3 else NODE_INERTIA) for i in range(n)}
    write_mtx(d / "M.mtx", n, mass)
    ni, nj = devices(node, nx, ny, nz)
    off = sum(1 for (i, j) in ent if i != j)
    return {"dir": d, "n": n, "nnz": len(ent) + off, "node_i": ni, "node_j": nj}


def write_deck(case: dict, law: str, duration: float, system: str = "auto") -> Path:
    n = case["n"]
    infl = ["1.0" if i % 6 == 0 else "0.0" for i in range(n)]
    labels = [f"'n{i // 6 + 1} {('ux', 'uy', 'uz', 'rx', 'ry', 'rz')[i % 6]}'" for i in range(n)]
    nd = len(case["node_i"])
    extra = "eps = {0}".format(", ".join(["1.0e-3"] * nd)) if law == "velocity" else \
        "f = {0}".format(", ".join(["1.0e-4"] * nd))
    technique = "newmark"
    if law == "coulomb":
        extra, technique = "", "moreau_jean"
    text = f"""&matrices
  k_file = 'K.mtx', m_file = 'M.mtx'
  influence = {", ".join(infl)}
  label = {", ".join(labels)}
/
&friction
  n_devices = {nd}
  node_i = {fortran_list(case["node_i"])}
  node_j = {fortran_list(case["node_j"])}
  law = {", ".join([repr(law)] * nd)}
  p = {", ".join(["1.5e5"] * nd)}
  mu = {", ".join(["1.0"] * nd)}
  {extra}
/
&damping
  damping_type = 'rayleigh', rayleigh_a0 = 0.3, rayleigh_a1 = 1.0e-3
/
&excitation
  excitation_type = 'harmonic', amplitude = 0.05, frequency = 1.0, dt_record = 0.01, duration = {duration!r}
/
&integration
  n1 = 10, technique = '{technique}', linear_system = '{system}'
/
&output
  dir = 'out', name = '{law}_{system}_{duration:g}', write_history = .false., n_modes = 0
/
"""
    path = case["dir"] / f"{law}_{system}_{duration:g}.nml"
    path.write_text(text)
    return path


def run(deck: Path) -> dict:
    """The executable on the deck in a process of its own: its processor time (wait4's
    rusage of that child alone) and peak resident memory, VmHWM polled from /proc while it
    runs (its own address space's high-water mark: wait4's ru_maxrss would also count the
    pages of this Python process, which the child shares between fork and exec)."""
    t0 = time.perf_counter()
    with open(deck.with_suffix(".log"), "wb") as log:
        p = subprocess.Popen([str(EXE), deck.name], cwd=deck.parent, stdout=log, stderr=subprocess.STDOUT,
                             env=dict(os.environ, OPENBLAS_NUM_THREADS="1"))
        hwm = 0
        status_file = Path(f"/proc/{p.pid}/status")
        while True:
            pid, status, ru = os.wait4(p.pid, os.WNOHANG)
            if pid:
                break
            try:
                hwm = max(hwm, int(status_file.read_text().split("VmHWM:")[1].split()[0]))
            except (OSError, IndexError, ValueError):
                pass
            time.sleep(0.01)
        p.returncode = os.waitstatus_to_exitcode(status)
    wall = time.perf_counter() - t0
    if p.returncode != 0:
        raise RuntimeError(f"{deck}: exit {p.returncode}: {deck.with_suffix('.log').read_text()[-800:]}")
    summary = json.loads((deck.parent / "out" / f"{deck.stem}.summary.json").read_text())
    return {"wall_s": wall, "cpu_s": ru.ru_utime + ru.ru_stime, "vmhwm_mb": hwm / 1024.0, "summary": summary}


def newmark_steps(st: dict) -> int:
    """Newmark steps of every size a run took (dt1, dt2, finer, nested, implicit)."""
    return sum(int(st.get(k, 0)) for k in ("steps_dt1", "steps_dt2", "steps_finer", "steps_nested", "steps_implicit"))


def measure(case: dict, law: str, durations: tuple[float, float], system: str = "auto") -> dict:
    rows = []
    for dur in durations:
        r = run(write_deck(case, law, dur, system))
        st = r["summary"]
        newmark = newmark_steps(st)
        rows.append({"duration_s": dur, "cpu_s": r["cpu_s"], "wall_s": r["wall_s"], "vmhwm_mb": r["vmhwm_mb"],
                     "steps_dt1": int(st["steps_dt1"]), "newmark_steps": newmark,
                     "half_bandwidth": st.get("half_bandwidth"), "linear_system": st.get("linear_system"),
                     "factorizations": st.get("factorizations"), "factor_updates": st.get("factor_updates"),
                     "partial_factorizations": st.get("partial_factorizations"),
                     "transitions": int(sum(st["stick_to_slip"])), "period_stuck_s": st.get("period_stuck_s"),
                     "omega_max_rad_s": st.get("omega_max_rad_s")})
    a, b = rows
    per_dt1 = (b["cpu_s"] - a["cpu_s"]) / max(b["steps_dt1"] - a["steps_dt1"], 1)
    per_nm = (b["cpu_s"] - a["cpu_s"]) / max(b["newmark_steps"] - a["newmark_steps"], 1)
    # the set-up: a run of two record steps (20 dt1 steps, the motion still small), less them
    short = run(write_deck(case, law, SETUP_DURATION, system))
    setup = short["cpu_s"] - per_nm * newmark_steps(short["summary"])
    dsteps = max(b["steps_dt1"] - a["steps_dt1"], 1)
    return {"law": law, "system": system, "n": case["n"], "nnz": case["nnz"], "runs": rows, "us_per_dt1_step": 1e6 * per_dt1,
            "us_per_newmark_step": 1e6 * per_nm, "setup_s": setup,
            "newmark_per_dt1": (b["newmark_steps"] - a["newmark_steps"]) / dsteps,
            "updates_per_dt1": ((b["factor_updates"] or 0) - (a["factor_updates"] or 0)) / dsteps,
            "partial_per_dt1": ((b["partial_factorizations"] or 0) - (a["partial_factorizations"] or 0)) / dsteps}


def exponent(rows: list[dict], key: str) -> float:
    """p of key ~ nnz^p, least squares in logarithms."""
    x = np.log([r["nnz"] for r in rows])
    y = np.log([max(r[key], 1e-9) for r in rows])
    return float(np.polyfit(x, y, 1)[0])


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--family", choices=("tower", "plan", "both"), default="tower")
    ap.add_argument("--storeys", default="20,40,60,93", help="tower: storeys of the 3 x 3 plan (93: 5022 DOFs)")
    ap.add_argument("--plans", default="4,6,9", help="plan: nodes along a side of the 10-storey plan")
    ap.add_argument("--laws", default="velocity,hysteretic", help="velocity, hysteretic (Newmark), coulomb "
                    "(Moreau-Jean)")
    ap.add_argument("--solvers", default="auto",
                    help="&integration's linear_system of each run: auto, dense, banded, sparse (comma list)")
    ap.add_argument("--durations", default="1,2", help="two durations [s]")
    ap.add_argument("--work", default=str(ROOT / "build" / "matrix_scale"))
    ap.add_argument("--out", default=None, help="directory of matrix_scale.json (default: --work)")
    args = ap.parse_args()
    if not EXE.exists():
        sys.exit(f"{EXE} is missing: run tools/setup.sh first")
    durations = tuple(float(x) for x in args.durations.split(","))
    work = Path(args.work)
    shapes = []
    if args.family in ("tower", "both"):
        shapes += [("tower", 3, 3, int(s)) for s in args.storeys.split(",")]
    if args.family in ("plan", "both"):
        shapes += [("plan", int(p), int(p), 10) for p in args.plans.split(",")]
    results = []
    print("command: " + " ".join([Path(sys.executable).name, "bench/matrix_scale.py"] + sys.argv[1:]), flush=True)
    print(f"{'family':6s} {'plan':>5s} {'storeys':>7s} {'law':10s} {'system':13s} {'DOFs':>5s} {'nnz(K)':>8s} {'band':>5s} "
          f"{'set-up s':>8s} {'us/dt1':>8s} {'us/NM':>8s} {'us/NM/nnz':>9s} "
          f"{'VmHWM MB (' + args.durations + ' s)':>20s} {'NM/dt1':>6s} {'upd/dt1':>7s} {'part/dt1':>8s}", flush=True)
    for family, nx, ny, nz in shapes:
        case = make_case(work, family, nx, ny, nz)
        for law, system in [(lw, sy) for lw in args.laws.split(",") for sy in args.solvers.split(",")]:
            r = measure(case, law, durations, system)
            r.update(family=family, plan=f"{nx}x{ny}", storeys=nz)
            results.append(r)
            a, b = r["runs"]
            took = f"{system}->{a['linear_system']}" if system == "auto" else system
            print(f"{family:6s} {nx}x{ny:<3d} {nz:7d} {law:10s} {took:13s} {r['n']:5d} {r['nnz']:8d} {a['half_bandwidth']!s:>5s} "
                  f"{r['setup_s']:8.2f} {r['us_per_dt1_step']:8.0f} {r['us_per_newmark_step']:8.1f} "
                  f"{1e3 * r['us_per_newmark_step'] / r['nnz']:9.3f} {a['vmhwm_mb']:9.1f} {b['vmhwm_mb']:9.1f} "
                  f"{r['newmark_per_dt1']:6.1f} {r['updates_per_dt1']:7.1f} {r['partial_per_dt1']:8.2f}",
                  flush=True)
    for family in sorted({r["family"] for r in results}):
        for law, system in [(lw, sy) for lw in args.laws.split(",") for sy in args.solvers.split(",")]:
            rows = [r for r in results if r["family"] == family and r["law"] == law and r["system"] == system]
            if len(rows) > 1:
                print(f"{family} {law} {system}: time per step ~ nnz^p, p = {exponent(rows, 'us_per_newmark_step'):.2f} "
                      f"(per Newmark step), {exponent(rows, 'us_per_dt1_step'):.2f} (per dt1 step), "
                      f"set-up {exponent(rows, 'setup_s'):.2f}, over nnz = "
                      f"{', '.join(str(r['nnz']) for r in rows)}", flush=True)
    out = Path(args.out) if args.out else work
    out.mkdir(parents=True, exist_ok=True)
    (out / "matrix_scale.json").write_text(json.dumps(results, indent=1, default=str))
    return 0


if __name__ == "__main__":
    sys.exit(main())
