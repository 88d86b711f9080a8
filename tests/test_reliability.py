"""Reliability, each rule with its regression test: nothing in a deck is skipped unread, strings
are never cut, a directory or a binary file says so, the executable and the extension agree
(NUL, non-ASCII text and paths), overflowing values are rejected up front naming group,
variable and value, no result is non-finite, the work of a step refinement is bounded, and
memory that cannot be had is an error (the executable's and Python's), never a crash."""

from __future__ import annotations

import json
import os
import re
import subprocess
import sys
import textwrap
import time

import frictiondyn
import numpy as np
import pytest
from conftest import INPUTS, ROOT, deck_text, paper_groups
from frictiondyn import DeckError, FrictiondynError, OutOfMemoryError, SolverError


def short_deck(law="velocity", duration=1.0) -> str:
    """The paper's test 4 deck (law as asked) for `duration` seconds, as the file gives it."""
    text = (INPUTS / f"test4_{law}.nml").read_text()
    return text.replace("duration = 40.0", f"duration = {duration}")


def both(tmp_path, text: str | bytes, name: str = "case.nml", files: dict | None = None):
    """Run a deck by the executable (in tmp_path/exe) and by frictiondyn.run (in tmp_path/py):
    (exe returncode, exe stderr, python outcome: a Result or the exception). A file whose
    content is None is made a directory."""
    out = []
    for where in ("exe", "py"):
        work = tmp_path / where
        work.mkdir()
        for fname, content in (files or {}).items():
            if content is None:
                (work / fname).mkdir()
                continue
            (work / fname).write_bytes(content.encode() if isinstance(content, str) else content)
        deck = work / name
        deck.write_bytes(text.encode() if isinstance(text, str) else text)
        out.append((work, deck))
    (exe_dir, exe_deck), (py_dir, py_deck) = out
    proc = subprocess.run(
        [frictiondyn.executable(), exe_deck.name], cwd=exe_dir, capture_output=True, text=True
    )
    cwd = os.getcwd()
    os.chdir(py_dir)
    try:
        try:
            outcome = frictiondyn.run(py_deck.name)
        except Exception as exc:  # noqa: BLE001 - the test looks at the type
            outcome = exc
    finally:
        os.chdir(cwd)
    return proc.returncode, proc.stderr, outcome


def assert_both_reject(tmp_path, text, words, name="case.nml", files=None, kind=DeckError):
    code, err, outcome = both(tmp_path, text, name, files)
    assert code == 1, err
    assert isinstance(outcome, kind), repr(outcome)
    message = err.removeprefix("frictiondyn: error: ").strip()
    assert message == str(outcome), "the executable and the extension say it differently"
    for w in words:
        assert w in message, f"{w!r} not in {message!r}"
    assert not (tmp_path / "exe" / "out").exists() and not (tmp_path / "py" / "out").exists()
    return message


# ---------------------------------------------------------------- nothing skipped unread

GROUP_OPENINGS = [
    ("& friction", ["line 18", "'&' must be followed by the group name"]),
    ("x&friction", ["line 18", "'&' not read as the start of a group"]),
    ("\u00a0&friction", ["line 18", "non-ASCII character, byte 194"]),
    ("!&friction", ["line 19", "an assignment outside any group"]),  # commented out: its body
]


@pytest.mark.parametrize("opening, words", GROUP_OPENINGS, ids=[o for o, _ in GROUP_OPENINGS])
def test_a_group_not_opened_by_its_first_word_is_an_error(tmp_path, opening, words):
    """Each of these ran with no friction device and exit status 0."""
    text = short_deck().replace("&friction", opening)
    assert_both_reject(tmp_path, text, ["case.nml", *words])


@pytest.mark.parametrize("group", ["integration", "output"])
def test_the_optional_groups_are_not_skipped_either(tmp_path, group):
    text = short_deck().replace(f"&{group}", f"& {group}")
    assert_both_reject(tmp_path, text, ["case.nml", f"'& {group}'"])


def test_the_legacy_dollar_form_is_read_as_the_group(tmp_path):
    """'$friction ... $end' is read (docs/namelist.md), to the same results as '&friction /'."""
    text = short_deck()
    legacy = text.replace("&friction", "$FRICTION").replace(
        "  eps = 1.0e-3                 ! m/s\n/", "  eps = 1.0e-3                 ! m/s\n$end"
    )
    assert "$end" in legacy
    a = frictiondyn.run_text(text, "a.nml")
    b = frictiondyn.run_text(legacy, "a.nml")
    assert b.summary["n_devices"] == 1 and b.summary["stick_to_slip"][0] > 0
    assert np.array_equal(a.data, b.data)


@pytest.mark.parametrize(
    "change, words",
    [
        (("&damping", "n_dof = 3\n&damping"), ["line 14", "an assignment outside any group"]),
        (("&damping", "/\n&damping"), ["line 14", "'/' outside any group"]),
        (("&damping", "Deck title\n&damping"), ["line 14", "text outside any group"]),
        (("dir = 'out'", "dir = out/x"), ["'x'", "after the end of group &output"]),
        (("  xi = 0.015", "  xi = 0.015\n  XI = 0.05"), ["'xi' is assigned again"]),
        (("  n1 = 20", "  n1 = 20 &x"), ["'&' inside a group"]),
    ],
    ids=["assignment", "slash", "title", "unquoted slash", "twice", "ampersand"],
)
def test_text_outside_a_group_is_an_error(tmp_path, change, words):
    text = short_deck()
    assert change[0] in text
    assert_both_reject(tmp_path, text.replace(*change, 1), ["case.nml", *words])


