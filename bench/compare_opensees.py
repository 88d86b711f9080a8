"""frictiondyn against OpenSeesPy, side by side in one process, on the same models.

    .venv/bin/python bench/compare_opensees.py            # the full comparison (about 20 min)
    .venv/bin/python bench/compare_opensees.py --quick    # a smoke version (under a minute)

Installs what it needs beyond the tests: openseespy from PyPI into the running environment
(and, from a fresh clone, sets frictiondyn up with tools/setup.sh first). Cases
(bench/opensees_models.py):

- the paper's test 4 (inputs/test4_<law>.nml, 10 s, dt = dt_r / 20): frictiondyn's hysteretic
  law against an OpenSees ElasticPP zeroLength link, its velocity law against OpenSees's
  CoulombDamper material;
- a shear building of N storeys with a friction damper in every storey (hysteretic law =
  ElasticPP link) under 20 s of a synthetic ground acceleration, N = 2 ... 10000 (--sizes).
  (The velocity law's building is measured by bench/scale.py, frictiondyn alone: against
  OpenSees's CoulombDamper links its absolute accelerations differ by up to 40 %, the two
  codes resolving the stiff damping of the sticking band differently.)

frictiondyn keeps in its history the roof's DOF and the first device only (its summary has
every DOF's and device's peaks), as OpenSees keeps envelopes only. Its cost is given per
dt1 step (what OpenSees takes) and per Newmark step taken (dt1, dt2 and finer steps: the
paper's step control redoes a dt1 step in which a device changes phase as n2 dt2 steps).

For each case, first each code runs once in a subprocess of its own (its peak resident memory
is measured there, VmHWM); both codes' peaks (|u| and |absolute acceleration| of every DOF,
|deformation| and |force| of every device) must agree within --peak-tol (3 %), or no speed is
reported for the case and the exit status is 1. Then, in this process, each code runs
--repeats times (after one warm-up), interleaved, and every timed run's peaks are checked
against the other code's again. Model build is not timed: OpenSees's analyze() is timed apart
from the commands that build the model; frictiondyn's cost per step is (run of the deck - run
of the same deck over one record interval) / (difference in steps), so that reading and
checking the deck is left out (its end-to-end time is reported too). A code whose runs would
not fit in --budget seconds for a case is run once (or not at all, when a single run is
predicted from the smaller cases to exceed the budget), and the table says so.

Writes <out>/compare_opensees.json and <out>/compare_opensees.png (log-log cost per step and
peak memory against N). Nothing is asserted here about speed: it is measured.
"""

from __future__ import annotations

import argparse
import json
import math
import os
import platform
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

# numpy's bundled OpenBLAS starts one busy-waiting thread per core after its first call (the
# building case's record is made with numpy): on a 2-core machine they took a core from
# whichever code was timed next. Neither code uses that BLAS; one thread is enough.
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
os.environ.setdefault("OMP_NUM_THREADS", "1")

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent
VENV = ROOT / ".venv"
SIZES = [2, 10, 30, 100, 300, 1000, 3000, 10000]
QUICK_SIZES = [2, 10, 30]
CHILD_TAG = "@@child-result@@ "
CHILD_OVERHEAD_S = 30.0  # allowed beyond the budget to a single-run process (start, imports, build)


# ----------------------------------------------------------------------------- environment


def ensure_frictiondyn() -> None:
    """frictiondyn importable here, or set up (tools/setup.sh) and re-run in the project's .venv."""
    try:
        import frictiondyn  # noqa: F401

        return
    except ImportError:
        pass
    venv_python = VENV / "bin" / "python"
    in_venv = Path(sys.prefix).resolve() == VENV.resolve()
    if in_venv or not venv_python.exists():
        if os.environ.get("FD_BENCH_REEXEC") == "setup":
            sys.exit("compare_opensees: frictiondyn is still not importable after tools/setup.sh")
        print(
            "compare_opensees: frictiondyn is not installed; running tools/setup.sh",
            flush=True,
        )
        subprocess.run(["bash", str(ROOT / "tools" / "setup.sh")], check=True)
        os.environ["FD_BENCH_REEXEC"] = "setup"
    else:
        os.environ["FD_BENCH_REEXEC"] = "venv"
    os.execv(
        str(venv_python),
        [str(venv_python), str(Path(__file__).resolve()), *sys.argv[1:]],
    )


def ensure_openseespy(install: bool) -> str:
    """Import openseespy, installing it from PyPI into this environment when missing."""
    try:
        import openseespy.opensees
    except ImportError:
        if not install:
            sys.exit("compare_opensees: openseespy is not installed (and --no-install was given)")
        print(
            f"compare_opensees: installing openseespy from PyPI into {sys.prefix}",
            flush=True,
        )
        subprocess.run([sys.executable, "-m", "pip", "install", "-q", "openseespy"], check=True)
        import openseespy.opensees  # noqa: F401
    from importlib.metadata import version

    return version("openseespy")


def _proc_status(key: str) -> float:
    """A memory figure of this process from /proc/self/status, in MB (VmRSS, VmHWM)."""
    with open("/proc/self/status") as fh:
        for line in fh:
            if line.startswith(key + ":"):
                return int(line.split()[1]) / 1024.0
    return float("nan")


