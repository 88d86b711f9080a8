"""Bad decks and records: a message naming group (or file and line), variable and value,
a non-zero exit, and no output file left behind."""

from __future__ import annotations

import copy
import re

import frictiondyn
import numpy as np
import pytest
from conftest import ROOT, deck_text, paper_groups
from frictiondyn import FrictiondynError


def modified(change):
    groups = paper_groups(4, "velocity")
    groups["excitation"]["duration"] = 0.5
    change(groups)
    return groups


def _set(group, var, value):
    def change(g):
        g[group][var] = value

    return change


def _drop(group):
    def change(g):
        del g[group]

    return change


# a planar bearing under both masses (x: mass 1, y: mass 2)
_BEARING = {"n_bearings": 1, "dof_xi": 1, "dof_yi": 2, "dof_xj": 0, "dof_yj": 0, "law": "velocity",
            "p": 24.8, "mu": 0.1}

CASES = [
    # (id, change, words the message must contain)
    ("missing group", _drop("springs"), ["&springs", "missing"]),
    ("negative mass", _set("model", "mass", [6.301, -2.53]), ["&model", "mass(2)", "-2.53", "> 0"]),
    ("zero mass", _set("model", "mass", [0.0, 2.53]), ["&model", "mass(1)", "= 0 "]),
    ("n1 < 1", _set("integration", "n1", 0), ["&integration", "n1", "= 0 "]),
    ("beta > 1/2", _set("integration", "beta", 0.6), ["&integration", "beta", "0.6"]),
    ("beta = 0", _set("integration", "beta", 0.0), ["&integration", "beta", "= 0 "]),
    ("gamma < 1/2", _set("integration", "gamma", 0.3), ["&integration", "gamma", "0.3"]),
    (
        "spring to a missing DOF",
        _set("springs", "node_j", [0, 3]),
        ["&springs", "node_j(2)", "= 3 "],
    ),
    ("spring to itself", _set("springs", "node_j", [0, 2]), ["&springs", "node_j(2)", "= 2 "]),
    ("negative stiffness", _set("springs", "k", [1084.0, -5.0]), ["&springs", "k(2)", "-5"]),
    ("NaN mass", _set("model", "mass", [float("nan"), 2.53]), ["&model", "mass(1)", "NaN"]),
    ("too many masses", _set("model", "mass", [1.0, 2.0, 3.0]), ["&model", "mass(3)", "3.0"]),
    (
        "unknown damping",
        _set("damping", "damping_type", "caughey"),
        ["&damping", "damping_type", "caughey"],
    ),
    ("xi >= 1", _set("damping", "xi", 1.5), ["&damping", "xi", "1.5"]),
    (
        "rayleigh xi without modes",  # it would be left unused: an undamped run
        lambda g: g["damping"].update(damping_type="rayleigh", xi=0.05),
        ["&damping", "xi = 0.05", "mode_i and mode_j"],
    ),
    ("zero frequency", _set("excitation", "frequency", 0.0), ["&excitation", "frequency", "= 0 "]),
    ("negative duration", _set("excitation", "duration", -1.0), ["&excitation", "duration", "-1"]),
    ("unknown excitation", _set("excitation", "excitation_type", "sine"), ["&excitation", "sine"]),
    # friction input
    ("eps = 0", _set("friction", "eps", 0.0), ["&friction", "eps(1)", "= 0 "]),
    ("eps < 0", _set("friction", "eps", -1e-3), ["&friction", "eps(1)", "-0.001"]),
    ("eps1 = 0", _set("friction", "eps1", 0.0), ["&friction", "eps1(1)", "= 0 "]),
    ("f = 0", _set("friction", "f", 0.0), ["&friction", "f(1)", "= 0 "]),
    ("f < 0", _set("friction", "f", -1e-5), ["&friction", "f(1)", "-1.0E-5"]),
    ("n = 1", _set("integration", "n", 1.0), ["&integration", "n = 1", "> 1"]),
    ("n < 1", _set("integration", "n", 0.5), ["&integration", "n = 0.5"]),
    ("n2 < 1", _set("integration", "n2", 0), ["&integration", "n2", "= 0 "]),
    ("P < 0", _set("friction", "p", -61.81), ["&friction", "p(1)", "-61.81"]),
    ("mu < 0", _set("friction", "mu", -0.22), ["&friction", "mu(1)", "-0.22"]),
    ("device to itself", _set("friction", "node_j", 1), ["&friction", "node_j(1)", "= 1 "]),
    ("device to a missing DOF", _set("friction", "node_j", 7), ["&friction", "node_j(1)", "= 7 "]),
    ("unknown law", _set("friction", "law", "coloumb"), ["&friction", "law(1)", "coloumb"]),
    ("more than 2e9 steps", _set("excitation", "duration", 4.0e7), ["&integration", "n1", "2e9"]),
    ("dt_min above dt2", _set("integration", "dt_min", 1.0), ["&integration", "dt_min", "= 1"]),
    (
        "unknown linear_system",
        _set("integration", "linear_system", "cholmod"),
        ["&integration", "linear_system", "'cholmod'", "'banded'", "'sparse'"],
    ),
    (
        "unknown refinement",
        _set("integration", "refinement", "fine"),
        ["&integration", "refinement", "'fine'", "'step'", "'nested'"],
    ),
    # the vertical component: only bearings take it, on the first component's step
    (
        "vertical component without bearings",
        lambda g: g.update(excitation3=dict(g["excitation"])),
        ["&excitation3", "vertical", "&bearings"],
    ),
    (
        "vertical component's dt_record",
        lambda g: g.update(bearings=_BEARING, excitation3={**g["excitation"], "dt_record": 0.003}),
        ["&excitation3", "dt_record = 0.003", "&excitation's"],
    ),
    (
        "vertical component's frequency",
        lambda g: g.update(bearings=_BEARING, excitation3={**g["excitation"], "frequency": -2.0}),
        ["&excitation3", "frequency", "-2"],
    ),
    # a bearing's elastic vertical support: kv >= 0, its damping a ratio below critical
    (
        "negative vertical stiffness",
        lambda g: g.update(bearings={**_BEARING, "kv": -2.5e6}),
        ["&bearings", "kv(1) = -2", ">= 0 N/m"],
    ),
    (
        "vertical damping ratio of 1",
        lambda g: g.update(bearings={**_BEARING, "kv": 2.5e6, "zeta_v": 1.0}),
        ["&bearings", "zeta_v(1) = 1", "0 <= zeta_v < 1"],
    ),
    (
        "negative vertical damping ratio",
        lambda g: g.update(bearings={**_BEARING, "kv": 2.5e6, "zeta_v": -0.05}),
        ["&bearings", "zeta_v(1) = -0.05", "0 <= zeta_v < 1"],
    ),
    # the overturning takes floors at their storey heights: a model of masses has none
    (
        "overturning of a model of masses",
        lambda g: g.update(bearings={**_BEARING, "overturning": True}),
        ["&bearings", "overturning", "&floors"],
    ),
]


