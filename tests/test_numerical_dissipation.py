"""The energy the integration itself dissipates (summary ``energy_residual_ratio`` and
``energy_balance``, docs/theory.md section 7): against Newmark's recursion run step by step
in numpy for an undamped oscillator with gamma > 1/2; round-off for gamma = 1/2 on the
paper's decks; the warning from the executable, the command line and Python."""

from __future__ import annotations

import contextlib
import io
import warnings

import frictiondyn as fd
import numpy as np
import pytest
from conftest import INPUTS, ok
from frictiondyn.cli import main as cli

M, K, U0 = 2.0, 800.0, 0.01  # omega = 20 rad/s


def oscillator(dt: float, steps: int, gamma: float, beta: float) -> str:
    """An undamped oscillator released from U0 (the table at rest)."""
    return f"""
&model
  n_dof = 1
  mass = {M!r}
  u0 = {U0!r}
/
&springs
  n_springs = 1
  node_i = 1
  node_j = 0
  k = {K!r}
/
&damping
  damping_type = 'none'
/
&excitation
  excitation_type = 'none'
  dt_record = {dt!r}
  duration = {dt * steps!r}
/
&integration
  n1 = 1
  gamma = {gamma!r}
  beta = {beta!r}
/
"""


def newmark_energy(dt: float, steps: int, gamma: float, beta: float) -> float:
    """The energy 1/2 k u^2 + 1/2 m v^2 after `steps` steps of Newmark's recursion."""
    w2 = K / M
    u, v, a = U0, 0.0, -w2 * U0
    for _ in range(steps):
        u1 = (u + dt * v + dt * dt * (0.5 - beta) * a) / (1 + beta * w2 * dt * dt)
        a1 = -w2 * u1
        v = v + dt * ((1 - gamma) * a + gamma * a1)
        u, a = u1, a1
    return 0.5 * K * u * u + 0.5 * M * v * v


@pytest.mark.parametrize(
    "w_dt, steps, status",
    [(0.2, 100, "dissipative"), (0.05, 150, "closed"), (0.5, 200, "dissipative")],
)
def test_the_ratio_is_newmarks_own_dissipation(run, w_dt, steps, status):
    """gamma = 0.6, beta = 0.3025: the energy Newmark's recursion loses (no input, no damping,
    no device) over the energy the oscillator started with, to 1e-9; "dissipative" beyond 5 %
    (w dt = 0.2, 100 steps: 32 %; 0.05, 150 steps: 3.5 %; 0.5, 200 steps: 99 %)."""
    gamma, beta = 0.6, 0.3025
    dt = w_dt / 20.0
    r = ok(run(oscillator(dt, steps, gamma, beta)))
    s = r.summary()
    e0 = 0.5 * K * U0 * U0
    expected = (e0 - newmark_energy(dt, steps, gamma, beta)) / e0
    assert s["energy_residual_ratio"] == pytest.approx(expected, rel=1e-9, abs=1e-12)
    assert s["energy_balance"] == status
    assert ("the integration dissipated" in r.stderr) == (status == "dissipative")
    if status == "dissipative":
        assert f"{100 * expected:.1f} % of the energy" in r.stderr


def test_average_acceleration_dissipates_nothing(run):
    """gamma = 1/2: the residual is round-off, on the oscillator (to 1e-12 of its energy after
    2000 steps) and on the paper's decks (to 1e-12 of the energy through them)."""
    r = ok(run(oscillator(0.01, 2000, 0.5, 0.25)))
    assert abs(r.summary()["energy_residual_ratio"]) < 1e-12
    for deck in ("test3_hysteretic", "test4_velocity", "building5_friction"):
        s = fd.run(INPUTS / f"{deck}.nml").summary
        assert abs(s["energy_residual_ratio"]) < 1e-12 and s["energy_balance"] == "closed", deck


def test_the_warning_from_python_and_the_command_line(tmp_path):
    """The same words as the executable's, as a FrictiondynWarning and on standard error."""
    text = oscillator(0.01, 1000, 0.6, 0.3025)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        s = fd.run_text(text).summary
    words = [str(w.message) for w in caught if issubclass(w.category, fd.FrictiondynWarning)]
    assert len(words) == 1 and "the integration dissipated" in words[0]
    assert f"{100 * s['energy_residual_ratio']:.1f} %" in words[0]
    deck = tmp_path / "osc.nml"
    deck.write_text(text)
    err = io.StringIO()
    with contextlib.redirect_stderr(err), contextlib.redirect_stdout(io.StringIO()):
        assert cli(["run", str(deck), "--out", str(tmp_path / "out"), "--quiet"]) == 0
    assert "frictiondyn: warning: the integration dissipated" in err.getvalue()


