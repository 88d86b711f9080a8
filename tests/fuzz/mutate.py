"""Mutations of the bundled decks and records for the fuzz campaign (tests/fuzz/run.py).

A *base* is a deck (its text) and the files it reads (records), taken from inputs/ with its
duration shortened (2 s; 3 s of the building's record) so that a valid case costs tens of
milliseconds, plus three record decks made here (one value a line, time-value columns, a
displacement record). A *case* is a base with 1 to 3 mutations drawn by a seeded generator:
the same (seed, index) always gives the same case.

Mutations, by what they touch:

- deck lines: deleted, repeated, swapped, truncated at any byte, CRLF or CR line ends;
- deck values (of every group, &storeys, &braces, &isolators too): wrong types, extreme
  values (1e308, 4.9e-324, -0, huge integers), NaN and Inf, huge counts (n_dof = 10000,
  100000*1.0), empty values, repeat counts, misspelled names;
- deck syntax: '& name', 'x&name', a non-breaking space, '$name ... $end', a '/' deleted or
  doubled, text or assignments outside groups, a variable given twice;
- text: non-ASCII (UTF-8 in comments and strings, Latin-1 bytes, invalid UTF-8), binary
  lines, very long lines and strings (past the 31, 32 and 1024 character capacities of
  labels, keywords and paths);
- whole files: empty, binary, a deck that is a directory, a missing deck, non-ASCII and long
  deck file names;
- records: lines deleted, repeated or truncated, values NaN/Inf/1e308/1e-320, list-directed
  tokens ('3*0.1', '/', '*'), empty lines, columns changed, AT2 headers (NPTS, DT) broken,
  empty and binary records, non-ASCII record names, paths that are directories or missing.

Paths written by a case stay inside its directory: `dir` and `record_file` mutations are
relative or point at places that cannot be created (never '/' as root would allow).
"""

from __future__ import annotations

import math
import random
import re
from dataclasses import dataclass, field
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
INPUTS = ROOT / "inputs"


@dataclass
class Case:
    """One fuzz case: the files of its directory and the deck to run."""

    index: int
    deck_name: str
    files: dict[str, bytes | None]  # None: a directory
    base: str
    mutations: list[str] = field(default_factory=list)
    touched: set[str] = field(default_factory=set)  # 'deck', 'record', 'path'


# ---------------------------------------------------------------- bases

def _record_bases() -> dict[str, tuple[str, dict[str, bytes]]]:
    """Decks of the paper's test 4 driven by records made here (3 formats, 2 s)."""
    dt, n = 0.005, 401
    t = [k * dt for k in range(n)]
    w = 2 * math.pi * 4.104
    acc = [-0.004052 * w * w * math.sin(w * x) for x in t]
    disp = [0.004052 * math.sin(w * x) for x in t]
    deck = (INPUTS / "test4_velocity.nml").read_text()
    harmonic = re.search(r"&excitation.*?\n/\n", deck, re.S).group(0)

    def with_record(file: str, extra: str) -> str:
        exc = (
            "&excitation\n  excitation_type = 'record'\n"
            f"  record_file = '{file}'\n  dt_record = 0.005\n{extra}/\n"
        )
        return deck.replace(harmonic, exc)

    values = "".join(f"{a:.10e}\n" for a in acc).encode()
    columns = "".join(f"{x:.4f}, {a:.10e}\n" for x, a in zip(t, acc)).encode()
    dvalues = ("# table displacement [m]\n" + "".join(f"{d:.10e}\n" for d in disp)).encode()
    return {
        "record_values": (with_record("acc.txt", ""), {"acc.txt": values}),
        "record_columns": (with_record("acc2.txt", "  record_format = 'time_value'\n"),
                           {"acc2.txt": columns}),
        "record_displacement": (
            with_record("disp.txt", "  record_kind = 'displacement'\n  record_units = 'm'\n"),
            {"disp.txt": dvalues},
        ),
    }


def bases() -> dict[str, tuple[str, dict[str, bytes]]]:
    """name -> (deck text, {file: content}) for every bundled deck and the record decks."""
    out = {}
    for path in sorted(INPUTS.glob("*.nml")):
        text = path.read_text()
        files = {}
        for m in re.finditer(r"record_file\s*=\s*'([^']+)'", text):
            files[m.group(1)] = (INPUTS / m.group(1)).read_bytes()
        text = re.sub(r"duration = (?:40|30)\.0", "duration = 2.0", text)
        if files and "duration" not in text:
            text = text.replace("excitation_type = 'record'",
                                "excitation_type = 'record'\n  duration = 3.0", 1)
        out[path.stem] = (text, files)
    out.update(_record_bases())
    return out


