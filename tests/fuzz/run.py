#!/usr/bin/env python3
"""Fuzz campaign: mutated decks and records fed to the executable and to the Python API.

    python tests/fuzz/run.py --count 10000 --seed 1          # the campaign of docs/reliability.md
    python tests/fuzz/run.py --count 300 --seed 7 --jobs 2   # a short one (CI runs one as a test)

Each case (tests/fuzz/mutate.py: a bundled deck or record with 1 to 3 mutations, the same for
the same seed and index) is written twice into a directory of its own: one copy is run by the
executable (`frictiondyn DECK`), the other by a long-lived Python worker (tests/fuzz/worker.py:
Session(deck).solve(), result(), write(), and run_text of the same text). Each run is bounded
in time (--timeout, times $FRICTIONDYN_TIME_SCALE: time_scale) and in memory (--mem, an
address-space limit), and its outcome classified:

- success: both ran, wrote the same files (byte for byte, but for run_time_s), valid JSON
  summaries with no null but in the keys that can be undefined (docs/namelist.md);
- clean error: both refused with the same message, naming the deck file (or the record file,
  or a group or variable), leaving no file behind; the Python exception a FrictiondynError;
- long by request: a valid deck (the reader accepts it) that asks for at least LONG_STEPS
  steps of dt1 = dt_record / n1 and is stopped at the time limit: the work the deck asks
  for, not a hang (the step refinement itself is bounded: docs/namelist.md); reported apart;

and every other outcome is a failure, counted by kind: crash (the executable killed by a
signal, an exit status other than 0 and 1, a gfortran runtime message), interpreter death,
wrong exception type, hang, partial output left, anonymous message, disagreement (executable
against Python, or the file against run_text), null in a summary where no value can be
undefined (or a summary that is not JSON). The report gives the counts, the failures by
what the case mutated (deck, record, path) and, for each failure, the case to reproduce it
(`--case I` runs case I alone and keeps its directory).
"""

from __future__ import annotations

import argparse
import json
import os
import re
import resource
import select
import shutil
import subprocess
import sys
import tempfile
import time
from collections import Counter
from dataclasses import dataclass, field
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
import mutate  # noqa: E402
from undefined import null_keys, undefined_keys  # noqa: E402


def _no_constant(name: str) -> None:
    raise ValueError(f"{name} is not JSON")

FAILURES = [
    "crash",
    "interpreter death",
    "wrong exception type",
    "hang",
    "partial output left",
    "anonymous message",
    "disagreement",
    "null in a summary",
]
RUNTIME_ERRORS = re.compile(
    r"Fortran runtime (error|warning)|Program received signal|Backtrace|Segmentation|"
    r"Operating system error|Allocation would exceed|double free|corrupted|AddressSanitizer|runtime error:|"
    r"ERROR STOP|Error termination"
)
GROUPS = ("model", "springs", "damping", "friction", "excitation", "integration", "output")
# the checked build (tools/test_checked.sh): the sanitizers bound memory (memory_bound)
CHECKED = bool(os.environ.get("FRICTIONDYN_CHECKED"))


def time_scale() -> float:
    """The factor by which every time bound of a case is multiplied: $FRICTIONDYN_TIME_SCALE,
    1 when unset. The checked build (tools/test_checked.sh) sets it, its instrumented code
    being several times slower (case 180 of seed 2024, the campaign's longest: 6.8 s in the
    normal build, 28 s in the checked one): the same work is bounded, not a shorter run."""
    text = os.environ.get("FRICTIONDYN_TIME_SCALE", "1")
    try:
        scale = float(text)
    except ValueError:
        scale = float("nan")
    if not 0.0 < scale < float("inf"):
        raise ValueError(f"FRICTIONDYN_TIME_SCALE = {text!r}: a positive number is needed")
    return scale


TIME_SCALE = time_scale()
LONG_STEPS = 1e7  # dt1 steps from which a valid deck that runs past the time limit asks for it


@dataclass
class Outcome:
    index: int
    base: str
    mutations: list[str]
    touched: set[str]
    kind: str = ""  # success, clean error
    failures: list[str] = field(default_factory=list)
    details: list[str] = field(default_factory=list)
    seconds: float = 0.0

    def fail(self, what: str, detail: str) -> None:
        if what not in self.failures:
            self.failures.append(what)
        self.details.append(f"{what}: {detail}")


