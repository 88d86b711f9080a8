#!/usr/bin/env python3
"""Step campaign: does a run's own report say when its step is too coarse for a record?

    python tests/fuzz/step_campaign.py --first 1 --last 200000    # docs/studies.md's figures (~25 min)
    python tests/fuzz/step_campaign.py --first 1 --last 5000      # a short one (~40 s)

Every seed of tests/fuzz/physics.py in the range whose table motion is a record is run by the
executable twice, with refinement 'step': at its n1 and at 16 n1 (the reference; no other
change). A run counts as wrong when the peak |u| of a DOF is more than 5 % from the
reference's (and, in a second criterion, more than 10 %). The campaign then counts, for the
record step check (`record_resolution = "unresolved"`, docs/theory.md section 6), the runs
it flags, its precision (flagged runs that are wrong) and its recall (wrong runs it flags),
overall and apart for runs with and without a stick-slip transition, and the wrong runs that
it alone reports among the run's reports (mode_resolution, stick_resolution, energy_balance,
correctness violations). Results go to --out as JSON lines, one a seed; a campaign resumes
where it stopped, and `--report` prints the tables of a file again without running.
"""

from __future__ import annotations

import argparse
import json
import os
import shutil
import subprocess
import sys
import tempfile
from multiprocessing import Pool
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
import physics  # noqa: E402

KEEP = ("n_dof", "n_devices", "peak_u_m", "record_step_error", "record_step_error_stuck",
        "record_step_error_free", "record_step_system", "record_resolution", "mode_resolution",
        "stick_resolution",
        "energy_balance", "correctness_violations", "stick_to_slip", "slip_to_stick",
        "slip_reversals")
REFINE = 16           # the reference's n1 is REFINE times the deck's
TIMEOUT = (300.0, 60.0)  # seconds: the run, the reference
EXE = ""              # set in main (a copy, so that a rebuild during the campaign is harmless)


def run_deck(case: dict, n1: int, timeout: float) -> dict:
    where = Path(tempfile.mkdtemp(prefix=f"step_campaign_{case['seed']}_"))
    try:
        deck = physics.deck_text(case, "step", n1=n1).replace("output_every = 1", "output_every = 0")
        (where / "deck.nml").write_text(deck)
        (where / "rec.txt").write_text(physics.record_text(case))
        try:
            p = subprocess.run([EXE, "deck.nml"], cwd=where, capture_output=True, text=True,
                               timeout=timeout)
        except subprocess.TimeoutExpired:
            return {"n1": n1, "rc": "timeout"}
        out = {"n1": n1, "rc": p.returncode, "record_warning": "record_step_error" in p.stderr}
        if p.returncode == 0:
            summary = json.loads((where / "out" / "run.summary.json").read_text())
            out["s"] = {k: summary.get(k) for k in KEEP}
        else:
            out["err"] = p.stderr[-300:]
        return out
    finally:
        shutil.rmtree(where, ignore_errors=True)


def one(seed: int) -> dict:
    case = physics.gen_case(seed)
    n1 = case["integ"]["n1"]
    runs = [run_deck(case, n1, TIMEOUT[0])]
    if runs[0]["rc"] == 0:
        runs.append(run_deck(case, REFINE * n1, TIMEOUT[1]))
    return {"seed": seed, "ic": bool(case["ic"]), "runs": runs}


def peak_error(a: float, b: float) -> float:
    if b == 0.0:
        return 0.0 if a == 0.0 else float("inf")
    return abs(a / b - 1.0)


def report(path: Path) -> None:
    rows = []
    failed = mismatch = 0
    for line in path.read_text().splitlines():
        r = json.loads(line)
        if len(r["runs"]) < 2 or any(x["rc"] != 0 for x in r["runs"]):
            failed += 1
            continue
        s, ref = r["runs"][0]["s"], r["runs"][1]["s"]
        flag = s["record_resolution"] == "unresolved"
        mismatch += flag != r["runs"][0]["record_warning"]
        others = (s["mode_resolution"] == "unresolved" or s["stick_resolution"] == "unresolved"
                  or s["energy_balance"] != "closed" or s["correctness_violations"] > 0)
        slid = any(s["stick_to_slip"]) or any(s["slip_to_stick"]) or any(s["slip_reversals"])
        err = max(peak_error(a, b) for a, b in zip(s["peak_u_m"], ref["peak_u_m"]))
        rows.append((flag, others, slid, r["ic"], err))
    print(f"{path}: {len(rows)} pairs of runs; {failed} seeds without both runs "
          f"(a refused deck or a reference past its time limit); warning without the verdict "
          f"or the reverse: {mismatch}")
    print("| runs | criterion | runs | wrong | flagged | flagged and wrong | precision | recall "
          "| wrong runs only it reports |")
    print("|---|---|---|---|---|---|---|---|---|")
    subsets = (("all", lambda r: True), ("no transition", lambda r: not r[2]),
               ("a transition", lambda r: r[2]), ("initial conditions", lambda r: r[3]))
    for limit in (0.05, 0.10):
        for name, keep in subsets:
            sub = [r for r in rows if keep(r)]
            wrong = [r for r in sub if r[4] > limit]
            flagged = [r for r in sub if r[0]]
            hit = [r for r in wrong if r[0]]
            alone = [r for r in hit if not r[1]]
            prec = f"{len(hit) / len(flagged):.2f}" if flagged else "-"
            rec = f"{len(hit) / len(wrong):.2f}" if wrong else "-"
            print(f"| {name} | peak u off by > {limit:.0%} | {len(sub)} | {len(wrong)} | "
                  f"{len(flagged)} | {len(hit)} | {prec} | {rec} | {len(alone)} |")


def main() -> int:
    global EXE
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--first", type=int, default=1, help="first seed")
    ap.add_argument("--last", type=int, default=5000, help="last seed")
    ap.add_argument("--jobs", type=int, default=os.cpu_count() or 1)
    ap.add_argument("--out", type=Path, default=Path("out/campaigns/step_campaign.jsonl"))
    ap.add_argument("--report", action="store_true", help="print the tables of --out, run nothing")
    args = ap.parse_args()
    if not args.report:
        import frictiondyn

        args.out.parent.mkdir(parents=True, exist_ok=True)
        done = set()
        if args.out.exists():
            done = {json.loads(x)["seed"] for x in args.out.read_text().splitlines()}
        seeds = [s for s in range(args.first, args.last + 1)
                 if s not in done and physics.gen_case(s)["exc"]["type"] == "record"]
        with tempfile.TemporaryDirectory() as tmp:
            EXE = str(Path(tmp) / "frictiondyn")
            shutil.copy2(frictiondyn.executable(), EXE)
            with args.out.open("a") as f, Pool(args.jobs) as pool:
                for rec in pool.imap_unordered(one, seeds, chunksize=8):
                    f.write(json.dumps(rec) + "\n")
                    f.flush()
    report(args.out)
    return 0


if __name__ == "__main__":
    sys.exit(main())
