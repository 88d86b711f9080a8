"""A velocity-law band whose force the step leaves alternating (summary ``band_x``,
``band_alternation_N``, ``band_alternation_s``, ``band_resolution``; docs/theory.md section 6):
the trapezoidal rule's factor (1 - x) / (1 + x) on a stiff band, the alternation against the
exact technique (in the forces and accelerations, not the displacements), a random deck whose
accelerations it multiplied, and the paper's decks, whose x > 1 leaves none."""

from __future__ import annotations

import warnings

import f90nml
import frictiondyn as fd
import numpy as np
import pytest
from conftest import INPUTS, ok
from test_numerical_dissipation import stiff_band

FLOOR = 0.05  # fd_band_alternation's alternation_floor: the share of P mu counted


def test_a_stiff_band_alternates_by_the_trapezoidal_factor(run):
    """Two masses coupled by a band of c1 = P mu / eps = 1e7 N s/m (x = c1 dt1 / (2 m_r) =
    7.5e4) released with 0.4 m/s between them: the trapezoidal rule leaves that velocity
    alternating, multiplied by r = (1 - x) / (1 + x) a step. The run of second differences
    starts at the third step's force, |D| / 4 = c1 0.4 |r| (1 + |r|)^2 / 4, and every later
    step stays above 5 % of P mu (|r|^800 = 0.979), so the time counted is the run less two
    steps. The
    exact technique holds the masses together with a few newtons: after 1 s the difference
    of the forces is the alternation itself, decayed by |r|^200 = 0.995; the displacements
    agree."""
    r = ok(run(stiff_band(1e8, "0.0, 0.4")))
    s = r.summary()
    c1, dt1, mr = 1e7, 0.005, 1.0 * 0.5 / 1.5
    x = c1 * dt1 / (2 * mr)
    assert s["band_x"][0] == pytest.approx(x, rel=1e-12)
    q = (x - 1) / (x + 1)
    expect = c1 * 0.4 * q * (1 + q) ** 2 / 4
    assert s["band_alternation_N"][0] == pytest.approx(expect, rel=1e-5)
    assert s["band_alternation_s"][0] == pytest.approx(4.0 - 2 * dt1, abs=1e-9)
    assert s["band_resolution"] == "unresolved"
    assert "alternates step to step in its band" in r.stderr
    assert "dt1 < 6.667E-08 s or widen eps" in r.stderr

    e = ok(run(stiff_band(1e8, "0.0, 0.4", technique="event_driven")))
    h, g = r.history(), e.history()
    late = h["t"] > 1.0
    diff = np.max(np.abs(h["F1"][late] - g["F1"][late]))
    assert 0.99 * expect <= diff <= expect
    assert np.max(np.abs(g["F1"][late])) < 1e-5 * expect
    for k in (1, 2):
        assert s["peak_u_m"][k - 1] == pytest.approx(e.summary()["peak_u_m"][k - 1], rel=1e-3)
    assert e.summary()["band_resolution"] == "not applicable"


@pytest.mark.parametrize(
    "law, factor",
    [
        ("mu_law = 'table'\n  mu_table_v = 1.0, 2.0\n  mu_table_mu = 0.1, 0.0", 1.0),
        ("mu_law = 'exponential'\n  mu_max = 0.0\n  mu_min = 0.1\n  mu_rate = 1.0", np.exp(-1.0)),
    ],
)
def test_a_band_with_a_speed_dependent_mu_is_watched(run, law, factor):
    """A speed-dependent mu whose value at the table's last point (or mu_max) is 0 but whose
    band coupling P mu(eps) / eps is the constant law's 1e7 N s/m times mu(eps) / 0.1 (1 for
    the table, exp(-1) for the exponential at eps = 1 m/s): x scales by that factor, and the
    alternation, c1 0.4 |r| (1 + |r|)^2 / 4 with |r| near 1, by it too. (These devices were
    once taken for devices without friction: never watched, and never sliding.)"""
    const = ok(run(stiff_band(1e8, "0.0, 0.4"))).summary()
    deck = stiff_band(1e8, "0.0, 0.4").replace("  mu = 0.1\n", "  " + law + "\n")
    s = ok(run(deck)).summary()
    assert s["band_x"][0] == pytest.approx(factor * const["band_x"][0], rel=1e-12)
    assert s["band_alternation_N"][0] == pytest.approx(
        factor * const["band_alternation_N"][0], rel=1e-4
    )
    assert s["band_resolution"] == "unresolved"


def test_numerical_damping_is_no_cure(run):
    """Newmark's gamma > 1/2 damps the alternation, r -> -(1 - gamma) / gamma (-2/3 at
    gamma = 0.6), but the band's start, an acceleration of 8e6 m/s2, enters the displacement
    through (1/2 - beta) h^2 a: the masses move 0.4 m and 1 m where they move 7 mm, and the
    energy check, not this one, says so. Hence the warning advises n1 or eps, not gamma."""
    deck = stiff_band(1e8, "0.0, 0.4").replace("n1 = 4", "n1 = 4\n  gamma = 0.6\n  beta = 0.3025")
    r = ok(run(deck))
    s = r.summary()
    assert s["band_alternation_s"][0] <= 5 * 0.005  # the run's five steps, then gone
    assert max(s["peak_u_m"]) > 50 * 0.0074
    assert s["energy_balance"] == "energy error"