# ---------------------------------------------------------------- strings never cut

@pytest.mark.parametrize(
    "change, words",
    [
        (("dir = 'out'", "dir = '" + "d" * 1025 + "'"), ["&output", "dir is a string of 1025"]),
        (("law = 'velocity'", "law = 'velocity" + " " * 30 + "x'"), ["law is a string of 39"]),
        (("  n1 = 20", "  technique = 'newmark" + " " * 30 + "!'"), ["technique is a string of 38"]),
    ],
    ids=["dir", "law", "technique"],
)
def test_a_string_longer_than_its_capacity_is_an_error(tmp_path, change, words):
    """'velocity' followed by blanks and a character beyond the 32nd ran as 'velocity'."""
    assert_both_reject(tmp_path, short_deck().replace(*change, 1), ["case.nml", *words])


def test_a_record_file_name_longer_than_1024_is_an_error(tmp_path):
    g = paper_groups(4)
    g["excitation"] = {
        "excitation_type": "record",
        "record_file": "r" * 1100,
        "dt_record": 0.01,
    }
    assert_both_reject(tmp_path, deck_text(g), ["record_file is a string of 1100", "at most 1024"])


# ---------------------------------------------------------------- directories, binary, NUL

def test_a_directory_as_the_deck_says_so(tmp_path):
    (tmp_path / "d.nml").mkdir()
    r = subprocess.run([frictiondyn.executable(), "d.nml"], cwd=tmp_path, capture_output=True,
                       text=True)
    assert r.returncode == 1 and "'d.nml' is a directory, not a file" in r.stderr
    with pytest.raises(DeckError, match="'.*d.nml' is a directory, not a file"):
        frictiondyn.run(tmp_path / "d.nml")


def test_a_directory_as_the_record_file_says_so(tmp_path):
    g = paper_groups(4)
    g["excitation"] = {"excitation_type": "record", "record_file": "rec", "dt_record": 0.01}
    code, err, outcome = both(tmp_path, deck_text(g), files={"rec": None})
    assert code == 1 and "record_file = 'rec'" in err and "is a directory, not a file" in err
    assert isinstance(outcome, DeckError) and "is a directory, not a file" in str(outcome)


def test_a_nul_character_is_an_error_for_the_executable_and_run_text_alike(tmp_path):
    """run_text dropped everything after a NUL while the executable read it."""
    text = short_deck().replace("! m/s", "! m/s\x00 what follows", 1)
    code, err, outcome = both(tmp_path, text)
    assert code == 1 and "case.nml', line 24: a NUL character" in err
    assert isinstance(outcome, DeckError) and "case.nml', line 24: a NUL character" in str(outcome)
    with pytest.raises(DeckError, match="case.nml, line 24: a NUL character"):
        frictiondyn.run_text(text, "case.nml")


def test_a_binary_deck_is_an_error(tmp_path):
    junk = bytes(range(1, 256)) * 4  # no NUL, no newline: one line of binary
    assert_both_reject(tmp_path, junk, ["case.nml", "line 1", "outside any group"])


# ---------------------------------------------------------------- non-ASCII text and paths

def test_non_ascii_comments_and_paths_run_as_in_the_executable(tmp_path):
    """A µ in a comment, a deck tëst.nml, a record accél.txt: TypeError before."""
    t = np.arange(0, 1.0 + 1e-9, 0.005)
    record = "\n".join(f"{x:.9e}" for x in 2.0 * np.sin(2 * np.pi * 4.1 * t)) + "\n"
    g = paper_groups(4)
    g["excitation"] = {"excitation_type": "record", "record_file": "accél.txt", "dt_record": 0.005}
    text = "! µ = 0.22, ε = 1e-3: a comment in UTF-8\n" + deck_text(g)
    code, err, outcome = both(tmp_path, text, name="tëst.nml", files={"accél.txt": record})
    assert code == 0, err
    assert isinstance(outcome, frictiondyn.Result), repr(outcome)
    exe = frictiondyn.read_history(tmp_path / "exe" / "out" / "tëst.csv")
    assert np.array_equal(exe.data, outcome.data)
    assert outcome.summary["deck"] == "tëst.nml"
    r = frictiondyn.run_text(text, "tëst.nml", base_dir=tmp_path / "py")
    assert np.array_equal(r.data, outcome.data)
    # the outputs under a non-ASCII directory, by the library's writer
    with frictiondyn.Session(tmp_path / "py" / "tëst.nml") as s:
        csv, summ = s.solve().write(tmp_path / "sortie-é")
    assert csv.name == "tëst.csv" and summ.exists()
    assert np.array_equal(frictiondyn.read_history(csv).data, outcome.data)


def test_a_text_that_is_not_unicode_is_a_deck_error():
    with pytest.raises(DeckError, match="cannot be encoded"):
        frictiondyn.run_text(short_deck() + "! \ud800 a lone surrogate\n")


