#!/usr/bin/env python3
"""AT2 header and body fuzzer: mutated PEER NGA records fed to the executable's reader.

    python tests/fuzz/at2_fuzz.py --count 5000 --seed 1     # a long campaign, by request
    python tests/fuzz/at2_fuzz.py --case 17 --seed 1        # one case, its file printed

Each case is a PEER-like record (a seeded body of 5 to 40 samples in one of the layouts
real files have: 5E15.7 as this project writes them, PEER's 5E14.7 without the leading
zero, or values separated freely; line 4 in the NPTS= / old / colon spelling) with 1 to 3
mutations, each of which either keeps the record's meaning (tabs in line 4, CRLF line
ends, trailing blanks, blank lines, units spelled otherwise, a value moved within its free
format) or breaks one documented rule (docs/namelist.md, record formats: NPTS or DT given
twice, a value after DT on line 4, NPTS off by one, a number cut inside, a value moved out
of its fixed-width field, a tab between fixed-width fields, units that are not known).
The expected outcome follows: a record that keeps its meaning must run and its table
acceleration (the history's ag column) must be exactly the file's values times the unit's
factor (within the round-off of the step times, 1e-12); a record that breaks a rule must be refused (exit status 1) with a message naming
the record file, a line and the rule (one of the phrases the mutation's rule is told with)
and no output left. Anything else is a failure: a crash, a record read with other values,
a refusal of a valid record, a refusal that names no line or another rule.
"""

from __future__ import annotations

import argparse
import random
import re
import subprocess
import sys
import tempfile
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

G = 9.80665
FACTOR = {"G": G, "CM/S/S": 0.01, "CM/SEC/SEC": 0.01, "GAL": 0.01, "M/S/S": 1.0, "MM/S2": 0.001}

DECK = """&model
  n_dof = 1
  mass = 1000.0
/
&springs
  n_springs = 1, node_i = 1, node_j = 0, k = 4.0e5
/
&damping
  damping_type = 'rayleigh', rayleigh_a0 = 0.1
/
&excitation
  excitation_type = 'record', record_file = 'rec.AT2'
/
&integration
  n1 = 1
/
&output
  name = 'case'
/
"""


@dataclass
class Case:
    index: int
    lines: list[str]                   # the file's lines, without line ends
    body: list[float]                  # the values it holds (when it is valid)
    factor: float = G                  # m/s2 per unit of the file
    layout: str = "e15"                # 'e15', 'e14' (fixed-width) or 'free'
    spelling: str = "new"
    mutations: list[str] = field(default_factory=list)
    # a broken rule: (line number, phrases of which the message must hold one)
    broken: list[tuple[int, tuple[str, ...]]] = field(default_factory=list)
    eol: str = "\n"

    def text(self) -> str:
        return self.eol.join(self.lines) + self.eol


def fmt(x: float, layout: str) -> str:
    if layout == "e15":
        return f"{x:15.7E}"
    if layout == "e14":  # PEER's: no leading zero, '.1187585E-02'
        m, e = f"{x:.6E}".split("E")
        mant = m.replace(".", "")
        sign = "-" if x < 0 else ""
        digits = mant.lstrip("-")
        exp = int(e) + 1
        return f"{sign}.{digits}E{exp:+03d}".rjust(14)
    return repr(round(x, 6))


def base(index: int, rng: random.Random) -> Case:
    n = rng.randint(5, 40)
    layout = rng.choice(["e15", "e14", "free"])
    spelling = rng.choice(["new", "old", "colon"])
    raw = [rng.uniform(-0.5, 0.5) for _ in range(n)]
    toks = [fmt(x, layout) for x in raw]
    values = [float(t) for t in toks]
    dt = rng.choice(["  .0100", ".0050", "0.02"])
    line4 = {"new": f"NPTS=  {n}, DT= {dt} SEC", "old": f"  {n}   {dt}   NPTS, DT",
             "colon": f"NPTS, DT: {n} {dt} SEC"}[spelling]
    head = ["PEER NGA STRONG MOTION DATABASE RECORD", f"FUZZ EVENT {index}, STATION X, 090",
            "ACCELERATION TIME SERIES IN UNITS OF G", line4]
    if layout == "free":
        rows, k = [], 0
        while k < n:
            m = rng.randint(1, 6)
            rows.append(" ".join(toks[k:k + m]))
            k += m
    else:
        rows = ["".join(toks[i:i + 5]) for i in range(0, n, 5)]
    return Case(index, head + rows, values, G, layout, spelling)


# ------------------------------------------------------------------------- mutations
# each takes the case and the random source, changes the case, and says what it did

def tabs_in_line_4(c: Case, rng: random.Random) -> None:
    c.lines[3] = "\t".join(c.lines[3].split())
    c.mutations.append("tabs in line 4")