# Fuzz seed 1181 (tests/fuzz/physics.py): three masses on springs, the heavier two coupled by
# two velocity-law devices in parallel, released from rest with offsets (no table motion).
SEED_1181 = """
&model
  n_dof = 3
  mass = 0.4758023004091374, 12.393197105318732, 7.933205110759262
  u0 = -0.008607713261927042, -0.015057769053136702, 0.019657747949091215
/
&springs
  n_springs = 3
  node_i = 1, 2, 3
  node_j = 0, 1, 1
  k = 5394.033527931343, 1639.4852211917585, 934.7204127162066
/
&damping
  damping_type = 'stiffness'
  xi = 0.05252105938450953
  period = 0.9671281821150209
/
&friction
  n_devices = 2
  node_i = 3, 3
  node_j = 2, 2
  law = '{law}', '{law}'
  p = 103.21516863642096, 103.21516863642096
  mu = 0.28692399004490393, 0.28692399004490393
  eps = 1.2249046769603922e-05, 1.2249046769603922e-05
/
&excitation
  excitation_type = 'none'
  dt_record = 0.005
  duration = 1.5740869885154467
/
&integration
  technique = '{technique}'
  n1 = 16
/
&output
  output_every = 1
/
"""


def test_the_alternation_multiplies_the_peak_accelerations(run):
    """Seed 1181: the two devices in their band (x = 78 each alone, 156 together) hold masses 2
    and 3 together. The exact technique's holding force is at most 10.4 N a device; the
    velocity law's alternates by 9.9 N a device for 0.047 s, so its peak force is 20.1 N (93 %
    over) and the peak absolute accelerations of DOFs 2 and 3 are 3 and 4 times the exact
    ones, while every displacement agrees to 1e-4 (3.8e-5: the band's creep). The warning
    names it, and its amplitude accounts for the acceleration of DOF 3 (two devices,
    2 A / m3) to 3 %."""
    r = ok(run(SEED_1181.format(law="velocity", technique="newmark")))
    e = ok(run(SEED_1181.format(law="coulomb", technique="event_driven")))
    s, x = r.summary(), e.summary()
    assert s["band_resolution"] == "unresolved"
    assert "the force of device 1 alternates" in r.stderr and "1 more device(s)" in r.stderr
    assert s["band_x"] == pytest.approx([2 * 78.101] * 2, rel=1e-4)
    amp = s["band_alternation_N"][0]
    assert s["band_alternation_N"][1] == amp and FLOOR * 103.215 * 0.28692 < amp
    assert s["peak_force_N"][0] > 1.9 * x["peak_force_N"][0]
    for k in (1, 2):
        assert s["peak_aabs_mps2"][k] > 2.9 * x["peak_aabs_mps2"][k]
    assert s["peak_u_m"] == pytest.approx(x["peak_u_m"], rel=1e-4)
    h, g = r.history(), e.history()
    err3 = np.max(np.abs(h["aabs3"] - g["aabs3"]))
    assert 2 * amp / 7.933205110759262 == pytest.approx(err3, rel=0.03)


@pytest.mark.parametrize("test", [1, 2, 3, 4, 5])
def test_the_papers_decks_have_no_alternation(run, test):
    """The paper's velocity-law decks: x = (P mu / eps) dt1 / (2 m_r) from the deck (1.3 to 1.9
    for tests 1-3, so that a static x > 1 would condemn them; their errors are 1e-5), and no
    alternation counted: the band's entries decay within the run of forces a count needs."""
    path = INPUTS / f"test{test}_velocity.nml"
    nml = f90nml.read(path)
    fr, m = nml["friction"], nml["model"]["mass"]
    dt1 = nml["excitation"]["dt_record"] / nml["integration"]["n1"]
    mr = m[0] * m[1] / (m[0] + m[1])
    x = fr["p"] * fr["mu"] / fr["eps"] * dt1 / (2 * mr)
    r = ok(run(path.read_text()))
    s = r.summary()
    assert s["band_x"][0] == pytest.approx(x, rel=1e-12)
    assert s["band_resolution"] == "resolved" and s["band_alternation_N"] == [0.0]
    assert "alternates" not in r.stderr
    if test <= 3:
        assert x > 1


def test_python_warns_alike(run):
    """Python issues the executable's warnings word for word (one text, fd_warnings), with
    the summary's figures."""
    deck = SEED_1181.format(law="velocity", technique="newmark")
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        res = fd.run_text(deck)
    text = [str(w.message) for w in caught if issubclass(w.category, fd.FrictiondynWarning)]
    exe = ok(run(deck)).stderr.splitlines()
    prefix = "frictiondyn: warning: "
    assert [t.split(": ", 1)[1] for t in text] == [x[len(prefix) :] for x in exe if x.startswith(prefix)]
    band = [t for t in text if "alternates step to step" in t]
    assert len(band) == 1
    assert f"band_alternation_N = +-{res.summary['band_alternation_N'][0]:.3E} N" in band[0]
    assert "dt1 < 2.001E-06 s or widen eps" in band[0] and "1 more device(s)" in band[0]


def test_hysteretic_decks_are_not_applicable(run):
    """No velocity-law device: nothing watched."""
    s = ok(run((INPUTS / "test1_hysteretic.nml").read_text())).summary()
    assert s["band_resolution"] == "not applicable" and s["band_x"] == [0.0]
