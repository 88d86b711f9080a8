#!/usr/bin/env python3
"""Fuzz campaign of ``sweep collect`` on damaged sweep folders.

    python tests/fuzz/collect_damage.py --count 5000 --seed 1     # the long campaign
    python tests/fuzz/collect_damage.py --count 150 --seed 2024   # what tests/test_sweep.py runs
    python tests/fuzz/collect_damage.py --case 17 --seed 1 --keep DIR

A real sweep of six runs (a 1-DOF deck with friction, six friction coefficients: six
different peaks) is run once by the executable. Each case (drawn from (seed, index): the
same case every time) is a copy of its folder with 1 to 4 damages: summaries truncated at
any byte, swapped or copied between runs, linked to another run's, replaced by JSON of
another type ([1, 2], 123, "x", null), by bytes that are not UTF-8, by a directory, by
nesting 10^5 deep, by NaN; keys collect reads given the wrong JSON type (deck_sha256,
frictiondyn_version, warnings, record); values set to null (a quantity a run does not
define); error.txt added (not UTF-8, 1 MiB, a directory), moved or copied between runs;
the manifest truncated, of the wrong type, not UTF-8, a run's entry of the wrong type; the
results table a directory. Collect runs in this process (``frictiondyn.sweep.main``) and
the outcome must be:

- a damaged manifest (or a table that cannot be written): one SweepError line naming the
  file;
- otherwise: results.csv with one row per run, in order; each run not done named in the
  report (failed, damaged, or missing); exit status 0 exactly when every run is done;
  every run whose summary is its own undamaged one done; and every row marked done
  carries the values of that run's own summary (its deck's SHA-256 and its own peaks, a
  null written NaN), never another run's.

Any other outcome is a failure, counted by kind: traceback, bad message, wrong pairing (a
done row with values that are not its run's own), wrong status, not reported, no table.
"""

from __future__ import annotations

import argparse
import contextlib
import csv
import io
import json
import os
import random
import shutil
import sys
import tempfile
import time
from collections import Counter
from dataclasses import dataclass, field
from pathlib import Path

FAILURES = ["traceback", "bad message", "wrong pairing", "wrong status", "not reported",
            "no table"]
MUS = [0.05, 0.1, 0.15, 0.2, 0.3, 0.45]
N = len(MUS)
CHECKED = ["peak_s_m[1]", "peak_u_m[1]", "energy_friction_J", "samples", "period_stuck_s"]

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


def make_pristine(where: Path) -> Path:
    """The folder of a sweep of N runs, run by the executable, without results.csv."""
    from frictiondyn import sweep as sw

    where.mkdir(parents=True)
    (where / "base.nml").write_text(BASE_DECK)
    (where / "s.toml").write_text('base = "base.nml"\nwrite_history = false\n[cross]\n'
                                  f'"friction.mu" = {MUS}\n')
    sweep = sw.expand(where / "s.toml", where / "sweep")
    try:
        counts = sw.run_local(sweep, jobs=2, progress=False)
    finally:
        sweep.close()
    assert counts["done"] == N, counts
    return where / "sweep"


def rid(i: int) -> str:
    return f"r{i:04d}"


@dataclass
class Outcome:
    index: int
    damages: list[str]
    kind: str = ""  # "table", "clean error"
    failures: list[str] = field(default_factory=list)
    details: list[str] = field(default_factory=list)
    seconds: float = 0.0

    def fail(self, what: str, detail: str) -> None:
        if what not in self.failures:
            self.failures.append(what)
        self.details.append(f"{what}: {detail[:500]}")