def test_the_command_line_prints_no_traceback_for_bad_input(tmp_path):
    cases = {
        "tëst.nml": short_deck().replace("&friction", "& friction"),
        "bin.nml": bytes(range(256)),
        "µ.nml": "&model\n n_dof = 'deux'\n/\n",
    }
    (tmp_path / "dir.nml").mkdir()
    for name, content in cases.items():
        (tmp_path / name).write_bytes(content.encode() if isinstance(content, str) else content)
    for name in [*cases, "dir.nml", "missing.nml"]:
        r = subprocess.run([sys.executable, "-m", "frictiondyn", "run", name], cwd=tmp_path,
                           capture_output=True, text=True)
        assert r.returncode == 1, (name, r.stderr)
        assert "Traceback" not in r.stderr, r.stderr
        lines = r.stderr.strip().splitlines()
        assert len(lines) == 1 and lines[0].startswith("frictiondyn: error: ") and name in lines[0]


# ---------------------------------------------------------------- a deck read once

def test_a_deck_replaced_while_run_reads_it_is_already_read(tmp_path, monkeypatch):
    """fd.run read the deck twice (once for the shape, once to run): a deck replaced in
    between gave "history buffer of the wrong shape". The Session reads it once: the result
    is the first deck's, whatever the file holds when the solver starts."""
    deck = tmp_path / "d.nml"
    deck.write_text(short_deck(duration=1.0))
    reference = frictiondyn.run_text(deck.read_text(), "d.nml")
    core = frictiondyn._api._core

    class Replacing:  # _core, but the deck is replaced (by a 3-DOF one) just before solving
        def __getattr__(self, name):
            return getattr(core, name)

        def fd_session_solve(self, handle, *args):
            deck.write_text(short_deck(duration=2.0).replace("n_dof = 2", "n_dof = 3"))
            return core.fd_session_solve(handle, *args)

    monkeypatch.setattr(frictiondyn._api, "_core", Replacing())
    r = frictiondyn.run(deck)
    monkeypatch.undo()
    assert r.data.shape == reference.data.shape == (201, 12)
    assert np.array_equal(r.data, reference.data)
    with pytest.raises(DeckError, match="mass"):  # the new file, read now, is the 3-DOF one
        frictiondyn.run(deck)


# ---------------------------------------------------------------- overflow, up front

OVERFLOWS = [
    (("p = 61.81", "p = 1e300"), ["&friction", "p(1) = 1.0E300", "at most 1.0E30"]),
    (("amplitude = 0.004052", "amplitude = 1e300"), ["&excitation", "amplitude = 1.0E300"]),
    (("eps = 1.0e-3 ", "eps = 1e-300 "), ["&friction", "eps(1) = 1.0E-300", "at least 1.0E-30"]),
    (("mass = 6.301, 2.530", "mass = 6.301, 1e-40"), ["&model", "mass(2) = 1.0E-40"]),
    (("k = 1084.0, 2895.0", "k = 1084.0, 1e31"), ["&springs", "k(2) = 1.0E31"]),
    (("frequency = 4.104", "frequency = 1e35"), ["&excitation", "frequency = 1.0E35"]),
]


@pytest.mark.parametrize("change, words", OVERFLOWS, ids=[c[0][1] for c in OVERFLOWS])
def test_overflowing_values_are_rejected_naming_group_variable_and_value(tmp_path, change, words):
    """These failed as "the effective stiffness is not positive definite" or "the integration
    diverged", or ended with null energies and exit status 0."""
    text = short_deck()
    assert change[0] in text
    assert_both_reject(tmp_path, text.replace(*change), ["case.nml", *words])


def test_a_record_sample_of_1e308_is_rejected_up_front(tmp_path):
    g = paper_groups(4)
    g["excitation"] = {"excitation_type": "record", "record_file": "r.txt", "dt_record": 0.01}
    files = {"r.txt": "0.0\n0.5\n1e308\n0.1\n"}
    assert_both_reject(tmp_path, deck_text(g), ["&excitation", "record_file", "1.0E308 m/s2"],
                       files=files)


@pytest.mark.parametrize("law, old, new, named", [
    ("hysteretic", "f = 1.0e-5 ", "f = 1.0e-29", "f(1) = 1.0E-29"),
    ("velocity", "eps = 1.0e-3 ", "eps = 1.0e-29", "eps(1) = 1.0E-29"),
])
def test_a_stiffness_beyond_the_digits_of_the_step_is_rejected(tmp_path, law, old, new, named):
    """The hysteretic law with f = 1e-29 m between two masses ('not positive definite'
    before), and the velocity law's band eps = 1e-29 m/s (its sticking damping P mu / eps in
    the effective stiffness): the deck's own variable is named."""
    assert old in short_deck(law)
    text = short_deck(law).replace(old, new)
    assert_both_reject(tmp_path, text, ["&friction", named, "1000000000000.0 times", "raise n1"])


def test_a_speed_dependent_band_beyond_the_digits_of_the_step_is_rejected(tmp_path):
    """The band's coupling is P mu(eps) / eps: a table falling from mu = 0.5 to 1e-6 (a
    static-to-kinetic drop) with eps = 1e-18 m/s has a coupling 5e5 times what its last mu
    gives. The check takes mu(eps) (it took the last mu: a ratio of 8.7e8, accepted): the
    damping in the message is gamma / (beta dt1) P mu(eps) / eps."""
    text = short_deck("velocity").replace(
        "mu = 0.22\n  eps = 1.0e-3 ",
        "mu_law = 'table'\n  mu_table_v = 0.0, 1.0\n  mu_table_mu = 0.5, 1.0e-6\n  eps = 1.0e-18 ")
    assert "1.0e-18" in text
    msg = assert_both_reject(tmp_path, text,
                             ["&friction", "eps(1) = 1.0E-18", "1000000000000.0 times"])
    kd = float(msg.split("sticking stiffness of device 1, ")[1].split()[0])
    mu_eps = 0.5 + (1.0e-6 - 0.5) * 1.0e-18
    assert kd == pytest.approx(0.5 / (0.25 * 2.5e-4) * 61.81 * mu_eps / 1.0e-18, rel=1e-12)


