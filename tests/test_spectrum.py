"""Elastic response spectra (frictiondyn.response_spectrum, python -m frictiondyn spectrum):
the library's exact stepping against an independent one, Chopra's closed-form recurrence
for a load linear in a step (Dynamics of Structures, table 5.2.1), on the bundled synthetic
AT2 record; against the closed-form response of an oscillator to a harmonic table motion and
to an impulse; the record read with the deck's settings; bad input named."""

from __future__ import annotations

import math
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import frictiondyn
from frictiondyn.spectrum import G, response_spectrum

ROOT = Path(__file__).resolve().parents[1]
AT2 = ROOT / "inputs" / "synthetic_pga035.AT2"


def chopra_peaks(ag: np.ndarray, dt: float, period: float, xi: float) -> tuple[float, float]:
    """Peak |u| and peak |u'' + ag| of a unit-mass oscillator from rest, by the closed-form
    recurrence with the step cut into m parts (at least 20 samples a period)."""
    w = 2 * math.pi / period
    m = max(1, math.ceil(20 * dt * w / (2 * math.pi)))
    h = dt / m
    k = w * w
    r = math.sqrt(1 - xi * xi)
    wd = w * r
    e = math.exp(-xi * w * h)
    s, c = math.sin(wd * h), math.cos(wd * h)
    A = e * (xi / r * s + c)
    B = e * s / wd
    C = (2 * xi / (w * h) + e * (((1 - 2 * xi * xi) / (wd * h) - xi / r) * s
                                 - (1 + 2 * xi / (w * h)) * c)) / k
    D = (1 - 2 * xi / (w * h) + e * ((2 * xi * xi - 1) / (wd * h) * s + 2 * xi / (w * h) * c)) / k
    A1 = -e * w / r * s
    B1 = e * (c - xi / r * s)
    C1 = (-1 / h + e * ((w / r + xi / (h * r)) * s + c / h)) / k
    D1 = (1 - e * (xi / r * s + c)) / (k * h)
    frac = np.arange(m + 1) / m
    p = -(ag[:-1, None] + (ag[1:] - ag[:-1])[:, None] * frac[None, :])  # (steps, m + 1)
    p0 = p[:, :-1].ravel()
    p1 = p[:, 1:].ravel()
    u = v = 0.0
    umax, amax = 0.0, abs(ag[0])
    for a0, a1 in zip(p0, p1):
        u, v = A * u + B * v + C * a0 + D * a1, A1 * u + B1 * v + C1 * a0 + D1 * a1
        umax = max(umax, abs(u))
        amax = max(amax, abs(2 * xi * w * v + w * w * u))
    return umax, amax


def at2_values() -> tuple[np.ndarray, float]:
    lines = AT2.read_text().splitlines()
    dt = float(lines[3].split("DT=")[1].split()[0])
    vals = np.array([float(x) for line in lines[4:] for x in line.split()])
    return vals * G, dt


@pytest.mark.parametrize("period", [0.1, 0.5, 2.0])
def test_against_the_closed_form_recurrence(period):
    ag, dt = at2_values()
    s = response_spectrum(AT2, periods=[0.0, period], xi=0.05)
    umax, amax = chopra_peaks(ag, dt, period, 0.05)
    assert s.sd[1] == pytest.approx(umax, rel=1e-8)
    assert s.sa[1] == pytest.approx(amax, rel=1e-8)
    w = 2 * math.pi / period
    assert s.psa[1] == pytest.approx(w * w * s.sd[1], rel=1e-14)
    assert s.psv[1] == pytest.approx(w * s.sd[1], rel=1e-14)
    # T = 0: the peak ground acceleration (the header says PGA 0.35 g)
    assert s.psa[0] == pytest.approx(np.max(np.abs(ag)), rel=1e-12)
    assert s.psa[0] / G == pytest.approx(0.35, rel=1e-3)


def harmonic_response(t, amp, omega_f, period, xi):
    """u(t) and u'(t) of a unit-mass oscillator from rest under a table acceleration
    amp sin(omega_f t): the closed form, steady state and transient (Chopra, section 3.2)."""
    w = 2 * math.pi / period
    wd = w * math.sqrt(1 - xi * xi)
    r = omega_f / w
    den = (1 - r * r) ** 2 + (2 * xi * r) ** 2
    c = -amp / (w * w) * (1 - r * r) / den  # u_p = c sin + d cos of omega_f t
    d = -amp / (w * w) * (-2 * xi * r) / den
    e1 = -d
    e2 = (xi * w * e1 - c * omega_f) / wd
    env = np.exp(-xi * w * t)
    u = env * (e1 * np.cos(wd * t) + e2 * np.sin(wd * t)) + c * np.sin(omega_f * t) + d * np.cos(omega_f * t)
    v = (env * (-xi * w * (e1 * np.cos(wd * t) + e2 * np.sin(wd * t))
                + wd * (-e1 * np.sin(wd * t) + e2 * np.cos(wd * t)))
         + c * omega_f * np.cos(omega_f * t) - d * omega_f * np.sin(omega_f * t))
    return u, v


