"""Whether dt1 resolves a recorded table motion
(fortran/technique/resolution/fd_record_resolution.f90): the reported error of the peak linear
response against the run itself (its own Newmark steps against a run 64 times finer, read at
the same instants, from rest and from initial conditions); the verdict on the system the run
was in (a sliding fuzz deck whose stuck system is 25 % off and whose run is right); a fuzz
deck whose peaks are 84-98 % off at n1 = dt_record / dt1 = 1 reported, with the warning from
the executable and Python, and resolved at n1 = 16; the bundled record decks resolved; not
applicable to harmonic motion and without modes."""

from __future__ import annotations

import math
import warnings

import frictiondyn as fd
import numpy as np
import pytest
from conftest import INPUTS, ok
from frictiondyn.synthetic import synthetic_record, write_at2

F_N = 5.0  # the oscillator's natural frequency [Hz]

OSCILLATOR = f"""
&model
  n_dof = 1
  mass = 1.0
/
&springs
  n_springs = 1
  node_i = 1
  node_j = 0
  k = {(2 * math.pi * F_N) ** 2!r}
/
&damping
  damping_type = 'stiffness'
  xi = 0.02
  period = {1 / F_N!r}
/
&excitation
  excitation_type = 'record'
  record_file = 'rec.AT2'
/
&integration
  n1 = N1
/
&output
  output_every = EVERY
/
"""


@pytest.fixture(scope="module")
def record_file(tmp_path_factory):
    """8 s of a synthetic record at dt = 0.02 s whose ground filter sits at the oscillator's
    frequency: the resonant part of its spectrum is what a step's period error moves."""
    rec = synthetic_record(duration=8.0, dt=0.02, pga_g=0.3, seed=11, wg=2 * math.pi * F_N, zg=0.3)
    return write_at2(rec, tmp_path_factory.mktemp("rec") / "rec.AT2").read_text()


def _true_errors(run, deck_at, n1: int, files: dict, name: str):
    """The deck (deck_at(n1, every)) at n1 with every step written and at 64 n1 with every
    64th (the same instants): the coarse run and each DOF's |peak |u| / the fine run's - 1|,
    the error the step alone makes in the peak read at the steps."""
    coarse = ok(run(deck_at(n1, 1), name=name, files=files))
    fine = ok(run(deck_at(64 * n1, 64), name=name + "_fine", files=files))
    s, h_c, h_f = coarse.summary(), coarse.history(), fine.history()
    assert len(h_c["t"]) == len(h_f["t"]) and np.allclose(h_c["t"], h_f["t"], atol=1e-9)
    true = []
    for i in range(1, s["n_dof"] + 1):
        peak = s["peak_u_m"][i - 1]
        assert peak == pytest.approx(np.max(np.abs(h_c[f"u{i}"])), rel=1e-12)  # every step written
        true.append(abs(peak / np.max(np.abs(h_f[f"u{i}"])) - 1))
    return coarse, true


INITIAL = {
    "rest": "",
    # the peak in the record's response, of a changed phase: 2.1 % and 1.5 % at n1 = 2 and 4,
    # where the same check from rest says 3.0 % and 1.1 %
    "small_u0_v0": "\n  u0 = 0.006\n  v0 = -0.15",
    # the peak in the first cycles of the free vibration: 0.4 % at n1 = 1, where the check
    # from rest says 21 % (the fuzz campaign's false alarms on decks with initial conditions)
    "large_u0_v0": "\n  u0 = 0.02\n  v0 = -0.5",
}