# ---------------------------------------------------------------- bounded work

def test_a_band_no_step_resolves_stops_the_run_at_once(tmp_path):
    """eps1 = 1e-30: 24 million refined steps and 13 million violations for 2 s of motion
    (4.9e-324: 260 s); now an error at the first violation left at dt_min, naming eps1(1),
    its value and the bound P mu dt_min / m (13.6 N * 4.88e-9 s / 1.805 kg = 3.68e-8 m/s)."""
    text = short_deck("hysteretic", duration=2.0).replace("eps1 = 1.0e-3 ", "eps1 = 1.0e-30")
    start = time.monotonic()
    msg = assert_both_reject(tmp_path, text, ["case.nml", "&friction", "eps1(1) = 1.0E-30",
                                              "3.678166258"], kind=SolverError)
    assert time.monotonic() - start < 10
    pmu, dt_min = 61.81 * 0.22, 0.005 / 20 / 50 / 2**10
    m = 6.301 * 2.530 / (6.301 + 2.530)
    bound = float(msg.split("P mu dt_min / m = ")[1].split()[0])
    assert bound == pytest.approx(pmu * dt_min / m, rel=1e-12)
    assert "widen eps1(1)" in msg


def test_a_locked_device_may_have_any_band(run):
    """A device that never slides (P mu far above any force it carries) never violates the
    condition: its band, below P mu dt_min / m, is no error (the rigid-chain test's deck)."""
    g = paper_groups(4, "velocity", p=1.0e6)
    g["excitation"]["duration"] = 1.0
    r = run(g)
    assert r.returncode == 0, r.stderr
    s = r.summary()
    assert s["stick_to_slip"] == [0] and s["correctness_violations"] == 0


@pytest.mark.parametrize(
    "integration, words",
    [
        ({"n2": 2_000_000}, ["n2 = 2000000", "at most 1048576"]),
        ({"n2": 2000}, ["dt_min = 0", "n2 * 2**L <= 1048576", "L = 10"]),
        ({"n2": 50, "dt_min": 1e-13}, ["dt_min = 1.0E-13", "L = 25"]),
    ],
    ids=["n2", "n2 and the default floor", "dt_min"],
)
def test_the_work_of_a_refinement_is_bounded(tmp_path, integration, words):
    g = paper_groups(4)
    g["excitation"]["duration"] = 1.0
    g["integration"].update(integration)
    assert_both_reject(tmp_path, deck_text(g), ["&integration", *words])


def test_a_refinement_within_the_bound_runs(run):
    g = paper_groups(4)
    g["excitation"]["duration"] = 0.5
    g["integration"].update({"n2": 1024})  # 1024 * 2**10 = 2**20 steps at most per dt1 step
    r = run(g)
    assert r.returncode == 0, r.stderr


# ---------------------------------------------------------------- memory

# the checked build (tools/test_checked.sh): executables and the extension under the address
# sanitizer, whose start-up reserves more address space than any RLIMIT_AS a test would set
CHECKED = bool(os.environ.get("FRICTIONDYN_CHECKED"))

LIMIT = textwrap.dedent(
    """
    import resource, sys
    def vm():
        for line in open('/proc/self/status'):
            if line.startswith('VmSize:'):
                return int(line.split()[1]) * 1024
    """
)


def big_deck(n: int) -> str:
    """n masses in a chain to the table, its effective stiffness stored dense (linear_system;
    the banded default would need only 16 n bytes an array): its matrices alone need 8 n**2
    bytes each."""
    nodes = ", ".join(str(i) for i in range(1, n + 1))
    below = ", ".join(str(i) for i in range(0, n))
    return textwrap.dedent(
        f"""
        &model n_dof = {n}, mass = {n}*1.0 /
        &springs n_springs = {n}, node_i = {nodes}, node_j = {below}, k = {n}*1.0e4 /
        &damping damping_type = 'none' /
        &excitation excitation_type = 'none', dt_record = 0.01, duration = 0.02 /
        &integration linear_system = 'dense' /
        """
    ).lstrip()