# ---------------------------------------------------------------- value pools

EXTREME_REALS = [
    "0", "0.0", "-0.0", "-1", "1e308", "-1e308", "1.7976931348623157e308", "2e308", "1e-308",
    "4.9e-324", "1e-320", "1e300", "1e-300", "1e30", "1e31", "1e-30", "1e-31", "1e15", "1e-15",
    "NaN", "nan", "Inf", "-Inf", "Infinity", "+inf", "1e", "1.0.0", "1d300", "0x10", "1,5",
]
EXTREME_INTS = [
    "0", "-1", "1", "2", "3", "10000", "10001", "40000", "40001", "100000", "2147483647",
    "2147483648", "-2147483648", "-2147483649", "99999999999999999999", "1e9", "2.5", "1000",
]
WRONG_TYPES = [
    "'text'", "\"text\"", ".true.", ".false.", "T", "x", "1 2 3", "(1.0, 2.0)", "'", "\"", "''",
    "*", "3*", "2*1.0", "100000*1.0", "10000*1.0", "r*1", "=", ",", ",,", "/", "!", "&", "$",
]
STRINGS = [
    "'velocity'", "'hysteretic'", "'coulomb'", "'newmark'", "'event_driven'", "'stiffness'",
    "'rayleigh'", "'none'", "'harmonic'", "'record'", "'acceleration'", "'displacement'",
    "'VELOCITY'", "' velocity'", "'velocity '", "''", "'x'", "'µ'", "'vélocité'",
    "'velocity" + " " * 30 + "x'", "'" + "a" * 33 + "'", "'" + "d" * 1025 + "'",
    "'" + "é" * 600 + "'", "'it''s'", "'a/b'", "'../x'", "'out/sub/deeper'", "'.'",
    "'/nonexistent/dir/x'", "'/proc/x'", "'with space'", "'ü'", "'\t'",
    "'exponential'", "'table'", "'constant'", "'stuck'", "'free'", "'" + "l" * 31 + "'",
    "'" + "l" * 32 + "'", "'a,b'", "'a\"b'", "'a\\b'",
]
NON_ASCII = ["µ", "é", "ü", "€", "😀", "\u00a0", "\ufeff", "\u2028", "ε", "Ω"]
JUNK_LINES = [
    "Title of the deck", "n_dof = 3", "/", "&", "$", "&end", "$end", "= =", "& friction",
    "x&friction", "\u00a0&friction", "$friction", "&model /", "&unknown /", "! comment",
    "\t", "   ", "mass(1) = 2.0", "&MODEL", "&model&", "&1", "&model x=1 / y", "'quoted'",
]


def _value_pool(rng: random.Random, var: str) -> str:
    """A replacement value for variable `var`, from the pool of its kind (or any)."""
    ints = {"n_dof", "n_springs", "n_devices", "node_i", "node_j", "n1", "n2", "ramp_cycles",
            "output_every", "n_storeys", "n_braces", "n_isolators", "spring", "mode_i", "mode_j",
            "n_modes"}
    strs = {"law", "damping_type", "excitation_type", "record_kind", "record_file", "dir",
            "name", "technique", "record_format", "record_units", "mu_law", "mode_system",
            "label"}
    base = var.split("(")[0].strip().lower()
    r = rng.random()
    if r < 0.6:
        if base in ints:
            return rng.choice(EXTREME_INTS)
        if base in strs:
            return rng.choice(STRINGS)
        if base in {"check_correctness", "write_history"}:
            return rng.choice([".true.", ".false.", "T", "F", "1", "'yes'"])
        return rng.choice(EXTREME_REALS)
    if r < 0.85:
        return rng.choice(WRONG_TYPES)
    return rng.choice(EXTREME_REALS + EXTREME_INTS + STRINGS)


# ---------------------------------------------------------------- deck mutations

ASSIGN = re.compile(r"([A-Za-z_][A-Za-z0-9_]*(?:\([^)]*\))?)\s*=\s*")


def _lines(text: str) -> list[str]:
    return text.split("\n")


def m_delete_line(rng, text):
    lines = _lines(text)
    del lines[rng.randrange(len(lines))]
    return "\n".join(lines), "delete a line"


