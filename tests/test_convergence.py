"""The time-step convergence study (driver/frictiondyn/convergence.py, ``frictiondyn
converge``): its levels are the deck at finer steps and nothing else; its verdict follows the
closed form of Newmark's error on a linear oscillator; it finds the step-dependent results
the paper (Fig. 3's coarse step) and a fuzz deck (a sticking spring's ringing) exhibit, and
passes the paper's converged decks; it refuses what it cannot study, and Ctrl-C stops it."""

from __future__ import annotations

import json
import math
import os
import signal
import subprocess
import sys
import time

import frictiondyn as fd
import pytest
from conftest import INPUTS
from frictiondyn.cli import main as cli
from frictiondyn.convergence import step_convergence
from test_stick_ringing import ringing_deck

# A 10 Hz oscillator (m = 1 kg, 2 % stiffness-proportional damping) driven at resonance by a
# table displacement of 1 mm; dt_record = 10.7 ms is incommensurate with the period, so the
# steps sample every phase of the steady state.
OSCILLATOR = """
&model
  n_dof = 1
  mass = 1.0
/
&springs
  n_springs = 1
  node_i = 1
  node_j = 0
  k = 3947.8417604357433
/
&damping
  damping_type = 'stiffness'
  xi = 0.02
  period = 0.1
/
&excitation
  excitation_type = 'harmonic'
  dt_record = 0.0107
  amplitude = 0.001
  frequency = 10.0
  duration = 12.0
  ramp_cycles = 20
/
&integration
  n1 = N1
/
"""


def newmark_amplitude(dt: float) -> float:
    """Steady-state amplitude of the oscillator under average acceleration at step dt: for a
    linear system the rule is the trapezoidal rule, whose response to a sampled e^(i w t) is
    the exact one at the frequency Omega = (2 / dt) tan(w dt / 2) (the bilinear transform)."""
    w = 2 * math.pi * 10.0
    psi = 0.1 * 0.02 / math.pi  # C = psi K, psi = T xi / pi
    om = 2 / dt * math.tan(w * dt / 2)
    return 0.001 * w * w / abs(complex(w * w - om * om, psi * w * w * om))


def write(tmp_path, text: str, name: str = "deck.nml"):
    path = tmp_path / name
    path.write_text(text)
    return path


def test_the_verdict_follows_newmarks_error_on_an_oscillator(tmp_path):
    """At resonance the amplitude moves with the step through Newmark's frequency error:
    10 % from n1 = 2 to 4, 0.83 % from 4 to 8 (closed form). With rtol = 1 % the study at
    n1 = 2 does not converge and the one at n1 = 4 does; with rtol = 0.5 % neither. The peaks
    it reports are the closed-form amplitudes."""
    coarse = step_convergence(write(tmp_path, OSCILLATOR.replace("N1", "2"), "n2.nml"))
    assert coarse.n1 == [2, 4] and not coarse.converged
    assert "peak_u_m" in [q.key for q in coarse.moved]
    deck = write(tmp_path, OSCILLATOR.replace("N1", "4"), "n4.nml")
    fine = step_convergence(deck)
    assert fine.n1 == [4, 8] and fine.converged, str(fine)
    (u,) = [q for q in fine.quantities if q.key == "peak_u_m"]
    for value, s in zip(u.values, fine.summaries):
        assert value == pytest.approx(newmark_amplitude(s["dt1_s"]), rel=1e-5)
    change = abs(newmark_amplitude(fine.summaries[1]["dt1_s"]) / newmark_amplitude(fine.summaries[0]["dt1_s"]) - 1)
    assert 0.005 < change < 0.01
    strict = step_convergence(deck, rtol=0.005)
    assert not strict.converged and [q.key for q in strict.moved][0] in ("peak_u_m", "peak_v_mps", "peak_aabs_mps2")
    # no device: no device quantity, no friction energy, no count
    assert {q.key for q in fine.quantities} == {"peak_u_m", "peak_v_mps", "peak_aabs_mps2", "peak_base_shear_N"}


def test_levels_are_the_deck_at_finer_steps(tmp_path):
    """Each level is the deck with n1 (and dt_min, given in seconds) scaled and nothing else:
    its summary equals that of the deck edited by hand."""
    text = (INPUTS / "test4_hysteretic.nml").read_text().replace("40.0", "2.0")
    text = text.replace("n2 = 50", "n2 = 50\n  dt_min = 1e-6")
    assert "dt_min = 1e-6" in text and "n1 = 20" in text
    report = step_convergence(write(tmp_path, text), levels=2)
    assert report.n1 == [20, 40, 80]
    for k, s in enumerate(report.summaries):
        edited = text.replace("n1 = 20", f"n1 = {20 * 2**k}").replace("dt_min = 1e-6", f"dt_min = {1e-6 / 2**k!r}")
        ref = fd.run_text(edited, base_dir=INPUTS).summary
        assert s["dt_min_s"] == ref["dt_min_s"] == pytest.approx(1e-6 / 2**k, rel=1e-15)
        for key in ("dt1_s", "peak_u_m", "peak_aabs_mps2", "peak_force_N", "stick_to_slip",
                    "energy_friction_J", "steps_dt1", "steps_dt2", "correctness_violations"):
            assert s[key] == ref[key], (k, key)