def test_the_executable_out_of_memory_is_an_error_not_a_crash(tmp_path):
    """A 4000-DOF deck under a 300 MB address-space limit: its K, C and factor (128 MB
    each) cannot all be had. The gfortran runtime aborted ("Allocation would exceed memory
    limit", signal 6) before; now an error naming what could not be had, exit status 1."""
    (tmp_path / "big.nml").write_text(big_deck(4000))
    script = LIMIT + textwrap.dedent(
        f"""
        import os, subprocess
        env = dict(os.environ)
        def limit():
            resource.setrlimit(resource.RLIMIT_AS, (300 * 2**20, 300 * 2**20))
        if {CHECKED!r}:
            # the address sanitizer reserves terabytes of address space when it starts: there,
            # an allocation over 100 MB fails instead (malloc returns NULL, as under the limit)
            env["ASAN_OPTIONS"] = env.get("ASAN_OPTIONS", "") + ":max_allocation_size_mb=100"
            limit = None
        r = subprocess.run([{frictiondyn.executable()!r}, 'big.nml'], preexec_fn=limit,
                           capture_output=True, text=True, env=env)
        print(r.returncode)
        print(r.stderr)
        """
    )
    r = subprocess.run([sys.executable, "-c", script], cwd=tmp_path, capture_output=True,
                       text=True, timeout=120)
    code, _, err = r.stdout.partition("\n")
    assert code == "1", r.stdout + r.stderr
    assert "big.nml" in err and "not enough memory" in err and "4000" in err
    assert not (tmp_path / "out").exists()


def test_python_out_of_memory_raises_the_packages_exception(tmp_path):
    """The same deck through the extension in a Python whose address space is limited to
    what it uses plus 300 MB: OutOfMemoryError (a FrictiondynError and a MemoryError); the
    interpreter died with the gfortran runtime before."""
    (tmp_path / "big.nml").write_text(big_deck(4000))
    script = LIMIT + textwrap.dedent(
        """
        import frictiondyn
        resource.setrlimit(resource.RLIMIT_AS, (vm() + 300 * 2**20, vm() + 300 * 2**20))
        try:
            frictiondyn.run('big.nml')
        except frictiondyn.OutOfMemoryError as exc:
            print('OutOfMemoryError', isinstance(exc, MemoryError), exc)
        """
    )
    env = dict(os.environ, OPENBLAS_NUM_THREADS="1")
    r = subprocess.run([sys.executable, "-c", script], cwd=tmp_path, capture_output=True,
                       text=True, timeout=120, env=env)
    assert r.returncode == 0, r.stderr
    assert r.stdout.startswith("OutOfMemoryError True big.nml: not enough memory"), r.stdout


def test_the_exact_techniques_state_out_of_memory_raises_the_packages_exception(tmp_path):
    """The exact technique's state of a 4000-DOF chain with one Coulomb device (its K and C
    dense, 128 MB each) in a Python whose address space is limited to what it uses plus 200
    MB: OutOfMemoryError (the status of memory that could not be had) naming the state, not
    a solver error."""
    deck = big_deck(4000).replace("&integration linear_system = 'dense' /", "&integration technique = 'event_driven' /")
    deck = deck.replace("&excitation excitation_type = 'none',", "&excitation excitation_type = 'harmonic', "
                        "amplitude = 0.01, frequency = 1.0,")
    (tmp_path / "big.nml").write_text(deck + "&friction n_devices = 1, node_i = 1, node_j = 0, law = 'coulomb', "
                                      "p = 1.0, mu = 0.1 /\n&output n_modes = 0 /\n")
    script = LIMIT + textwrap.dedent(
        """
        import frictiondyn
        resource.setrlimit(resource.RLIMIT_AS, (vm() + 200 * 2**20, vm() + 200 * 2**20))
        try:
            frictiondyn.run('big.nml')
        except frictiondyn.FrictiondynError as exc:
            print(type(exc).__name__, isinstance(exc, MemoryError), exc)
        """
    )
    env = dict(os.environ, OPENBLAS_NUM_THREADS="1")
    r = subprocess.run([sys.executable, "-c", script], cwd=tmp_path, capture_output=True,
                       text=True, timeout=120, env=env)
    assert r.returncode == 0, r.stderr
    assert r.stdout.strip() == ("OutOfMemoryError True big.nml: not enough memory for the exact technique's state "
                                "of n_dof = 4000 DOFs and n_devices = 1 devices"), r.stdout


def test_a_history_numpy_cannot_hold_raises_the_packages_exception(tmp_path, monkeypatch):
    """numpy's MemoryError for the history buffer becomes OutOfMemoryError naming the deck,
    the size and what to change."""

    def no_memory(ncol, nout):
        raise MemoryError

    text = short_deck(duration=0.5)
    monkeypatch.setattr(frictiondyn._api, "_history_array", no_memory)
    with pytest.raises(OutOfMemoryError, match=r"h.nml: not enough memory for the history .*"
                       r"101 samples of 12 columns.*output_every"):
        frictiondyn.run_text(text, "h.nml")


# ---------------------------------------------------------------- no null in a summary

def test_no_summary_of_a_successful_run_holds_null_but_where_undefined():
    """Every bundled deck: a finite number for every summary value (json has no NaN), or
    null in a key whose value can be undefined (docs/namelist.md, "Undefined values")."""
    sys.path.insert(0, str(ROOT / "tests" / "fuzz"))
    from undefined import null_keys, undefined_keys

    for deck in sorted(INPUTS.glob("*.nml")):
        text = re.sub(r"duration = (?:40|30)\.0", "duration = 1.0", deck.read_text())
        r = frictiondyn.run_text(text, deck.name, base_dir=INPUTS)
        assert null_keys(json.loads(r.summary_text)) <= undefined_keys(), deck.name
        assert "NaN" not in json.dumps(r.summary), deck.name