@pytest.mark.parametrize("initial", INITIAL)
@pytest.mark.parametrize("n1", [1, 2, 4])
def test_the_error_is_the_runs_own(run, record_file, n1, initial):
    """One mode, so the check's estimate is exact: its Newmark recursion is the run's, and its
    exact piecewise-linear response is what a run 64 times finer gives at the same instants
    (the rows every 64 of its steps). The two agree to the fine run's own error, from rest and
    from initial conditions (which the check starts from, as the run does)."""
    deck = OSCILLATOR.replace("mass = 1.0", "mass = 1.0" + INITIAL[initial])

    def deck_at(n, every):
        return deck.replace("N1", str(n)).replace("EVERY", str(every))

    coarse, (measured,) = _true_errors(run, deck_at, n1, {"rec.AT2": record_file}, "oscillator")
    s = coarse.summary()
    assert s["record_step_error"][0] == pytest.approx(measured, abs=5e-4)  # 21 %, 3.0 %, 1.1 %
    resolved = s["record_step_error"][0] <= 0.05
    assert s["record_resolution"] == ("resolved" if resolved else "unresolved")
    assert ("does not resolve the record" in coarse.stderr) == (not resolved)
    if initial == "large_u0_v0":
        assert s["peak_u_time_s"][0] < 0.2 and measured < 0.005
        assert s["record_resolution"] == "resolved"
    if n1 == 1 and initial == "rest":
        # w dt1 = 0.63 (10 steps a period, "resolved" by omega_max dt1 <= 2), and yet:
        assert s["mode_resolution"] == "resolved" and measured > 0.05
        assert s["record_resolution"] == "unresolved"


# Fuzz seed 3063: three masses, a hysteretic device from the top mass to the table, 2.86 s of
# a record at dt_record = dt1 = 0.02 s (144 samples). The 14.6 kg mass on its stiff spring
# (a 9 Hz mode, 2.5 % damping) comes out with peak |u| 83 % above the converged run's;
# omega_max dt1 = 1.7 (resolved), energy closed, no violation: no other report.
SEED_3063 = """
&model
  n_dof = 3
  mass = 14.593586010234441, 0.7476763939462862, 1.5322203654148379
/
&springs
  n_springs = 3
  node_i = 1, 2, 3
  node_j = 0, 1, 2
  k = 49469.39553209949, 890.8601685472624, 3153.4784842391646
/
&damping
  damping_type = 'rayleigh'
  xi = 0.025079639349802164
  mode_i = 1
  mode_j = 2
/
&friction
  n_devices = 1
  node_i = 3
  node_j = 0
  law = 'hysteretic'
  p = 7.051345506429146
  mu = 0.22418688546598037
  eps(1) = 0.01118717963589323
  eps1(1) = 0.010226138858663188
  f(1) = 0.009529801987459856
/
&excitation
  excitation_type = 'record'
  dt_record = 0.02
  record_file = 'rec.txt'
  record_format = 'values'
/
&integration
  n1 = N1
  n2 = 11
  n = 1.01
/
&output
  n_modes = 2
/
"""

# its record [m/s2], to 7 digits
SEED_3063_RECORD = """
0 0.720231 0.7575753 0.03327301 -0.582046 -0.2228001 0.9544383 1.825846 1.444261 0.09986196
-0.8611406 -0.3650062 1.227614 2.34243 1.650653 -0.6334853 -2.700489 -3.054751 -1.732695
0.1572832 1.52236 1.976803 1.63312 0.531811 -1.434346 -3.953076 -5.844227 -5.54627 -2.396192
2.443918 6.489088 7.695112 6.036037 3.436416 2.015745 2.193999 2.435755 0.9456734 -2.241175
-4.833687 -4.141074 0.3198012 5.865971 8.428825 5.756246 -0.6416085 -6.521863 -8.137168
-5.025365 -0.1222483 2.754193 1.842229 -1.590968 -4.788701 -5.952495 -5.419509 -4.760659
-4.92583 -5.287262 -4.401774 -1.621874 2.052457 4.668856 4.862146 2.821586 -0.07058341
-2.402292 -3.544975 -3.529258 -2.453964 -0.3088681 2.547103 4.949881 5.378408 3.214738
-0.3184755 -2.693463 -1.984781 1.369575 4.622993 4.806502 1.21264 -3.879796 -6.982575
-6.235135 -2.86689 -0.00657016 0.1039186 -1.781433 -3.00209 -1.854574 0.9479385 3.098182
2.846244 0.4945482 -1.973466 -2.630329 -1.122385 1.240938 2.709027 2.464776 1.056223
-0.2730775 -0.6190218 0.04667474 1.111897 1.932691 2.237391 2.094387 1.654094 0.9994534
0.2120885 -0.5138154 -0.9119243 -0.836114 -0.4071813 0.05686608 0.2830083 0.2386881 0.1043705
0.06232353 0.1132828 0.09613412 -0.1181293 -0.4571898 -0.6767284 -0.5702207 -0.1673038
0.2650068 0.4271501 0.2239301 -0.1659999 -0.4397589 -0.4063159 -0.1151612 0.212265 0.3707487
0.3159795 0.1602751 0.04908553 0.03882092 0.07447783 0.06604519 -0.01930546
"""