class Worker:
    """The Python worker process, restarted after a death or a hang."""

    def __init__(self, mem: int):
        self.mem = mem
        self.proc = None

    def start(self):
        env = dict(memory_bound(self.mem), OPENBLAS_NUM_THREADS="1", PYTHONFAULTHANDLER="1")
        self.proc = subprocess.Popen(
            [sys.executable, str(Path(__file__).with_name("worker.py")), str(self.mem)],
            stdin=subprocess.PIPE, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
            env=env, bufsize=1,
        )

    def ask(self, req: dict, timeout: float):
        """(answer or None, 'ok' | 'hang' | 'death', stderr of a dead worker)."""
        if self.proc is None or self.proc.poll() is not None:
            self.start()
        self.proc.stdin.write(json.dumps(req) + "\n")
        self.proc.stdin.flush()
        ready, _, _ = select.select([self.proc.stdout], [], [], timeout)
        if not ready:
            self.kill()
            return None, "hang", ""
        line = self.proc.stdout.readline()
        if not line:
            self.proc.wait()
            err = self.proc.stderr.read()[-3000:]
            code = self.proc.returncode
            self.proc = None
            return None, "death", f"exit status {code}: {err}"
        return json.loads(line), "ok", ""

    def kill(self):
        if self.proc is not None:
            self.proc.kill()
            self.proc.wait()
            self.proc = None

    def close(self):
        if self.proc is not None:
            self.proc.stdin.close()
            self.proc.wait(timeout=30)
            self.proc = None


def write_case(case: mutate.Case, where: Path) -> None:
    where.mkdir(parents=True)
    for name, content in case.files.items():
        p = where / name
        if content is None:
            p.mkdir()
        else:
            p.write_bytes(content)


def listing(where: Path) -> set[str]:
    return {str(p.relative_to(where)) for p in where.rglob("*")}


def executable() -> str:
    import frictiondyn

    return frictiondyn.executable()


def memory_bound(mem: int) -> dict[str, str]:
    """The environment of a run bounded to mem MiB. The address space is limited (RLIMIT_AS:
    run_exe, worker.py) but in the checked build (tools/test_checked.sh), whose address
    sanitizer reserves terabytes of address space as it starts: there an allocation larger
    than mem MiB fails (malloc returns NULL, allocator_may_return_null is set) instead."""
    env = dict(os.environ)
    if CHECKED:
        env["ASAN_OPTIONS"] = env.get("ASAN_OPTIONS", "") + f":max_allocation_size_mb={mem}"
    return env


def run_exe(exe: str, case: mutate.Case, where: Path, timeout: float, mem: int):
    def limit():
        resource.setrlimit(resource.RLIMIT_AS, (mem * 2**20, mem * 2**20))

    try:
        p = subprocess.run([exe, case.deck_name], cwd=where, capture_output=True, timeout=timeout,
                           preexec_fn=None if CHECKED else limit, env=memory_bound(mem),
                           check=False)
    except subprocess.TimeoutExpired:
        return None
    return p


def names_input(message: str, case: mutate.Case) -> bool:
    """The message names the deck file, a file of the case, a group or a variable."""
    if case.deck_name in message or any(n in message for n in case.files if n):
        return True
    return any(f"&{g}" in message for g in GROUPS)


def without_run_time(text: str) -> str:
    return re.sub(r'"run_time_s": [^\n]*', "", text)


def requested_steps(deck: Path) -> float | None:
    """Steps of dt1 = dt_record / n1 a deck the reader accepts asks for (read by the library
    in a process of its own: the history's rows, one every output_every dt1 steps, or every
    n1 steps when output_every = 0, also for a record deck whose duration is its record's),
    None when unknown."""
    script = ("import sys, frictiondyn\n"
              "with frictiondyn.Session(sys.argv[1]) as s:\n"
              "    print(s.shape[0] - 1)\n")
    try:
        p = subprocess.run([sys.executable, "-c", script, str(deck)], capture_output=True,
                           timeout=60 * TIME_SCALE, text=True, check=False)
    except subprocess.TimeoutExpired:
        return None
    if p.returncode != 0:
        return None
    try:
        import f90nml

        nml = f90nml.read(str(deck))
        n1 = int(nml.get("integration", {}).get("n1", 20))
        every = int(nml.get("output", {}).get("output_every", 0))
        return float(p.stdout.split()[-1]) * (every if every > 0 else n1)
    except Exception:  # noqa: BLE001 - a deck f90nml cannot read: unknown
        return None