def star_deck(n: int) -> str:
    """n masses, each on a spring to the table and to mass 1 and on a Coulomb device to the
    table, integrated by Moreau-Jean: the band of its reduced system is as wide as the model,
    n**2 numbers (8000 DOFs: 512 MB)."""
    nodes = ", ".join(str(i) for i in range(1, n + 1))
    others = ", ".join(str(i) for i in range(2, n + 1))
    return textwrap.dedent(
        f"""
        &model n_dof = {n}, mass = {n}*1.0 /
        &springs n_springs = {2 * n - 1}, node_i = {nodes}, {others},
                 node_j = {n}*0, {n - 1}*1, k = {2 * n - 1}*1.0e4 /
        &damping damping_type = 'none' /
        &friction n_devices = {n}, node_i = {nodes}, node_j = {n}*0, law = {n}*'coulomb',
                  p = {n}*10.0, mu = {n}*0.3 /
        &excitation excitation_type = 'harmonic', amplitude = 0.01, frequency = 2.0,
                    dt_record = 0.01, duration = 0.02 /
        &integration technique = 'moreau_jean' /
        """
    ).lstrip()


def test_moreau_jean_out_of_memory_is_an_error_not_a_crash(tmp_path):
    """The Moreau-Jean technique's work space (its edges, the reduced band system, the
    solver's arrays) is sized by the deck too: an 8000-DOF star under the 300 MB limit of
    test_the_executable_out_of_memory... is an error naming what could not be had (its
    allocations were unchecked: the gfortran runtime aborted)."""
    (tmp_path / "star.nml").write_text(star_deck(8000))
    script = LIMIT + textwrap.dedent(
        f"""
        import os, subprocess
        env = dict(os.environ)
        def limit():
            resource.setrlimit(resource.RLIMIT_AS, (300 * 2**20, 300 * 2**20))
        if {CHECKED!r}:
            env["ASAN_OPTIONS"] = env.get("ASAN_OPTIONS", "") + ":max_allocation_size_mb=100"
            limit = None
        r = subprocess.run([{frictiondyn.executable()!r}, 'star.nml'], preexec_fn=limit,
                           capture_output=True, text=True, env=env)
        print(r.returncode)
        print(r.stderr)
        """
    )
    r = subprocess.run([sys.executable, "-c", script], cwd=tmp_path, capture_output=True,
                       text=True, timeout=300, check=False)
    code, _, err = r.stdout.partition("\n")
    assert code == "1", r.stdout + r.stderr
    assert "star.nml" in err and "not enough memory" in err and "8000" in err, err
    assert not (tmp_path / "out").exists()


def test_no_character_function_with_an_allocatable_result():
    """README's rule for the Fortran library: no function with a character(len=:),
    allocatable result. gfortran 12 keeps such a result's length in a static variable of
    the caller, and runs side by side in threads then mix their texts up (warning texts
    did so: test_many_concurrent_runs_of_the_same_files_are_identical fails when they do).
    Every function's result declaration in fortran/ and the extension is read."""
    root = ROOT
    sources = sorted((root / "fortran").rglob("*.f90")) + sorted((root / "driver").rglob("*.f90"))
    assert len(sources) > 40
    head = re.compile(r"^\s*(?:(?:pure|elemental|recursive|impure)\s+)*(?:[\w(),= ]+\s+)?function\s+(\w+)"
                      r"\s*\([^)]*\)\s*(?:result\s*\(\s*(\w+)\s*\))?", re.I | re.M)
    bad = []
    for f in sources:
        text = f.read_text(errors="replace")
        for m in head.finditer(text):
            name, res = m.group(1), m.group(2) or m.group(1)
            end = re.search(r"^\s*end\s+function", text[m.end():], re.I | re.M)
            body = text[m.end(): m.end() + (end.start() if end else 0)]
            decl = re.compile(r"character\s*\(\s*len\s*=\s*:\s*\)\s*,\s*allocatable[^\n!]*::[^\n!]*\b"
                              + re.escape(res) + r"\b", re.I)
            if decl.search(body):
                bad.append(f"{f.relative_to(root)}: {name}")
    assert not bad, bad


def test_lapack_interfaces_are_declared_once_and_generated_files_once():
    """The interfaces of the LAPACK and BLAS routines the library calls are in one module,
    fortran/linalg/fd_lapack.f90 (one argument list each, not a copy per module), and every
    file the build generates (configure_file) is generated by one meson.build statement
    (meson warns and overwrites otherwise)."""
    lapack = re.compile(r"^\s*(?:pure\s+)?subroutine\s+(d[a-z0-9]+)\s*\(", re.I | re.M)
    # a routine that takes another's argument list: procedure(dpotrf) :: dpotf2
    shared = re.compile(r"^\s*procedure\s*\(\s*\w+\s*\)\s*::\s*(d[a-z0-9]+(?:\s*,\s*d[a-z0-9]+)*)\s*$",
                        re.I | re.M)
    declared: dict[str, list[str]] = {}
    for f in sorted((ROOT / "fortran").rglob("*.f90")):
        text = f.read_text(errors="replace")
        names = [n for block in re.findall(r"^\s*interface\s*$(.*?)^\s*end\s+interface", text, re.I | re.M | re.S)
                 for n in lapack.findall(block)]
        names += [n.strip() for group in shared.findall(text) for n in group.split(",")]
        for name in names:
            declared.setdefault(name.lower(), []).append(str(f.relative_to(ROOT)))
    assert {"dpotrf", "dpbtrf", "dsymv", "dsterf", "dsbgvx", "dpotf2", "dgemv"} <= set(declared)
    elsewhere = {n: fs for n, fs in declared.items() if fs != ["fortran/linalg/fd_lapack.f90"]}
    assert not elsewhere, elsewhere
    outputs = []
    for build in sorted(ROOT.rglob("meson.build")):
        if any(p.startswith((".venv", "build")) for p in build.relative_to(ROOT).parts):
            continue
        for m in re.finditer(r"configure_file\((.*?)\n\)", build.read_text(), re.S):
            out = re.search(r"output:\s*'([^']+)'", m.group(1))
            outputs.append(f"{build.parent.relative_to(ROOT)}/{out.group(1)}")
    assert "fortran/core/fd_version.f90" in outputs
    assert len(outputs) == len(set(outputs)), outputs