def assert_rejected(r, words):
    assert r.returncode != 0
    for w in words:
        assert w in r.stderr, f"{w!r} not in {r.stderr!r}"
    assert r.stdout == ""
    assert not r.outdir.exists(), "a rejected deck left output behind"


@pytest.mark.parametrize("change, words", [c[1:] for c in CASES], ids=[c[0] for c in CASES])
def test_bad_value(run, change, words):
    assert_rejected(run(modified(change)), words)


def test_good_deck_of_the_same_family_runs(run):
    """The base of the cases above is a valid deck: the failures come from the change."""
    r = run(modified(lambda g: None))
    assert r.returncode == 0, r.stderr
    assert r.outdir.exists()


TEXT_CASES = [
    (
        "misspelled variable",
        ("  n1 = 20", "  nn1 = 20"),
        ["&integration", "line", "nn1", "20", "unknown"],
    ),
    ("wrong-typed integer", ("  n1 = 20", "  n1 = 2.5x"), ["&integration", "n1", "2.5x"]),
    ("string for a number", ("  n1 = 20", "  n1 = 'twenty'"), ["&integration", "n1", "twenty"]),
    (
        "number for a logical",
        ("  n = 10", "  check_correctness = 7"),
        ["&integration", "check_correctness", "7"],
    ),
    ("unknown group", ("&springs", "&spring"), ["&spring", "unknown group", "line"]),
    (
        "unclosed group",
        ("  duration = 0.5\n/", "  duration = 0.5\n"),
        ["&excitation", "not closed"],
    ),
    (
        "repeated group",
        ("&output", "&model\n  n_dof = 2\n/\n&output"),
        ["&model", "more than once"],
    ),
]


