"""Whether the main step resolves the structure's highest modes (fortran/technique/
fd_mode_resolution.f90): the summary's omega_max against closed forms and numpy's eigenvalues
of the system each technique integrates, the status against omega_max dt1 = 2, the wrong
period it reports (the trapezoidal rule's, exactly), and the warnings of the executable and
the command line."""

from __future__ import annotations

import contextlib
import io
import math
import warnings

import frictiondyn as fd
import numpy as np
import pytest
from conftest import INPUTS, K1, K2, M1, M2, MU, P, deck_text, ok
from frictiondyn.cli import main as cli

WARNING = "does not resolve the highest modes"


def chain_omega_max(masses, springs) -> float:
    """sqrt of the largest eigenvalue of M^-1/2 K M^-1/2 (numpy), springs (i, j, k), node 0
    the table."""
    n = len(masses)
    k = np.zeros((n, n))
    for i, j, s in springs:
        for a, b, sign in ((i, i, 1), (j, j, 1), (i, j, -1), (j, i, -1)):
            if a > 0 and b > 0:
                k[a - 1, b - 1] += sign * s
    d = 1 / np.sqrt(np.asarray(masses, float))
    return math.sqrt(np.linalg.eigvalsh(d[:, None] * k * d[None, :])[-1])


def test_paper_test4_hysteretic_closed_form(run):
    """Test 4, hysteretic law: the stiffest system Newmark integrates has the sticking spring
    P mu / f between the masses; its highest omega is the larger root of the two-mass
    characteristic equation (1e-12), 868 rad/s, resolved by dt1 = 0.25 ms (omega dt1 = 0.22)."""
    r = ok(run((INPUTS / "test4_hysteretic.nml").read_text().replace("40.0", "0.05")))
    s = r.summary()
    kc = P * MU / 1e-5
    b = (M1 * (K2 + kc) + M2 * (K1 + kc)) / (M1 * M2)
    c = (K1 * K2 + kc * (K1 + K2)) / (M1 * M2)
    omega = math.sqrt(0.5 * (b + math.sqrt(b * b - 4 * c)))
    assert s["omega_max_rad_s"] == pytest.approx(omega, rel=1e-12)
    assert s["omega_max_dt1"] == pytest.approx(omega * s["dt1_s"], rel=1e-12)
    assert s["mode_resolution"] == "resolved"
    assert WARNING not in r.stderr


def test_paper_test4_velocity_springs_only(run):
    """Test 4, velocity law: the device adds damping, not stiffness; the two bars are then
    uncoupled and the highest omega is max(sqrt(k1/m1), sqrt(k2/m2))."""
    s = ok(run((INPUTS / "test4_velocity.nml").read_text().replace("40.0", "0.05"))).summary()
    omega = max(math.sqrt(K1 / M1), math.sqrt(K2 / M2))
    assert s["omega_max_rad_s"] == pytest.approx(omega, rel=1e-12)
    assert s["mode_resolution"] == "resolved"


G = 9.80665