def machine() -> dict:
    info = {
        "python": platform.python_version(),
        "platform": platform.platform(),
        "cores": os.cpu_count(),
    }
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                info["cpu"] = line.split(":", 1)[1].strip()
                break
        for line in Path("/proc/meminfo").read_text().splitlines():
            if line.startswith("MemTotal"):
                info["memory_gib"] = round(int(line.split()[1]) / 1024**2, 1)
        for line in Path("/etc/os-release").read_text().splitlines():
            if line.startswith("PRETTY_NAME="):
                info["os"] = line.split("=", 1)[1].strip('"')
    except OSError:
        pass
    try:
        info["gfortran"] = subprocess.run(
            ["gfortran", "--version"], check=False, capture_output=True, text=True
        ).stdout.splitlines()[0]
    except (OSError, IndexError):
        pass
    try:
        info["git_commit"] = subprocess.run(
            ["git", "-C", str(ROOT), "rev-parse", "--short", "HEAD"],
            check=False,
            capture_output=True,
            text=True,
        ).stdout.strip()
    except OSError:
        pass
    try:
        from frictiondyn import _core

        libs = subprocess.run(
            ["ldd", _core.__file__], check=False, capture_output=True, text=True
        ).stdout
        info["frictiondyn_lapack"] = sorted(
            {ln.split()[0] for ln in libs.splitlines() if "lapack" in ln or "blas" in ln}
        )
    except (ImportError, OSError):
        pass
    return info


# ----------------------------------------------------------------------------- child runs


def child_main(args) -> int:
    """One run of one code on one case, in a process of its own: peaks, time, memory."""
    sys.path.insert(0, str(HERE))
    import opensees_models as om

    out: dict = {}
    if args.child == "fd":
        import frictiondyn as fd

        case = om.make_case(args.case, args.quick)
        rss0 = _proc_status("VmRSS")
        t0, c0 = time.perf_counter(), time.process_time()
        res = fd.run(args.deck, **fd_keep(case))
        out["seconds"] = time.perf_counter() - t0
        out["cpu_seconds"] = time.process_time() - c0
        out["peaks"] = {q: v.tolist() for q, v in om.frictiondyn_peaks(res).items()}
        s = res.summary
        out["stats"] = {
            k: s[k]
            for k in (
                "steps_dt1",
                "steps_nested",
                "steps_implicit",
                "implicit_redos",
                "implicit_fallbacks",
                "steps_dt2",
                "steps_finer",
                "factorizations",
                "factor_updates",
                "partial_factorizations",
                "linear_system",
                "half_bandwidth",
                "period_stuck_s",
            )
            if k in s
        }
        if "stick_to_slip" in s:
            out["stats"]["stick_to_slip"] = int(sum(s["stick_to_slip"]))
        if "correctness_violations" in s:
            out["stats"]["correctness_violations"] = s["correctness_violations"]
        out["history_mb"] = res.data.nbytes / 1e6
    else:
        om.import_opensees()
        case = om.make_case(args.case, args.quick)
        settings = om.OpenSeesSettings(**json.loads(args.ops_settings))
        rss0 = _proc_status("VmRSS")
        run = om.run_opensees(case, settings)
        out["seconds"] = run.seconds
        out["cpu_seconds"] = run.cpu_seconds
        out["build_seconds"] = run.build_seconds
        out["peaks"] = {q: v.tolist() for q, v in run.peaks.items()}
    out["rss_before_mb"] = rss0
    out["rss_peak_mb"] = _proc_status("VmHWM")
    print(CHILD_TAG + json.dumps(out), flush=True)
    return 0


def fd_keep(case) -> dict:
    """What frictiondyn keeps in its history: every column for test 4, the roof DOF and the
    first device for a building (its summary has every peak; OpenSees keeps envelopes)."""
    if getattr(case, "n_storeys", None) is None:
        return {}
    return {"dofs": [case.n_dof], "devices": [1]}


def newmark_steps(stats: dict) -> int | None:
    """Newmark steps a frictiondyn run solved (frictiondyn.newmark_steps); None for a run
    without step counts."""
    if "steps_dt1" not in stats:
        return None
    from frictiondyn import newmark_steps as steps

    return steps(stats)


def run_child(code: str, spec: str, args, deck: Path | None, timeout: float) -> dict:
    cmd = [
        sys.executable,
        str(Path(__file__).resolve()),
        "--child",
        code,
        "--case",
        spec,
        "--ops-settings",
        args.ops_settings,
    ]
    if deck is not None:
        cmd += ["--deck", str(deck)]
    if args.quick:
        cmd.append("--quick")
    try:
        p = subprocess.run(cmd, check=False, capture_output=True, text=True, timeout=timeout)
    except subprocess.TimeoutExpired:
        return {
            "error": f"a single run did not end within {timeout:.0f} s (stopped)",
            "timed_out": True,
        }
    for line in p.stdout.splitlines():
        if line.startswith(CHILD_TAG):
            return json.loads(line[len(CHILD_TAG) :])
    tail = (p.stderr or p.stdout).strip().splitlines()[-5:]
    return {"error": f"exit status {p.returncode}: " + " | ".join(tail)}


# ----------------------------------------------------------------------------- one case


def _worst(diff: dict) -> tuple[float, str]:
    q = max(diff, key=lambda k: diff[k][0])
    return diff[q][0], q


def _predict(history: list[tuple[int, float]], n: int) -> float | None:
    """A single run's time at size n from the last two measured sizes (power law, exponent
    clamped to [1, 3]; 1 when only one size is known: optimistic, the run's time limit guards)."""
    if not history:
        return None
    (n1, t1) = history[-1]
    p = 1.0
    if len(history) >= 2:
        (n0, t0) = history[-2]
        if t0 > 0 and n1 != n0:
            p = min(3.0, max(1.0, math.log(t1 / t0) / math.log(n1 / n0)))
    return t1 * (n / n1) ** p