def crlf(c: Case, rng: random.Random) -> None:
    c.eol = "\r\n"
    c.mutations.append("CRLF line ends")


def trailing_blanks(c: Case, rng: random.Random) -> None:
    k = rng.randrange(4, len(c.lines))
    c.lines[k] += " " * rng.randint(1, 4)
    c.mutations.append(f"trailing blanks on line {k + 1}")


def blank_line_in_body(c: Case, rng: random.Random) -> None:
    k = rng.randrange(5, len(c.lines) + 1)
    c.lines.insert(k, "")
    # the rules broken on the lines after it are now one line further
    c.broken = [(line + 1 if line > k else line, p) for line, p in c.broken]
    c.mutations.append(f"blank line {k + 1}")


def units(c: Case, rng: random.Random) -> None:
    if any("units" in m for m in c.mutations):
        return
    u = rng.choice([*FACTOR, "FT/S2", "FURLONGS"])
    c.lines[2] = f"ACCELERATION TIME SERIES IN UNITS OF {u}"
    if u in FACTOR:
        c.factor = FACTOR[u]
    else:
        c.broken.append((3, ("units of", "not units")))
    c.mutations.append(f"units {u}")


def key_twice(c: Case, rng: random.Random) -> None:
    key = rng.choice(["NPTS", "DT"])
    if c.spelling == "new":
        c.lines[3] += f", {key}= {len(c.body) if key == 'NPTS' else '.0100'}"
    else:
        c.lines[3] += f" {key}"
    c.broken.append((4, (f"{key} is given twice",)))
    c.mutations.append(f"{key} twice")


def value_after_dt(c: Case, rng: random.Random) -> None:
    c.lines[3] += rng.choice(["  1.4126416E-01", " 0.5", "\t7"])
    c.broken.append((4, ("after NPTS and DT",)))
    c.mutations.append("a value after DT")


def npts_off(c: Case, rng: random.Random) -> None:
    n = len(c.body)
    m = n + rng.choice([-1, 1])
    if m < 1 or any("NPTS" in x for x in c.mutations):
        return
    c.lines[3] = c.lines[3].replace(f"{n}", f"{m}", 1)
    if m > n:
        c.broken.append((0, ("line 4 declares NPTS",)))   # names line 4 after the count
    else:
        c.broken.append((last_values_line(c) + 1, ("beyond the NPTS",)))
    c.mutations.append(f"NPTS {m} for {n} values")


def last_values_line(c: Case) -> int:
    return max(k for k in range(4, len(c.lines)) if c.lines[k].strip())


def cut_last_number(c: Case, rng: random.Random) -> None:
    """The file cut inside its last number (a truncated download)."""
    if any("cut" in m for m in c.mutations):
        return
    n = last_values_line(c)
    c.lines = c.lines[:n + 1]   # nothing follows a cut
    last = c.lines[-1].rstrip()
    tok = last.split()[-1]
    if len(tok) < 2:
        return
    k = rng.randint(1, len(tok) - 1)   # keep at least one character of it
    cut = last[:len(last) - k]
    if c.layout == "free":
        # a free-format body has no fields: the shorter number is what the file says,
        # when it is a number at all
        try:
            c.body[-1] = float(cut.split()[-1])
        except ValueError:
            c.broken.append((len(c.lines), ("is not a number", "is NaN")))
    else:
        c.broken.append((len(c.lines), ("not at the end of a field", "is not a number")))
    c.lines[-1] = cut
    c.mutations.append(f"last number cut by {k}")
    # nothing may follow a cut file
    c.eol_final = ""  # type: ignore[attr-defined]


def shift_value(c: Case, rng: random.Random) -> None:
    """One value of a body line moved one column left (its field's padding to its right)."""
    # not line 5: it sets the fields (moved there, it would set none)
    body = [k for k in range(5, len(c.lines)) if len(c.lines[k].split()) >= 2]
    if not body:
        return
    k = rng.choice(body)
    s = c.lines[k]
    tokens = list(re.finditer(r"\S+", s))  # split() splits at tabs too: find the same tokens
    j = rng.randrange(1, len(tokens))
    pos, end = tokens[j].start(), tokens[j].end()
    if s[pos - 2] != " ":
        return   # one blank before it: moved, it would be glued to the value before
    c.lines[k] = s[:pos - 1] + s[pos:end] + " " + s[end:]
    if c.layout != "free":
        c.broken.append((k + 1, ("not at the end of a field",)))
    c.mutations.append(f"value {j + 1} of line {k + 1} moved left")


def tab_between_values(c: Case, rng: random.Random) -> None:
    body = [k for k in range(5, len(c.lines)) if len(c.lines[k].split()) >= 2]
    if not body:
        return
    k = rng.choice(body)
    toks = c.lines[k].split()
    c.lines[k] = toks[0] + "\t" + "  ".join(toks[1:])
    if c.layout != "free":
        c.broken.append((k + 1, ("a tab or a comma",)))
    c.mutations.append(f"a tab on line {k + 1}")