def m_repeat_line(rng, text):
    lines = _lines(text)
    i = rng.randrange(len(lines))
    lines[i:i] = [lines[i]] * rng.choice([1, 2, 5])
    return "\n".join(lines), f"repeat line {i + 1}"


def m_swap_lines(rng, text):
    lines = _lines(text)
    i, j = rng.randrange(len(lines)), rng.randrange(len(lines))
    lines[i], lines[j] = lines[j], lines[i]
    return "\n".join(lines), f"swap lines {i + 1} and {j + 1}"


def m_truncate(rng, text):
    n = rng.randrange(len(text) + 1)
    return text[:n], f"truncate at {n}"


def m_line_ends(rng, text):
    how = rng.choice(["\r\n", "\r", "\n\n", "\t\n"])
    out = text.replace("\n", how)
    if rng.random() < 0.5:
        out = out.rstrip("\r\n\t")
    return out, f"line ends {how!r}"


def m_value(rng, text):
    matches = [m for m in ASSIGN.finditer(text) if not text[: m.start()].rstrip().endswith("!")]
    matches = [m for m in matches if "!" not in text[text.rfind("\n", 0, m.start()) + 1: m.start()]]
    if not matches:
        return text, "no value"
    m = rng.choice(matches)
    end = m.end()
    # the value runs to the next assignment, '!' or end of line
    stop = len(text)
    for ch in ("\n", "!"):
        k = text.find(ch, end)
        if k >= 0:
            stop = min(stop, k)
    nxt = ASSIGN.search(text, end, stop)
    if nxt:
        stop = nxt.start()
    new = _value_pool(rng, m.group(1))
    sep = ", " if nxt else " "
    return text[:end] + new + sep + text[stop:], f"{m.group(1)} = {new}"


def m_count(rng, text):
    var = rng.choice(["n_dof", "n_springs", "n_devices", "n1", "n2", "output_every", "ramp_cycles",
                      "n_storeys", "n_braces", "n_isolators", "n_modes"])
    value = rng.choice(EXTREME_INTS)
    out, n = re.subn(rf"\b{var}\s*=\s*[^,\n!/]*", f"{var} = {value}", text, count=1)
    return out, f"{var} = {value}" if n else "no count"


def m_huge_array(rng, text):
    var = rng.choice(["mass", "k", "p", "mu", "u0", "v0", "eps", "node_i", "node_j", "weight",
                      "slip_load", "height", "radius"])
    value = rng.choice(["100000*1.0", "10001*1.0", "40001*1", "10000*0.5", "2147483647*1.0"])
    out, n = re.subn(rf"\b{var}\s*=\s*[^!\n/]*", f"{var} = {value} ", text, count=1)
    return out, f"{var} = {value}" if n else "no array"


def m_rename(rng, text):
    matches = list(ASSIGN.finditer(text))
    if not matches:
        return text, "no name"
    m = rng.choice(matches)
    name = m.group(1)
    new = rng.choice([name + "x", name[:-1], name.upper(), "x" + name, name.replace("_", ""),
                      name + "(0)", name + "(99999)", name + "(-1)", name + "(1:2)"])
    return text[: m.start(1)] + new + text[m.end(1):], f"{name} -> {new}"


def m_group_syntax(rng, text):
    groups = list(re.finditer(r"^&(\w+)", text, re.M))
    closes = [m.start() for m in re.finditer(r"^/", text, re.M)]
    kind = rng.choice(["space", "prefix", "nbsp", "dollar", "drop_close", "double_close",
                       "end", "upper", "tab", "drop_open", "same_line"])
    if kind in ("drop_close", "double_close") and closes:
        k = rng.choice(closes)
        if kind == "drop_close":
            return text[:k] + text[k + 1:], "a '/' deleted"
        return text[:k] + "/\n" + text[k:], "a '/' doubled"
    if not groups:
        return text, "no group"
    g = rng.choice(groups)
    name = g.group(1)
    new = {
        "space": f"& {name}", "prefix": f"x&{name}", "nbsp": f"\u00a0&{name}",
        "dollar": f"${name}", "end": f"&{name}", "upper": f"&{name.upper()}",
        "tab": f"\t&{name}", "drop_open": "", "same_line": f"&{name} /",
    }.get(kind, f"&{name}")
    out = text[: g.start()] + new + text[g.end():]
    if kind in ("dollar", "end"):  # close this group with $end / &end instead of '/'
        k = out.find("\n/", g.start())
        if k >= 0:
            out = out[: k + 1] + ("$end" if kind == "dollar" else "&END") + out[k + 2:]
    return out, f"group &{name}: {kind}"


