#!/usr/bin/env python3
"""Sweep-spec fuzz campaign: mutated TOML specs through ``python -m frictiondyn sweep --slurm``.

    python tests/fuzz/sweep_spec.py --count 5000 --seed 1     # the long campaign
    python tests/fuzz/sweep_spec.py --count 60 --seed 2024    # what tests/test_sweep.py runs
    python tests/fuzz/sweep_spec.py --case 17 --seed 1 --keep DIR   # one case, kept

Each case (drawn from (seed, index): the same case every time) is a valid spec of a small
base deck with 1 to 3 mutations: values of the wrong type (numbers, lists, TOML dates,
inline tables, empty strings) for every top-level key; hostile names and directories
(newlines, quotes, ``$(...)``, backticks, blanks, '#', '%', '..'); huge crossings (up to
1e30 runs); unknown top-level keys, groups and variables, misspelt names, key syntax;
values of the wrong type, non-finite, with control characters; [zip] lists of different
lengths; one variable given twice; damaged text (cut at any byte, bytes inserted, not
UTF-8). It runs in this process through ``frictiondyn.sweep.main`` (``--slurm --exe STUB
--max-runs 64``) in a directory of its own, the working directory, and its outcome is:

- clean error: a SweepError of one line, and nothing written (the directory as before);
- sweep: exit status 0, the manifest holds as many runs as the spec makes, each deck the
  manifest names has its SHA-256, and the job script, run by bash as task 0 would be
  (PATH with stubs of sbatch, srun and touch that leave a mark; the executable a stub at a
  path named to inject commands), runs the executable once, in the sweep directory, with
  ``--list decks.txt --index 0``;

and every other outcome is a failure, counted by kind: traceback (any other exception),
injection (a file the spec asks a command to create, a stub called, the executable run
otherwise), bad message (more than one line, empty), output left after an error, wrong
sweep. The report gives the counts and, for each failure, the case to reproduce it.
"""

from __future__ import annotations

import argparse
import contextlib
import datetime
import io
import json
import math
import os
import random
import shutil
import subprocess
import sys
import tempfile
import time
from collections import Counter
from dataclasses import dataclass, field
from pathlib import Path

FAILURES = ["traceback", "injection", "bad message", "output left", "wrong sweep"]
MAX_RUNS = 64

BASE_DECK = """&model
  n_dof = 1
  mass = 10.0
/
&springs
  n_springs = 1
  node_i = 1
  node_j = 0
  k = 1.0e4
/
&damping
  damping_type = 'none'
/
&friction
  n_devices = 1
  node_i = 1
  node_j = 0
  law = 'hysteretic'
  p = 98.1
  mu = 0.3
/
&excitation
  excitation_type = 'harmonic'
  amplitude = 0.02
  frequency = 3.0
  dt_record = 0.01
  duration = 1.0
/
"""

INJECT = "INJECTED"
HOSTILE_NAMES = ["..", ".", "../x", "a/b", "/etc", "-rf", f"$(touch {INJECT}_N)",
                 f"`touch {INJECT}_N`", "a\nb", "a b", "\u00e9t\u00e9", "x" * 300, "a'b", 'a"b',
                 "", "ok_name", "v1.2-3"]
HOSTILE_DIRS = [f"sweep\ntouch {INJECT}_D #", f"s $(touch {INJECT}_D)", f"s `touch {INJECT}_D`",
                "it's", 'say "hi"', "a b # c", "/dev/null", "sub/../sub2", "%A %a %%", "back\\slash",
                "tab\tx", ".", "x" * 200, "s;touch INJECTED_D", "s|touch INJECTED_D", "s&&x",
                "s\rx", "\u00e9t\u00e9 sweep", "deep/er/still"]
WRONG = [5, 1.5, True, False, [], ["x"], {"a": 1}, datetime.datetime(1979, 5, 27, 7, 32),
         datetime.date(2020, 1, 1), datetime.time(7, 32), "", "x" * 300, "no", 0, -1, 10**30,
         float("nan"), float("inf"), [[1, 2], [3]]]
VARS = ["friction.mu", "friction.p", "friction.eps1", "excitation.amplitude",
        "excitation.frequency", "excitation.duration", "springs.k", "model.mass",
        "integration.n1", "output.output_every", "friction.law", "damping.damping_type"]