def test_a_step_that_misses_the_record_is_reported(run):
    """n1 = 1: the check says DOF 1's peak linear response moves by 84 % (the linear system's
    peak at n1 = 1 is 98 % above its converged value, the friction run's 83 %); n1 = 16:
    resolved, no warning, the peaks within 0.5 % of n1 = 64. Reported by the executable and by
    Python, naming the DOF; no other report fires."""
    files = {"rec.txt": "\n".join(SEED_3063_RECORD.split()) + "\n"}  # one value a line
    coarse = ok(run(SEED_3063.replace("N1", "1"), name="coarse", files=files))
    fine = ok(run(SEED_3063.replace("N1", "16"), name="fine", files=files))
    ref = ok(run(SEED_3063.replace("N1", "64"), name="ref", files=files))
    c, f, r = coarse.summary(), fine.summary(), ref.summary()
    assert c["record_resolution"] == "unresolved" and 0.8 < c["record_step_error"][0] < 0.9
    assert max(c["record_step_error"][1:]) < 0.1
    assert c["peak_u_m"][0] / r["peak_u_m"][0] > 1.8
    assert f["record_resolution"] == "resolved" and max(f["record_step_error"]) < 0.005
    assert max(abs(a / b - 1) for a, b in zip(f["peak_u_m"], r["peak_u_m"])) < 0.005
    assert c["mode_resolution"] == "resolved" and c["correctness_violations"] == 0
    assert c["energy_balance"] == "closed" and c["harmonic_resolution"] == "not applicable"
    # the device slid (16 times): the free system is judged, and named
    said = (
        "peak linear response of DOF 1 by 84.3 % "
        "(record_step_error > 0.05, free system)"
    )
    assert c["stick_to_slip"][0] > 0 and said in coarse.stderr
    assert "does not resolve the record" not in fine.stderr
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        fd.run_text(SEED_3063.replace("N1", "1"), base_dir=coarse.workdir)
    words = [str(w.message) for w in caught if issubclass(w.category, fd.FrictiondynWarning)]
    assert len(words) == 1 and said in words[0]


@pytest.mark.parametrize(
    "deck", ["building5_bare", "building5_dampers", "building5_friction", "isolated_fps"]
)
def test_the_bundled_record_decks_are_resolved(deck):
    s = fd.run(INPUTS / f"{deck}.nml").summary
    assert s["record_resolution"] == "resolved"
    assert 0 < max(s["record_step_error"]) < 1e-3


def test_not_applicable_to_harmonic_motion_and_without_modes(run, record_file):
    s = fd.run(INPUTS / "test4_velocity.nml").summary
    assert s["record_resolution"] == "not applicable" and not any(s["record_step_error"])
    deck = OSCILLATOR.replace("N1", "1").replace("EVERY", "0\n  n_modes = 0")
    s = ok(run(deck, files={"rec.AT2": record_file})).summary()
    assert s["record_resolution"] == "not applicable"


def _deck_with(
    groups: str, n1: int, extra_integration: str = "", duration: float = 8.0, every: int = 0
) -> str:
    """The oscillator's deck with other &model..&friction groups (the record of the fixture);
    with every > 0, a history row every that many steps."""
    output = f"&output\n  output_every = {every}\n/\n" if every else ""
    return (
        groups
        + f"""
&excitation
  excitation_type = 'record'
  record_file = 'rec.AT2'
  duration = {duration}
/
&integration
  n1 = {n1}{extra_integration}
/
"""
        + output
    )


