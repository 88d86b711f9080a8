#!/usr/bin/env python3
"""Band campaign: does a run report the velocity-law band forces its step leaves alternating?

    python tests/fuzz/band_campaign.py --first 1 --last 5000     # docs/studies.md's figures (~3 min)
    python tests/fuzz/band_campaign.py --report                  # the tables of --out again

Every seed of tests/fuzz/physics.py in the range with a velocity-law device (P mu(eps) > 0)
is run by the executable at its n1, a history row every dt1 step, and again at n1 m (rows
every m steps, so at the same times), m the smallest power of two that brings every such
device's x = (P mu(eps) / eps) dt1 / (2 m_r) below 0.5: the band damped by the step. There
is no reference when m > 64; with m = 1 the run is its own reference (counted apart). The
run's report is its summary's `band_alternation_N` (a device is flagged when it is > 0,
docs/theory.md section 6). Against the reference, per velocity-law device, in units of
P mu(eps): the history error (the largest |F - F_ref| over the common rows, and over the
rows where the device is in its band), its ratio to band_alternation_N, and the peaks that
move by more than 5 % (the device's |F|, any DOF's |aabs| and |u|).

Recall counts the devices whose error alternates where their own force does: at a row,
the error's second difference has changed sign three times in a row, each above 4 x 0.05
P mu (the detector's rule, without its band gate), and so has the run's own force; the row
is "in" the band when the three rows of the difference are, "out" when none is, else "edge".
Results go to --out as JSON lines, one a seed; a campaign resumes where it stopped.
"""

from __future__ import annotations

import argparse
import json
import shutil
import subprocess
import sys
import tempfile
from multiprocessing import Pool
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
import physics  # noqa: E402

LIMIT = 0.05  # a share of P mu: the history error called wrong, the detector's floor
MAX_REFINE = 64  # the largest m tried for the reference
TIMEOUT = (120.0, 180.0)  # seconds: the run, the reference
EXE = ""  # set in main (a copy, so that a rebuild during the campaign is harmless)
KEEP = (
    "band_x",
    "band_alternation_N",
    "band_alternation_s",
    "peak_force_N",
    "peak_aabs_mps2",
    "peak_u_m",
    "dt1_s",
)


def mu_at(dev: dict, v: float) -> float:
    """mu(|v|) as fd_friction_velocity's sliding_mu."""
    if dev.get("mu_law") == "exponential":
        return dev["mu_max"] - (dev["mu_max"] - dev["mu_min"]) * np.exp(-dev["mu_rate"] * abs(v))
    if dev.get("mu_law") == "table":
        return float(np.interp(abs(v), dev["tv"], dev["tmu"]))
    return dev["mu"]


def band_devices(c: dict) -> list[tuple[int, float, float]]:
    """(device number, P mu(eps), x at the deck's n1 alone) of the velocity-law devices."""
    dt1 = c["exc"]["dt_record"] / c["integ"]["n1"]
    out = []
    for k, d in enumerate(c["devs"], 1):
        if d["law"] != "velocity":
            continue
        eps = d.get("eps", 1.0e-3)
        pmu = d["p"] * mu_at(d, eps)
        if pmu <= 0.0:
            continue
        mi = c["mass"][d["i"] - 1]
        mr = mi if d["j"] == 0 else mi * c["mass"][d["j"] - 1] / (mi + c["mass"][d["j"] - 1])
        out.append((k, pmu, pmu / eps * dt1 / (2.0 * mr)))
    return out


def run_deck(c: dict, n1: int, every: int, timeout: float) -> dict:
    """The deck at n1, a row every `every` steps: its summary, history and warnings."""
    where = Path(tempfile.mkdtemp(prefix=f"band_campaign_{c['seed']}_"))
    try:
        deck = physics.deck_text(c, "step", n1=n1).replace(
            "output_every = 1", f"output_every = {every}"
        )
        (where / "deck.nml").write_text(deck)
        if c["exc"]["type"] == "record":
            (where / "rec.txt").write_text(physics.record_text(c))
        try:
            p = subprocess.run(
                [EXE, "deck.nml"], cwd=where, capture_output=True, text=True, timeout=timeout
            )
        except subprocess.TimeoutExpired:
            return {"rc": "timeout"}
        if p.returncode != 0:
            return {"rc": p.returncode, "err": p.stderr[-300:]}
        summary = json.loads((where / "out" / "run.summary.json").read_text())
        with open(where / "out" / "run.csv") as fh:
            names = [h.split("[")[0] for h in fh.readline().strip().split(",")]
            data = np.loadtxt(fh, delimiter=",", ndmin=2)
        warnings = [ln for ln in p.stderr.splitlines() if ln.startswith("frictiondyn: warning:")]
        return {
            "rc": 0,
            "s": {k: summary[k] for k in KEEP},
            "h": {n: data[:, i] for i, n in enumerate(names)},
            "other_warning": any("alternates step to step" not in w for w in warnings),
        }
    finally:
        shutil.rmtree(where, ignore_errors=True)


