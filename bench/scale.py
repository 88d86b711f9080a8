"""frictiondyn alone at scale: cost and memory against the number of storeys, for both
regularized laws; memory against the duration; reading a large deck; the set-up before the
first step of 1e5 unconnected masses and of a 1e5-DOF chain; runs in threads; how fast Ctrl-C
stops a run.

    .venv/bin/python bench/scale.py                        # all of it (about 30 min)
    .venv/bin/python bench/scale.py --sizes 10,100 --no-extras   # a quick look
    .venv/bin/python bench/scale.py --sizes 10 --no-extras --setup 100000   # the set-up only
    .venv/bin/python bench/scale.py --sizes 10,100,1000 --no-extras --refinement nested
    .venv/bin/python bench/scale.py --out docs/performance       # what docs/performance.md shows

The building is bench/opensees_models.py's BuildingCase (a friction damper in every storey,
20 s of synthetic ground motion at dt_r = 10 ms, dt1 = 1 ms), with the hysteretic law and
with the velocity law (band eps = 1 mm/s). Each size runs in a process of its own (its peak
resident memory, VmHWM, is measured there), keeping the roof's DOF and the first device in
its history (the summary has every peak). The set-up case runs the executable on a deck of
n masses, each on a spring and a friction device (hysteretic) to the table, with no
connection between them, and on a chain of n masses (springs and devices between
neighbours), for two dt1 steps: its time is reading the deck, the matrices, the ordering
(reverse Cuthill-McKee, linear in DOFs + connections), the factorization and the modes,
nearly all of it before the first step. Cost is CPU time of the run (the machine may be
shared), per dt1 step and per Newmark step taken (dt1, dt2 and finer: the paper's step
control redoes a dt1 step in which a device changes phase as n2 = 50 dt2 steps, so the
number of Newmark steps per dt1 step grows with the number of devices until it saturates at
51). Writes <out>/scale.json and prints the tables. Nothing here asserts a speed.
"""

from __future__ import annotations

import argparse
import json
import math
import os
import signal
import statistics
import subprocess
import sys
import tempfile
import threading
import time
from pathlib import Path

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")  # numpy's BLAS threads spin otherwise
HERE = Path(__file__).resolve().parent
ROOT = HERE.parent
TAG = "@@scale-result@@ "


def _status(key: str) -> float:
    with open("/proc/self/status") as fh:
        for line in fh:
            if line.startswith(key + ":"):
                return int(line.split()[1]) / 1024.0
    return float("nan")


def child(args) -> int:
    """One run in this process: CPU and wall time, steps, peak memory."""
    import frictiondyn as fd

    rss0 = _status("VmRSS")
    t0, c0 = time.perf_counter(), time.process_time()
    with fd.Session(args.deck) as s:
        t_open = time.perf_counter() - t0
        s.select([args.n], [1])
        t1, c1 = time.perf_counter(), time.process_time()
        s.solve()
        wall, cpu = time.perf_counter() - t1, time.process_time() - c1
        r = s.result()
    st = r.summary
    out = {
        "wall_s": wall,
        "cpu_s": cpu,
        "open_s": t_open,
        "run_time_s": st["run_time_s"],
        "steps_dt1": st["steps_dt1"],
        "steps_dt2": st["steps_dt2"],
        "steps_nested": st["steps_nested"],
        "steps_finer": st["steps_finer"],
        "steps_implicit": st["steps_implicit"],
        "implicit_redos": st["implicit_redos"],
        "factorizations": st["factorizations"],
        "factor_updates": st["factor_updates"],
        "partial_factorizations": st["partial_factorizations"],
        "linear_system": st["linear_system"],
        "half_bandwidth": st["half_bandwidth"],
        "transitions": int(sum(st["stick_to_slip"])),
        "rss_before_mb": rss0,
        "rss_peak_mb": _status("VmHWM"),
        "history_mb": r.data.nbytes / 1e6,
    }
    print(TAG + json.dumps(out), flush=True)
    return 0


def run_child(deck: Path, n: int) -> dict:
    p = subprocess.run(
        [sys.executable, __file__, "--child", "--deck", str(deck), "--n", str(n)],
        capture_output=True,
        text=True,
        check=False,
    )
    for line in p.stdout.splitlines():
        if line.startswith(TAG):
            return json.loads(line[len(TAG):])
    raise RuntimeError(f"child failed: {p.stderr.strip()[-500:]}")