OSCILLATOR_GROUPS = f"""
&model
  n_dof = MASSES
/
&springs
  n_springs = 1
  node_i = 1
  node_j = 0
  k = {(2 * math.pi * 12.0) ** 2!r}
/
&damping
  damping_type = 'rayleigh'
  rayleigh_a1 = 0.0005
/
"""


def test_a_rigid_body_mode_does_not_hide_the_others(run, record_file):
    """A friction tuned-mass damper: a second mass held to a 12 Hz oscillator only by a
    velocity-law device. Stuck, the two are one 2 kg oscillator; free, the system is the 1 kg
    oscillator and a rigid-body mode whose drift (no a0 to bound it) would swamp the
    oscillator's peaks. That mode is left out, so the free system gives DOF 1 the 1 kg
    oscillator's own error and DOF 2 none, and the stuck system both DOFs the 2 kg
    oscillator's, to round-off. The verdict judges the system the run was in: the free one
    when the device slides; when a large P mu keeps it in its band throughout, the larger of
    the two (a velocity-law device in its band is a dashpot, neither rigid nor absent)."""
    files = {"rec.AT2": record_file}
    tmd = OSCILLATOR_GROUPS.replace("MASSES", "2\n  mass = 1.0, 1.0") + """
&friction
  n_devices = 1
  node_i = 2
  node_j = 1
  law = 'velocity'
  p = P_N
  mu = 0.1
  eps = 0.001
/
"""
    s = ok(run(_deck_with(tmd.replace("P_N", "9.81"), 3, duration=30.0), name="tmd", files=files))
    s = s.summary()
    locked_deck = _deck_with(tmd.replace("P_N", "1.0e7"), 3, duration=30.0)
    locked = ok(run(locked_deck, name="locked", files=files)).summary()
    alone = [
        _deck_with(OSCILLATOR_GROUPS.replace("MASSES", f"1\n  mass = {m}"), 3, duration=30.0)
        for m in (1.0, 2.0)
    ]
    free, stuck = (
        ok(run(deck, name=f"alone{i}", files=files)).summary()["record_step_error"][0]
        for i, deck in enumerate(alone)
    )
    assert free > 1.5 * stuck > 0  # 1.9 % against 0.6 %
    for x in (s, locked):
        assert x["record_step_error_free"] == pytest.approx([free, 0.0], rel=1e-9)
        assert x["record_step_error_stuck"] == pytest.approx([stuck, stuck], rel=1e-9)
    assert s["stick_to_slip"][0] > 0 and s["record_step_error"] == s["record_step_error_free"]
    assert s["record_step_system"] == "free"
    assert locked["stick_to_slip"] == [0] and locked["slip_to_stick"] == [0]
    assert locked["record_step_system"] == "stuck and free"
    assert locked["record_step_error"] == pytest.approx([free, stuck], rel=1e-9)


def test_a_stuck_device_with_an_initial_offset(run, record_file):
    """One mass on a spring and a hysteretic device that never slides (P mu huge), its sticking
    spring as stiff as the spring, u0 = -3 mm: the run oscillates about the stuck system's
    equilibrium u0 / 2, not about 0. With one mode the check reads the peak about that point
    and is exact: 5.9 % at n1 = 4, reported (read about 0 it said 4.3 %, "resolved")."""
    k = (2 * math.pi * 5.0) ** 2
    groups = OSCILLATOR_GROUPS.replace("MASSES", "1\n  mass = 1.0\n  u0 = -0.003").replace(
        f"k = {(2 * math.pi * 12.0) ** 2!r}", f"k = {k!r}") + f"""
&friction
  n_devices = 1
  node_i = 1
  node_j = 0
  law = 'hysteretic'
  p = 1.0e7
  mu = 0.1
  eps1 = 1.0
  f = {1.0e6 / k!r}
/
"""
    def deck_at(n, every):
        return _deck_with(groups, n, every=every)

    coarse, true = _true_errors(run, deck_at, 4, {"rec.AT2": record_file}, "offset")
    s, err = coarse.summary(), coarse.stderr
    assert s["stick_to_slip"] == [0] and s["record_step_system"] == "stuck"
    assert true[0] > 0.05
    assert s["record_step_error"][0] == pytest.approx(true[0], abs=5e-4)
    assert s["record_resolution"] == "unresolved" and "(record_step_error > 0.05, stuck system)" in err