def alternating_rows(y: np.ndarray, floor: float) -> np.ndarray:
    """Rows at which y's second difference has changed sign three times in a row, the four
    differences each above 4 floor (the detector's rule, on every row)."""
    d = np.zeros(len(y))
    d[2:] = y[2:] - 2 * y[1:-1] + y[:-2]
    rows = np.zeros(len(y), bool)
    run = 0
    for n in range(3, len(y)):
        run = run + 1 if d[n] * d[n - 1] < 0 and min(abs(d[n]), abs(d[n - 1])) > 4 * floor else 0
        rows[n] = run >= 3
    return rows


def rel(a: float, b: float) -> float:
    return abs(a - b) / abs(b) if b else float(a != 0.0)


def common_rows(bh: dict, rh: dict) -> tuple[np.ndarray, np.ndarray]:
    """The rows of two histories at the same times: their indices in each."""
    pick = np.clip(np.searchsorted(rh["t"], bh["t"] - 1e-9 * (1 + bh["t"])), 0, len(rh["t"]) - 1)
    common = np.abs(rh["t"][pick] - bh["t"]) <= 1e-9 * (1 + bh["t"])
    return np.nonzero(common)[0], pick[common]


def compare(base: dict, ref: dict, devices: list) -> dict:
    """The base run's errors against the reference at their common rows."""
    bh, rh = base["h"], ref["h"]
    ib, ir = common_rows(bh, rh)
    out = {"dev": {}}
    for k, pmu, _ in devices:
        f = bh[f"F{k}"][ib]
        err = (f - rh[f"F{k}"][ir]) / pmu
        inband = bh[f"phase{k}"][ib] == 0
        rows = alternating_rows(err, LIMIT) & alternating_rows(f / pmu, LIMIT)
        where = {}
        for n in np.nonzero(rows)[0]:
            inside = int(inband[n]) + int(inband[n - 1]) + int(inband[n - 2])
            where["in" if inside == 3 else "out" if inside == 0 else "edge"] = True
        out["dev"][str(k)] = {
            "error": float(np.max(np.abs(err))) if len(err) else 0.0,
            "error_band": float(np.max(np.abs(err[inband]))) if inband.any() else 0.0,
            "alternating": sorted(where),
            "peak_F": rel(base["s"]["peak_force_N"][k - 1], ref["s"]["peak_force_N"][k - 1]),
        }
    out["peak_aabs"] = max(
        rel(a, b) for a, b in zip(base["s"]["peak_aabs_mps2"], ref["s"]["peak_aabs_mps2"])
    )
    out["peak_u"] = max(rel(a, b) for a, b in zip(base["s"]["peak_u_m"], ref["s"]["peak_u_m"]))
    return out


def one(seed: int) -> dict:
    c = physics.gen_case(seed)
    devices = band_devices(c)
    n1 = c["integ"]["n1"]
    m = 1
    while max(x for _, _, x in devices) / m >= 0.5 and m <= MAX_REFINE:
        m *= 2
    rec = {"seed": seed, "m": m if m <= MAX_REFINE else None}
    base = run_deck(c, n1, 1, TIMEOUT[0])
    rec["rc"] = base["rc"]
    if base["rc"] != 0:
        return rec
    s = base["s"]
    rec["dt1"] = s["dt1_s"]
    rec["other_warning"] = base["other_warning"]
    rec["dev"] = {
        str(k): {
            "pmu": pmu,
            "band_x": s["band_x"][k - 1],
            "A": s["band_alternation_N"][k - 1] / pmu,
            "time": s["band_alternation_s"][k - 1],
        }
        for k, pmu, _ in devices
    }
    if m == 1:
        rec["self"] = True
    elif m <= MAX_REFINE:
        ref = run_deck(c, n1 * m, m, TIMEOUT[1])
        if ref["rc"] == 0:
            rec["cmp"] = compare(base, ref, devices)
        else:
            rec["ref_rc"] = ref["rc"]
    return rec


def quartiles(v) -> str:
    if not len(v):
        return "-"
    q = np.percentile(v, [0, 25, 50, 75, 100])
    return " / ".join(f"{x:.3g}" for x in q)


def share(a: int, b: int) -> str:
    return f"{a} of {b} ({a / b:.2f})" if b else f"{a} of 0"