def make_deck(work: Path, n: int, law: str, duration: float, refinement: str = "step") -> Path:
    sys.path.insert(0, str(HERE))
    import opensees_models as om

    case = om.BuildingCase(n, duration=duration, law=law, refinement=refinement)
    d = work / f"{law}_{refinement}_{n}_{duration:g}"
    d.mkdir(parents=True, exist_ok=True)
    return case.analysis().write_deck(d / "building.nml")


def exponents(pts: list[tuple[int, float]]) -> dict:
    out = {}
    for (n0, y0), (n1, y1) in zip(pts, pts[1:]):
        out[f"{n0}-{n1}"] = math.log(y1 / y0) / math.log(n1 / n0)
    if len(pts) > 2:
        (n0, y0), (n1, y1) = pts[0], pts[-1]
        out[f"{n0}-{n1}"] = math.log(y1 / y0) / math.log(n1 / n0)
    return out


def scaling(args, work: Path) -> dict:
    from frictiondyn import newmark_steps

    res: dict = {}
    for law in args.laws:
        rows = []
        for n in args.sizes:
            deck = make_deck(work, n, law, args.duration, args.refinement)
            r = run_child(deck, n)
            nm = newmark_steps(r)
            steps = round(args.duration / 1e-3)
            r.update(
                n=n,
                newmark_steps=nm,
                cpu_us_per_step=1e6 * r["cpu_s"] / steps,
                run_us_per_step=1e6 * r["wall_s"] / steps,
                run_us_per_newmark_step=1e6 * r["wall_s"] / nm,
                cpu_us_per_newmark_step=1e6 * r["cpu_s"] / nm,
            )
            rows.append(r)
            print(
                f"{law:10s} N = {n:6d}: {r['cpu_us_per_step']:10.1f} us/dt1 step, "
                f"{r['cpu_us_per_newmark_step']:8.2f} us/Newmark step (CPU; wall "
                f"{r['run_us_per_step']:.1f}, {r['run_us_per_newmark_step']:.2f}), steps {r['steps_dt1']} + "
                f"{r['steps_nested']} + {r['steps_dt2']} + "
                f"{r['steps_finer']}"
                + (f" + implicit {r['steps_implicit']} (+ {r['implicit_redos']} redone)"
                   if r["steps_implicit"] else "")
                + f", {r['transitions']} transitions, factor: "
                f"{r['factorizations']} full, {r['partial_factorizations']} partial, "
                f"{r['factor_updates']} updates; deck read {r['open_s']:.3f} s; peak RSS "
                f"{r['rss_peak_mb']:.0f} MB",
                flush=True,
            )
        res[law] = {
            "rows": rows,
            "exponent_per_dt1_step": exponents([(r["n"], r["cpu_us_per_step"]) for r in rows]),
            "exponent_per_newmark_step": exponents(
                [(r["n"], r["cpu_us_per_newmark_step"]) for r in rows]
            ),
            "exponent_memory_above_start": exponents(
                [(r["n"], max(r["rss_peak_mb"] - r["rss_before_mb"], 1e-3)) for r in rows]
            ),
        }
    return res


def memory_vs_duration(args, work: Path) -> dict:
    n = args.memory_size
    out = {}
    for duration in (args.duration / 2, args.duration):
        r = run_child(make_deck(work, n, "hysteretic", duration), n)
        out[f"{duration:g}"] = {"rss_peak_mb": r["rss_peak_mb"], "rss_before_mb": r["rss_before_mb"]}
        print(f"memory, N = {n}, {duration:g} s: peak RSS {r['rss_peak_mb']:.1f} MB "
              f"(before the run {r['rss_before_mb']:.1f} MB)", flush=True)
    return out


def deck_reading(work: Path, n: int) -> dict:
    import frictiondyn as fd

    deck = make_deck(work, n, "hysteretic", 1.0)
    size = deck.stat().st_size + (deck.parent / "record.txt").stat().st_size
    ts = []
    for _ in range(5):
        t0 = time.perf_counter()
        with fd.Session(deck):
            pass
        ts.append(time.perf_counter() - t0)
    print(f"reading the {n}-storey deck ({size / 1e6:.2f} MB with its record): "
          f"median {statistics.median(ts) * 1e3:.1f} ms of 5", flush=True)
    return {"n": n, "bytes": size, "median_s": statistics.median(ts), "runs_s": ts}