def run_case(spec: str, args, history: dict, om, fd) -> dict:
    case = om.make_case(spec, args.quick)
    kind = spec.split(":")[0]
    n_size = case.n_dof if kind.startswith("building") else None
    history = history.setdefault(kind, {"fd": [], "ops": []})  # predictions per kind of case
    rec: dict = {
        "case": spec,
        "name": case.name,
        "n_dof": case.n_dof,
        "steps": case.n_steps,
        "dt_s": case.dt,
        "duration_s": case.duration,
        "notes": [],
    }
    if kind.startswith("test4"):
        rec["opensees_material"] = case.opensees_material
        rec["law"] = case.law
        rec["refinement"] = case.refinement
    else:
        rec["law"] = case.law
        rec["refinement"] = case.refinement
        rec["opensees_material"] = case.opensees_material
    print(
        f"\n== {case.name}: {case.n_dof} DOFs, {case.n_steps} steps of {case.dt * 1e3:g} ms",
        flush=True,
    )
    tmp = tempfile.TemporaryDirectory(prefix="fd_bench_")
    work = Path(tmp.name)
    full_an, short_an = case.analysis(), case.short_analysis()
    deck = full_an.write_deck(work / f"{case.name}.nml")
    (work / "short").mkdir()
    deck_short = short_an.write_deck(work / "short" / f"{case.name}_short.nml")
    short_steps = round(case.dt_record / case.dt)

    # 1. one run of each code in its own process: peaks, single-run time, peak memory
    child = {}
    for code, label in (("fd", "frictiondyn"), ("ops", "OpenSees")):
        pred = _predict(history[code], n_size) if n_size else None
        if pred is not None and pred > args.budget:
            note = (
                f"{label} not run: a single run is predicted to take {pred:.3g} s "
                f"(from the smaller buildings) > budget {args.budget:g} s"
            )
            rec["notes"].append(note)
            print("   " + note, flush=True)
            child[code] = {
                "error": "skipped (predicted beyond budget)",
                "predicted_s": pred,
            }
            continue
        # the budget is for the run; the process also starts Python and builds the model
        limit = args.budget + CHILD_OVERHEAD_S
        child[code] = run_child(code, spec, args, deck if code == "fd" else None, limit)
        c = child[code]
        if c.get("timed_out") and n_size:
            history[code].append((n_size, limit))  # a lower bound: larger N are not tried
        if "error" in c:
            note = f"{label}: {c['error']}"
            rec["notes"].append(note)
            print("   " + note, flush=True)
        else:
            if n_size:
                history[code].append((n_size, c["seconds"]))
            print(
                f"   {label:<12} single run {c['seconds']:9.3f} s, peak RSS "
                f"{c['rss_peak_mb']:7.1f} MB",
                flush=True,
            )
    rec["single_run"] = child
    ok_fd, ok_ops = "error" not in child["fd"], "error" not in child["ops"]

    # 2. the same answer, or no speed
    ref = {}
    if ok_fd and ok_ops:
        import numpy as np

        ref["fd"] = {q: np.array(v) for q, v in child["fd"]["peaks"].items()}
        ref["ops"] = {q: np.array(v) for q, v in child["ops"]["peaks"].items()}
        diff = om.compare_peaks(ref["fd"], ref["ops"])
        rec["peak_difference"] = {q: {"max_rel": d, "at": i + 1} for q, (d, i) in diff.items()}
        worst, q = _worst(diff)
        rec["peaks_agree"] = worst <= args.peak_tol
        print(
            f"   peaks: largest difference {100 * worst:.3f} % (peak |{q}| of "
            f"{'DOF' if q in ('u', 'aabs') else 'device'} {diff[q][1] + 1}); "
            + ("agree" if rec["peaks_agree"] else f"DISAGREE (> {100 * args.peak_tol:g} %)"),
            flush=True,
        )
        if not rec["peaks_agree"]:
            rec["notes"].append("peaks disagree: no speed reported")
            tmp.cleanup()
            return rec
    else:
        rec["peaks_agree"] = None
        rec["notes"].append("peaks not cross-checked (one code did not run)")

    # 3. timed runs, interleaved, in this process
    timed = []
    if ok_fd and child["fd"]["seconds"] * (args.repeats + 1) <= args.budget:
        timed.append("fd")
    if ok_ops and child["ops"]["seconds"] * (args.repeats + 1) <= args.budget:
        timed.append("ops")
    for code, label in (("fd", "frictiondyn"), ("ops", "OpenSees")):
        if code not in timed and "error" not in child[code]:
            note = (
                f"{label}: {args.repeats + 1} runs would exceed the budget of "
                f"{args.budget:g} s; its figure is the single run"
            )
            rec["notes"].append(note)
            print("   " + note, flush=True)
    variants = []
    if "fd" in timed:
        variants += ["fd", "fd_short"] + (["fd_e2e"] if kind.startswith("test4") else [])
    if "ops" in timed:
        variants.append("ops")
    times: dict[str, list[float]] = {v: [] for v in variants}
    cpu_times: dict[str, list[float]] = {v: [] for v in variants}
    ops_build: list[float] = []
    settings = om.OpenSeesSettings(**json.loads(args.ops_settings))
    worst_timed = 0.0

    def one(v: str, keep: bool) -> None:
        nonlocal worst_timed
        peaks = None
        if v.startswith("fd"):
            w0, c0 = time.perf_counter(), time.process_time()
            if v == "fd":
                peaks = om.frictiondyn_peaks(fd.run(deck, **fd_keep(case)))
            elif v == "fd_short":
                fd.run(deck_short, **fd_keep(case))
            else:
                peaks = om.frictiondyn_peaks(full_an.run())
            wall, cpu = time.perf_counter() - w0, time.process_time() - c0
        else:
            r = om.run_opensees(case, settings)
            wall, cpu, peaks = r.seconds, r.cpu_seconds, r.peaks
            if keep:
                ops_build.append(r.build_seconds)
        if peaks is not None and ref:
            other = ref["ops"] if v.startswith("fd") else ref["fd"]
            w, q = _worst(om.compare_peaks(peaks, other))
            worst_timed = max(worst_timed, w)
            if w > args.peak_tol:
                raise RuntimeError(
                    f"{case.name}: a timed {v} run's peak |{q}| differs by "
                    f"{100 * w:.2f} % from the other code's"
                )
        if keep:
            times[v].append(wall)
            cpu_times[v].append(cpu)

    for v in variants:  # warm-up
        one(v, keep=False)
    for rep in range(args.repeats):
        for v in variants if rep % 2 == 0 else variants[::-1]:
            one(v, keep=True)
    tmp.cleanup()

    # 4. figures: wall-clock medians (what a user waits), and CPU-time medians (this process's
    # CPU seconds: on a machine shared with other work, the better estimate of an idle one)
    n = case.n_steps
    res: dict = {
        "repeats": args.repeats if timed else 0,
        "timed_codes": timed,
        "timed_peak_difference_max": worst_timed if timed else None,
    }
    med = {v: statistics.median(t) for v, t in times.items()}
    cmed = {v: statistics.median(t) for v, t in cpu_times.items()}
    if "fd" in timed:
        res["fd_run_s"] = med["fd"]
        res["fd_run_s_range"] = [min(times["fd"]), max(times["fd"])]
        res["fd_setup_s"] = med["fd_short"]
        res["fd_us_per_step"] = 1e6 * (med["fd"] - med["fd_short"]) / (n - short_steps)
        res["fd_cpu_us_per_step"] = 1e6 * (cmed["fd"] - cmed["fd_short"]) / (n - short_steps)
        res["fd_end_to_end_us_per_step"] = 1e6 * med["fd"] / n
        if "fd_e2e" in times:
            res["fd_analysis_run_s"] = med["fd_e2e"]
            res["fd_analysis_run_cpu_s"] = cmed["fd_e2e"]
        res["fd_runs"] = len(times["fd"])
    elif ok_fd:
        res["fd_run_s"] = child["fd"]["seconds"]
        res["fd_us_per_step"] = 1e6 * child["fd"]["seconds"] / n
        res["fd_cpu_us_per_step"] = 1e6 * child["fd"]["cpu_seconds"] / n
        res["fd_end_to_end_us_per_step"] = res["fd_us_per_step"]
        res["fd_runs"] = 1
    if "ops" in timed:
        res["ops_analyze_s"] = med["ops"]
        res["ops_analyze_s_range"] = [min(times["ops"]), max(times["ops"])]
        res["ops_build_s"] = statistics.median(ops_build)
        res["ops_us_per_step"] = 1e6 * med["ops"] / n
        res["ops_cpu_us_per_step"] = 1e6 * cmed["ops"] / n
        res["ops_runs"] = len(times["ops"])
    elif ok_ops:
        res["ops_analyze_s"] = child["ops"]["seconds"]
        res["ops_build_s"] = child["ops"]["build_seconds"]
        res["ops_us_per_step"] = 1e6 * child["ops"]["seconds"] / n
        res["ops_cpu_us_per_step"] = 1e6 * child["ops"]["cpu_seconds"] / n
        res["ops_runs"] = 1
    if "fd_us_per_step" in res and "ops_us_per_step" in res and rec["peaks_agree"]:
        res["ratio"] = res["ops_us_per_step"] / res["fd_us_per_step"]
        res["ratio_cpu"] = res["ops_cpu_us_per_step"] / res["fd_cpu_us_per_step"]
        if "fd_analysis_run_s" in res:
            res["ratio_end_to_end"] = (res["ops_analyze_s"] + res["ops_build_s"]) / res[
                "fd_analysis_run_s"
            ]
    # frictiondyn per Newmark step taken (its dt2 re-integrations included): the unit of work
    # that is O(N) in the structure, against OpenSees's per dt1 step
    nm = newmark_steps(child["fd"].get("stats", {})) if ok_fd else None
    if nm and "fd_us_per_step" in res:
        res["fd_newmark_steps"] = nm
        res["fd_us_per_newmark_step"] = res["fd_us_per_step"] * n / nm
        res["fd_cpu_us_per_newmark_step"] = res["fd_cpu_us_per_step"] * n / nm
    for code in ("fd", "ops"):
        if ok_fd if code == "fd" else ok_ops:
            res[f"{code}_rss_peak_mb"] = child[code]["rss_peak_mb"]
            res[f"{code}_rss_before_mb"] = child[code]["rss_before_mb"]
    rec.update(res)
    parts = []
    if "fd_us_per_step" in res:
        parts.append(f"frictiondyn {res['fd_us_per_step']:.2f} us/step ({_runs(res['fd_runs'])})")
    if "ops_us_per_step" in res:
        parts.append(f"OpenSees {res['ops_us_per_step']:.2f} us/step ({_runs(res['ops_runs'])})")
    if "ratio" in res:
        parts.append(f"ratio {res['ratio']:.2f}")
    print(f"   {case.name}: " + ", ".join(parts), flush=True)
    return rec