def classify(case, exe_dir, py_dir, proc, answer, status, death, inputs) -> Outcome:
    o = Outcome(case.index, case.base, case.mutations, case.touched)
    if proc is None or status == "hang":
        steps = requested_steps(py_dir / case.deck_name)
        if steps is not None and steps >= LONG_STEPS:
            o.kind = "long by request"
            o.details.append(f"{steps:.3g} steps of dt1 asked for")
            return o
    # the executable
    exe_ok = False
    exe_msg = ""
    if proc is None:
        o.fail("hang", "the executable ran past the time limit")
    else:
        err = proc.stderr.decode("utf-8", "replace")
        if proc.returncode < 0 or proc.returncode not in (0, 1) or RUNTIME_ERRORS.search(err):
            o.fail("crash", f"executable exit status {proc.returncode}: {err[-500:]}")
        exe_ok = proc.returncode == 0
        lines = [ln for ln in err.split("\n") if ln.startswith("frictiondyn: error: ")]
        if not exe_ok and proc.returncode == 1:
            if len(lines) != 1:
                o.fail("crash", f"not one error line: {err[-500:]}")
            exe_msg = lines[0].removeprefix("frictiondyn: error: ") if lines else err
        if exe_ok and lines:
            o.fail("crash", f"exit status 0 with an error: {err[-300:]}")
    # the Python worker
    py_ok = False
    py_msg = ""
    if status == "hang":
        o.fail("hang", "the Python API ran past the time limit")
    elif status == "death":
        o.fail("interpreter death", death[-800:])
    else:
        s = answer["session"]
        w = answer.get("write")
        for step in (s, w):
            if step is None:
                continue
            if step["status"] == "wrong":
                o.fail("wrong exception type",
                       f"{step['type']}: {step['message']} {step.get('traceback', '')}")
            if step["status"] == "error":
                py_msg = step["message"]
                if step["type"] not in ("DeckError", "SolverError", "OutOfMemoryError",
                                        "OutputError"):
                    o.fail("wrong exception type", f"{step['type']}: {py_msg}")
        py_ok = s["status"] == "ok" and w is not None and w["status"] == "ok"
        t = answer.get("text")
        if t is not None:
            if t["status"] == "wrong":
                o.fail("wrong exception type", f"run_text {t['type']}: {t['message']}")
            elif t["status"] != s["status"]:
                o.fail("disagreement", f"Session {s['status']} but run_text {t['status']}: "
                       f"{s.get('message', '')} / {t.get('message', '')}")
            elif t["status"] == "ok" and t["value"]["digest"] != s["value"]["digest"]:
                o.fail("disagreement", "run_text and Session give different results")
            elif t["status"] == "error" and t["message"] != s["message"]:
                file_level = re.search(r"NUL|does not exist|is a directory|not readable|larger than",
                                       s["message"])
                if not file_level:
                    o.fail("disagreement", f"run_text says {t['message']!r}, "
                                           f"Session {s['message']!r}")
    memory = "not enough memory" in exe_msg or "not enough memory" in py_msg
    # both
    if proc is not None and status == "ok" and not o.failures:
        if exe_ok != py_ok and not memory:
            o.fail("disagreement", f"executable {'ran' if exe_ok else 'refused: ' + exe_msg}; "
                                   f"Python {'ran' if py_ok else 'refused: ' + py_msg}")
        elif not exe_ok and not py_ok and exe_msg != py_msg and not memory:
            o.fail("disagreement", f"executable: {exe_msg!r}; Python: {py_msg!r}")
    for msg in (exe_msg, py_msg):
        if msg and not names_input(msg, case):
            o.fail("anonymous message", msg)
    # files left, files written
    for where, ok, label in ((exe_dir, exe_ok, "executable"), (py_dir, py_ok, "Python")):
        extra = listing(where) - inputs
        temps = [e for e in extra if e.endswith(".tmp") or "/." in "/" + e]
        if temps:
            o.fail("partial output left", f"{label}: temporary files {sorted(temps)[:5]}")
        if not ok and extra:
            o.fail("partial output left", f"{label} refused the deck but left {sorted(extra)[:5]}")
    if exe_ok and py_ok and not o.failures:
        written = sorted(listing(exe_dir) - inputs)
        if written != sorted(listing(py_dir) - inputs):
            o.fail("disagreement", f"written files differ: {written} / "
                                   f"{sorted(listing(py_dir) - inputs)}")
        else:
            for rel in written:
                a, b = exe_dir / rel, py_dir / rel
                if a.is_dir():
                    continue
                ta, tb = a.read_bytes(), b.read_bytes()
                if rel.endswith(".json"):
                    # null only where a value can be undefined (docs/namelist.md, "Undefined
                    # values"); NaN and Infinity are not JSON at all
                    try:
                        bad = null_keys(json.loads(ta, parse_constant=_no_constant))
                        bad -= undefined_keys()
                    except ValueError as e:
                        bad = {f"invalid JSON: {e}"}
                    if bad:
                        o.fail("null in a summary", f"{rel}: {', '.join(sorted(bad))}")
                    ta = without_run_time(ta.decode("utf-8", "replace")).encode()
                    tb = without_run_time(tb.decode("utf-8", "replace")).encode()
                if ta != tb:
                    o.fail("disagreement", f"{rel} differs between the executable and Python")
    if not o.failures:
        o.kind = "success" if exe_ok else "clean error"
    return o