def test_a_weak_velocity_law_coupling_is_judged_both_ways(run, record_file):
    """A 3 kg mass coupled to a 5 Hz oscillator by a velocity-law device whose band is a weak
    dashpot (P mu / eps = 1 N s/m) that it never leaves: the run is nearly the free
    oscillator, 15 % off at n1 = 1; the rigid-link (stuck) system alone says 0.8 %. No device
    slid, but the device is not rigid in its band: the larger of the two systems is judged,
    and the run reported."""
    groups = OSCILLATOR_GROUPS.replace("MASSES", "2\n  mass = 1.0, 3.0").replace(
        f"k = {(2 * math.pi * 12.0) ** 2!r}", f"k = {(2 * math.pi * 5.0) ** 2!r}") + """
&friction
  n_devices = 1
  node_i = 2
  node_j = 1
  law = 'velocity'
  p = 10.0
  mu = 0.1
  eps = 1.0
/
"""
    def deck_at(n, every):
        return _deck_with(groups, n, every=every)

    coarse, true = _true_errors(run, deck_at, 1, {"rec.AT2": record_file}, "weak")
    s, err = coarse.summary(), coarse.stderr
    assert s["stick_to_slip"] == [0] and s["slip_to_stick"] == [0] and true[0] > 0.1
    assert max(s["record_step_error_stuck"]) < 0.01 < 0.1 < s["record_step_error_free"][0]
    assert s["record_step_system"] == "stuck and free"
    assert s["record_step_error"][0] == s["record_step_error_free"][0]
    assert s["record_resolution"] == "unresolved" and "(record_step_error > 0.05, stuck and free)" in err


def test_not_applicable_when_the_judged_system_has_no_mode(run, record_file):
    """A block sliding on the table with no spring: its free system is one rigid-body mode,
    left out, so the system the run was in has nothing to estimate: "not applicable", not a
    "resolved" at 0 (the stuck system's sticking-spring mode, which a first version judged,
    said 27 %; the run is 3.4 % off)."""
    groups = """
&model
  n_dof = 1
  mass = 2.0
/
&springs
  n_springs = 0
/
&damping
  damping_type = 'none'
/
&friction
  n_devices = 1
  node_i = 1
  node_j = 0
  law = 'hysteretic'
  p = 19.62
  mu = 0.05
  eps1 = 0.001
  f = 0.001
/
"""
    r = ok(run(_deck_with(groups, 1), name="block", files={"rec.AT2": record_file}))
    s = r.summary()
    assert s["stick_to_slip"][0] > 0
    assert s["record_resolution"] == s["record_step_system"] == "not applicable"
    assert not any(s["record_step_error"]) and "resolve the record" not in r.stderr


# Fuzz seed 99734: a 21.9 kg mass tied to the table by a hysteretic device whose sticking
# spring P mu / f = 2.4e6 N/m makes the stuck system stiff (undamped modes of 45 and 59 Hz);
# the two masses' stiff spring leaves the free system one of 52 Hz and one of 0.8 Hz. The
# device slides 7 times in 1.16 s of record.
SEED_99734 = """
&model
  n_dof = 2
  mass = 1.7477667771632877, 21.89537547304514
/
&springs
  n_springs = 2
  node_i = 1, 2
  node_j = 0, 1
  k = 611.633308449509, 171299.94521340673
/
&damping
  damping_type = 'none'
/
&friction
  n_devices = 1
  node_i = 2
  node_j = 0
  law = 'hysteretic'
  p = 112.00005212985668
  mu = 0.09557296314283058
  eps1 = 0.003618980205278566
  f = 4.435799496375959e-06
/
&excitation
  excitation_type = 'record'
  dt_record = 0.02
  record_file = 'rec.txt'
  record_format = 'values'
/
&integration
  n1 = N1
  n2 = 14
  n = 1.5
/
"""