@pytest.mark.parametrize(
    "old_new, words", [c[1:] for c in TEXT_CASES], ids=[c[0] for c in TEXT_CASES]
)
def test_malformed_deck(run, old_new, words):
    groups = modified(lambda g: None)
    groups["output"] = {"dir": "out"}
    text = deck_text(groups)
    old, new = old_new
    assert old in text
    assert_rejected(run(text.replace(old, new, 1)), words)


def test_missing_deck_file(tmp_path):
    import subprocess

    import frictiondyn

    r = subprocess.run(
        [frictiondyn.executable(), "nope.nml"], cwd=tmp_path, capture_output=True, text=True
    )
    assert r.returncode != 0
    assert "nope.nml" in r.stderr and "does not exist" in r.stderr
    assert list(tmp_path.iterdir()) == []


def record_deck():
    g = modified(lambda g: None)
    g["excitation"] = {"excitation_type": "record", "record_file": "rec.txt", "dt_record": 0.01}
    return g


@pytest.mark.parametrize(
    "text, words",
    [
        ("0.0\n0.1\nnan\n0.2\n", ["rec.txt", "line 3", "nan", "not finite"]),
        ("0.0\n0.1\n0.1x\n0.2\n", ["rec.txt", "line 3", "0.1x", "not a number"]),
        ("0.0\n0.1\n# comment\n0.2 0.3\n", ["rec.txt", "line 4", "column"]),
        ("0.00 0.0\n0.01 0.1\n0.03 0.2\n", ["rec.txt", "line 3", "0.03", "dt_record"]),
        ("0.5\n", ["rec.txt", "1 samples"]),
    ],
)
def test_bad_record(run, text, words):
    assert_rejected(run(record_deck(), files={"rec.txt": text}), ["&excitation"] + words)


def test_missing_record_file(run):
    assert_rejected(run(record_deck()), ["&excitation", "record_file", "rec.txt", "does not exist"])


# ---------------------------------------------------------------- extreme values, every variable
# Whether a deck gives a variable is read from the deck's text, never from a value: the
# largest numbers a deck can write, and the most negative, are values like any other. Each
# is given to every variable of every group the reader declares (its namelist statements in
# fortran/io/fd_deck.f90: a new variable cannot escape this test), in a deck where that
# variable is used; the deck is refused with a message naming the group and the variable,
# or, where the value is valid, the run uses it.

EXTREMES = [-1.7976931348623157e308, 1.7976931348623157e308, -2147483647, 2147483647]


def reader_variables() -> dict[str, list[str]]:
    """{group: [variables]} from the namelist statements of the deck reader."""
    src = (ROOT / "fortran" / "io" / "fd_deck.f90").read_text()
    src = re.sub(r"&[ \t]*\n[ \t]*", " ", src)  # continuation lines joined
    groups = {}
    for group, names in re.findall(r"^[ \t]*namelist[ \t]*/(\w+)/(.*)$", src, re.M):
        groups[group] = [n.strip().lower() for n in names.split(",")]
    return groups


RECORD = "".join(f"{0.1 * ((i % 7) - 3):.3f}\n" for i in range(41))  # 41 samples
AT2 = (
    "PEER STRONG MOTION DATABASE RECORD\nTEST\n"
    "ACCELERATION TIME SERIES IN UNITS OF G\nNPTS=   41, DT=   .0050 SEC\n" + RECORD
)