def setup_deck(work: Path, n: int, chain: bool) -> Path:
    """n masses of 1000 kg on springs of 2e6 N/m and hysteretic friction devices: to the
    table (unconnected), or each to the mass below (a chain); two dt1 steps of harmonic
    table motion, no history file."""
    below = [i - 1 for i in range(1, n + 1)] if chain else [0] * n
    nodes = " ".join(str(i) for i in range(1, n + 1))
    below_s = " ".join(str(b) for b in below)
    text = (
        f"&model\n n_dof = {n}\n mass = {n}*1000.0\n/\n"
        f"&springs\n n_springs = {n}\n node_i = {nodes}\n node_j = {below_s}\n k = {n}*2.0e6\n/\n"
        "&damping\n damping_type = 'rayleigh'\n rayleigh_a0 = 0.2\n rayleigh_a1 = 4.0e-4\n/\n"
        f"&friction\n n_devices = {n}\n node_i = {nodes}\n node_j = {below_s}\n"
        f" law = {n}*'hysteretic'\n p = {n}*1000.0\n mu = {n}*1.0\n f = {n}*5.0e-4\n/\n"
        "&excitation\n excitation_type = 'harmonic'\n amplitude = 0.01\n frequency = 2.0\n"
        " dt_record = 0.002\n duration = 0.002\n/\n"
        "&integration\n n1 = 2\n/\n"
        f"&output\n dir = '{work / 'out'}'\n name = 'setup'\n write_history = .false.\n/\n"
    )
    d = work / f"setup_{'chain' if chain else 'free'}_{n}"
    d.mkdir(parents=True, exist_ok=True)
    deck = d / "setup.nml"
    deck.write_text(text)
    return deck


def setup_time(work: Path, n: int, exe: str) -> dict:
    """Wall and CPU time of the executable on the set-up decks (two dt1 steps)."""
    import resource

    out: dict = {"n": n, "executable": exe}
    for kind in ("free", "chain"):
        deck = setup_deck(work, n, kind == "chain")
        before = resource.getrusage(resource.RUSAGE_CHILDREN)
        t0 = time.perf_counter()
        p = subprocess.run([exe, str(deck)], capture_output=True, text=True, check=False)
        wall = time.perf_counter() - t0
        after = resource.getrusage(resource.RUSAGE_CHILDREN)
        if p.returncode != 0:
            raise RuntimeError(f"{exe} {deck}: {p.stderr.strip()[-500:]}")
        cpu = after.ru_utime + after.ru_stime - before.ru_utime - before.ru_stime
        out[kind] = {"wall_s": wall, "cpu_s": cpu}
        print(f"set-up, {n} DOFs, {'a chain' if kind == 'chain' else 'unconnected masses'}: "
              f"{cpu:.2f} s CPU, {wall:.2f} s wall (two dt1 steps; {exe})", flush=True)
    return out


def threads(work: Path, n: int) -> dict:
    """Two runs one after the other, then two at once in two threads: wall times."""
    import frictiondyn as fd

    deck = make_deck(work, n, "hysteretic", 5.0)

    def one():
        fd.run(deck, dofs=[n], devices=[1])

    one()  # warm-up
    t0 = time.perf_counter()
    one()
    one()
    seq = time.perf_counter() - t0
    t0 = time.perf_counter()
    th = [threading.Thread(target=one) for _ in range(2)]
    for t in th:
        t.start()
    for t in th:
        t.join()
    par = time.perf_counter() - t0
    print(f"threads, N = {n}: two runs in sequence {seq:.2f} s, in two threads {par:.2f} s "
          f"(overlap: {seq / par:.2f}x; {os.cpu_count()} cores, load {os.getloadavg()[0]:.1f})",
          flush=True)
    return {"n": n, "sequential_s": seq, "threads_s": par, "speedup": seq / par,
            "cores": os.cpu_count(), "load": os.getloadavg()[0]}