# ---------------------------------------------------------------- echoed values are capped

MEGA = 1_000_000


@pytest.mark.parametrize(
    "change, words",
    [
        (("  n1 = 20", "  n1 = 20, nn1 = " + "7" * MEGA), ["unknown variable 'nn1'", "77777"]),
        (("  n1 = 20", "  n1 = " + "x" * MEGA), ["variable 'n1' has a bad value 'xxxx"]),
        (("  n1 = 20", "  " + "n" * MEGA + " = 20"), ["unknown variable 'nnnn", "(value 20)"]),
        (("&damping", "&" + "d" * MEGA), ["unknown group &dddd"]),
        (("&damping", "deck " + "t" * MEGA + "\n&damping"), ["text outside any group"]),
    ],
    ids=["unknown variable's value", "bad value", "variable name", "group name", "text outside"],
)
def test_a_megabyte_value_is_echoed_as_80_characters_and_its_length(tmp_path, change, words):
    """A 1 MB unknown value gave a 1 MB stderr line and a 1,000,073-character DeckError."""
    text = short_deck()
    assert change[0] in text
    message = assert_both_reject(tmp_path, text.replace(*change, 1), ["case.nml", *words])
    assert f"... ({MEGA} characters)" in message or f"... ({MEGA + 5} characters)" in message
    assert len(message) < 400, len(message)


def test_a_record_whose_first_line_is_a_megabyte_is_echoed_capped(tmp_path):
    """A record_file naming a file that is no record echoed its first line whole."""
    g = paper_groups(4)
    g["excitation"] = {"excitation_type": "record", "record_file": "r.txt", "dt_record": 0.01}
    message = assert_both_reject(tmp_path, deck_text(g), ["record_file = 'r.txt'", "line 1",
                                 "'" + "q" * 80 + f"... ({MEGA} characters)' is not a number"],
                                 files={"r.txt": "q" * MEGA + "\n0.1\n"})
    assert len(message) < 400


@pytest.mark.parametrize(
    "line3, line4, words",
    [
        ("ACCELERATION TIME SERIES IN UNITS OF G", "NPTS=  3, DT=  .0100 SEC " + "w" * MEGA,
         ["line 4", "after NPTS and DT"]),
        ("ACCELERATION TIME SERIES IN UNITS OF G", "NPTS=  3, NPTS= 3, DT=  .0100 SEC " + "w" * MEGA,
         ["line 4", "NPTS is given twice"]),
        ("ACCELERATION TIME SERIES IN UNITS OF G", "NPTS=  3, DT=  .0100 " + "M" * MEGA,
         ["line 4", "DT is followed by"]),
        ("ACCELERATION TIME SERIES IN UNITS OF " + "F" * MEGA, "NPTS=  3, DT=  .0100 SEC",
         ["line 3", "the header declares units of"]),
        ("ACCELERATION TIME SERIES IN UNITS OF G", "DT=  .0100 SEC " + "x" * MEGA,
         ["line 4", "NPTS is missing"]),
    ],
)
def test_an_at2_header_line_of_a_megabyte_is_echoed_capped(tmp_path, line3, line4, words):
    """The AT2 header's messages quote the line they refuse: 80 characters and its length."""
    g = paper_groups(4)
    g["excitation"] = {"excitation_type": "record", "record_file": "r.AT2", "record_format": "at2"}
    at2 = "\n".join(["PEER NGA STRONG MOTION DATABASE RECORD", "TEST", line3, line4,
                     "  .1000000E-01  .2000000E-01  .1000000E-01"]) + "\n"
    message = assert_both_reject(tmp_path, deck_text(g), ["record file", *words, "characters)"],
                                 files={"r.AT2": at2})
    assert len(message) < 600, len(message)


def test_an_echo_is_cut_between_utf8_characters_and_counts_characters(tmp_path):
    text = short_deck().replace("  n1 = 20", "  n1 = " + "é" * 100, 1)
    message = assert_both_reject(tmp_path, text, ["'" + "é" * 80 + "... (100 characters)'"])
    assert "\ufffd" not in message


def test_the_executable_caps_an_unknown_option_and_index(tmp_path):
    long = 100_000  # an argument of the command line is at most 128 KiB
    r = subprocess.run([frictiondyn.executable(), "--" + "x" * long], capture_output=True,
                       text=True)
    assert r.returncode == 2 and f"... ({long + 2} characters)'" in r.stderr and len(r.stderr) < 400
    (tmp_path / "l.txt").write_text("a.nml\n")
    r = subprocess.run([frictiondyn.executable(), "--list", "l.txt", "--index", "1" * long],
                       cwd=tmp_path, capture_output=True, text=True)
    assert r.returncode == 2 and f"... ({long} characters)'" in r.stderr and len(r.stderr) < 400