@pytest.mark.parametrize("radius", [0.0, 2.0])
def test_bearing_under_a_vertical_component_at_its_largest_normal_force(tmp_path, radius):
    """A 1000 kg block on one hysteretic bearing (flat, or a friction pendulum of R = 2 m) to
    the table, springs 2e4 N/m along x and 1e4 along y, its static normal force p = M g and
    a constant vertical acceleration a_z = 0.8 g: N = 1.8 p all the run. The structure's
    stiffness along x is then k_x, the sticking spring N mu / f and the pendulum's N / R (a
    force lagged one step in Newmark's step), so omega_max^2 = (k_x + N (mu / f + 1 / R)) / M
    (1e-12); at the deck's p it would be 25 % lower, and dt1 = 25 ms resolves that system
    (omega dt1 = 1.75 flat) but not the structure's."""
    m, kx, mu, f, p = 1000.0, 2.0e4, 0.1, 2.0e-4, 1000.0 * G
    (tmp_path / "az.txt").write_text(f"{0.8 * G:.17e}\n" * 41)
    bearing = {"n_bearings": 1, "dof_xi": 1, "dof_yi": 2, "dof_xj": 0, "dof_yj": 0, "p": p, "mu": mu,
               "law": "hysteretic", "f": f, "eps1": 1.0e-3}
    if radius:
        bearing["radius"] = radius
    groups = {
        "model": {"n_dof": 2, "mass": [m, m]},
        "springs": {"n_springs": 2, "node_i": [1, 2], "node_j": [0, 0], "k": [kx, 1.0e4]},
        "damping": {"damping_type": "none"},
        "bearings": bearing,
        "excitation": {"excitation_type": "harmonic", "amplitude": 0.08, "frequency": 1.0, "dt_record": 0.025,
                       "duration": 1.0},
        "excitation3": {"excitation_type": "record", "record_file": "az.txt", "record_format": "values",
                        "record_units": "m/s2", "dt_record": 0.025},
        "integration": {"n1": 1},
        "output": {"dir": "out"},
    }
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        s = fd.run_text(deck_text(groups), "v.nml", tmp_path).summary
    n_max = s["bearing_max_normal_force_N"][0]
    assert n_max == pytest.approx(1.8 * p, rel=1e-14)
    stiff = 1.0 / radius if radius else 0.0
    omega = math.sqrt((kx + n_max * (mu / f + stiff)) / m)
    assert s["omega_max_rad_s"] == pytest.approx(omega, rel=1e-12)
    assert s["omega_max_dt1"] == pytest.approx(omega * 0.025, rel=1e-12)
    assert math.sqrt((kx + p * (mu / f + stiff)) / m) * 0.025 < 2.0 < s["omega_max_dt1"]
    assert s["mode_resolution"] == "unresolved"
    assert any(WARNING in str(w.message) for w in caught)


def building(n: int, law: str, technique: str | None) -> fd.Analysis:
    """n storeys of 1000/n t, storey springs and brace-like devices stiffer at the base."""
    m = 1e6 / n
    k = [4e9 * (1 + (n - i) / n) for i in range(n)]
    devices = [
        fd.Device(i + 1, i, 0.05 * m * 9.81 * (n - i), 1.0, law=law, f=1e-3, eps=1e-3)
        for i in range(n)
    ]
    return fd.Analysis(
        masses=[m] * n,
        springs=[fd.Spring(i + 1, i, k[i]) for i in range(n)],
        damping=fd.Damping("none"),
        devices=devices,
        excitation=fd.FreeVibration(dt_record=0.01, duration=0.02),
        integration=fd.Integration(technique=technique, n1=10),
        u0=[1e-3 * (i + 1) / n for i in range(n)],
    )


@pytest.mark.filterwarnings("ignore::frictiondyn.FrictiondynWarning")
@pytest.mark.parametrize("n", [20, 300])
def test_building_against_numpy(n):
    """Shear buildings of 20 (dsygv) and 300 storeys (Lanczos): Newmark with hysteretic
    devices integrates the springs plus the sticking springs P mu / f, Moreau-Jean with
    Coulomb devices the springs alone (rigid links only lower the top of the spectrum); omega
    equal to numpy's to 1e-12 (dense) and 1e-4 (Lanczos, never above it), and the status
    follows omega dt1 against 2."""
    for law, technique in (("hysteretic", None), ("coulomb", "moreau_jean")):
        an = building(n, law, technique)
        s = an.run().summary
        springs = [(sp.node_i, sp.node_j, sp.k) for sp in an.springs]
        if law == "hysteretic":
            springs += [(d.node_i, d.node_j, d.p * d.mu / d.f) for d in an.devices]
        exact = chain_omega_max(an.masses, springs)
        got = s["omega_max_rad_s"]
        if n <= 64:
            assert got == pytest.approx(exact, rel=1e-12), law
        else:
            assert got <= exact * (1 + 1e-12), law
            assert got == pytest.approx(exact, rel=1e-4), law
        expected = "unresolved" if got * s["dt1_s"] > 2 else "resolved"
        assert s["mode_resolution"] == expected


