"""The time-step convergence study (driver/frictiondyn/convergence.py, ``frictiondyn
converge``): its levels are the deck at finer steps and nothing else; its verdict follows the
closed form of Newmark's error on a linear oscillator; it finds the step-dependent results
the paper (Fig. 3's coarse step) and a fuzz deck (a sticking spring's ringing) exhibit, and
passes the paper's converged decks; it refuses what it cannot study, and Ctrl-C stops it."""

from __future__ import annotations

import json
import math
import os
import re
import resource
import signal
import subprocess
import sys
import time
from pathlib import Path

import frictiondyn as fd
import pytest
from conftest import INPUTS
from frictiondyn.cli import main as cli
from frictiondyn.convergence import SAFETY_DIFFERENCE, SAFETY_RICHARDSON, estimate_error, step_convergence
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
    coarse = step_convergence(write(tmp_path, OSCILLATOR.replace("N1", "2"), "n2.nml"), levels=1)
    assert coarse.n1 == [2, 4] and not coarse.converged
    assert "peak_u_m" in [q.key for q in coarse.moved]
    deck = write(tmp_path, OSCILLATOR.replace("N1", "4"), "n4.nml")
    fine = step_convergence(deck, levels=1)
    assert fine.n1 == [4, 8] and fine.converged, str(fine)
    (u,) = [q for q in fine.quantities if q.key == "peak_u_m"]
    for value, s in zip(u.values, fine.summaries):
        assert value == pytest.approx(newmark_amplitude(s["dt1_s"]), rel=1e-5)
    change = abs(newmark_amplitude(fine.summaries[1]["dt1_s"]) / newmark_amplitude(fine.summaries[0]["dt1_s"]) - 1)
    assert 0.005 < change < 0.01
    strict = step_convergence(deck, levels=1, rtol=0.005)
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
    the deck at twice and four times n1, and their estimated step errors are within 1 % (the
    step the paper chose resolves its experiment; the laws' own errors are another matter,
    test_the_velocity_laws_error_estimate_against_the_exact_technique)."""
    for law in ("hysteretic", "velocity"):
        report = step_convergence(INPUTS / f"test{test}_{law}.nml", law=False)
        assert report.converged and report.n1 == [20, 40, 80], str(report)
        assert not report.law_summaries


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
    assert saved["converged"] is False and saved["n1"] == [2, 4, 8]
    assert saved == json.loads(json.dumps(report.to_dict()))
    assert cli(["converge", str(INPUTS / "test4_velocity.nml")]) == 0
    assert "converged: every quantity agrees" in capsys.readouterr().out
    assert cli(["converge", str(INPUTS / "test4_velocity.nml"), "--no-law", "--levels", "1"]) == 0
    text = capsys.readouterr().out
    assert "n1 = 20, 40 (" in text and "the step's errors alone" in text


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


def _cpu_seconds(pid: int) -> float:
    """The processor time (user and system) process pid has used so far [s]."""
    fields = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()
    return (int(fields[11]) + int(fields[12])) / os.sysconf("SC_CLK_TCK")


def test_ctrl_c_stops_every_level(tmp_path):
    """Ctrl-C during a study of a long deck (three levels, about 10 s of work) stops it within
    a second: exit status 130, "interrupted"."""
    text = (INPUTS / "test4_hysteretic.nml").read_text().replace("n1 = 20", "n1 = 400")
    deck = write(tmp_path, text)
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    subprocess.run([sys.executable, "-m", "frictiondyn", "--help"], capture_output=True, check=True)
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    startup = (after.ru_utime + after.ru_stime) - (before.ru_utime + before.ru_stime)
    proc = subprocess.Popen(
        [sys.executable, "-m", "frictiondyn", "converge", str(deck), "--levels", "2"],
        stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
    )
    # the command's start-up done (imports, the deck read) and the levels running: the child
    # has spent twice the processor time a bare start-up takes, plus half a second (processor
    # time, not wall time: under load a start-up takes seconds of wall time)
    limit = time.monotonic() + 120.0
    while proc.poll() is None and time.monotonic() < limit and _cpu_seconds(proc.pid) < 2 * startup + 0.5:
        time.sleep(0.05)
    assert proc.poll() is None, proc.communicate()
    sent = time.monotonic()
    os.kill(proc.pid, signal.SIGINT)
    out, err = proc.communicate(timeout=30)
    waited = time.monotonic() - sent
    assert proc.returncode == 130, err
    assert "interrupted" in err and waited < 1.0, (waited, err)


def test_estimate_error_on_known_series():
    """q(h) = 1 + 0.3 h^1.5 at h = 1, 1/2, 1/4: the order 1.5 and the limit 1 come out exactly,
    each level's error is 1.25 times its distance to it. Changes that alternate in sign, or do
    not shrink, or from two levels are plain differences (3 times the distance to the finest
    level), with the reason; changes at round-off are 'unchanged'."""
    e = estimate_error([1 + 0.3 * h**1.5 for h in (1.0, 0.5, 0.25)], 2, 1.0)
    assert e.method == "richardson" and e.order == pytest.approx(1.5, abs=1e-12)
    assert e.extrapolated == pytest.approx(1.0, abs=1e-14)
    for err, h in zip(e.errors, (1.0, 0.5, 0.25)):
        assert err == pytest.approx(SAFETY_RICHARDSON * 0.3 * h**1.5, rel=1e-12)
    # four levels: every triple's order must be consistent
    assert estimate_error([1 + 0.3 * h for h in (1.0, 0.5, 0.25, 0.125)], 2, 1.0).order == pytest.approx(1.0)
    assert estimate_error([1.0, 1.1, 1.15, 1.3], 2, 1.0).method == "difference"
    alternating = estimate_error([1.0, 1.1, 1.05], 2, 1.0)
    assert alternating.method == "difference" and "alternate" in alternating.reason
    assert alternating.errors == pytest.approx([SAFETY_DIFFERENCE * 0.05] * 3)
    assert "do not shrink" in estimate_error([1.0, 1.1, 1.3], 2, 1.0).reason
    assert "outside" in estimate_error([1.0, 1.1, 1.1001], 2, 1.0).reason  # order 10
    assert "two levels" in estimate_error([1.0, 1.1], 2, 1.0).reason
    same = estimate_error([2.0, 2.0 + 1e-12, 2.0], 2, 2.0)
    assert same.method == "unchanged" and same.error == pytest.approx(1e-12)


def test_richardson_on_the_resonant_oscillator(tmp_path):
    """The resonant oscillator at n1 = 6, 12, 24: the peak displacement converges at the
    measured order 2.9 (Newmark's frequency error is of second order; the amplitude, near a
    resonance, goes with its square as the step shrinks), above Newmark's theoretical 2: the
    estimate is Richardson's at order 2, named with the order measured, and the estimated
    error of n1 = 6, 1.25 times its distance to the finest level plus the finest's own, is
    1.30 times its true error against the closed form (the amplitude at dt -> 0, 25 mm)."""
    report = step_convergence(write(tmp_path, OSCILLATOR.replace("N1", "6")))
    assert report.n1 == [6, 12, 24] and report.converged, str(report)
    (u,) = [q for q in report.quantities if q.key == "peak_u_m"]
    e = u.estimate
    assert e.method == "richardson" and e.order == 2.0 and u.law_estimate is None
    assert 2.5 < e.measured < 3.2
    true = abs(u.values[0] - newmark_amplitude(1e-12))
    assert 1.0 < u.error / true < 1.5, (u.error, true)
    assert e.extrapolated == pytest.approx(0.025, rel=5e-5)
    assert e.errors[0] == pytest.approx(SAFETY_RICHARDSON * abs(u.values[0] - u.values[2]) + e.errors[2])
    assert "peak |u| DOF 1" in str(report)
    assert f"step {e.error:.3g}: Richardson at order 2, the theoretical ({e.measured:.2f} measured)" \
        in str(report)
    assert report.to_dict()["quantities"][0]["estimate_method"] == (
        f"step: Richardson at order 2, the theoretical ({e.measured:.2f} measured)")


def test_the_velocity_laws_error_estimate_against_the_exact_technique():
    """Test 4 under the velocity law (eps = 1e-3 m/s, n1 = 20): the law levels (eps / 2,
    eps / 4 at n1 = 80) converge at the measured order 1.00, and the estimated error of every
    peak displacement and acceleration and of the friction energy is 1.0 to 1.5 times its
    true error against the exact technique (measured 1.24 to 1.26: the safety factor 1.25
    on a Richardson estimate that is almost exact)."""
    report = step_convergence(INPUTS / "test4_velocity.nml")
    exact = fd.run(INPUTS / "test4_coulomb.nml").summary
    assert report.converged and len(report.law_summaries) == 2
    checked = 0
    for q in report.quantities:
        if q.key not in ("peak_u_m", "peak_aabs_mps2", "energy_friction_J"):
            continue
        assert q.law_estimate.method == "richardson" and abs(q.law_estimate.order - 1) < 0.05
        ref = exact[q.key] if q.key == "energy_friction_J" else exact[q.key][int(q.item.split()[-1]) - 1]
        assert 1.0 < q.error / abs(q.values[0] - ref) < 1.5, (q.key, q.item)
        checked += 1
    assert checked == 5


BUILDING = """
&model
 n_dof = 3
 mass = 300e3, 300e3, 250e3