KEY_JUNK = ["a b", "x.y.z", "friction.mu(0)", "friction.mu(99)", "friction.mu(-1)", "",
            "deck.x", "fr\u00efction.mu", "friction.", ".mu", "friction.mu()", "friction.mu(1)(2)",
            "friction..mu", "friction.mu(99999999999)", "output.name", "output.dir",
            "run", "status", "message", "deck_sha256", "1abc", "_", "friction.mu(1)"]


@dataclass
class Case:
    index: int
    spec: dict
    mutations: list[str]
    text_damage: list[tuple[str, int, bytes]] = field(default_factory=list)


@dataclass
class Outcome:
    index: int
    mutations: list[str]
    kind: str = ""  # "clean error", "sweep"
    failures: list[str] = field(default_factory=list)
    details: list[str] = field(default_factory=list)
    seconds: float = 0.0

    def fail(self, what: str, detail: str) -> None:
        if what not in self.failures:
            self.failures.append(what)
        self.details.append(f"{what}: {detail[:600]}")


# --------------------------------------------------------------------------------- cases
def valid_spec(rng: random.Random) -> dict:
    spec: dict = {"base": "base.nml", "write_history": False}
    if rng.random() < 0.5:
        spec["name"] = rng.choice(["f", "fz", "sweep_1", "a.b-c"])
    cross = {}
    for key in rng.sample(VARS[:8], rng.randint(0, 2)):
        cross[key] = [round(rng.uniform(0.05, 0.5), 3) for _ in range(rng.randint(1, 3))]
    spec["cross"] = cross
    if rng.random() < 0.5:
        n = rng.randint(1, 3)
        spec["zip"] = {"label": [f"l{i}" for i in range(n)],
                       "friction.f": [0.001 * (i + 1) for i in range(n)]}
    return spec


def _mutate(rng: random.Random, spec: dict, case: Case) -> str:
    if rng.random() < 0.4:  # mostly hostile values a sweep may take: a sweep, and its script
        kind = rng.choice(["name", "directory", "directory", "huge", "jobs", "label"])
    else:
        kind = rng.choice(["top type", "name", "directory", "huge", "unknown top",
                           "unknown group", "unknown variable", "key junk", "value type",
                           "zip lengths", "duplicate", "base", "deck key", "text", "label", "jobs"])
    if kind not in ("top type", "text"):  # a table a former mutation replaced is a table again
        for t in ("cross", "zip"):
            if t in spec and not isinstance(spec[t], dict):
                spec[t] = {}
    tables = [t for t in ("cross", "zip") if spec.get(t)] or ["cross"]
    table = rng.choice(tables)
    if not isinstance(spec.setdefault(table, {}), dict):
        spec[table] = {}
    if kind == "top type":
        key = rng.choice(["name", "base", "jobs", "directory", "write_history", "cross", "zip"])
        spec[key] = rng.choice(WRONG)
        return f"{key} = {spec[key]!r}"[:80]
    if kind == "name":
        spec["name"] = rng.choice(HOSTILE_NAMES)
        return f"name = {spec['name']!r}"[:80]
    if kind == "directory":
        spec["directory"] = rng.choice(HOSTILE_DIRS)
        return f"directory = {spec['directory']!r}"[:80]
    if kind == "huge":
        keys = rng.sample(VARS, rng.randint(1, len(VARS)))
        width = rng.choice([1, 2, 3, 10, 100, 1000, 5000])
        for k in keys:
            spec.setdefault("cross", {})[k] = [0.1 + 1e-4 * i for i in range(width)]
            spec.get("zip", {}).pop(k, None)
        return f"{len(keys)} keys x {width} values crossed"
    if kind == "unknown top":
        key = rng.choice(["nmae", "bsae", "job", "dirctory", "write_histroy", "crss", "zipp",
                          "extra", "Name"])
        spec[key] = 1
        return f"top-level key {key!r}"
    if kind == "unknown group":
        key = rng.choice(["frction.mu", "brace.stiffness", "Friction2.mu", "output_.dir",
                          "integraton.n1", "xx.yy"])
        spec[table][key] = [0.1]
        return f"[{table}] {key!r}"
    if kind == "unknown variable":
        var = rng.choice(VARS)
        group, name = var.split(".")
        i = rng.randrange(len(name))
        typo = rng.choice([name[:i] + name[i + 1:], name[:i] + "x" + name[i:],
                           name[:i] + name[i + 1:i + 2] + name[i:i + 1] + name[i + 2:]])
        if typo == name:
            typo = name + "s"
        spec[table][f"{group}.{typo}"] = [0.1]
        return f"[{table}] '{group}.{typo}'"
    if kind == "key junk":
        key = rng.choice(KEY_JUNK)
        spec[table][key] = [rng.choice([0.1, "x", 1])]
        return f"[{table}] key {key!r}"
    if kind == "value type":
        key = rng.choice(VARS + ["label"])
        bad = rng.choice(WRONG)
        values = rng.choice([[bad], bad, [0.1, bad], [[bad]], ["a\nb"], ["x\x00y"], []])
        spec[table][key] = values
        if table == "zip":
            spec["zip"] = {key: values}
        return f"[{table}] {key} = {values!r}"[:80]
    if kind == "zip lengths":
        spec["zip"] = {"label": ["a", "b"], "friction.f": [0.001, 0.002, 0.003]}
        return "[zip] lists of 2 and 3"
    if kind == "duplicate":
        a = rng.choice(["friction.mu", "springs.k"])
        b = rng.choice([a.upper(), a.title(), a + "(1)"])
        spec.setdefault("cross", {})[a] = [0.1]
        spec.setdefault("zip", {}).clear()
        spec["zip"][b] = [0.2]
        return f"{a!r} and {b!r}"
    if kind == "base":
        spec["base"] = rng.choice(["missing.nml", "subdir", "/dev/null", "empty.nml",
                                   "../../nope.nml", "base.nml\n", "bad.nml"])
        return f"base = {spec['base']!r}"
    if kind == "deck key":
        spec.pop("base", None) if rng.random() < 0.5 else None
        spec[table]["deck"] = rng.choice([["base.nml", "missing.nml"], [5], ["subdir"],
                                          ["base.nml", "base.nml"], [""], ["bad.nml"]])
        if table == "zip":
            spec["zip"] = {"deck": spec["zip"]["deck"]}
        return f"[{table}] deck = {spec[table]['deck']!r}"
    if kind == "label":
        key = rng.choice(["run", "status", "message", "warnings", "slip", "deck_sha256"])
        spec["cross"] = spec.get("cross") or {}
        spec["cross"][key] = ["a", "b"]
        return f"label {key!r}"
    if kind == "jobs":
        spec["jobs"] = rng.choice([0, -3, 2, 10**6, "4", 1.5, True])
        return f"jobs = {spec['jobs']!r}"
    # damaged text, applied after rendering
    how = rng.choice(["cut", "insert", "latin1", "dup line"])
    case.text_damage.append((how, rng.randrange(1 << 30), bytes(rng.randrange(256)
                                                                   for _ in range(rng.randint(1, 6)))))
    return f"text: {how}"