def damage(rng: random.Random, sdir: Path, state: dict) -> str:
    """One damage; ``state`` keeps what the oracle needs: runs whose summary may no longer
    be their own undamaged one ("touched"), nulls set, whether the manifest is damaged or
    the table cannot be written."""
    runs = sdir / "runs"
    i, j = rng.sample(range(N), 2)
    s_i, s_j = runs / f"{rid(i)}.summary.json", runs / f"{rid(j)}.summary.json"
    e_i, e_j = runs / f"{rid(i)}.error.txt", runs / f"{rid(j)}.error.txt"
    kind = rng.choice(["truncate", "swap", "copy", "link", "other json", "not utf-8",
                       "directory", "deep", "nan", "key type", "null", "delete", "error added",
                       "error moved", "manifest", "table", "value type"])

    def clear(path: Path) -> None:
        if path.is_dir() and not path.is_symlink():
            shutil.rmtree(path)
        else:
            path.unlink(missing_ok=True)

    def put(path: Path, data: bytes) -> None:
        """Write the file itself: a link planted before is replaced, never written through
        (that would change the other run's summary behind the oracle's back)."""
        if path.is_symlink():
            path.unlink()
        path.write_bytes(data)

    def text(path: Path) -> bytes | None:
        try:
            return path.read_bytes()
        except OSError:
            return None

    if kind == "truncate" and (data := text(s_i)) is not None:
        at = rng.randrange(len(data))
        put(s_i, data[:at])
        state["touched"].add(i)
        return f"{rid(i)} summary cut at byte {at}"
    if kind == "swap":
        a, b = text(s_i), text(s_j)
        for path, data in ((s_i, b), (s_j, a)):
            clear(path)
            if data is not None:
                put(path, data)
        state["touched"] |= {i, j}
        return f"summaries of {rid(i)} and {rid(j)} swapped"
    if kind == "copy" and (data := text(s_j)) is not None:
        clear(s_i)
        put(s_i, data)
        state["touched"].add(i)
        return f"summary of {rid(j)} copied over {rid(i)}'s"
    if kind == "link":
        clear(s_i)
        s_i.symlink_to(s_j.name)
        state["touched"].add(i)
        return f"summary of {rid(i)} a link to {rid(j)}'s"
    if kind == "other json":
        clear(s_i)
        put(s_i, (rng.choice(["[1, 2]", "123", '"x"', "null", "true", "{}", "[]", ""])).encode())
        state["touched"].add(i)
        return f"{rid(i)} summary {s_i.read_text()!r}"
    if kind == "not utf-8" and (data := text(s_i)) is not None:
        at = rng.randrange(len(data) + 1)
        put(s_i, data[:at] + b"\xff\xfe\xc3" + data[at:])
        state["touched"].add(i)
        return f"{rid(i)} summary with bytes not UTF-8 at {at}"
    if kind == "directory":
        clear(s_i)
        s_i.mkdir()
        state["touched"].add(i)
        return f"{rid(i)} summary a directory"
    if kind == "deep":
        clear(s_i)
        put(s_i, ("[" * 100000 + "]" * 100000).encode())
        state["touched"].add(i)
        return f"{rid(i)} summary nested 1e5 deep"
    if kind == "nan" and (data := text(s_i)) is not None:
        put(s_i, data.replace(b'"samples": ', b'"samples": NaN, "was": ', 1))
        state["touched"].add(i)
        return f"{rid(i)} summary with NaN"
    if kind in ("key type", "null", "value type"):
        try:
            summ = json.loads(s_i.read_text())
            assert isinstance(summ, dict)
        except Exception:  # noqa: BLE001 - damaged already: nothing to change in it
            return f"{rid(i)}: no summary to change"
        if kind == "key type":
            key = rng.choice(["deck_sha256", "frictiondyn_version", "warnings", "record"])
            summ[key] = rng.choice([5, None, [], ["x", 1], "x", {"a": 1}, True])
            state["touched"].add(i)
            what = f"{rid(i)} summary {key} = {summ[key]!r}"
        elif kind == "null":
            key = rng.choice(["period_stuck_s", "peak_u_m", "energy_friction_J"])
            summ[key] = [None] if isinstance(summ.get(key), list) else None
            state["nulls"].setdefault(i, set()).add(key)
            what = f"{rid(i)} summary {key} null"
        else:
            key = rng.choice(["n_dof", "technique", "peak_s_m", "events"])
            summ[key] = rng.choice([{"x": [1, {"y": None}]}, "text,with \"quotes\"\n", [[1, 2]],
                                    1e308, -0.0, "\u00e9"])
            state["values"].setdefault(i, set()).add(key)
            what = f"{rid(i)} summary {key} = {summ[key]!r}"
        put(s_i, (json.dumps(summ)).encode())
        return what
    if kind == "delete":
        clear(s_i)
        state["touched"].add(i)
        return f"{rid(i)} summary deleted"
    if kind == "error added":
        clear(e_i)
        how = rng.choice(["text", "bytes", "big", "dir"])
        if how == "dir":
            e_i.mkdir()
        else:
            e_i.write_bytes({"text": b"frictiondyn: error: simulated\n",
                             "bytes": b"\xff\xfe\x00 bad \x80\n",
                             "big": b"x" * (1 << 20)}[how])
        return f"{rid(i)} error.txt added ({how})"
    if kind == "error moved" and e_j.exists():
        data = text(e_j)
        clear(e_i)
        if data is not None:
            put(e_i, data)
        return f"error.txt of {rid(j)} copied to {rid(i)}"
    if kind == "manifest":
        m = sdir / "manifest.json"
        how = rng.choice(["cut", "list", "bytes", "run type", "run id", "run sha", "params"])
        data = m.read_bytes()
        if how == "cut":
            m.write_bytes(data[:rng.randrange(len(data))])
        elif how == "list":
            m.write_text(rng.choice(["[]", "{}", "5", "null", '{"runs": {}}']))
        elif how == "bytes":
            m.write_bytes(b"\xff" + data)
        else:
            try:
                man = json.loads(data)
                entry = man["runs"][i]
                assert isinstance(entry, dict)
            except Exception:  # noqa: BLE001 - damaged already
                m.write_bytes(data[:len(data) // 2])
                state["manifest"] = True
                return "manifest: cut"
            if how == "run type":
                man["runs"][i] = rng.choice([5, None, "r0000", []])
            elif how == "run id":
                entry["id"] = rng.choice([5, "r0000; touch X", "../r0001", rid(j)])
            elif how == "run sha":
                entry["deck_sha256"] = rng.choice([None, "x", 5, ""])
            else:
                entry["params"] = rng.choice([[], "x", None, 5])
            m.write_text(json.dumps(man))
        state["manifest"] = True
        return f"manifest: {how}"
    if kind == "table":
        clear(sdir / "results.csv")
        (sdir / "results.csv").mkdir()
        state["table"] = True
        return "results.csv a directory"
    return f"{kind}: nothing to damage"


def flat_expected(summ: dict) -> dict[str, str]:
    from frictiondyn import sweep as sw

    flat: dict = {}
    sw._flatten("", summ, flat)
    return {k: str(sw._csv_value(v)) for k, v in flat.items()}


def run_case(seed: int, index: int, pristine: Path, cdir: Path) -> Outcome:
    from frictiondyn import sweep as sw

    rng = random.Random(f"collect/{seed}/{index}")
    shutil.copytree(pristine, cdir, symlinks=True)
    state = {"touched": set(), "nulls": {}, "values": {}, "manifest": False, "table": False}
    damages = [damage(rng, cdir, state) for _ in range(rng.randint(1, 4))]
    o = Outcome(index, damages)
    own = {i: json.loads((pristine / "runs" / f"{rid(i)}.summary.json").read_text())
           for i in range(N)}
    out = io.StringIO()
    code, error = None, None
    try:
        with contextlib.redirect_stdout(out), contextlib.redirect_stderr(io.StringIO()):
            code = sw.main(["collect", str(cdir)])
    except sw.SweepError as exc:
        error = str(exc)
    except BaseException as exc:  # noqa: BLE001 - what is looked for
        import traceback

        o.fail("traceback", f"{type(exc).__name__}: {exc} {traceback.format_exc()[-1200:]}")
        return o
    if state["manifest"] or state["table"]:
        name = "manifest.json" if state["manifest"] else "results.csv"
        if error is None:
            o.fail("wrong status", f"collect of a damaged {name} gave exit status {code}")
        elif "\n" in error or name not in error:
            o.fail("bad message", repr(error))
        else:
            o.kind = "clean error"
            o.details.append(error)
        return o
    if error is not None:
        o.fail("wrong status", f"collect refused: {error}")
        return o
    report = out.getvalue()
    try:
        with open(cdir / "results.csv", newline="") as fh:
            rows = list(csv.DictReader(fh))
    except OSError as exc:
        o.fail("no table", str(exc))
        return o
    if [r["run"] for r in rows] != [rid(i) for i in range(N)]:
        o.fail("no table", f"rows {[r['run'] for r in rows]}")
        return o
    for i, row in enumerate(rows):
        status = row["status"]
        if status not in ("done", "failed", "damaged", "missing"):
            o.fail("wrong status", f"{rid(i)}: status {status!r}")
        if float(row["friction.mu"]) != MUS[i]:
            o.fail("wrong pairing", f"{rid(i)}: friction.mu {row['friction.mu']}")
        path = cdir / "runs" / f"{rid(i)}.summary.json"
        if i not in state["touched"] and status != "done":
            o.fail("wrong status", f"{rid(i)}: its own summary, but {status}: {row['message']}")
        if status != "done":
            if status in ("failed", "damaged") and f"{status}: {rid(i)} (index {i})" not in report:
                o.fail("not reported", f"{rid(i)} {status} not named")
            if status == "missing" and "missing:" not in report:
                o.fail("not reported", f"{rid(i)} missing not named")
            if any(row.get(c) for c in CHECKED):
                o.fail("wrong pairing", f"{rid(i)} {status} with values")
            continue
        # done: the summary there is the run's own, and the row holds its values
        try:
            there = json.loads(path.read_text())
        except Exception as exc:  # noqa: BLE001
            o.fail("wrong status", f"{rid(i)} done with an unreadable summary ({exc})")
            continue
        if there.get("deck_sha256") != own[i]["deck_sha256"]:
            o.fail("wrong pairing", f"{rid(i)} done with the summary of another deck")
        expected = flat_expected({k: v for k, v in own[i].items()
                                  if k not in ("deck", "frictiondyn_version", "warnings",
                                               "deck_sha256")})
        changed = state["nulls"].get(i, set()) | state["values"].get(i, set())
        for c in CHECKED:
            base = c.split("[")[0]
            if base in changed:
                want = flat_expected({base: there[base]}).get(c, "")
            else:
                want = expected.get(c, "")
            if row.get(c, "") != want:
                o.fail("wrong pairing", f"{rid(i)} {c} = {row.get(c)!r}, its own {want!r}")
        for key in state["nulls"].get(i, ()):
            if row.get(key, row.get(f"{key}[1]")) != "NaN":
                o.fail("wrong status", f"{rid(i)} {key}: null written {row.get(key)!r}")
    all_done = all(r["status"] == "done" for r in rows)
    if (code == 0) != all_done:
        o.fail("wrong status", f"exit status {code} with {[r['status'] for r in rows]}")
    if not o.failures:
        o.kind = "table"
    return o


def campaign(count: int, seed: int, first: int = 0, keep: Path | None = None,
             only: int | None = None, progress=None) -> list[Outcome]:
    outcomes = []
    indices = [only] if only is not None else range(first, first + count)
    with tempfile.TemporaryDirectory(prefix="frictiondyn-collectfuzz-") as tmp:
        pristine = make_pristine(Path(tmp) / "pristine")
        for i in indices:
            cdir = Path(tmp) / f"case{i}"
            t0 = time.monotonic()
            o = run_case(seed, i, pristine, cdir)
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
        "tables": kinds["table"],
        "clean errors": kinds["clean error"],
        **{f: fails[f] for f in FAILURES},
        "failing cases": sum(1 for o in outcomes if o.failures),
        "longest case [s]": round(max((o.seconds for o in outcomes), default=0.0), 2),
        "failures": [{"case": o.index, "damages": o.damages, "details": o.details}
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
    print(f"collect fuzz campaign: seed {args.seed}, {rep['runs']} cases "
          f"(tests/fuzz/collect_damage.py --count {args.count} --seed {args.seed} "
          f"--first {args.first})")
    for key in ["runs", "tables", "clean errors", *FAILURES, "wall time [s]"]:
        print(f"  {key:16s} {rep[key]}")
    for f in rep["failures"][:50]:
        print(f"case {f['case']} ({'; '.join(f['damages'])}):")
        for d in f["details"]:
            print(f"    {d[:400]}")
    if args.case is not None:
        for o in outcomes:
            print(f"case {o.index}: {o.kind or 'FAIL'}: {'; '.join(o.damages)}")
            for d in o.details:
                print(f"    {d[:400]}")
    return 1 if rep["failing cases"] else 0


if __name__ == "__main__":
    sys.path.insert(0, os.fspath(Path(__file__).resolve().parent))
    sys.exit(main())