def test_the_energy_through_a_driven_structure(run):
    """The denominator for a driven run: the sum over the steps of |input work of the step|,
    -(1/2)(ag + ag1) m du, recomputed here from the history written at every step (gamma =
    0.6, the resonant oscillator of test_convergence at n1 = 2: dissipative)."""
    from test_convergence import OSCILLATOR

    text = OSCILLATOR.replace("N1", "2\n  gamma = 0.6, beta = 0.3025") + "&output\n  output_every = 1\n/\n"
    r = ok(run(text))
    s, h = r.summary(), r.history()
    work = -0.5 * (h["ag"][1:] + h["ag"][:-1]) * 1.0 * np.diff(h["u1"])
    gross = np.sum(np.abs(work))
    assert s["energy_input_J"] == pytest.approx(np.sum(work), rel=1e-9)
    assert s["energy_residual_ratio"] == pytest.approx(s["energy_residual_J"] / gross, rel=1e-9)
    assert s["energy_balance"] == "dissipative" and s["energy_residual_ratio"] > 0.05


def test_a_run_that_blows_up_is_reported_not_stopped(run):
    """Linear acceleration beyond its stability limit (w dt = 4 > sqrt(12)): 100 steps grow
    the energy by a factor of about 1e51, still finite, so the run ends and warns. The ratio,
    the closed form's (newmark_energy), is written in scientific notation: a fixed format of
    that size overflowed its record and stopped the executable, and with it the Python
    interpreter, before the summary was written."""
    deck = oscillator(0.2, 100, 0.5, 1 / 6)
    r = ok(run(deck))
    s = r.summary()
    e0 = 0.5 * K * U0 * U0
    expected = (e0 - newmark_energy(0.2, 100, 0.5, 1 / 6)) / e0
    assert s["energy_residual_ratio"] == pytest.approx(expected, rel=1e-9)
    assert expected < -1e40
    line = f"the integration created {100 * abs(expected):.1E} % of the energy"
    assert line in r.stderr and any(line in w for w in s["warnings"])
    with pytest.warns(fd.FrictiondynWarning, match="the integration created"):
        fd.run_text(deck)


def test_an_energy_error_is_not_called_numerical_damping(run):
    """Linear acceleration (gamma = 1/2, beta = 1/6) has no numerical damping, but its energy
    is not conserved by the accounting: a positive residual (w dt = 1.6, stable below
    sqrt(12)) is an "energy error", and the warning names beta, not gamma."""
    r = ok(run(oscillator(0.08, 200, 0.5, 1 / 6)))
    s = r.summary()
    e0 = 0.5 * K * U0 * U0
    expected = (e0 - newmark_energy(0.08, 200, 0.5, 1 / 6)) / e0
    assert s["energy_residual_ratio"] == pytest.approx(expected, rel=1e-9)
    assert abs(expected) > 0.05
    assert s["energy_balance"] == "energy error"
    assert "an energy error of the step (Newmark beta /= 1/4" in r.stderr
    assert "numerical damping" not in r.stderr


def stiff_band(p: float, v0: str, technique: str = "newmark", excitation: str | None = None) -> str:
    """Two masses (1 and 0.5 kg, the heavier on a 6.2 Hz spring to the table) coupled by a
    friction device with P mu / eps = p / 10 N s/m, released from u0 = 6 mm with velocities
    v0; n1 = 4 at dt_record = 0.02 s. With the velocity law the band's
    x = (P mu / eps) dt1 / (2 m_r) is 7.5e4 p / 1e8: the trapezoidal rule then leaves any
    relative velocity inside the band alternating from step to step."""
    law = "coulomb" if technique == "event_driven" else "velocity"
    exc = excitation or "  excitation_type = 'none'\n  dt_record = 0.02\n  duration = 4.0"
    return f"""
&model
  n_dof = 2
  mass = 1.0, 0.5
  u0 = 0.006, 0.006
  v0 = {v0}
/
&springs
  n_springs = 1
  node_i = 1
  node_j = 0
  k = 1480.4406601634037
/
&damping
  damping_type = 'rayleigh'
  rayleigh_a1 = 0.0005
/
&friction
  n_devices = 1
  node_i = 2
  node_j = 1
  law = '{law}'
  p = {p!r}
  mu = 0.1
  eps = 1.0
/
&excitation
{exc}
/
&integration
  technique = '{technique}'
  n1 = 4
/
&output
  output_every = 1
/
"""


def _late_force(r) -> float:
    """Largest |F| of the device after t = 1 s (the masses locked together long before)."""
    h = r.history()
    return float(np.max(np.abs(h["F1"][h["t"] > 1.0])))