def report(path: Path) -> None:
    recs = [json.loads(x) for x in path.read_text().splitlines() if x.strip()]
    ran = [r for r in recs if r["rc"] == 0]
    print(
        f"seeds with a velocity-law device: {len(recs)}; run: {len(ran)}; refused or failed: "
        f"{len(recs) - len(ran)}; own reference (m = 1): {sum('self' in r for r in ran)}; "
        f"no reference (m > {MAX_REFINE}): {sum(r['m'] is None for r in ran)}"
    )
    devs = [(r, k, d) for r in ran for k, d in r["dev"].items()]
    flagged = [(r, k, d) for r, k, d in devs if d["A"] > 0]
    runs = {r["seed"]: r for r, _, _ in flagged}
    print(
        f"flagged: {len(runs)} runs, {len(flagged)} devices (of {len(ran)} runs, "
        f"{len(devs)} devices); with a reference: {sum('cmp' in r for r in runs.values())} runs, "
        f"{sum('cmp' in r for r, _, _ in flagged)} devices; "
        f"own reference: {sum('self' in r for r, _, _ in flagged)}"
    )
    ref = [(r, d, r["cmp"]["dev"][k]) for r, k, d in devs if "cmp" in r]
    fl = [(r, d, e) for r, d, e in ref if d["A"] > 0]
    un = [(r, d, e) for r, d, e in ref if d["A"] == 0]
    for name, group in (("flagged", fl), ("not flagged", un)):
        err = [e["error"] for _, _, e in group]
        print(
            f"{name} devices with a reference: error > {LIMIT} P mu: "
            f"{share(sum(x > LIMIT for x in err), len(err))}; "
            f"median error {np.median(err) if err else 0:.3g} P mu"
        )
    print(
        f"flagged: error / band_alternation_N (min / q25 / median / q75 / max): "
        f"{quartiles([e['error'] / d['A'] for _, d, e in fl])}; in the band: "
        f"{quartiles([e['error_band'] / d['A'] for _, d, e in fl])}"
    )
    for name, sel in (
        ("flagged", [r for r in runs.values() if "cmp" in r]),
        ("not flagged", [r for r in ran if "cmp" in r and r["seed"] not in runs]),
    ):
        moved = [
            max(r["cmp"]["peak_aabs"], max(e["peak_F"] for e in r["cmp"]["dev"].values())) > LIMIT
            for r in sel
        ]
        print(
            f"{name} runs: a peak |F| or |aabs| more than 5 % off: {share(sum(moved), len(sel))}; "
            f"a peak |u|: {sum(r['cmp']['peak_u'] > LIMIT for r in sel)}"
        )
    alt = [(d, e) for _, d, e in ref if e["error"] > LIMIT and e["alternating"]]
    print(
        f"recall (error > {LIMIT} P mu, alternating where the force does): "
        f"{share(sum(d['A'] > 0 for d, _ in alt), len(alt))}"
    )

    def place(rows: list[str]) -> str:
        return (
            "in the band"
            if "in" in rows
            else "at its edge only"
            if "edge" in rows
            else "outside only"
        )

    for where in ("in the band", "at its edge only", "outside only"):
        sel = [d for d, e in alt if place(e["alternating"]) == where]
        print(f"  alternating {where}: {share(sum(d['A'] > 0 for d in sel), len(sel))}")
    print(f"flagged devices with band_x < 1: {sum(d['band_x'] < 1 for _, _, d in flagged)}")
    steps = [d["time"] / r["dt1"] for r, _, d in flagged]
    print(
        f"flagged: band_alternation_s (s) {quartiles([d['time'] for _, _, d in flagged])}; "
        f"under 10 dt1: {sum(x < 10 for x in steps)}, under 1 dt1: {sum(x < 1 for x in steps)}"
    )
    print(
        f"flagged runs with no other warning: {sum(not r['other_warning'] for r in runs.values())}"
    )


def main() -> int:
    global EXE
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--first", type=int, default=1)
    ap.add_argument("--last", type=int, default=5000)
    ap.add_argument("--jobs", type=int, default=2)
    ap.add_argument("--out", type=Path, default=Path("band_campaign.jsonl"))
    ap.add_argument("--report", action="store_true", help="print the tables of --out and stop")
    args = ap.parse_args()
    if not args.report:
        import frictiondyn

        work = Path(tempfile.mkdtemp(prefix="band_campaign_exe_"))
        EXE = str(shutil.copy2(frictiondyn.executable(), work / "frictiondyn"))
        done = set()
        if args.out.exists():
            done = {json.loads(x)["seed"] for x in args.out.read_text().splitlines() if x.strip()}
        seeds = [
            s
            for s in range(args.first, args.last + 1)
            if s not in done and band_devices(physics.gen_case(s))
        ]
        with args.out.open("a") as f, Pool(args.jobs) as pool:
            for rec in pool.imap_unordered(one, seeds, chunksize=4):
                f.write(json.dumps(rec) + "\n")
                f.flush()
        shutil.rmtree(work, ignore_errors=True)
    report(args.out)
    return 0


if __name__ == "__main__":
    sys.exit(main())