def _runs(n: int) -> str:
    return "1 run" if n == 1 else f"{n} runs"


# ----------------------------------------------------------------------------- report


def _fmt(x, spec=".2f", none="n/a") -> str:
    return none if x is None else format(x, spec)


def _ratio_text(r: dict, key: str = "ratio") -> str:
    x = r.get(key)
    if x is None:
        return "n/a"
    return f"{x:.1f}x faster" if x >= 1 else f"{1 / x:.1f}x slower"


def _us(r: dict, code: str, spec: str) -> str:
    """'wall (CPU)' microseconds per step of one code, marked when a single run."""
    return (
        f"{_fmt(r.get(f'{code}_us_per_step'), spec)} ({_fmt(r.get(f'{code}_cpu_us_per_step'), spec)})"
        f"{_mark(r, code)}"
    )


def _mark(r: dict, code: str) -> str:
    return "" if r.get(f"{code}_runs", 0) != 1 else " (1 run)"


def tables(results: list[dict], peak_tol: float) -> str:
    out = []
    t4 = [r for r in results if r["case"].startswith("test4")]
    if t4:
        out.append("Paper's test 4 (2 DOFs, 1 device), frictiondyn against OpenSeesPy:\n")
        out.append(
            "| frictiondyn law | OpenSees material | steps | frictiondyn us/step wall (CPU) | "
            "OpenSees us/step wall (CPU) | frictiondyn is, wall (CPU) | "
            "frictiondyn Analysis.run() s | OpenSees build + analyze s | end to end | "
            "peaks differ by |"
        )
        out.append("|---|---|---|---|---|---|---|---|---|---|")
        for r in t4:
            e2e = r.get("ratio_end_to_end")
            ops_e2e = (r["ops_analyze_s"] + r["ops_build_s"]) if "ops_analyze_s" in r else None
            law = r["law"] if r.get("refinement", "step") == "step" else f"{r['law']} ({r['refinement']})"
            out.append(
                f"| {law} | {r['opensees_material']} | {r['steps']} | "
                f"{_us(r, 'fd', '.2f')} | {_us(r, 'ops', '.2f')} | "
                f"{_ratio_text(r)} ({_ratio_text(r, 'ratio_cpu')}) | "
                f"{_fmt(r.get('fd_analysis_run_s'), '.4f')} | {_fmt(ops_e2e, '.4f')} | "
                f"{_fmt(e2e, '.1f')}x | {_peak_text(r)} |"
            )
    for law, material, refinement in (
        ("hysteretic", "ElasticPP", "step"),
        ("hysteretic", "ElasticPP", "nested"),
        ("hysteretic", "ElasticPP", "implicit"),
        ("velocity", "CoulombDamper", "step"),
    ):
        b = [
            r
            for r in results
            if r["case"].startswith("building")
            and r.get("law", "hysteretic") == law
            and r.get("refinement", "step") == refinement
        ]
        if not b:
            continue
        out.append(
            f"\nShear building, a friction damper ({law} law = {material} link) in every "
            f"storey; frictiondyn's refinement '{refinement}':\n"
        )
        out.append(
            "| storeys N | steps | frictiondyn us/step wall (CPU) | OpenSees us/step wall (CPU) | "
            "frictiondyn is, wall (CPU) | frictiondyn Newmark steps, us each (CPU) | "
            "peaks differ by | frictiondyn peak RSS MB | OpenSees peak RSS MB | "
            "frictiondyn steps dt1 + nested + dt2, transitions |"
        )
        out.append("|---|---|---|---|---|---|---|---|---|---|")
        for r in b:
            st = r["single_run"]["fd"].get("stats", {})
            steps = (
                f"{st['steps_dt1']} + {st.get('steps_nested', 0)} + {st['steps_dt2']}, "
                f"{st.get('stick_to_slip', '?')}"
                if "steps_dt1" in st
                else "n/a"
            )
            nm = (
                f"{r['fd_newmark_steps']}, {r['fd_us_per_newmark_step']:.2f} "
                f"({r['fd_cpu_us_per_newmark_step']:.2f})"
                if "fd_newmark_steps" in r
                else "n/a"
            )
            out.append(
                f"| {r['n_dof']} | {r['steps']} | {_us(r, 'fd', '.1f')} | {_us(r, 'ops', '.1f')} | "
                f"{_ratio_text(r)} ({_ratio_text(r, 'ratio_cpu')}) | {nm} | {_peak_text(r)} | "
                f"{_fmt(r.get('fd_rss_peak_mb'), '.0f')} | "
                f"{_fmt(r.get('ops_rss_peak_mb'), '.0f')} | {steps} |"
            )
        out.append("\n" + growth_text(b))
    notes = [f"- {r['name']}: {n}" for r in results for n in r["notes"]]
    if notes:
        out.append("\nNotes:\n" + "\n".join(notes))
    return "\n".join(out)