# its record [m/s2], to 7 digits
SEED_99734_RECORD = """
0 -0.08794881 -0.2427225 -0.3761401 -0.3694694 -0.195679 -0.04588852 -0.2011401 -0.6543996
-0.9480102 -0.6017021 0.2376698 0.758165 0.2893778 -0.8841774 -1.694461 -1.254071 -0.04117005
1.02163 1.372281 1.074897 0.4694683 -0.145695 -0.4848419 -0.2498699 0.5795226 1.485432 1.735567
1.141449 0.3776702 0.3373874 1.145322 1.967957 1.90058 0.950443 0.0131715 -0.08341326 0.5636602
1.225486 1.410554 1.140642 0.6533123 0.1094481 -0.3673726 -0.5797718 -0.3916318 0.0368437
0.3037866 0.1459349 -0.2814734 -0.574804 -0.5162607 -0.2745305 -0.1685054 -0.3039737 -0.4988904
-0.5307472 -0.3764042 -0.1871681
"""


def test_a_sliding_run_is_not_judged_by_its_stuck_system(run):
    """The stuck system's modes, undamped and run through the whole record at 12 and 16 steps
    a period, have their peaks 19 % and 25 % off; the run, whose stick phases are short, is
    right: its peaks are within 0.2 % of a run 16 times finer. The device slid, so the verdict
    judges the free system (1e-5): resolved, no warning; the stuck system's figure stays in
    the summary. Of
    51 613 random record decks, judging the stuck system in sliding runs too added 411 flags,
    99 of them on runs more than 5 % off."""
    files = {"rec.txt": "\n".join(SEED_99734_RECORD.split()) + "\n"}
    coarse = ok(run(SEED_99734.replace("N1", "14"), name="coarse", files=files))
    ref = ok(run(SEED_99734.replace("N1", "224"), name="ref", files=files))
    c, r = coarse.summary(), ref.summary()
    assert c["stick_to_slip"][0] > 0
    assert max(c["record_step_error_stuck"]) > 0.2
    assert max(abs(a / b - 1) for a, b in zip(c["peak_u_m"], r["peak_u_m"])) < 0.002
    assert c["record_step_error"] == c["record_step_error_free"]
    assert max(c["record_step_error"]) < 0.01 and c["record_resolution"] == "resolved"
    assert "does not resolve the record" not in coarse.stderr


def test_a_mode_beyond_the_step_is_left_to_mode_resolution(run, record_file):
    """Linear acceleration (beta = 1/6) is stable up to omega dt1 = sqrt(12): a sticking
    spring P mu / f = 1e5 N/m on 1 kg at dt1 = 0.02 s (omega dt1 = 6.3) is beyond it. The
    run survives (the device slides) and mode_resolution reports the mode. The record check
    leaves it out (its recursion would diverge: 3e89 in a first version) and gives what the
    free system alone gives, the oscillator without its device; nothing overflows, over a
    record and 4 s of free vibration after it."""
    device = """
&friction
  n_devices = 1
  node_i = 1
  node_j = 0
  law = 'hysteretic'
  p = 0.1
  mu = 0.1
  f = 1.0e-7
/
"""
    files = {"rec.AT2": record_file}
    groups = OSCILLATOR_GROUPS.replace("MASSES", "1\n  mass = 1.0")
    rule = "\n  beta = 0.1666666666666667"
    r = ok(run(_deck_with(groups + device, 1, rule, duration=12.0), name="device", files=files))
    alone = ok(run(_deck_with(groups, 1, rule, duration=12.0), name="alone", files=files))
    s, a = r.summary(), alone.summary()
    assert s["omega_max_dt1"] > math.sqrt(12) and s["mode_resolution"] == "unresolved"
    assert a["record_step_error"][0] > 0.005  # 12 Hz at 4.2 steps a period: 0.96 %
    assert s["record_step_error"] == pytest.approx(a["record_step_error"], rel=1e-9)
    assert s["record_resolution"] == a["record_resolution"] == "resolved"
    assert all(math.isfinite(x) for x in s["peak_u_m"] + s["peak_aabs_mps2"])


