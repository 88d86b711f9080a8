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