def growth_text(b: list[dict]) -> str:
    """Exponents p of cost ~ N^p between successive sizes and over the whole range, per dt1
    step and per Newmark step (CPU time: the better figure on a shared machine)."""
    lines = []
    for key, label in (
        ("fd_cpu_us_per_step", "frictiondyn per dt1 step"),
        ("fd_cpu_us_per_newmark_step", "frictiondyn per Newmark step"),
        ("ops_cpu_us_per_step", "OpenSees per step"),
    ):
        pts = [(r["n_dof"], r[key]) for r in b if r.get(key)]
        pts = [(n, y) for n, y in pts if n >= 10]
        if len(pts) < 2:
            continue
        parts = [
            f"{n0}-{n1}: {math.log(y1 / y0) / math.log(n1 / n0):.2f}"
            for (n0, y0), (n1, y1) in zip(pts, pts[1:])
        ]
        (n0, y0), (n1, y1) = pts[0], pts[-1]
        whole = math.log(y1 / y0) / math.log(n1 / n0)
        lines.append(f"- {label}: N^p with p = {', '.join(parts)}; {n0}-{n1}: {whole:.2f}")
    return "Growth of the cost (CPU) with N:\n" + "\n".join(lines) if lines else ""


def _peak_text(r: dict) -> str:
    if r.get("peaks_agree") is None:
        return "not checked"
    w, q = _worst({k: (v["max_rel"], v["at"]) for k, v in r["peak_difference"].items()})
    return f"{100 * w:.2f} % (\\|{q}\\|)" + ("" if r["peaks_agree"] else " DISAGREE")