def base_groups() -> dict[str, dict]:
    """A short run of every group: two masses, a velocity-law device, a brace, a curved
    isolator and two storeys under a harmonic table motion."""
    g = paper_groups(4, "velocity")
    g["friction"]["eps"] = 1.0e-3
    g["braces"] = {"n_braces": 1, "node_i": 2, "node_j": 0, "slip_load": 50.0, "stiffness": 1.0e4}
    g["isolators"] = {"n_isolators": 1, "node_i": 2, "node_j": 0, "law": "velocity",
                      "weight": 24.8, "mu": 0.1, "radius": 2.0}
    g["storeys"] = {"n_storeys": 2, "node_i": [1, 2], "node_j": [2, 0], "height": [3.0, 3.0]}
    g["damping"]["period"] = 0.3  # the stuck system has no free DOF: no period of its own
    g["excitation"]["duration"] = 0.1
    g["output"] = {"dir": "out"}
    return g


# the decks in which a variable is used, beyond base_groups: {context: (group, changes)}
CONTEXTS = {
    "rayleigh": ("damping", {"damping_type": "rayleigh", "rayleigh_a0": 0.1,
                             "rayleigh_a1": 0.001}),
    "rayleigh modes": ("damping", {"damping_type": "rayleigh", "xi": 0.05, "mode_i": 1,
                                   "mode_j": 2}),
    "exponential": ("friction", {"mu_law": "exponential", "mu_max": 0.3, "mu_min": 0.2,
                                 "mu_rate": 10.0}),
    "table": ("friction", {"mu_law": "table", "mu_table_v": [0.0, 0.1],
                           "mu_table_mu": [0.3, 0.2]}),
    "record": ("excitation", {"excitation_type": "record", "record_file": "r.txt",
                              "dt_record": 0.005, "duration": 0.1}),
    "at2": ("excitation", {"excitation_type": "record", "record_file": "r.at2",
                           "duration": 0.1}),
    "hysteretic": ("friction", {"law": "hysteretic", "f": 1.0e-5}),
    "hysteretic isolator": ("isolators", {"law": "hysteretic", "f": 1.0e-5}),
    "hysteretic bearing": ("bearings", {"law": "hysteretic", "f": 1.0e-5}),
}
USED_IN = {
    ("damping", "rayleigh_a0"): ["rayleigh"], ("damping", "rayleigh_a1"): ["rayleigh"],
    ("damping", "mode_i"): ["rayleigh modes"], ("damping", "mode_j"): ["rayleigh modes"],
    ("damping", "mode_system"): ["rayleigh modes"],
    ("friction", "mu_max"): ["exponential"], ("friction", "mu_min"): ["exponential"],
    ("friction", "mu_rate"): ["exponential"],
    ("friction", "mu_table_v"): ["table"], ("friction", "mu_table_mu"): ["table"],
    ("excitation", "record_file"): ["record"], ("excitation", "record_kind"): ["record"],
    ("excitation", "record_scale"): ["record"], ("excitation", "record_format"): ["record"],
    ("excitation", "record_units"): ["record"],
    ("excitation", "dt_record"): [None, "record", "at2"],
    ("floors", "inertia"): ["floor inertia"], ("floor_braces", "eps"): ["floor velocity"],
    ("floor_braces", "law"): [None, "floor velocity"],
    ("excitation", "duration"): [None, "record", "at2"],
    ("friction", "f"): ["hysteretic"], ("friction", "eps1"): ["hysteretic"],
    ("isolators", "f"): ["hysteretic isolator"], ("isolators", "eps1"): ["hysteretic isolator"],
    ("bearings", "f"): ["hysteretic bearing"], ("bearings", "eps1"): ["hysteretic bearing"],
}


def extreme_cases():
    for group, names in reader_variables().items():
        for var in names:
            for context in USED_IN.get((group, var), [None]):
                for value in EXTREMES:
                    yield group, var, context, value


FLOOR_GROUPS = ("floors", "frames", "floor_braces")