def m_junk_line(rng, text):
    lines = _lines(text)
    i = rng.randrange(len(lines) + 1)
    junk = rng.choice(JUNK_LINES + ["x" * rng.choice([200, 5000, 100000])])
    lines.insert(i, junk)
    return "\n".join(lines), f"line {i + 1}: {junk[:20]!r}"


def m_non_ascii(rng, text):
    ch = rng.choice(NON_ASCII)
    where = rng.choice(["comment", "anywhere", "string"])
    if where == "comment":
        i = text.find("!")
        if i >= 0:
            return text[: i + 1] + ch + text[i + 1:], f"{ch!r} in a comment"
    if where == "string":
        i = text.find("'")
        if i >= 0:
            return text[: i + 1] + ch + text[i + 1:], f"{ch!r} in a string"
    i = rng.randrange(len(text) + 1)
    return text[:i] + ch + text[i:], f"{ch!r} at {i}"


MUTATIONS_DECK = [
    (m_delete_line, 3), (m_repeat_line, 2), (m_swap_lines, 1), (m_truncate, 2),
    (m_line_ends, 1), (m_value, 8), (m_count, 2), (m_huge_array, 1), (m_rename, 2),
    (m_group_syntax, 3), (m_junk_line, 2), (m_non_ascii, 2),
]


def _pick(rng, weighted):
    total = sum(w for _, w in weighted)
    r = rng.uniform(0, total)
    for f, w in weighted:
        r -= w
        if r <= 0:
            return f
    return weighted[-1][0]


# ---------------------------------------------------------------- record mutations

RECORD_TOKENS = ["NaN", "nan", "Inf", "-inf", "1e308", "-1e308", "2e308", "1e-320", "abc",
                 "1.0.0", "3*0.1", "/", "*", "", "1,2", "1 2 3", "0x1p3", "1d0", "+-1", "é",
                 "1e", ".", "-", "1e30", "1e31", "1.0e-30"]


def r_mutate(rng, data: bytes) -> tuple[bytes, str]:
    kind = rng.choice(["delete", "repeat", "truncate", "token", "token", "token", "empty",
                       "binary", "header", "columns", "many", "non_ascii", "nul"])
    lines = data.split(b"\n")
    if kind == "delete":
        del lines[rng.randrange(len(lines))]
        return b"\n".join(lines), "record: delete a line"
    if kind == "repeat":
        i = rng.randrange(len(lines))
        lines[i:i] = [lines[i]] * rng.choice([1, 3])
        return b"\n".join(lines), f"record: repeat line {i + 1}"
    if kind == "truncate":
        n = rng.randrange(len(data) + 1)
        return data[:n], f"record: truncate at {n}"
    if kind == "token":
        i = rng.randrange(len(lines))
        tok = rng.choice(RECORD_TOKENS)
        parts = lines[i].split()
        if parts:
            parts[rng.randrange(len(parts))] = tok.encode()
            lines[i] = b" ".join(parts)
        else:
            lines[i] = tok.encode()
        return b"\n".join(lines), f"record: line {i + 1} token {tok!r}"
    if kind == "empty":
        return b"", "record: empty"
    if kind == "binary":
        return bytes(rng.randrange(256) for _ in range(rng.choice([10, 1000]))), "record: binary"
    if kind == "header":
        text = data.decode("latin-1")
        new = rng.choice(["NPTS=   2000, DT=      .01 SEC", "NPTS=   0, DT= .01 SEC",
                          "NPTS=  -5, DT= .01 SEC", "NPTS= 2001, DT= 0 SEC",
                          "NPTS= 2001, DT= -0.01 SEC", "NPTS= 2001, DT= nan SEC",
                          "NPTS= 99999999999, DT= .01 SEC", "DT= .01 SEC", "NPTS= 2001",
                          "NPTS= 2001, DT= 1e-40 SEC", "NPTS= 2001, DT= 1e40 SEC"])
        out, n = re.subn(r"NPTS=.*SEC", new, text, count=1)
        return out.encode("latin-1"), f"record: header {new!r}" if n else "record: no header"
    if kind == "columns":
        i = rng.randrange(len(lines))
        lines[i] = lines[i] + b" 1.0"
        return b"\n".join(lines), f"record: a column added at line {i + 1}"
    if kind == "many":
        return data + b"0.0\n" * rng.choice([1000, 200000]), "record: many more samples"
    if kind == "nul":
        i = rng.randrange(len(data) + 1)
        return data[:i] + b"\x00" + data[i:], "record: a NUL byte"
    i = rng.randrange(len(lines))
    lines[i] = lines[i] + rng.choice(NON_ASCII).encode()
    return b"\n".join(lines), "record: non-ASCII"