def plot(results: list[dict], path: Path, meta: dict) -> None:
    from matplotlib.figure import Figure

    b = [
        r
        for r in results
        if r["case"].startswith("building")
        and r.get("law", "hysteretic") == "hysteretic"
        and r.get("refinement", "step") == "step"
    ]
    if not b:
        return
    fig = Figure(figsize=(11, 4.6))
    ax1, ax2 = fig.subplots(1, 2)
    styles = {
        "fd": ("frictiondyn (hysteretic law)", "C0", "o"),
        "ops": ("OpenSeesPy (ElasticPP links)", "C3", "s"),
    }
    nm = [(r["n_dof"], r["fd_cpu_us_per_newmark_step"]) for r in b if "fd_cpu_us_per_newmark_step" in r]
    if nm:
        xs, ys = zip(*nm)
        ax1.plot(xs, ys, "-.", color="C2", marker="^", ms=6, lw=1.1,
                 label="frictiondyn per Newmark step (dt1, dt2 or finer), CPU")
    bv = [r for r in results if r["case"].startswith("building_velocity")]
    for code, color in (("fd", "C0"), ("ops", "C3")):
        pts = [(r["n_dof"], r[f"{code}_cpu_us_per_step"]) for r in bv if r.get(f"{code}_cpu_us_per_step")]
        if pts:
            xs, ys = zip(*pts)
            ax1.plot(xs, ys, ":", color=color, marker="v", ms=5, lw=1,
                     label=("frictiondyn velocity law" if code == "fd" else "OpenSeesPy CoulombDamper")
                     + ", CPU")
    for code, (label, color, marker) in styles.items():
        pts = [
            (r["n_dof"], r[f"{code}_us_per_step"], r.get(f"{code}_runs", 0))
            for r in b
            if f"{code}_us_per_step" in r
        ]
        cpts = [
            (r["n_dof"], r[f"{code}_cpu_us_per_step"])
            for r in b
            if r.get(f"{code}_cpu_us_per_step") is not None
        ]
        if cpts:
            xs, ys = zip(*cpts)
            ax1.plot(
                xs,
                ys,
                "--",
                color=color,
                lw=0.9,
                alpha=0.7,
                label=label.split(" (")[0] + ", CPU time",
            )
        if pts:
            xs, ys, _ = zip(*pts)
            ax1.plot(xs, ys, "-", color=color, lw=1.2, label=label + ", wall")
            for x, y, n in pts:
                ax1.plot(x, y, marker, color=color, ms=7, mfc=color if n > 1 else "white")
        mem = [
            (r["n_dof"], r[f"{code}_rss_peak_mb"], r[f"{code}_rss_before_mb"])
            for r in b
            if f"{code}_rss_peak_mb" in r
        ]
        if mem:
            xs, ys, y0 = zip(*mem)
            ax2.plot(
                xs,
                ys,
                "-" + marker,
                color=color,
                ms=6,
                label=label.split(" (")[0] + ": peak",
            )
            ax2.plot(
                xs,
                y0,
                ":",
                color=color,
                lw=1,
                label=label.split(" (")[0] + ": before the run (imports, model)",
            )
    ns = sorted({r["n_dof"] for r in b})
    lows = [
        min(r[f"{c}_us_per_step"] for c in ("fd", "ops") if f"{c}_us_per_step" in r)
        for r in b
        if r["n_dof"] == ns[0] and ("fd_us_per_step" in r or "ops_us_per_step" in r)
    ]
    if lows and len(ns) > 1:
        y0, x = lows[0] / 2, [ns[0], ns[-1]]
        ax1.plot(x, [y0 * v / ns[0] for v in x], ":", color="grey", lw=1, label="∝ N (guide)")
        ax1.plot(
            x,
            [y0 * (v / ns[0]) ** 2 for v in x],
            "--",
            color="grey",
            lw=1,
            label="∝ N² (guide)",
        )
    skipped = [r["n_dof"] for r in b if "fd_us_per_step" not in r]
    title = f"cost per step (median of {meta['repeats']} interleaved runs)"
    if skipped:
        title += "\nfrictiondyn not run at N = " + ", ".join(map(str, skipped)) + " (time budget)"
    ax1.set(
        xscale="log",
        yscale="log",
        xlabel="storeys N (DOFs)",
        ylabel="wall time per step [µs]",
        title=title,
    )
    ax1.grid(True, which="both", alpha=0.3)
    if ax1.get_legend_handles_labels()[0]:
        ax1.legend(fontsize=8, loc="upper left")
    ax1.text(
        0.98,
        0.02,
        "open marker: a single run (over budget)",
        transform=ax1.transAxes,
        ha="right",
        va="bottom",
        fontsize=7,
        color="grey",
    )
    ax2.set(
        xscale="log",
        xlabel="storeys N (DOFs)",
        ylabel="resident memory [MB]",
        title="peak RSS (VmHWM) of a process running one case",
    )
    from matplotlib.ticker import NullFormatter, ScalarFormatter

    for ax in (ax1, ax2):
        ax.set_xticks(ns)
        ax.xaxis.set_major_formatter(ScalarFormatter())
        ax.xaxis.set_minor_formatter(NullFormatter())
    ax2.set_ylim(bottom=0)
    ax2.grid(True, which="both", alpha=0.3)
    if ax2.get_legend_handles_labels()[0]:
        ax2.legend(fontsize=7, loc="best")
    m = meta["machine"]
    fig.suptitle(
        f"frictiondyn {meta['frictiondyn']} ({m.get('git_commit', '?')}) vs OpenSeesPy "
        f"{meta['openseespy']}: shear building with a friction damper per storey, "
        f"{b[0]['duration_s']:g} s at dt = {b[0]['dt_s'] * 1e3:g} ms\n{m.get('cpu', '')}, "
        f"{m.get('cores')} cores; OpenSees: {meta['opensees_settings_text']}",
        fontsize=8,
    )
    fig.tight_layout()
    fig.savefig(path, dpi=110)