def floor_groups() -> dict[str, dict]:
    """A short run of a building of rigid floors: two floors, two frames a storey, one brace
    with a friction damper a storey, under a harmonic table motion along 30 degrees."""
    return {
        "floors": {"n_floors": 2, "mass": [2.0e5, 2.0e5], "plan_x": [20.0, 20.0], "plan_y": [12.0, 12.0],
                   "cm_x": [0.0, 0.5], "cm_y": [0.0, 0.0], "height": [3.0, 3.0], "excitation_angle": 30.0},
        "frames": {"n_frames": 4, "storey": [1, 1, 2, 2], "angle": [0.0, 90.0, 0.0, 90.0],
                   "x": [0.0, 5.0, 0.0, 5.0], "y": [3.0, 0.0, 3.0, 0.0], "k": [2.0e8, 2.0e8, 1.0e8, 1.0e8]},
        "damping": {"damping_type": "rayleigh", "rayleigh_a0": 0.1, "rayleigh_a1": 0.001},
        "floor_braces": {"n_braces": 2, "storey": [1, 2], "angle": [45.0, 45.0], "x": [-4.0, -4.0],
                         "y": [2.0, 2.0], "slip_load": [1.0e5, 5.0e4], "stiffness": [1.0e8, 1.0e8],
                         "eps1": [1.0e-3, 1.0e-3], "label": ["b1", "b2"]},
        "excitation": {"excitation_type": "harmonic", "amplitude": 0.01, "frequency": 2.0,
                       "dt_record": 0.005, "duration": 0.1},
        "output": {"dir": "out"},
    }


K_MTX = "%%MatrixMarket matrix coordinate real symmetric\n2 2 3\n1 1 3.0e6\n2 1 -1.0e6\n2 2 1.0e6\n"
M_MTX = "%%MatrixMarket matrix coordinate real symmetric\n2 2 2\n1 1 1000.0\n2 2 800.0\n"


def matrix_groups() -> dict[str, dict]:
    """A short run of a structure of &matrices (K.mtx and M.mtx, two DOFs) with a device."""
    g = base_groups()
    for name in ("model", "springs", "storeys", "braces", "isolators"):
        g.pop(name)
    g = {"matrices": {"k_file": "K.mtx", "m_file": "M.mtx", "label": ["a", "b"], "influence": [1.0, 1.0],
                      "influence2": [0.0, 0.5]}, **g}
    g["damping"] = {"damping_type": "rayleigh", "rayleigh_a0": 0.1, "rayleigh_a1": 0.001}
    g["friction"].update(node_i=2, node_j=1)
    return g


def deck_with(group: str, var: str, context: str | None, value) -> tuple[dict, dict]:
    """The deck of the context with `value` given to the variable (its last element when the
    deck gives a list), and the deck that does not give that element (what a value taken for
    "not given" ran as)."""
    g = floor_groups() if group in FLOOR_GROUPS else matrix_groups() if group == "matrices" else base_groups()
    if group == "bearings":  # a planar bearing under both masses (x: mass 1, y: mass 2)
        g["bearings"] = {"n_bearings": 1, "dof_xi": 1, "dof_yi": 2, "dof_xj": 0, "dof_yj": 0,
                         "law": "velocity", "p": 24.8, "mu": 0.1, "radius": 2.0}
    if context == "floor inertia":
        g["floors"].pop("plan_x")
        g["floors"].pop("plan_y")
        g["floors"]["inertia"] = [1.0e7, 1.0e7]
    elif context == "floor velocity":
        g["floor_braces"].pop("stiffness")
        g["floor_braces"].update(law=["velocity", "velocity"], eps=[1.0e-3, 1.0e-3])
    elif context:
        cgroup, changes = CONTEXTS[context]
        if "mu_law" in changes:
            g[cgroup].pop("mu")
        if cgroup == "excitation":
            g[cgroup] = {}
        g[cgroup].update(changes)
    without = copy.deepcopy(g)
    old = g[group].get(var)
    if isinstance(old, list):
        g[group][var] = old[:-1] + [value]
        without[group][var] = old[:-1]
    else:
        g[group][var] = value
        without[group].pop(var, None)
    return g, without