def test_digits_lost_in_a_stiff_velocity_band(run):
    """Average acceleration closes the energy balance at round-off, so a residual above
    1e-8 is digits lost, and is reported. A relative velocity of 0.4 m/s inside a band of
    P mu / eps = 1e7 N s/m (x = 7.5e4) alternates sign at every step: the band's force stays
    near +-0.4 P mu for the whole run, decaying by the trapezoidal rule's (1 - x) / (1 + x) a
    step, where the exact technique's holding force is a few newtons (measured: ratio 3.3e-6,
    late force 3.98e6 N against 6.9 N). With the same
    momentum and no relative velocity in the band the balance closes (1.0e-11 at P = 1e9)."""
    bad = ok(run(stiff_band(1.0e8, "-0.3, 0.1"), name="bad"))
    exact = ok(run(stiff_band(1.0e8, "-0.3, 0.1", technique="event_driven"), name="exact"))
    s = bad.summary()
    assert abs(s["energy_residual_ratio"]) > 1e-8 and s["energy_balance"] == "digits lost"
    assert "the integration lost digits to round-off" in bad.stderr
    f_bad, f_exact = _late_force(bad), _late_force(exact)
    # the trapezoidal rule's factor for the band's dashpot, (1 - x) / (1 + x) a step, from
    # 0.4 m/s at t = 0 to the first step after 1 s (201 steps of 5 ms)
    c1, m_r, h = 1.0e8 * 0.1 / 1.0, 1.0 * 0.5 / 1.5, 0.005
    x = c1 * h / (2 * m_r)
    assert f_bad == pytest.approx(c1 * 0.4 * ((x - 1) / (x + 1)) ** 201, rel=1e-3)
    assert f_exact < 10.0 and f_bad > 1e5 * f_exact
    assert exact.summary()["energy_balance"] == "closed"
    calm = ok(run(stiff_band(1.0e9, "-0.16666666666666667, -0.16666666666666667"), name="calm"))
    c = calm.summary()
    assert abs(c["energy_residual_ratio"]) < 1e-8 and c["energy_balance"] == "closed"
    assert "lost digits" not in calm.stderr


def test_digits_lost_where_the_peak_is_silently_wrong(run, tmp_path):
    """A deck of a stiff band (P mu / eps = 1e9, x = 7.5e6) on 8 s of a synthetic record: the
    mass's peak displacement is 8.9 % above the exact technique's, the record step check
    says 3.35 % ("resolved") and the residual is 7.6e-3. The lost digits are reported, in
    the executable and in Python."""
    import math

    from frictiondyn.synthetic import synthetic_record, write_at2

    rec = write_at2(
        synthetic_record(duration=8.0, dt=0.02, pga_g=0.3, seed=11, wg=2 * math.pi * 5.0, zg=0.3),
        tmp_path / "rec.AT2",
    ).read_text()
    exc = "  excitation_type = 'record'\n  record_file = 'rec.AT2'"
    files = {"rec.AT2": rec}
    bad = ok(run(stiff_band(1.0e10, "-0.3, 0.1", excitation=exc), name="bad", files=files))
    exact = ok(run(stiff_band(1.0e10, "-0.3, 0.1", "event_driven", exc), name="exact", files=files))
    s = bad.summary()
    error = s["peak_u_m"][0] / exact.summary()["peak_u_m"][0] - 1
    assert error > 0.05
    assert s["record_resolution"] == "resolved" and max(s["record_step_error"]) < 0.05
    assert 1e-8 < abs(s["energy_residual_ratio"]) < 0.05
    assert s["energy_balance"] == "digits lost" and "lost digits" in bad.stderr
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        py = fd.run(bad.workdir / "bad.nml").summary
    words = [str(w.message) for w in caught if issubclass(w.category, fd.FrictiondynWarning)]
    assert py["energy_balance"] == "digits lost"
    assert any("lost digits to round-off" in w for w in words)
    assert any(f"{abs(py['energy_residual_ratio']):.1E}" in w for w in words)


def test_only_average_acceleration_has_the_round_off_limit(run):
    """beta = 1/4 with gamma = 0.6 damps numerically (the step's amplification below 1): its
    residual, a share of the energy well above round-off and below 0.05 (7.0e-3 over 200
    steps at omega dt = 0.02), is the method's, and the balance is "closed" under the 0.05
    limit, not "digits lost"."""
    r = ok(run(oscillator(0.001, 200, 0.6, 0.25)))
    s = r.summary()
    assert 1e-6 < s["energy_residual_ratio"] < 0.05
    assert s["energy_balance"] == "closed" and "warning" not in r.stderr