# ----------------------------------------------------------------------------- solver study

STUDY_ALGORITHMS = ("Newton", "KrylovNewton", "ModifiedNewton")
STUDY_SYSTEMS = ("BandGeneral", "BandSPD", "ProfileSPD", "UmfPack")


def ops_study(args, om) -> int:
    """OpenSees's solver settings against each other (median of --repeats interleaved runs):
    the evidence for the settings the comparison uses."""
    specs = [] if args.no_test4 else ["test4:hysteretic", "test4:velocity"]
    specs += [f"building:{n}" for n in args.sizes]
    configs = [(a, s) for a in STUDY_ALGORITHMS for s in STUDY_SYSTEMS]
    base = json.loads(args.ops_settings)
    out = {
        "repeats": args.repeats,
        "configs": [f"{a} + {s}" for a, s in configs],
        "cases": {},
    }
    print(
        f"OpenSees solver settings, us/step, median of {args.repeats} interleaved runs "
        f"(numberer {base['numberer']}, NormDispIncr {base['tol']:g})",
        flush=True,
    )
    status = 0
    for spec in specs:
        case = om.make_case(spec, args.quick)
        ref = om.frictiondyn_peaks(case.analysis().run())
        times = {c: [] for c in configs}
        worst = 0.0
        for rep in range(args.repeats):
            for a, s in configs if rep % 2 == 0 else configs[::-1]:
                settings = om.OpenSeesSettings(**{**base, "algorithm": a, "system": s})
                try:
                    r = om.run_opensees(case, settings)
                except RuntimeError:
                    times[(a, s)].append(float("nan"))
                    continue
                w, _ = _worst(om.compare_peaks(ref, r.peaks))
                worst = max(worst, w)
                times[(a, s)].append(1e6 * r.seconds / case.n_steps)
        med = {f"{a} + {s}": statistics.median(v) for (a, s), v in times.items()}
        out["cases"][case.name] = {"us_per_step": med, "peak_difference_max": worst}
        print(
            f"   {case.name}: done, peaks within {100 * worst:.2f} % of frictiondyn's",
            flush=True,
        )
        if worst > args.peak_tol:
            status = 1
    names = list(out["cases"])
    print("\n| algorithm + system | " + " | ".join(names) + " |")
    print("|---|" + "---|" * len(names))
    for c in out["configs"]:
        cells = " | ".join(f"{out['cases'][n]['us_per_step'][c]:.1f}" for n in names)
        print(f"| {c} | {cells} |")
    args.out.mkdir(parents=True, exist_ok=True)
    path = args.out / "compare_opensees_study.json"
    path.write_text(json.dumps(out, indent=1))
    print(f"json: {path}")
    return status


# ----------------------------------------------------------------------------- main