def campaign(count: int, seed: int, timeout: float = 60.0, mem: int = 2048, first: int = 0,
             keep: Path | None = None, progress=None, only: int | None = None) -> list[Outcome]:
    bases = mutate.bases()
    worker = Worker(mem)
    timeout = timeout * TIME_SCALE  # the same work bounded in a slower build (time_scale)
    outcomes = []
    indices = [only] if only is not None else range(first, first + count)
    with tempfile.TemporaryDirectory(prefix="frictiondyn-fuzz-") as tmp:
        exe = str(Path(tmp) / "frictiondyn")  # a copy: a reinstall during the campaign is harmless
        shutil.copy2(executable(), exe)
        for i in indices:
            case = mutate.make_case(seed, i, bases)
            cdir = Path(tmp) / f"case{i}"
            exe_dir, py_dir = cdir / "exe", cdir / "py"
            write_case(case, exe_dir)
            write_case(case, py_dir)
            inputs = listing(exe_dir)
            t0 = time.monotonic()
            proc = run_exe(exe, case, exe_dir, timeout, mem)
            answer, status, death = worker.ask({"dir": str(py_dir), "deck": case.deck_name},
                                               timeout)
            o = classify(case, exe_dir, py_dir, proc, answer, status, death, inputs)
            o.seconds = time.monotonic() - t0
            outcomes.append(o)
            if (o.failures or only is not None) and keep is not None:
                dest = keep / f"case{i}"
                shutil.rmtree(dest, ignore_errors=True)
                shutil.copytree(cdir, dest, symlinks=True)
            shutil.rmtree(cdir, ignore_errors=True)
            if progress:
                progress(o)
    worker.close()
    return outcomes