def outcome(summary: dict) -> dict:
    """A summary but what differs between runs of one configuration (the deck's hash, the
    wall-clock time)."""
    return {k: v for k, v in summary.items() if k not in ("deck_sha256", "run_time_s")}


# valid extreme values whose use the run's outcome does not show (checked otherwise): what
# the reader read, as the session says it, or a deck the value lets through
def _output(key):
    def check(text, where, result, value):
        with frictiondyn.Session.from_text(text, "case.nml", where) as s:
            return getattr(s.output, key) == repr(value)
    return check


def _all_modes(text, where, result, value):  # more modes than DOFs: all of them (the free
    return len(result.summary["periods_free_s"]) == 2  # system's; the stuck one is rigid)


def _history_limit(text, where, result, value):  # a 240 GB history is let through
    big = text.replace("duration = 0.1", "duration = 200000.0")
    big = big.replace("  dir = 'out'", "  dir = 'out'\n  output_every = 1")
    frictiondyn.Session.from_text(big, "case.nml", where).close()
    return True


def _runs(text, where, result, value):
    # eps1, the end-of-sliding band of the hysteretic law: 2147483647 m/s is valid (a band
    # no slide leaves), and a short run does not show it; the value is read (a negative one
    # is refused: test_extreme values above), not replaced by the default
    return True


USED = {
    ("output", "dir"): _output("dir"),
    ("output", "name"): _output("name"),
    ("output", "n_modes"): _all_modes,
    ("output", "max_history_mb"): _history_limit,
    ("friction", "eps1"): _runs,
    ("braces", "eps1"): _runs,
    ("isolators", "eps1"): _runs,
    ("floor_braces", "eps1"): _runs,
    ("bearings", "eps1"): _runs,
}


@pytest.mark.parametrize(
    "group, var, context, value", list(extreme_cases()),
    ids=[f"{g}.{v}{'@' + c if c else ''}={x!r}" for g, v, c, x in extreme_cases()],
)
def test_an_extreme_value_is_refused_or_used_never_taken_for_not_given(
    tmp_path, group, var, context, value
):
    """`v0 = 0.0, -1.7976931348623157e308` ran with v0(2) = 0; the same for u0, eps, eps1, f,
    an isolator's radius, a storey's height, a record's duration and dt_record, and
    history_dofs = -2147483647: the reader took the value for its "not given" marker."""
    (tmp_path / "r.txt").write_text(RECORD)
    (tmp_path / "r.at2").write_text(AT2)
    (tmp_path / "K.mtx").write_text(K_MTX)
    (tmp_path / "M.mtx").write_text(M_MTX)
    groups, without = deck_with(group, var, context, value)
    try:
        result = frictiondyn.run_text(deck_text(groups), "case.nml", tmp_path)
    except FrictiondynError as exc:
        message = str(exc)
        assert f"&{group}" in message, message
        assert re.search(rf"\b{var}\b", message), message
        assert "is not given" not in message, message
        return
    check = USED.get((group, var))
    if check is not None:
        assert check(deck_text(groups), tmp_path, result, value), f"{group}.{var} = {value!r}"
        return
    try:  # a valid value: the run is not the one without it
        reference = frictiondyn.run_text(deck_text(without), "case.nml", tmp_path)
    except FrictiondynError:
        return  # without it the deck is refused: the value was used
    same = outcome(reference.summary) == outcome(result.summary)
    same = same and np.array_equal(reference.data, result.data)
    assert not same, f"{group}.{var} = {value!r} ran as if it were not given"


def test_every_variable_of_the_reader_is_documented():
    """The variables of the extreme-value test are those of docs/namelist.md, group by group."""
    doc = (ROOT / "docs" / "namelist.md").read_text()
    sections = re.split(r"^## `&(\w+)`", doc, flags=re.M)
    documented = {
        sections[i]: {name for cell in re.findall(r"^\|([^|]*)\|", sections[i + 1], re.M)
                      for name in re.findall(r"`(\w+)[`(]", cell)}
        for i in range(1, len(sections), 2)
    }
    for group, names in reader_variables().items():
        assert set(names) <= documented[group], (group, set(names) - documented[group])
