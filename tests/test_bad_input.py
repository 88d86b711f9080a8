"""Bad decks and records: a message naming group (or file and line), variable and value,
a non-zero exit, and no output file left behind."""

from __future__ import annotations

import pytest
from conftest import deck_text, paper_groups


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
        _set("damping", "damping_type", "modal"),
        ["&damping", "damping_type", "modal"],
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
        "unknown refinement",
        _set("integration", "refinement", "fine"),
        ["&integration", "refinement", "'fine'", "'step'", "'nested'"],
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