def test_event_driven_not_applicable():
    """The event-driven technique takes no step: the question does not arise."""
    an = building(3, "coulomb", "event_driven")
    s = an.run().summary
    assert s["mode_resolution"] == "not applicable"
    assert s["omega_max_rad_s"] is None and s["omega_max_dt1"] is None  # undefined: null


def one_dof(omega_dt: float, dt: float = 0.01, steps: int = 40) -> fd.Analysis:
    """A mass on a spring with omega dt1 = omega_dt, free vibration from u0 = 1."""
    w = omega_dt / dt
    return fd.Analysis(
        masses=[1.0],
        springs=[fd.Spring(1, 0, w * w)],
        damping=fd.Damping("none"),
        excitation=fd.FreeVibration(dt_record=dt, duration=steps * dt),
        integration=fd.Integration(n1=1),
        u0=[1.0],
    )


@pytest.mark.filterwarnings("ignore::frictiondyn.FrictiondynWarning")
@pytest.mark.parametrize("omega_dt", [0.5, 4.0, 40.0])
def test_reported_period_is_the_trapezoidal_rule(omega_dt):
    """What the report means: average acceleration integrates a mode of omega dt1 with the
    phase 2 atan(omega dt1 / 2) a step, u_n = cos(n theta) exactly (1e-12): at omega dt1 = 4
    its period is 1.81 times the true one, at 40 it is 2.1 steps whatever the true period. The
    status is 'resolved' at 0.5 and 'unresolved' above 2."""
    r = one_dof(omega_dt).run()
    u = r.dof(1)["u"]
    theta = 2 * math.atan(omega_dt / 2)
    np.testing.assert_allclose(u, np.cos(np.arange(u.size) * theta), rtol=0, atol=1e-12)
    s = r.summary
    assert s["omega_max_dt1"] == pytest.approx(omega_dt, rel=1e-12)
    assert s["mode_resolution"] == ("resolved" if omega_dt <= 2 else "unresolved")


def test_executable_and_cli_warn(tmp_path, run):
    """An unresolved step is run (exit 0) and reported on stderr by the executable and by the
    command line, with omega_max dt1, in the same words; a resolved one is not."""
    deck = one_dof(4.0).write_deck(tmp_path / "stiff.nml")
    r = ok(run(deck.read_text(), name="stiff"))
    assert WARNING in r.stderr
    assert "omega_max_dt1 = 4.00 > 2" in r.stderr
    assert r.summary()["mode_resolution"] == "unresolved"
    err = io.StringIO()
    with contextlib.redirect_stderr(err), contextlib.redirect_stdout(io.StringIO()):
        assert cli(["run", str(deck), "--out", str(tmp_path / "cli")]) == 0
    line = [x for x in r.stderr.splitlines() if WARNING in x]
    assert len(line) == 1 and line[0] in err.getvalue().splitlines()
    soft = one_dof(0.5).write_deck(tmp_path / "soft.nml")
    assert WARNING not in ok(run(soft.read_text(), name="soft")).stderr


def test_python_warns():
    """The Python API warns (FrictiondynWarning) where the executable does: an unresolved
    step, and steps that violate the correctness condition (the paper's Fig. 3 deck); a
    resolved run is silent."""
    with pytest.warns(fd.FrictiondynWarning, match="does not resolve the highest modes"):
        one_dof(4.0).run()
    from frictiondyn.paper import paper_analysis

    coarse = paper_analysis(4, "hysteretic", coarse=True, duration=2.0)
    with pytest.warns(fd.FrictiondynWarning, match="violate the correctness condition"):
        r = coarse.run()
    assert r.summary["correctness_violations"] > 0
    with warnings.catch_warnings():
        warnings.simplefilter("error", fd.FrictiondynWarning)
        one_dof(0.5).run()