/
&springs
 n_springs = 3
 node_i = 1, 2, 3
 node_j = 0, 1, 2
 k = 400e6, 320e6, 200e6
/
&damping
 damping_type = 'rayleigh'
 rayleigh_a0 = 0.3
 rayleigh_a1 = 8e-4
/
&friction
 n_devices = 3
 node_i = 1, 2, 3
 node_j = 0, 1, 2
 law = 3*'LAW'
 mu = 3*0.3
 p = 1384000, 898900, 408600
 f = 3*1e-5
 eps1 = 3*1e-3
/
&storeys
 n_storeys = 3
 node_i = 1, 2, 3
 node_j = 0, 1, 2
/
&excitation
 excitation_type = 'record'
 record_file = 'RECORD'
 duration = 8.0
/
&integration
 technique = 'TECHNIQUE'
 n1 = 20
/
"""


def building(tmp_path, law: str, technique: str):
    """A 3-storey shear building (floors 300, 300, 250 t) with a rigid-plastic friction
    damper in each storey slipping at 0.3 times 1384, 899, 409 kN, under the first 8 s of the
    synthetic record."""
    text = BUILDING.replace("LAW", law).replace("TECHNIQUE", technique)
    return write(tmp_path, text.replace("RECORD", str(INPUTS / "synthetic_pga035.AT2")), f"{law}.nml")


def test_the_hysteretic_laws_acceleration_error_does_not_vanish_with_the_step(tmp_path, capsys):
    """The building's dampers under the hysteretic law (f = 1e-5 m): the peak floor 1
    acceleration is 3.64 m/s2 at n1 = 20, 40 and 80 (changes below 2e-6 of it: the step has
    converged), 4.0 % below the exact technique's 3.79 m/s2, and stays there at any n1: the
    sticking spring rings where the exact force jumps. The step levels cannot see it; the law
    levels (f and eps1 / 2, / 4) do: their changes have no consistent order, so the estimate
    is a plain difference (5.9 %, above the true 4.0 %), and the study is NOT converged and
    says that the law's error, not the step's, governs it (exit status 3). Without the law
    levels the report says that a regularized law's error is not included."""
    deck = building(tmp_path, "hysteretic", "newmark")
    exact = fd.run(building(tmp_path, "coulomb", "event_driven")).summary["peak_aabs_mps2"][0]
    report = step_convergence(deck)
    (a1,) = [q for q in report.quantities if q.key == "peak_aabs_mps2" and q.item == "DOF 1"]
    assert max(abs(v / a1.values[0] - 1) for v in a1.values) < 1e-5
    true = abs(a1.values[0] - exact)
    assert true > 0.03 * exact
    assert not report.converged and not a1.agrees
    assert a1.law_estimate.method == "difference" and a1.error >= true
    assert a1.estimate.error < 1e-4 * a1.values[0]  # the step's share
    out = tmp_path / "building.json"
    assert cli(["converge", str(deck), "--json", str(out)]) == 3
    text = capsys.readouterr().out
    assert "NOT converged" in text and "carry the law's error (eps or f)" in text
    assert re.search(r"; law [0-9.e+-]+: difference \(", text), text
    saved = json.loads(out.read_text())
    (row,) = [x for x in saved["quantities"] if x["key"] == "peak_aabs_mps2" and x["item"] == "DOF 1"]
    assert row["law"]["method"] == "difference" and row["estimated_error"] == pytest.approx(a1.error)
    alone = step_convergence(deck, law=False)
    assert "the step's errors alone" in str(alone)


def test_a_failed_law_level_is_named(monkeypatch):
    """A law level that cannot run (here a deck whose refined f is made invalid) stops the
    study with the library's message, the level it came from and how to leave such levels
    out."""
    import frictiondyn.convergence as conv

    real = conv._law_text
    monkeypatch.setattr(conv, "_law_text", lambda text, f: real(text, f).replace("    f = ", "    f = -", 1))
    with pytest.raises(fd.DeckError) as info:
        step_convergence(INPUTS / "test4_hysteretic.nml")
    text = str(info.value)
    assert "group &friction: f(1) = -5.0E-6 is invalid: must be > 0 m" in text, text
    assert text.endswith("(in the step convergence study, the level n1 = 80 with eps and f / 2; "
                         "--no-law (law=False) leaves the law levels out)"), text