def parse_args(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument(
        "--quick",
        action="store_true",
        help="smoke version: test 4 for 2 s, buildings N = 2, 10, 30 for 5 s, 3 repeats",
    )
    ap.add_argument("--repeats", type=int, default=None, help="timed runs per code (default 7)")
    ap.add_argument(
        "--sizes",
        type=str,
        default=None,
        help="comma-separated storey counts (default 2,10,30,100,300,1000,3000,10000)",
    )
    ap.add_argument("--no-test4", action="store_true", help="skip the paper's test 4")
    ap.add_argument(
        "--nested",
        action="store_true",
        help="also the buildings with frictiondyn's nested refinement (refinement = 'nested')",
    )
    ap.add_argument(
        "--implicit",
        action="store_true",
        help="also test 4 and the buildings with frictiondyn's implicit phases (refinement = 'implicit')",
    )
    ap.add_argument(
        "--no-buildings",
        action="store_true",
        help="only the paper's test 4",
    )
    ap.add_argument(
        "--budget",
        type=float,
        default=None,
        help="seconds allowed per code per case (default 600; quick 20)",
    )
    ap.add_argument(
        "--peak-tol",
        type=float,
        default=0.03,
        help="largest relative difference of peaks between the codes (default 0.03)",
    )
    ap.add_argument(
        "--out",
        type=Path,
        default=None,
        help="directory for the JSON and the plot (default out/bench, quick: out/bench/quick)",
    )
    ap.add_argument("--no-install", action="store_true", help="do not pip install openseespy")
    ap.add_argument(
        "--replot",
        action="store_true",
        help="only print the tables and redraw the plot from <out>/compare_opensees.json",
    )
    ap.add_argument(
        "--ops-study",
        action="store_true",
        help="instead: time OpenSees's solver settings against each other on the cases "
        "(each checked against frictiondyn's peaks) and write compare_opensees_study.json",
    )
    ap.add_argument("--ops-algorithm", default="KrylovNewton")
    ap.add_argument("--ops-system", default="BandGeneral")
    ap.add_argument("--ops-numberer", default="RCM")
    ap.add_argument("--ops-tol", type=float, default=1e-8, help="NormDispIncr tolerance [m]")
    ap.add_argument("--child", choices=["fd", "ops"], help=argparse.SUPPRESS)
    ap.add_argument("--case", help=argparse.SUPPRESS)
    ap.add_argument("--deck", help=argparse.SUPPRESS)
    ap.add_argument("--ops-settings", default=None, help=argparse.SUPPRESS)
    args = ap.parse_args(argv)
    if args.ops_settings is None:
        args.ops_settings = json.dumps(
            {
                "algorithm": args.ops_algorithm,
                "system": args.ops_system,
                "numberer": args.ops_numberer,
                "tol": args.ops_tol,
            }
        )
    if args.repeats is None:
        args.repeats = 3 if args.quick else 7
    if args.budget is None:
        args.budget = 20.0 if args.quick else 600.0
    if args.sizes is None:
        args.sizes = QUICK_SIZES if args.quick else SIZES
    else:
        args.sizes = [int(s) for s in args.sizes.split(",") if s]
    if args.no_buildings:
        args.sizes = []
    if args.out is None:
        args.out = ROOT / "out" / "bench" / ("quick" if args.quick else "")
    return args


def main(argv=None) -> int:
    args = parse_args(argv)
    if args.replot:
        data = json.loads((args.out / "compare_opensees.json").read_text())
        print(tables(data["results"], data["meta"]["peak_tol"]))
        plot(data["results"], args.out / "compare_opensees.png", data["meta"])
        return 0
    ensure_frictiondyn()
    if args.child:  # the frictiondyn child does not load OpenSees (its memory is measured)
        return child_main(args)
    ops_version = ensure_openseespy(not args.no_install)
    sys.path.insert(0, str(HERE))
    import frictiondyn as fd
    import opensees_models as om

    if args.ops_study:
        return ops_study(args, om)
    settings = om.OpenSeesSettings(**json.loads(args.ops_settings))
    meta = {
        "frictiondyn": getattr(fd, "__version__", "?"),
        "openseespy": ops_version,
        "numpy": __import__("numpy").__version__,
        "machine": machine(),
        "command": " ".join([Path(sys.executable).name, *sys.argv]),
        "quick": args.quick,
        "repeats": args.repeats,
        "budget_s": args.budget,
        "peak_tol": args.peak_tol,
        "opensees_settings": json.loads(args.ops_settings),
        "opensees_settings_text": settings.describe(),
        "load_average_start": os.getloadavg(),
    }
    print(
        f"frictiondyn {meta['frictiondyn']} against OpenSeesPy {ops_version} "
        f"({meta['machine'].get('cpu', '?')}, {meta['machine']['cores']} cores)"
    )
    print(f"OpenSees: {settings.describe()}")
    print(
        f"median of {args.repeats} interleaved runs; budget {args.budget:g} s per code per case; "
        f"peaks must agree within {100 * args.peak_tol:g} %"
    )
    specs = [] if args.no_test4 else ["test4:hysteretic", "test4:velocity"]
    specs += [f"building:{n}" for n in args.sizes]
    if args.nested:
        specs += [f"building_nested:{n}" for n in args.sizes]
    if args.implicit:
        if not args.no_test4:
            specs += ["test4_implicit:hysteretic", "test4_implicit:velocity"]
        specs += [f"building_implicit:{n}" for n in args.sizes]
    args.out.mkdir(parents=True, exist_ok=True)
    json_path = args.out / "compare_opensees.json"
    results: list[dict] = []
    history: dict[str, dict] = {}
    t_start = time.perf_counter()
    status = 0
    for spec in specs:
        try:
            rec = run_case(spec, args, history, om, fd)
        except RuntimeError as exc:  # a failed OpenSees analysis, a timed run's different peaks
            print(f"   ERROR {exc}", flush=True)
            rec = {
                "case": spec,
                "name": spec,
                "error": str(exc),
                "notes": [str(exc)],
                "peaks_agree": False,
                "single_run": {"fd": {}, "ops": {}},
                "n_dof": 0,
                "steps": 0,
            }
            status = 1
        if rec.get("peaks_agree") is False:
            status = 1
        results.append(rec)
        meta["load_average_end"] = os.getloadavg()
        meta["wall_time_s"] = time.perf_counter() - t_start
        tmp = json_path.with_name(json_path.name + ".tmp")
        tmp.write_text(json.dumps({"meta": meta, "results": results}, indent=1))
        tmp.replace(json_path)
    print()
    print(tables(results, args.peak_tol))
    png = args.out / "compare_opensees.png"
    plot(results, png, meta)
    print(
        f"\njson: {json_path}\nplot: {png}\n"
        f"wall time {meta['wall_time_s']:.0f} s; load average {meta['load_average_start'][0]:.2f} "
        f"at the start, {meta['load_average_end'][0]:.2f} at the end"
    )
    return status


if __name__ == "__main__":
    sys.exit(main())