INTERRUPT = """
import os, signal, sys, threading, time, frictiondyn as fd
deck = sys.argv[1]
def fire():
    global t_sig
    t_sig = time.perf_counter()
    os.kill(os.getpid(), signal.SIGINT)
threading.Timer(float(sys.argv[2]), fire).start()
try:
    with fd.Session(deck) as s:
        s.select([int(sys.argv[3])], [1])
        s.solve()
    print("finished")
except KeyboardInterrupt:
    print("latency", time.perf_counter() - t_sig)
"""


def interrupt(work: Path, n: int, repeats: int) -> dict:
    deck = make_deck(work, n, "hysteretic", 20.0)
    lat = []
    for k in range(repeats):
        p = subprocess.run([sys.executable, "-c", INTERRUPT, str(deck), str(0.3 + 0.07 * k), str(n)],
                           capture_output=True, text=True, check=False)
        words = p.stdout.split()
        if "latency" in words:  # the number follows the word (other output may come after it)
            lat.append(float(words[words.index("latency") + 1]))
        else:
            print(f"interrupt run {k}: no latency reported: {(p.stdout + p.stderr).strip()[-300:]!r}", flush=True)
    print(f"Ctrl-C during fd.run (N = {n}): KeyboardInterrupt after {statistics.median(lat) * 1e3:.1f} ms "
          f"(median of {len(lat)}), at most {max(lat) * 1e3:.1f} ms", flush=True)
    return {"n": n, "latency_s": lat, "median_s": statistics.median(lat), "max_s": max(lat)}


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--sizes", default="10,100,1000,10000")
    ap.add_argument("--laws", default="hysteretic,velocity")
    ap.add_argument("--duration", type=float, default=20.0)
    ap.add_argument(
        "--refinement",
        default="step",
        choices=["step", "nested", "implicit"],
        help="frictiondyn's refinement of a dt1 step with a phase change (docs/theory.md section 6)",
    )
    ap.add_argument("--memory-size", type=int, default=1000)
    ap.add_argument("--setup", type=int, default=100000,
                    help="DOFs of the set-up case (unconnected masses and a chain); 0: skip it")
    ap.add_argument("--exe", default=None, help="the executable of the set-up case (default: the package's)")
    ap.add_argument("--no-extras", action="store_true", help="only the scaling")
    ap.add_argument("--out", type=Path, default=ROOT / "out" / "bench")
    ap.add_argument("--child", action="store_true", help=argparse.SUPPRESS)
    ap.add_argument("--deck", help=argparse.SUPPRESS)
    ap.add_argument("--n", type=int, help=argparse.SUPPRESS)
    args = ap.parse_args(argv)
    if args.child:
        return child(args)
    args.sizes = [int(x) for x in args.sizes.split(",") if x]
    args.laws = [x for x in args.laws.split(",") if x]
    meta = {"command": " ".join([Path(sys.executable).name, *sys.argv]), "cores": os.cpu_count(),
            "load_start": os.getloadavg()}
    result: dict = {"meta": meta}
    with tempfile.TemporaryDirectory(prefix="fd_scale_") as tmp:
        work = Path(tmp)
        result["scaling"] = scaling(args, work)
        if args.setup:
            from frictiondyn import executable

            result["setup"] = setup_time(work, args.setup, args.exe or str(executable()))
        if not args.no_extras:
            result["memory_vs_duration"] = memory_vs_duration(args, work)
            result["deck_reading"] = deck_reading(work, max(args.sizes))
            result["threads"] = threads(work, 100)
            result["interrupt"] = interrupt(work, 1000, 10)
    meta["load_end"] = os.getloadavg()
    for law, r in result["scaling"].items():
        print(f"{law}: cost (CPU) per dt1 step ~ N^p, p = "
              + ", ".join(f"{k}: {v:.2f}" for k, v in r["exponent_per_dt1_step"].items()))
        print(f"{law}: cost (CPU) per Newmark step ~ N^p, p = "
              + ", ".join(f"{k}: {v:.2f}" for k, v in r["exponent_per_newmark_step"].items()))
        print(f"{law}: memory above the interpreter's ~ N^p, p = "
              + ", ".join(f"{k}: {v:.2f}" for k, v in r["exponent_memory_above_start"].items()))
    args.out.mkdir(parents=True, exist_ok=True)
    path = args.out / "scale.json"
    path.write_text(json.dumps(result, indent=1))
    print(f"json: {path}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
