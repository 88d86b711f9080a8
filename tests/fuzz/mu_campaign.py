#!/usr/bin/env python3
"""Speed-dependent mu campaign: how far is a run from the same deck at a much finer step?

    python tests/fuzz/mu_campaign.py --first 1 --last 3000        # docs/studies.md 1.2 (~2 min)
    python tests/fuzz/mu_campaign.py --exe old/frictiondyn --out old.jsonl   # another build

Every seed of tests/fuzz/physics.py in the range with a velocity-law device whose mu depends
on the sliding speed (mu_law 'exponential' or 'table') is run by the executable at its n1,
at 2 n1 and at 32 n1 (the reference), a history row every dt1 of the deck's n1, so at the
same times. Per such device, in units of its capacity P mu_largest: the largest |F - F_ref|
over the rows where the run and the reference slide in the same phase, and did so two rows
before and after (a transition a step apart from the reference's gives up to 2 P mu at one
row, whatever the law of mu: those rows are left out). Per run, the largest relative error
of a peak |u| and of a peak |absolute acceleration| against the reference. The report
prints their medians and upper percentiles at n1 and 2 n1, and the median ratio of the force
errors at 2 n1 and n1 (0.5: first order in the step, 0.25: second). Results go to --out as
JSON lines, one a seed.
"""

from __future__ import annotations

import argparse
import json
import shutil
import sys
import tempfile
from multiprocessing import Pool
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
import band_campaign  # noqa: E402
import physics  # noqa: E402

REFINE = 32  # the reference's n1, times the deck's
TIMEOUT = 300.0  # seconds a run


def followed(c: dict) -> list[tuple[int, dict]]:
    """(device number, device) of the velocity-law devices with a speed-dependent mu."""
    return [
        (k, d)
        for k, d in enumerate(c["devs"], 1)
        if d["law"] == "velocity" and d.get("mu_law") in ("exponential", "table")
    ]


def capacity(d: dict) -> float:
    """P times the largest mu of the device's law (fd_model's largest_mu)."""
    if d.get("mu_law") == "exponential":
        return d["p"] * max(d["mu_max"], d["mu_min"])
    return d["p"] * max(d["tmu"])


def errors(run: dict, ref: dict, devices: list) -> dict:
    """The run's errors against the reference at their common rows."""
    h, r = run["h"], ref["h"]
    ib, ir = band_campaign.common_rows(h, r)
    out = {"F": {}}
    for k, d in devices:
        cap = capacity(d)
        if cap <= 0.0:
            continue
        ph, pr = h[f"phase{k}"][ib], r[f"phase{k}"][ir]
        same = (ph == pr) & (ph != 0)
        keep = same.copy()
        for s in (1, 2):
            keep[s:] &= same[:-s]
            keep[:-s] &= same[s:]
        err = np.abs(h[f"F{k}"][ib] - r[f"F{k}"][ir]) / cap
        out["F"][str(k)] = float(err[keep].max()) if keep.any() else None
    for key, name in (("u", "peak_u_m"), ("aabs", "peak_aabs_mps2")):
        out[key] = max(band_campaign.rel(a, b) for a, b in zip(run["s"][name], ref["s"][name]))
    return out


def one(seed: int) -> dict:
    c = physics.gen_case(seed)
    n1 = c["integ"]["n1"]
    rec: dict = {"seed": seed}
    runs = {}
    for m in (1, 2, REFINE):
        runs[m] = band_campaign.run_deck(c, n1 * m, m, TIMEOUT)
        if runs[m]["rc"] != 0:
            rec["rc"] = [m, runs[m]["rc"], runs[m].get("err", "")]
            return rec
    for m in (1, 2):
        rec[str(m)] = errors(runs[m], runs[REFINE], followed(c))
    return rec


def pct(v) -> str:
    q = np.percentile(v, [50, 90, 99, 100]) if len(v) else []
    return " / ".join(f"{x:.2g}" for x in q) or "-"


def report(path: Path) -> None:
    rows = [json.loads(x) for x in path.read_text().splitlines() if x.strip()]
    ran = [r for r in rows if "rc" not in r]
    print(f"{len(rows)} decks with a speed-dependent mu, {len(ran)} ran at n1, 2 n1 and 32 n1")
    print("(median / 90 % / 99 % / largest)")
    for m in ("1", "2"):
        f = [e for r in ran for e in r[m]["F"].values() if e is not None]
        print(
            f"  n1 x {m}: force error / P mu on sliding rows {pct(f)} "
            f"({sum(e > 0.05 for e in f)} of {len(f)} devices > 0.05); "
            f"peak |u| {pct([r[m]['u'] for r in ran])}; "
            f"peak |aabs| {pct([r[m]['aabs'] for r in ran])}"
        )
    ratio = [
        r["2"]["F"][k] / e
        for r in ran
        for k, e in r["1"]["F"].items()
        if e is not None and e > 1e-3 and r["2"]["F"][k] is not None
    ]
    if ratio:
        print(f"  force error at 2 n1 / at n1, median of {len(ratio)}: {np.median(ratio):.2f}")


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--first", type=int, default=1)
    ap.add_argument("--last", type=int, default=3000)
    ap.add_argument("--jobs", type=int, default=2)
    ap.add_argument("--exe", type=Path, help="the executable (default: the installed one)")
    ap.add_argument("--out", type=Path, default=Path("mu_campaign.jsonl"))
    ap.add_argument("--report", action="store_true", help="print the report of --out and stop")
    args = ap.parse_args()
    if not args.report:
        if args.exe is None:
            import frictiondyn

            args.exe = Path(frictiondyn.executable())
        work = Path(tempfile.mkdtemp(prefix="mu_campaign_exe_"))
        # a copy, so that a rebuild during the campaign is harmless; the workers inherit it
        band_campaign.EXE = str(shutil.copy2(args.exe, work / "frictiondyn"))
        band_campaign.KEEP = ("peak_u_m", "peak_aabs_mps2")
        seeds = [s for s in range(args.first, args.last + 1) if followed(physics.gen_case(s))]
        with args.out.open("w") as f, Pool(args.jobs) as pool:
            for rec in pool.imap_unordered(one, seeds, chunksize=4):
                f.write(json.dumps(rec) + "\n")
        shutil.rmtree(work, ignore_errors=True)
    report(args.out)
    return 0


if __name__ == "__main__":
    sys.exit(main())