# ---------------------------------------------------------------- a case

def make_case(seed: int, index: int, all_bases=None) -> Case:
    """Case `index` of the campaign of `seed` (deterministic)."""
    rng = random.Random(f"frictiondyn-fuzz-{seed}-{index}")
    all_bases = all_bases or bases()
    name = rng.choice(sorted(all_bases))
    text, files = all_bases[name]
    files = dict(files)
    case = Case(index, "case.nml", {}, name)
    n = rng.choice([1, 1, 1, 2, 2, 3])
    deck = text
    for _ in range(n):
        r = rng.random()
        records = sorted(k for k, v in files.items() if v is not None)
        if records and r < 0.25:
            fname = rng.choice(records)
            files[fname], what = r_mutate(rng, files[fname])
            case.mutations.append(what)
            case.touched.add("record")
        elif r < 0.30:
            what = _path_mutation(rng, case, files)
            deck = _apply_path(deck, what, case, files)
        else:
            f = _pick(rng, MUTATIONS_DECK)
            deck, what = f(rng, deck)
            case.mutations.append(what)
            case.touched.add("deck")
    whole = rng.random()
    data = deck.encode("utf-8", "surrogatepass")
    if whole < 0.01:
        data, what = b"", "deck: empty"
        case.mutations.append(what)
        case.touched.add("deck")
    elif whole < 0.02:
        data = bytes(rng.randrange(256) for _ in range(rng.choice([50, 5000])))
        case.mutations.append("deck: binary")
        case.touched.add("deck")
    elif whole < 0.03:
        data = deck.encode("latin-1", "replace")
        case.mutations.append("deck: Latin-1")
        case.touched.add("deck")
    elif whole < 0.035:
        data = data + b"\n! " + b"x" * 3_000_000 + b"\n"
        case.mutations.append("deck: a 3 MB comment")
        case.touched.add("deck")
    case.files.update(files)
    if case.deck_name not in case.files:
        case.files[case.deck_name] = data
    return case


def _path_mutation(rng, case, files) -> str:
    return rng.choice(["deck_non_ascii", "deck_space", "deck_long", "deck_dir", "deck_missing",
                       "record_dir", "record_missing", "record_non_ascii", "record_dev_null",
                       "record_abs_missing", "record_dot", "output_nested", "output_is_file",
                       "output_dot_dot"])


def _apply_path(deck: str, what: str, case: Case, files: dict) -> str:
    case.mutations.append(f"path: {what}")
    case.touched.add("path")
    rec = re.search(r"record_file\s*=\s*'([^']*)'", deck)
    if what == "deck_non_ascii":
        case.deck_name = "tëst µ.nml"
    elif what == "deck_space":
        case.deck_name = "my deck.nml"
    elif what == "deck_long":
        case.deck_name = "d" * 200 + ".nml"
    elif what == "deck_dir":
        case.files[case.deck_name] = None
    elif what == "deck_missing":
        case.deck_name = "missing.nml"
        case.files["case.nml"] = deck.encode()
    elif what.startswith("record") and rec:
        old = rec.group(1)
        new = {
            "record_dir": "sub", "record_missing": "nope.txt", "record_non_ascii": "accél.txt",
            "record_dev_null": "/dev/null", "record_abs_missing": "/nonexistent/rec.txt",
            "record_dot": ".",
        }[what]
        if what == "record_dir":
            files["sub"] = None
        if what == "record_non_ascii" and old in files:
            files["accél.txt"] = files.pop(old)
        deck = deck.replace(f"'{old}'", f"'{new}'", 1)
    elif what == "output_nested":
        deck = deck.replace("dir = 'out'", "dir = 'out/a/b/c'", 1)
    elif what == "output_is_file":
        deck = deck.replace("dir = 'out'", "dir = 'case.nml/x'", 1)
    elif what == "output_dot_dot":
        deck = deck.replace("dir = 'out'", "dir = 'out/../out2'", 1)
    return deck
