"""Whether dt1 resolves the ringing of the hysteretic devices' sticking springs
(fortran/technique/resolution/fd_stick_ringing.f90): the frequency error it reports against the closed forms
of Newmark's rules, and the warning against what the step really does to the stick-slip
decisions: a deck whose device slides 81 times at n1 = 24 and never at any n1 >= 48 is
reported, one at n1 = 96 (the same decisions as n1 = 192) is not, and neither are the
paper's converged decks."""

from __future__ import annotations

import contextlib
import io
import math
import warnings

import frictiondyn as fd
import pytest
from conftest import INPUTS, M1, M2, MU, P, ok
from frictiondyn.cli import main as cli

WARNING = "the sticking spring of device"

# Three masses, four devices (random fuzz deck, seed 103021): device 2, hysteretic with
# f = 1.87e-6 m between masses 2 and 3, is a 6.6e5 N/m spring whose mode (226 Hz) lies between
# the 25th and 27th harmonics of the 8.8 Hz excitation, which device 1 (velocity law, a force
# close to a square wave) feeds. Newmark's frequency error at n1 = 24 (2.8 %) puts it on the
# 25th: the ringing grows until the device slides (81 times); from n1 = 48 on it never does,
# and its peak force converges to 0.913 N, 74 % of P mu.
RINGING_DECK = """
&model
  n_dof = 3
  mass = 0.636666681555486, 1.6740255989932191, 0.412215758813636
/
&springs
  n_springs = 3
  node_i = 1, 2, 3
  node_j = 0, 1, 2
  k = 4113.600997281284, 1485.4011894994571, 67.95915089603324
/
&damping
  damping_type = 'stiffness'
  xi = 0.04438772479596607
  period = 0.1647328140145145
/
&friction
  n_devices = 4
  node_i = 3, 2, 1, 1
  node_j = 0, 3, 0, 0
  law = 'velocity', 'hysteretic', 'velocity', 'velocity'
  p = 0.7435173025961468, 8.590329151685118, 2.438296412870482, 0.38208215035702625
  mu(1) = 0.2327260659643129
  mu(2) = 0.14430488432298288
  eps(2) = 1.9506458717108422e-05
  eps(3) = 0.0017683354860718664
  eps(4) = 0.020663219441776993
  eps1(2) = 0.0002872104868542958
  eps1(3) = 0.00024463842962946106
  f(1) = 1.549334674801157e-07
  f(2) = 1.8658319928435527e-06
  mu_law(3) = 'table'
  mu_table_v(:, 3) = 0.0488, 0.1451, 0.1569, 0.3011
  mu_table_mu(:, 3) = 0.04983565809311137, 0.22035176266434486, 0.19658785956766414, 0.031231991231375465
  mu_law(4) = 'exponential'
  mu_max(4) = 0.4925050690309953, mu_min(4) = 0.29799285224723737, mu_rate(4) = 49.86936646964634
/
&excitation
  excitation_type = 'harmonic'
  dt_record = 0.01
  amplitude = 0.0007880330971798994
  frequency = 8.817388946142497
  duration = 3.2080896603063276
  ramp_cycles = 3
/
&integration
  n1 = N1
  n2 = 41
  n = 5.0
/
&output
  dir = 'out'
  n_modes = 2
/
"""


def ringing_deck(n1: int) -> str:
    return RINGING_DECK.replace("N1", str(n1))


def trapezoidal_error(w: float) -> float:
    return 1 - 2 * math.atan(w / 2) / w


def test_frequency_error_closed_forms(run):
    """Test 4, hysteretic: the sticking spring P mu / f between the masses, m_r = m1 m2 /
    (m1 + m2); the average acceleration rule's frequency is 2 atan(w / 2) / dt1 (w = omega
    dt1 = 0.217: 0.39 % low), the linear acceleration rule's has cos(w~) = 1 - w^2 / (2 (1 +
    w^2 / 6)) (0.20 % low). The velocity law has no sticking spring: not applicable."""
    text = (INPUTS / "test4_hysteretic.nml").read_text().replace("40.0", "0.05")
    s = ok(run(text)).summary()
    omega = math.sqrt(P * MU / 1e-5 * (M1 + M2) / (M1 * M2))
    w = omega * s["dt1_s"]
    assert s["stick_frequency_error"][0] == pytest.approx(trapezoidal_error(w), rel=1e-9)
    assert 0.0038 < s["stick_frequency_error"][0] < 0.0040
    assert s["stick_resolution"] == "resolved" and s["stick_ringing_ratio"] == [0.0]
    linear = ok(run(text.replace("n2 = 50", "n2 = 50\n  beta = 0.1666666666666667"))).summary()
    wl = math.acos(1 - w * w / (2 * (1 + w * w * 0.1666666666666667)))
    assert linear["stick_frequency_error"][0] == pytest.approx(1 - wl / w, rel=1e-9)
    velocity = (INPUTS / "test4_velocity.nml").read_text().replace("40.0", "0.05")
    s = ok(run(velocity)).summary()
    assert s["stick_resolution"] == "not applicable" and s["stick_frequency_error"] == [0.0]