@pytest.mark.parametrize("period", [0.2, 0.6, 2.0])
@pytest.mark.parametrize("xi", [0.0, 0.05])
def test_against_the_closed_form_harmonic_response(tmp_path, period, xi):
    """A table acceleration 2 m/s2 sin(2 pi 1.5 t) sampled every 0.2 ms for 4 s: the peak
    displacement and absolute acceleration of the oscillator from rest are the closed form's
    (transient included) to 1e-5; the differences are the record's sampling (a motion linear
    between samples, (omega dt)^2 / 8) and the peaks' sampling, each below 1e-6."""
    dt, amp, omega_f = 2e-4, 2.0, 2 * math.pi * 1.5
    n = 20001
    rec = tmp_path / "harmonic.txt"
    rec.write_text("".join(f"{amp * math.sin(omega_f * k * dt):.17e}\n" for k in range(n)))
    s = response_spectrum(rec, periods=[period], xi=xi, format="values", units="m/s2", dt=dt)
    t = np.linspace(0.0, (n - 1) * dt, 2_000_001)
    u, v = harmonic_response(t, amp, omega_f, period, xi)
    w = 2 * math.pi / period
    assert s.sd[0] == pytest.approx(np.max(np.abs(u)), rel=1e-5)
    assert s.sa[0] == pytest.approx(np.max(np.abs(2 * xi * w * v + w * w * u)), rel=1e-5)
    assert s.psa[0] == pytest.approx(w * w * s.sd[0], rel=1e-14)


@pytest.mark.parametrize("xi", [0.0, 0.05, 0.2])
def test_against_the_closed_form_impulse_response(tmp_path, xi):
    """A one-sample pulse (a triangle of area I = a dt, dt = T / 5000) is an impulse to
    (omega dt)^2: the oscillator's peak displacement is the impulse response's first extreme,
    (I / omega) exp(-xi omega t*) at omega_d t* = atan(sqrt(1 - xi^2) / xi) (I / omega at a
    quarter period undamped), to 1e-5."""
    period, a = 0.5, 10.0
    dt = period / 5000
    rec = tmp_path / "pulse.txt"
    rec.write_text("0.0\n" + f"{a:.17e}\n" + "0.0\n" * 3000)
    s = response_spectrum(rec, periods=[period], xi=xi, format="values", units="m/s2", dt=dt)
    w = 2 * math.pi / period
    wd = w * math.sqrt(1 - xi * xi)
    t_star = (math.atan(math.sqrt(1 - xi * xi) / xi) if xi > 0 else math.pi / 2) / wd
    assert s.sd[0] == pytest.approx(a * dt / w * math.exp(-xi * w * t_star), rel=1e-5)


def test_record_settings_are_the_decks(tmp_path):
    """A plain values file in cm/s2 with record_units and dt gives the AT2's spectrum."""
    ag, dt = at2_values()
    plain = tmp_path / "rec.txt"
    plain.write_text("".join(f"{x * 100.0:.10e}\n" for x in ag))
    t = [0.2, 1.0]
    a = response_spectrum(AT2, periods=t)
    b = response_spectrum(plain, periods=t, format="values", units="cm/s2", dt=dt)
    np.testing.assert_allclose(b.psa, a.psa, rtol=1e-9)
    half = response_spectrum(AT2, periods=t, scale=0.5)
    np.testing.assert_allclose(half.sd, 0.5 * a.sd, rtol=1e-12)  # linear in the motion


def test_a_decks_motion(tmp_path):
    deck = ROOT / "inputs" / "isolated_fps.nml"
    s = response_spectrum(deck, periods=[0.0, 1.0])
    a = response_spectrum(AT2, periods=[0.0, 1.0])
    np.testing.assert_allclose(s.psa, a.psa, rtol=1e-12)
    with pytest.raises(frictiondyn.DeckError, match="not a record"):
        response_spectrum(ROOT / "inputs" / "test1_velocity.nml")


def test_bad_input(tmp_path):
    with pytest.raises(frictiondyn.DeckError, match="no such record file"):
        response_spectrum(tmp_path / "none.AT2")
    bad = tmp_path / "bad.txt"
    bad.write_text("0.1\nabc\n")
    with pytest.raises(frictiondyn.DeckError, match="line 2"):
        response_spectrum(bad, format="values", dt=0.01)
    with pytest.raises(frictiondyn.DeckError, match="xi"):
        response_spectrum(AT2, xi=1.0)
    with pytest.raises(ValueError, match="increase"):
        response_spectrum(AT2, periods=[1.0, 0.5])


def test_command_line(tmp_path):
    proc = subprocess.run(
        [sys.executable, "-m", "frictiondyn", "spectrum", str(AT2), "--out", str(tmp_path),
         "--periods", "0.05", "5", "30", "--plot"],
        capture_output=True, text=True,
    )
    assert proc.returncode == 0, proc.stderr
    assert "PGA 0.35" in proc.stdout
    rows = (tmp_path / "synthetic_pga035.spectrum.csv").read_text().splitlines()
    assert rows[0] == "period_s,sd_m,psv_mps,psa_mps2,psa_g,sa_mps2"
    assert len(rows) == 1 + 31
    assert (tmp_path / "spectrum.png").stat().st_size > 10000
    proc = subprocess.run(
        [sys.executable, "-m", "frictiondyn", "spectrum", str(tmp_path / "none.AT2")],
        capture_output=True, text=True,
    )
    assert proc.returncode == 1 and "no such record file" in proc.stderr