# ---------------------------------------------------------------- line ends, --list

def test_a_deck_whose_lines_end_with_cr_alone_says_so(tmp_path):
    """It said "required group &model is missing"."""
    text = short_deck().replace("\n", "\r")
    assert_both_reject(tmp_path, text, ["case.nml: its lines end with CR alone", "LF"])


def test_crlf_line_ends_run_as_lf_ones():
    a = frictiondyn.run_text(short_deck(duration=0.2), "a.nml")
    b = frictiondyn.run_text(short_deck(duration=0.2).replace("\n", "\r\n"), "a.nml")
    assert np.array_equal(a.data, b.data)


def test_list_of_a_directory_or_of_cr_lines_says_so(tmp_path):
    """`--list` on a directory said "has only 0 line(s)"."""
    (tmp_path / "decks").mkdir()
    r = subprocess.run([frictiondyn.executable(), "--list", "decks", "--index", "0"], cwd=tmp_path,
                       capture_output=True, text=True)
    assert r.returncode == 1 and "'decks' is a directory, not a file" in r.stderr, r.stderr
    (tmp_path / "l.txt").write_text("a.nml\rb.nml\r")
    r = subprocess.run([frictiondyn.executable(), "--list", "l.txt", "--index", "1"], cwd=tmp_path,
                       capture_output=True, text=True)
    assert r.returncode == 1 and "--list 'l.txt': its lines end with CR alone" in r.stderr, r.stderr
    r = subprocess.run([frictiondyn.executable(), "--list", "nope.txt", "--index", "0"],
                       cwd=tmp_path, capture_output=True, text=True)
    assert r.returncode == 1 and "'nope.txt' does not exist" in r.stderr, r.stderr


# ---------------------------------------------------------------- the history's size, up front

def history_deck(duration, every=1, limit=None):
    text = short_deck(duration=duration)
    extra = f"  output_every = {every}\n"
    if limit is not None:
        extra += f"  max_history_mb = {limit}\n"
    return text.replace("  dir = 'out'\n", "  dir = 'out'\n" + extra)


def test_a_history_beyond_max_history_mb_is_refused_up_front(tmp_path):
    """A 332-byte deck asked for about 29 GB of history, and wrote it."""
    # 2e5 s at dt1 = 0.005 / 20: 8e8 samples of 12 columns, 25 bytes a value: 2.4e11 bytes
    message = assert_both_reject(tmp_path, history_deck(2.0e5), [
        "group &output", "the history would take 223.5 GiB (800000001 samples of 12 columns)",
        "max_history_mb = 2048 MiB",
        "raise output_every (a sample every 1 dt1 steps now, of 800000000)",
        "history_dofs, history_devices: 2 and 1 now", "write_history = .false."])
    assert "max_history_mb" in message
    # the same run without a history file, or with the limit raised, is read (not run here)
    no_file = history_deck(2.0e5).replace("  output_every",
                                          "  write_history = .false.\n  output_every")
    frictiondyn.Session.from_text(no_file, "a.nml").close()
    frictiondyn.Session.from_text(history_deck(2.0e5, limit=300000), "a.nml").close()


@pytest.mark.parametrize("limit", [0, -1])
def test_max_history_mb_must_be_positive(tmp_path, limit):
    assert_both_reject(tmp_path, history_deck(0.1, limit=limit),
                       ["group &output", f"max_history_mb = {limit} is invalid", ">= 1"])


def test_the_history_size_is_the_files(tmp_path):
    """The estimate is the file's size but its header: a history of just over 1 MiB is
    refused with max_history_mb = 1, and one just under it is written, to that size."""
    # 12 columns x 25 bytes = 300 bytes a sample; 1 MiB = 3495.25 samples: 3495 fit
    under = history_deck(3494 * 0.005 / 20, limit=1)     # 3494 steps: 3495 samples
    over = history_deck(3495 * 0.005 / 20, limit=1)      # 3496 samples
    assert_both_reject(tmp_path, over, ["1.0 MiB (3496 samples of 12 columns)",
                                        "max_history_mb = 1 MiB"])
    deck = tmp_path / "under.nml"
    deck.write_text(under)
    r = subprocess.run([frictiondyn.executable(), "under.nml"], cwd=tmp_path, capture_output=True,
                       text=True)
    assert r.returncode == 0, r.stderr
    csv = tmp_path / "out" / "under.csv"
    header = csv.read_bytes().split(b"\n", 1)[0]
    assert csv.stat().st_size == 3495 * 12 * 25 + len(header) + 1 <= 1048576 + len(header) + 1


def test_an_analysis_whose_history_is_beyond_the_limit_raises_a_deck_error():
    """The Python model goes through the library's reader: the same check, before any run."""
    import dataclasses

    from frictiondyn import Output
    from frictiondyn.paper import paper_analysis

    a = paper_analysis(4, "velocity")
    a = dataclasses.replace(a, excitation=dataclasses.replace(a.excitation, duration=2.0e5),
                            output=Output(output_every=1))
    with pytest.raises(DeckError, match=r"group &output: the history would take .* GiB"):
        a.run()