def test_the_warning_is_where_the_step_decides_the_slides(run):
    """n1 = 24: device 2 slides 81 times where the converged answer (n1 = 192) never slides;
    the step dephases the sticking spring's ringing (2.76 % frequency error, stick_ringing_ratio
    above 1) and the executable says so, naming the device. n1 = 96: the converged decisions,
    and no warning."""
    runs = {n1: ok(run(ringing_deck(n1), name=f"n{n1}")) for n1 in (24, 96, 192)}
    s = {n1: r.summary() for n1, r in runs.items()}
    assert s[24]["stick_to_slip"][1] > 20 and s[192]["stick_to_slip"][1] == 0
    assert s[24]["stick_resolution"] == "unresolved"
    # device 2: P mu / f between masses 2 and 3 (m_r = m2 m3 / (m2 + m3)), average acceleration
    m2, m3 = 1.6740255989932191, 0.412215758813636
    k = 8.590329151685118 * 0.14430488432298288 / 1.8658319928435527e-06
    w = math.sqrt(k * (m2 + m3) / (m2 * m3)) * s[24]["dt1_s"]
    assert s[24]["stick_frequency_error"][1] == pytest.approx(trapezoidal_error(w), rel=1e-9)
    assert 0.027 < trapezoidal_error(w) < 0.028
    assert s[24]["stick_ringing_ratio"][1] > 2
    assert s[24]["stick_margin_N"][1] == 0.0  # its worst stick phase ends in a slide
    assert WARNING + " 2 " in runs[24].stderr
    assert "stick_ringing_ratio = " in runs[24].stderr and "raise n1" in runs[24].stderr
    # the other devices have no sticking spring
    assert [s[24]["stick_ringing_ratio"][d] for d in (0, 2, 3)] == [0.0, 0.0, 0.0]
    assert s[96]["stick_to_slip"] == s[192]["stick_to_slip"]
    for n1 in (96, 192):
        assert s[n1]["stick_resolution"] == "resolved", n1
        assert s[n1]["stick_ringing_ratio"][1] <= 1
        assert WARNING not in runs[n1].stderr


@pytest.mark.parametrize("test", [1, 2, 3, 4, 5])
def test_the_paper_decks_are_resolved(run, test):
    """The paper's hysteretic decks: their stick-slip counts at n1 and 2 n1 agree (within
    max(2, 1 %): the step does not decide them), and no warning."""
    text = (INPUTS / f"test{test}_hysteretic.nml").read_text()
    assert "  n1 = 20\n" in text
    r = ok(run(text, name=f"test{test}"))
    fine = ok(run(text.replace("  n1 = 20\n", "  n1 = 40\n"), name=f"test{test}_fine")).summary()
    count, reference = r.summary()["stick_to_slip"][0], fine["stick_to_slip"][0]
    assert abs(count - reference) <= max(2, 0.01 * reference)
    assert r.summary()["stick_resolution"] == "resolved"
    assert WARNING not in r.stderr


def test_the_coarse_fig3_deck_is_reported(run):
    """The deliberately coarse deck of Fig. 3 (n1 = 2: the frequency of its sticking spring is
    24 % low, and its highest modes are not resolved either): reported."""
    r = ok(run((INPUTS / "fig3_coarse.nml").read_text(), name="fig3"))
    s = r.summary()
    omega = math.sqrt(P * MU / 1e-5 * (M1 + M2) / (M1 * M2))
    assert s["stick_frequency_error"][0] == pytest.approx(trapezoidal_error(omega * s["dt1_s"]), rel=1e-9)
    assert s["stick_frequency_error"][0] > 0.2
    assert s["stick_resolution"] == "unresolved" and s["stick_ringing_ratio"][0] > 1
    assert WARNING + " 1 " in r.stderr


def test_python_and_cli_warn(tmp_path):
    """The Python API warns (FrictiondynWarning) where the executable does, and the command
    line prints it; a resolved run is silent."""
    with pytest.warns(fd.FrictiondynWarning, match=WARNING + " 2 rings"):
        r = fd.run_text(ringing_deck(24))
    assert r.summary["stick_resolution"] == "unresolved"
    with warnings.catch_warnings():
        warnings.simplefilter("error", fd.FrictiondynWarning)
        fd.run_text(ringing_deck(96))
    deck = tmp_path / "ringing.nml"
    deck.write_text(ringing_deck(24))
    err = io.StringIO()
    with contextlib.redirect_stderr(err), contextlib.redirect_stdout(io.StringIO()):
        assert cli(["run", str(deck), "--out", str(tmp_path / "cli")]) == 0
    assert WARNING + " 2 rings" in err.getvalue()