def make_case(seed: int, index: int) -> Case:
    rng = random.Random(f"sweep-spec/{seed}/{index}")
    case = Case(index, {}, [])
    case.spec = valid_spec(rng)
    for _ in range(rng.randint(1, 3)):
        case.mutations.append(_mutate(rng, case.spec, case))
    return case


def toml_value(v) -> str:
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, int):
        return str(v)
    if isinstance(v, float):
        return "nan" if math.isnan(v) else ("inf" if v > 0 else "-inf") if math.isinf(v) else repr(v)
    if isinstance(v, str):
        return json.dumps(v)  # a JSON string is a TOML basic string
    if isinstance(v, (datetime.datetime, datetime.date, datetime.time)):
        return v.isoformat()
    if isinstance(v, list):
        return "[" + ", ".join(toml_value(x) for x in v) + "]"
    if isinstance(v, dict):
        return "{" + ", ".join(f"{json.dumps(k)} = {toml_value(x)}" for k, x in v.items()) + "}"
    raise TypeError(type(v))


def render(case: Case) -> bytes:
    lines, tables = [], []
    for k, v in case.spec.items():
        if k in ("cross", "zip") and isinstance(v, dict):
            tables.append((k, v))
        else:
            lines.append(f"{json.dumps(k)} = {toml_value(v)}")
    for name, table in tables:
        lines.append(f"[{name}]")
        lines += [f"{json.dumps(k)} = {toml_value(v)}" for k, v in table.items()]
    data = ("\n".join(lines) + "\n").encode()
    for how, pos, junk in case.text_damage:
        at = pos % (len(data) + 1)
        if how == "cut":
            data = data[:at]
        elif how == "insert":
            data = data[:at] + junk + data[at:]
        elif how == "latin1":
            data = data[:at] + b"\xe9\xff" + data[at:]
        else:
            ls = data.split(b"\n")
            i = pos % max(1, len(ls))
            data = b"\n".join(ls[:i + 1] + ls[i:])
    return data