def report(outcomes: list[Outcome], seed: int) -> dict:
    kinds = Counter(o.kind for o in outcomes if o.kind)
    fails = Counter(f for o in outcomes for f in o.failures)
    by_touch = Counter()
    for o in outcomes:
        if o.failures:
            by_touch["+".join(sorted(o.touched)) or "none"] += 1
    return {
        "seed": seed,
        "runs": len(outcomes),
        "successes": kinds["success"],
        "clean errors": kinds["clean error"],
        "long by request": kinds["long by request"],
        **{f: fails[f] for f in FAILURES},
        "failing cases": sum(1 for o in outcomes if o.failures),
        "failing cases by what was mutated": dict(by_touch),
        "longest case [s]": round(max((o.seconds for o in outcomes), default=0.0), 2),
        "total time [s]": round(sum(o.seconds for o in outcomes), 1),
        "failures": [
            {"case": o.index, "base": o.base, "mutations": o.mutations, "details": o.details}
            for o in outcomes if o.failures
        ],
    }


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--count", type=int, default=1000, help="cases (default 1000)")
    ap.add_argument("--seed", type=int, default=1, help="seed of the campaign (default 1)")
    ap.add_argument("--first", type=int, default=0, help="index of the first case")
    ap.add_argument("--jobs", type=int, default=1, help="campaigns side by side (default 1)")
    ap.add_argument("--timeout", type=float, default=60.0, help="seconds a run may take")
    ap.add_argument("--mem", type=int, default=2048, help="MiB of address space a run may add")
    ap.add_argument("--case", type=int, help="run case CASE alone and keep its directory")
    ap.add_argument("--keep", type=Path, help="keep the directories of failing cases here")
    ap.add_argument("--json", type=Path, help="write the report here as JSON")
    ap.add_argument("--quiet", action="store_true")
    args = ap.parse_args(argv)
    keep = args.keep or (Path("fuzz-cases") if args.case is not None else None)
    start = time.monotonic()
    if args.case is not None:
        outcomes = campaign(1, args.seed, args.timeout, args.mem, keep=keep, only=args.case)
    elif args.jobs > 1:
        outcomes = parallel(args)
    else:
        done = [0]

        def progress(o):
            done[0] += 1
            if not args.quiet and (done[0] % 100 == 0 or o.failures):
                tag = f" FAIL {o.failures}" if o.failures else ""
                print(f"  {done[0]}/{args.count} case {o.index}{tag}", file=sys.stderr)

        outcomes = campaign(args.count, args.seed, args.timeout, args.mem, args.first, keep,
                            progress)
    rep = report(outcomes, args.seed)
    rep["wall time [s]"] = round(time.monotonic() - start, 1)
    if args.json:
        args.json.write_text(json.dumps(rep, indent=2, ensure_ascii=False))
    command = (f"--case {args.case} --seed {args.seed}" if args.case is not None
               else f"--count {args.count} --seed {args.seed} --first {args.first}")
    scaled = f", time bounds x {TIME_SCALE:g}: FRICTIONDYN_TIME_SCALE" if TIME_SCALE != 1 else ""
    print(f"fuzz campaign: seed {args.seed}, {rep['runs']} cases (tests/fuzz/run.py {command}, "
          f"--timeout {args.timeout:g} --mem {args.mem}{scaled})")
    for key in ["runs", "successes", "clean errors", "long by request", *FAILURES]:
        print(f"  {key:24s} {rep[key]}")
    print(f"  {'wall time [s]':24s} {rep['wall time [s]']}")
    if rep["failing cases by what was mutated"]:
        print(f"  failing cases by what was mutated: {rep['failing cases by what was mutated']}")
    for o in outcomes:
        if o.kind == "long by request":
            print(f"long by request: case {o.index} ({o.base}; {'; '.join(o.mutations)}): "
                  f"{o.details[0]}")
    for f in rep["failures"][:50]:
        print(f"case {f['case']} ({f['base']}; {'; '.join(f['mutations'])}):")
        for d in f["details"]:
            print(f"    {d[:400]}")
    return 1 if rep["failing cases"] else 0


def parallel(args) -> list[Outcome]:
    """--jobs campaigns of consecutive slices, each in a process of its own."""
    import concurrent.futures as cf

    n = args.jobs
    sizes = [args.count // n + (1 if k < args.count % n else 0) for k in range(n)]
    starts = [args.first + sum(sizes[:k]) for k in range(n)]
    with cf.ProcessPoolExecutor(n) as pool:
        futs = [pool.submit(campaign, sizes[k], args.seed, args.timeout, args.mem, starts[k],
                            args.keep) for k in range(n)]
        outcomes = [o for f in futs for o in f.result()]
    return sorted(outcomes, key=lambda o: o.index)


if __name__ == "__main__":
    sys.exit(main())