def test_a_deck_with_elements_and_an_empty_n1(tmp_path):
    """u0 given from element 2 (f90nml holds its start apart) and n1 = , (an empty value:
    the default 20): level 0 is the deck itself, level 1 the deck at n1 = 40."""
    text = (INPUTS / "test4_hysteretic.nml").read_text().replace("40.0", "1.0")
    text = text.replace("&model\n", "&model\n  u0(2) = 0.002\n", 1).replace("n1 = 20", "n1 = ,")
    report = step_convergence(write(tmp_path, text), levels=1)
    assert report.n1 == [20, 40]
    alone = fd.run_text(text, base_dir=INPUTS).summary
    for key in ("peak_u_m", "peak_s_m", "stick_to_slip", "energy_friction_J"):
        assert report.summaries[0][key] == alone[key], key


@pytest.mark.parametrize("test", [1, 2, 3, 4, 5])
def test_the_papers_decks_converge(test):
    """The paper's decks at their own step: both laws' peaks, energies and counts agree with
    the deck at twice n1 (the step the paper chose resolves its experiment)."""
    for law in ("hysteretic", "velocity"):
        report = step_convergence(INPUTS / f"test{test}_{law}.nml")
        assert report.converged, str(report)


def test_fig3s_coarse_step_does_not(tmp_path, capsys):
    """Fig. 3's coarse step (n1 = 2): the stick-slip history moves with the step (the paper's
    point), and the command exits with status 3; the JSON report is the report."""
    deck = INPUTS / "fig3_coarse.nml"
    report = step_convergence(deck)
    moved = {q.key for q in report.moved}
    assert "stick_to_slip" in moved and not report.converged
    assert any("correctness condition" in w for w in report.warnings[0])
    out = tmp_path / "conv.json"
    assert cli(["converge", str(deck), "--json", str(out)]) == 3
    text = capsys.readouterr().out
    assert "NOT converged" in text and "stick-to-slip transitions" in text
    saved = json.loads(out.read_text())
    assert saved["converged"] is False and saved["n1"] == [2, 4]
    assert saved == json.loads(json.dumps(report.to_dict()))
    assert cli(["converge", str(INPUTS / "test4_velocity.nml")]) == 0
    assert "converged: every quantity agrees" in capsys.readouterr().out


def test_a_ringing_sticking_spring_is_found(tmp_path):
    """The fuzz deck whose device 2 slides 81 times at n1 = 24 and never from 48 on: the study
    says its count moves, and shows the run's own ringing warning at n1 = 24 only."""
    report = step_convergence(write(tmp_path, ringing_deck(24)))
    (count,) = [q for q in report.quantities if q.key == "stick_to_slip" and q.item == "device 2"]
    assert count.values[0] > 20 and count.values[1] == 0 and not count.agrees
    assert any("sticking spring of device 2" in w for w in report.warnings[0])
    assert not any("sticking spring" in w for w in report.warnings[1])


def test_what_it_refuses(tmp_path, capsys):
    """The exact technique has no step to converge; a missing deck, a bad factor, level count
    or tolerance are errors naming the value; the command line prints one line, status 1."""
    with pytest.raises(fd.DeckError, match="technique = 'event_driven' is exact"):
        step_convergence(INPUTS / "test4_coulomb.nml")
    with pytest.raises(fd.DeckError, match="no such deck"):
        step_convergence(tmp_path / "absent.nml")
    bad = write(tmp_path, (INPUTS / "test4_velocity.nml").read_text().replace("n1 = 20", "n1 = -3"))
    with pytest.raises(fd.DeckError, match="n1"):
        step_convergence(bad)
    deck = INPUTS / "test4_velocity.nml"
    for kw, text in ((dict(factor=1), "factor = 1"), (dict(levels=0), "levels = 0"),
                     (dict(rtol=0.0), "rtol = 0.0"), (dict(rtol=1.5), "rtol = 1.5")):
        with pytest.raises(ValueError, match=text):
            step_convergence(deck, **kw)
    assert cli(["converge", str(INPUTS / "test4_coulomb.nml")]) == 1
    err = capsys.readouterr().err
    assert err.startswith("frictiondyn: error: ") and err.count("\n") == 1


def test_ctrl_c_stops_every_level(tmp_path):
    """Ctrl-C during a study of a long deck (three levels, about 10 s of work) stops it within
    a second: exit status 130, "interrupted"."""
    text = (INPUTS / "test4_hysteretic.nml").read_text().replace("n1 = 20", "n1 = 400")
    deck = write(tmp_path, text)
    proc = subprocess.Popen(
        [sys.executable, "-m", "frictiondyn", "converge", str(deck), "--levels", "2"],
        stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
    )
    time.sleep(1.0)  # imports, deck read, levels started
    assert proc.poll() is None, proc.communicate()
    sent = time.monotonic()
    os.kill(proc.pid, signal.SIGINT)
    out, err = proc.communicate(timeout=30)
    waited = time.monotonic() - sent
    assert proc.returncode == 130, err
    assert "interrupted" in err and waited < 1.0, (waited, err)