# ------------------------------------------------------------------------------- running
STUB_EXE = """#!/bin/sh
printf '%s\\n' "$PWD" "$@" >> "$FUZZ_RECORD"
"""
STUB_TOOL = """#!/bin/sh
echo "{tool} $*" >> "$FUZZ_MARKS"
"""


def prepare(where: Path) -> tuple[Path, Path]:
    """The inputs every case shares: stubs (on PATH, and the executable at a path named to
    inject commands)."""
    stubs = where / "stubs"
    stubs.mkdir(parents=True)
    for tool in ("sbatch", "srun", "touch"):
        (stubs / tool).write_text(STUB_TOOL.format(tool=tool))
        (stubs / tool).chmod(0o755)
    exe_dir = where / f"bin $(touch {INJECT}_X) `touch {INJECT}_Y` 'q' \"d\""
    exe_dir.mkdir()
    exe = exe_dir / "frictiondyn"
    exe.write_text(STUB_EXE)
    exe.chmod(0o755)
    return stubs, exe


def write_inputs(cdir: Path) -> None:
    cdir.mkdir(parents=True)
    (cdir / "base.nml").write_text(BASE_DECK)
    (cdir / "bad.nml").write_text(BASE_DECK.replace("mu = 0.3", "mu = -1.0"))
    (cdir / "empty.nml").write_text("")
    (cdir / "subdir").mkdir()


def listing(where: Path) -> dict[str, bytes | None]:
    out = {}
    for p in sorted(where.rglob("*")):
        rel = str(p.relative_to(where))
        out[rel] = None if p.is_dir() else p.read_bytes()
    return out


def run_case(case: Case, cdir: Path, stubs: Path, exe: Path) -> Outcome:
    from frictiondyn import sweep as sw

    o = Outcome(case.index, case.mutations)
    write_inputs(cdir)
    spec_path = cdir / "spec.toml"
    spec_path.write_bytes(render(case))
    before = listing(cdir)
    out, err = io.StringIO(), io.StringIO()
    old = os.getcwd()
    os.chdir(cdir)
    code, error = None, None
    try:
        with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
            code = sw.main([str(spec_path), "--slurm", "--exe", str(exe),
                            "--max-runs", str(MAX_RUNS)])
    except sw.SweepError as exc:
        error = str(exc)
    except BaseException as exc:  # noqa: BLE001 - what is looked for
        import traceback

        o.fail("traceback", f"{type(exc).__name__}: {exc} {traceback.format_exc()[-1200:]}")
        return o
    finally:
        os.chdir(old)
    if error is not None:
        if "\n" in error or not error.strip():
            o.fail("bad message", repr(error))
        after = listing(cdir)
        if after != before:
            new = sorted(set(after) - set(before)) or [k for k in after if after[k] != before.get(k)]
            o.fail("output left", f"{error[:200]} | {new[:5]}")
        if not o.failures:
            o.kind = "clean error"
            o.details.append(error)
        return o
    if code != 0:
        o.fail("wrong sweep", f"exit status {code}: {out.getvalue()[-300:]}")
        return o
    check_sweep(o, cdir, spec_path, out.getvalue(), stubs)
    check_injection(o, cdir)
    if not o.failures:
        o.kind = "sweep"
    return o


def check_sweep(o: Outcome, cdir: Path, spec_path: Path, stdout: str, stubs: Path) -> None:
    from frictiondyn import sweep as sw

    spec = sw.load_spec(spec_path)
    sdir = Path(stdout.split(" runs in ", 1)[1].split(" (", 1)[0]) if " runs in " in stdout else None
    if sdir is None or not (sdir / "manifest.json").exists():
        o.fail("wrong sweep", f"no sweep directory in {stdout[:300]!r}")
        return
    if cdir.resolve() not in sdir.resolve().parents and sdir.resolve() != cdir.resolve():
        o.fail("wrong sweep", f"sweep directory {sdir} outside the case's directory")
    sweep = sw.load(sdir)
    if len(sweep.runs) != sw.count_runs(spec):
        o.fail("wrong sweep", f"{len(sweep.runs)} runs, the spec makes {sw.count_runs(spec)}")
    for run in sweep.runs:
        if sw._sha256((sdir / run.deck).read_bytes()) != run.deck_sha256:
            o.fail("wrong sweep", f"{run.deck}: not the deck of the manifest")
    script = sdir / "sweep.sbatch"
    record = cdir / "exe_record.txt"
    marks = cdir / "marks.txt"
    env = {"PATH": f"{stubs}:/usr/bin:/bin", "SLURM_ARRAY_TASK_ID": "0",
           "SLURM_ARRAY_JOB_ID": "1", "FUZZ_RECORD": str(record), "FUZZ_MARKS": str(marks),
           "HOME": str(cdir)}
    t = subprocess.run(["bash", str(script)], env=env, cwd=cdir, capture_output=True, timeout=60)
    if t.returncode != 0:
        o.fail("wrong sweep", f"job script exit status {t.returncode}: {t.stderr[-300:]!r}")
    calls = record.read_text().split("\n") if record.exists() else []
    if calls[:5] != [str(sdir), "--list", "decks.txt", "--index", "0"] or len(calls) != 6:
        o.fail("injection", f"the executable ran as {calls[:8]!r}, not once in {sdir}")
    if marks.exists():
        o.fail("injection", f"stubs called: {marks.read_text()[:200]!r}")