MJ_BUILDING = """&model n_dof = 5, mass = 3.0e5, 3.0e5, 3.0e5, 3.0e5, 2.5e5 /
&springs n_springs = 5, node_i = 1, 2, 3, 4, 5, node_j = 0, 1, 2, 3, 4,
  k = 4.0e8, 3.5e8, 3.0e8, 2.5e8, 2.0e8 /
&damping damping_type = 'rayleigh', xi = 0.02, mode_i = 1, mode_j = 3, mode_system = 'free' /
&friction n_devices = 5, node_i = 1, 2, 3, 4, 5, node_j = 0, 1, 2, 3, 4,
  p = 9.483e6, 7.521e6, 5.559e6, 3.597e6, 1.635e6, mu = 5*0.3, law = 5*'coulomb' /
&excitation excitation_type = 'record', record_file = 'RECORD', duration = 25.0 /
&integration technique = 'TECH' INTEGRATION /
"""


def test_moreau_jean_is_judged_by_its_own_recursion():
    """A 5-storey building with a Coulomb damper in every storey under the synthetic record,
    by Moreau-Jean with theta = 1 at n1 = 2 (dt1 = 5 ms): the step alone moves the free
    system's peak linear response by more than 10 % (its own theta-method against the exact
    step), the run is unresolved and warned, and its top-storey slip is more than 20 % off
    the exact technique's. At n1 = 10 the check is resolved."""
    deck = MJ_BUILDING.replace("RECORD", str(INPUTS / "synthetic_pga035.AT2"))
    exact = fd.run_text(deck.replace("TECH", "event_driven").replace("INTEGRATION", "")).summary
    with warnings.catch_warnings(record=True) as w:
        warnings.simplefilter("always")
        coarse = fd.run_text(deck.replace("TECH", "moreau_jean")
                             .replace("INTEGRATION", ", theta = 1.0, n1 = 2")).summary
    assert coarse["record_resolution"] == "unresolved" and coarse["record_step_system"] == "free"
    assert min(coarse["record_step_error"]) > 0.09
    assert any("does not resolve the record" in str(x.message) for x in w)
    assert abs(coarse["peak_s_m"][4] / exact["peak_s_m"][4] - 1) > 0.2  # what the warning is about
    fine = fd.run_text(deck.replace("TECH", "moreau_jean")
                       .replace("INTEGRATION", ", theta = 1.0, n1 = 10")).summary
    assert fine["record_resolution"] == "resolved"


@pytest.mark.parametrize("technique", ["newmark", "moreau_jean"])
def test_a_device_sliding_from_the_start_is_judged_free(run, record_file, technique):
    """The tuned-mass deck with a Coulomb device (velocity law under Newmark) and the second
    mass thrown at 1 m/s: the device slides from t = 0 through the whole second of record
    (P mu = 0.01 N slows it by 0.01 m/s) with no transition and no reversal. Its one slide
    makes the run the free system's, under each technique (the stuck system's error, the
    2 kg oscillator's, is not the run's)."""
    law = "'coulomb'" if technique == "moreau_jean" else "'velocity'\n  eps = 1.0e-4"
    groups = OSCILLATOR_GROUPS.replace("MASSES", "2\n  mass = 1.0, 1.0\n  v0 = 0.0, 1.0") + f"""
&friction
  n_devices = 1
  node_i = 2
  node_j = 1
  law = {law}
  p = 0.1
  mu = 0.1
/
"""
    deck = _deck_with(groups, 4, f"\n  technique = '{technique}'", duration=1.0)
    s = ok(run(deck, name=f"thrown_{technique}", files={"rec.AT2": record_file})).summary()
    assert s["slip_excursions"] == [1] and s["stick_to_slip"] == [0]
    assert s["slip_to_stick"] == [0] and s["slip_reversals"] == [0]
    assert s["record_step_system"] == "free"
    assert s["record_step_error"] == s["record_step_error_free"]
    assert s["record_step_error_free"] != s["record_step_error_stuck"]