def cut_middle_number(c: Case, rng: random.Random) -> None:
    """A number of an inner line that lost its exponent (fixed-width layouts only)."""
    if c.layout == "free" or len(c.lines) < 7:
        return
    k = rng.randrange(5, len(c.lines) - 1)
    s = c.lines[k]
    e = s.find("E")
    if e < 0:
        return
    c.lines[k] = s[:e] + " " * 4 + s[e + 4:]
    c.broken.append((k + 1, ("not at the end of a field",)))
    c.mutations.append(f"a number of line {k + 1} lost its exponent")


MUTATIONS = [tabs_in_line_4, crlf, trailing_blanks, blank_line_in_body, units, key_twice,
             value_after_dt, npts_off, cut_last_number, shift_value, tab_between_values,
             cut_middle_number]


def make_case(index: int, seed: int) -> Case:
    rng = random.Random(seed * 1_000_003 + index)
    c = base(index, rng)
    for _ in range(rng.randint(1, 3)):
        rng.choice(MUTATIONS)(c, rng)
    return c


# ------------------------------------------------------------------------- running

def run_case(c: Case, exe: str, where: Path) -> list[str]:
    """The failures of one case (empty: as expected)."""
    where.mkdir(parents=True, exist_ok=True)
    (where / "case.nml").write_text(DECK)
    text = c.text()
    if getattr(c, "eol_final", None) == "":
        text = text[:-len(c.eol)]
    (where / "rec.AT2").write_bytes(text.encode())
    r = subprocess.run([exe, "case.nml"], cwd=where, capture_output=True, text=True, timeout=60)
    out = where / "out"
    fails = []
    if r.returncode not in (0, 1):
        return [f"exit status {r.returncode}: {r.stderr[-300:]}"]
    if c.broken:
        if r.returncode == 0:
            return [f"accepted a record that breaks a rule ({c.mutations})"]
        msg = r.stderr
        if "record file 'rec.AT2'" not in msg:
            fails.append(f"the message names no record file: {msg!r}")
        ok = False
        for line, phrases in c.broken:
            named = f"line {line}" in msg if line else "line 4" in msg
            if named and any(p in msg for p in phrases):
                ok = True
        if not ok:
            fails.append(f"refused, but not for the rule broken {c.broken}: {msg.strip()!r}")
        if out.exists() and any(out.iterdir()):
            fails.append("a refused record left output files")
        return fails
    if r.returncode != 0:
        return [f"refused a valid record ({c.mutations}): {r.stderr.strip()!r}"]
    lines = (out / "case.csv").read_text().splitlines()
    ag = np.array([float(row.split(",")[1]) for row in lines[1:]])
    want = np.array(c.body) * c.factor
    # the history's ag is the record at the step times t = k dt (round-off of t: 1e-14)
    if ag.size != want.size or not np.allclose(ag, want, rtol=1e-12, atol=1e-12 * np.abs(want).max()):
        fails.append(f"read other values ({c.mutations}): {ag[:4]} ... for {want[:4]} ...")
    return fails


def campaign(count: int, seed: int, exe: str, work: Path, first: int = 0) -> dict:
    failures, refused, accepted = [], 0, 0
    for i in range(first, first + count):
        c = make_case(i, seed)
        where = work / f"case{i}"
        fails = run_case(c, exe, where)
        if fails:
            failures.append((i, c.mutations, fails))
        elif c.broken:
            refused += 1
        else:
            accepted += 1
    return {"runs": count, "accepted": accepted, "refused": refused, "failures": failures}


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--count", type=int, default=200)
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--case", type=int, default=None, help="run case I alone, print its file")
    ap.add_argument("--exe", default=None, help="the executable (default: frictiondyn.executable())")
    args = ap.parse_args(argv)
    exe = args.exe
    if exe is None:
        import frictiondyn
        exe = frictiondyn.executable()
    with tempfile.TemporaryDirectory() as tmp:
        if args.case is not None:
            c = make_case(args.case, args.seed)
            sys.stdout.write(c.text())
            print(f"mutations: {c.mutations}; broken: {c.broken}")
            print(run_case(c, exe, Path(tmp) / "case") or "as expected")
            return 0
        rep = campaign(args.count, args.seed, exe, Path(tmp))
    print(f"{rep['runs']} cases: {rep['accepted']} read, {rep['refused']} refused as they should be, "
          f"{len(rep['failures'])} failures")
    for i, muts, fails in rep["failures"][:20]:
        print(f"  case {i} {muts}: {fails[0]}")
    return 1 if rep["failures"] else 0


if __name__ == "__main__":
    sys.exit(main())