def check_injection(o: Outcome, cdir: Path) -> None:
    """No file named as a spec's command would create it (no name of the cases starts so)."""
    for p in cdir.rglob(f"{INJECT}*"):
        o.fail("injection", f"{p.relative_to(cdir)} exists")


def campaign(count: int, seed: int, first: int = 0, keep: Path | None = None,
             only: int | None = None, progress=None) -> list[Outcome]:
    outcomes = []
    indices = [only] if only is not None else range(first, first + count)
    with tempfile.TemporaryDirectory(prefix="frictiondyn-specfuzz-") as tmp:
        stubs, exe = prepare(Path(tmp) / "shared")
        for i in indices:
            case = make_case(seed, i)
            cdir = Path(tmp) / f"case{i}"
            t0 = time.monotonic()
            o = run_case(case, cdir, stubs, exe)
            o.seconds = time.monotonic() - t0
            outcomes.append(o)
            if (o.failures or only is not None) and keep is not None:
                dest = keep / f"case{i}"
                shutil.rmtree(dest, ignore_errors=True)
                shutil.copytree(cdir, dest, symlinks=True)
            shutil.rmtree(cdir, ignore_errors=True)
            if progress:
                progress(o)
    return outcomes


def report(outcomes: list[Outcome], seed: int) -> dict:
    kinds = Counter(o.kind for o in outcomes if o.kind)
    fails = Counter(f for o in outcomes for f in o.failures)
    return {
        "seed": seed,
        "runs": len(outcomes),
        "sweeps": kinds["sweep"],
        "clean errors": kinds["clean error"],
        **{f: fails[f] for f in FAILURES},
        "failing cases": sum(1 for o in outcomes if o.failures),
        "longest case [s]": round(max((o.seconds for o in outcomes), default=0.0), 2),
        "failures": [{"case": o.index, "mutations": o.mutations, "details": o.details}
                     for o in outcomes if o.failures],
    }


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--count", type=int, default=1000, help="cases (default 1000)")
    ap.add_argument("--seed", type=int, default=1, help="seed of the campaign (default 1)")
    ap.add_argument("--first", type=int, default=0, help="index of the first case")
    ap.add_argument("--case", type=int, help="run case CASE alone and keep its directory")
    ap.add_argument("--keep", type=Path, help="keep the directories of failing cases here")
    ap.add_argument("--json", type=Path, help="write the report here as JSON")
    args = ap.parse_args(argv)
    keep = args.keep or (Path("fuzz-cases") if args.case is not None else None)
    start = time.monotonic()
    outcomes = campaign(args.count, args.seed, args.first, keep, args.case)
    rep = report(outcomes, args.seed)
    rep["wall time [s]"] = round(time.monotonic() - start, 1)
    if args.json:
        args.json.write_text(json.dumps(rep, indent=2, ensure_ascii=False))
    print(f"sweep-spec fuzz campaign: seed {args.seed}, {rep['runs']} cases "
          f"(tests/fuzz/sweep_spec.py --count {args.count} --seed {args.seed} --first {args.first})")
    for key in ["runs", "sweeps", "clean errors", *FAILURES, "wall time [s]"]:
        print(f"  {key:16s} {rep[key]}")
    for f in rep["failures"][:50]:
        print(f"case {f['case']} ({'; '.join(f['mutations'])}):")
        for d in f["details"]:
            print(f"    {d[:400]}")
    if args.case is not None:
        for o in outcomes:
            print(f"case {o.index}: {o.kind or 'FAIL'}: {'; '.join(o.mutations)}")
            for d in o.details:
                print(f"    {d[:400]}")
    return 1 if rep["failing cases"] else 0


if __name__ == "__main__":
    sys.exit(main())
