"""Planar bearings on elastic vertical supports (`kv`, `zeta_v` of &bearings).

Each bearing's share m = p / g of the mass stands on its own vertical spring kv with a dashpot
c = 2 zeta_v sqrt(kv m): with z the compression beyond the static one and a_z the ground's
vertical acceleration (upward positive), m z'' + c z' + kv z = m a_z and N = p + kv z + c z'
in contact; the support cannot pull, so where N falls to 0 the mass lifts off and falls freely
(z'' = a_z + g) until it lands. The oscillator is advanced by the exact step map for a_z linear
in each step, lift-off and landing located within the step.

- a harmonic a_z = A sin(W t): the steady N oscillates about p with the amplitude
  p |H| A' / g, |H| the damped oscillator's force transmissibility and A' = A sinc^2(W h / 2)
  the amplitude at W of a_z taken linear between the steps h (both techniques);
- kv -> infinity tends to the rigid support N = p (1 + a_z / g) at the rate the oscillator's
  closed form says (the difference bounded by m A W / (wn - W));
- a pulse a_z = -1.5 g: the lift-off at the closed form's time acos(1 - g / a) / wn, the free
  flight's landing time and peak uplift, to round-off (a_z linear between the record's samples
  is what the map integrates exactly);
- the energy balance closes with the vertical oscillators, their flights and their dashpots.
"""
from __future__ import annotations

import numpy as np
import pytest

import frictiondyn
from conftest import deck_text

G = 9.80665
M = 1000.0
P = M * G
TV = 0.05                     # vertical period [s]
WN = 2 * np.pi / TV
KV = M * WN**2                # the bearing carries the whole block: m = p / g = M


def block(kv: float | None, zeta: float = 0.0, exc3: dict | None = None, *, law: str = "velocity",
          technique: str = "newmark", horizontal: bool = False, dt: float = 0.01, duration: float = 4.0,
          n1: int = 10, radius: float = 0.0) -> dict:
    """A block (DOFs 1: x, 2: y) on one bearing to the table carrying its weight; the table at
    rest (or a harmonic motion along x and y: horizontal); the vertical component exc3."""
    bearing = {"law": law, "p": P, "mu": 0.1, "radius": radius}
    if law == "velocity":
        bearing["eps"] = 1.0e-3
    elif law == "hysteretic":
        bearing.update(f=2.0e-4, eps1=1.0e-3)
    if kv is not None:
        bearing.update(kv=kv, zeta_v=zeta)
    g = {
        "model": {"n_dof": 2, "mass": [M, M]},
        "springs": {"n_springs": 2, "node_i": [1, 2], "node_j": [0, 0], "k": [2.0e4, 1.0e4]},
        "damping": {"damping_type": "none"},
        "bearings": {"n_bearings": 1, "dof_xi": 1, "dof_yi": 2, "dof_xj": 0, "dof_yj": 0, **bearing},
        "excitation": {"excitation_type": "none", "dt_record": dt, "duration": duration},
        "integration": {"n1": n1, "technique": technique},
        "output": {"dir": "out", "output_every": 1},
    }
    if horizontal:
        g["excitation"] = {"excitation_type": "harmonic", "amplitude": 0.08, "frequency": 1.0,
                           "dt_record": dt, "duration": duration}
    if exc3 is not None:
        g["excitation3"] = exc3
    return g


def harmonic(amplitude_g: float, f: float, dt: float = 0.01, duration: float = 4.0) -> dict:
    """&excitation3 harmonic: x_z = a0 sin(W t), a_z = -a0 W^2 sin(W t) of amplitude amplitude_g g."""
    w = 2 * np.pi * f
    return {"excitation_type": "harmonic", "amplitude": amplitude_g * G / w**2, "frequency": f,
            "dt_record": dt, "duration": duration}


def run(tmp_path, g: dict, name: str = "v.nml") -> frictiondyn.Result:
    return frictiondyn.run_text(deck_text(g), name, tmp_path)


def amplitude_at(t, y, w: float) -> float:
    """The amplitude of y's component at the circular frequency w (least squares on sin, cos)."""
    x = np.column_stack([np.sin(w * t), np.cos(w * t), np.ones_like(t)])
    c, *_ = np.linalg.lstsq(x, y, rcond=None)
    return float(np.hypot(c[0], c[1]))


def transmissibility(r: float, zeta: float) -> float:
    return float(np.sqrt(1 + (2 * zeta * r) ** 2) / np.sqrt((1 - r**2) ** 2 + (2 * zeta * r) ** 2))


@pytest.mark.parametrize("zeta, law, technique", [(0.05, "velocity", "newmark"), (0.0, "hysteretic", "newmark"),
                                                  (0.05, "coulomb", "moreau_jean")])
def test_harmonic_vertical_motion_gives_the_transmitted_normal_force(tmp_path, zeta, law, technique):
    """a_z of 0.3 g at 10 Hz on a support of 20 Hz (r = 0.5): N oscillates about p with the
    amplitude p |H| A' / g. The fit takes [2 s, 4 s], whole periods of the motion and of the
    support's free vibration (which zeta_v = 0 keeps and zeta_v = 0.05 damps to e^-12.6):
    orthogonal to it. Measured within 1e-7 of the closed form."""
    f = 10.0
    w = 2 * np.pi * f
    res = run(tmp_path, block(KV, zeta, harmonic(0.3, f), law=law, technique=technique))
    t = res["t"]
    keep = t >= 2.0 - 1e-9
    amp = amplitude_at(t[keep], res["N1"][keep] - P, w)
    h = 0.001                                 # dt1 = dt_record / n1
    a_linear = 0.3 * G * (np.sin(w * h / 2) / (w * h / 2)) ** 2
    expected = P * transmissibility(w / WN, zeta) * a_linear / G
    assert expected > 1.3 * 0.3 * P           # the support amplifies: |H| = 1.33 (zeta 0)
    assert amp == pytest.approx(expected, rel=1e-6)
    assert res.summary["bearing_uplift_count"] == [0]
    assert res.summary["bearing_uplift_peak_m"] == [0.0]


def test_stiff_support_tends_to_the_rigid_one(tmp_path):
    """A block sliding under a horizontal harmonic and a vertical one of 0.5 g at 3 Hz: N on a
    support of vertical period T differs from the rigid p (1 + a_z / g) by at most
    m A W / (wn - W) (the closed form from rest: the quasi-static lag m A W^2 / (wn^2 - W^2) and
    the free vibration m A W wn / (wn^2 - W^2)), first order in W / wn: a tenth of T, a tenth of
    the difference; plus the response to a_z taken linear between the steps h (its error
    m A (W h)^2 / 8 = 0.22 N; the run is off the sine's closed form by 2.8 times that at most,
    measured: bounded here by 4 times). T = 5.3 ms and 0.53 ms (shorter than the step dt1 = 1 ms:
    the map is exact; not a divisor of it, whose free vibration the steps would sample at its
    zeros). The bearing's peak displacement moves by less than the friction's change mu dN / (p mu)."""
    f = 3.0
    w = 2 * np.pi * f
    a = 0.5 * G
    h = 1.0e-3
    rigid = run(tmp_path, block(None, exc3=harmonic(0.5, f), horizontal=True), "rigid.nml")
    diffs = []
    for tv in (5.3e-3, 5.3e-4):
        wn = 2 * np.pi / tv
        r = run(tmp_path, block(M * wn**2, exc3=harmonic(0.5, f), horizontal=True), "stiff.nml")
        assert np.array_equal(r["t"], rigid["t"])
        diff = float(np.max(np.abs(r["N1"] - rigid["N1"])))
        free = M * a * w / (wn - w)
        assert 0.9 * free < diff <= free + 4 * M * a * (w * h) ** 2 / 8, (tv, diff, free)
        diffs.append(diff)
        peak = np.asarray(r.summary["bearing_peak_displacement_m"])
        peak0 = np.asarray(rigid.summary["bearing_peak_displacement_m"])
        assert np.abs(peak / peak0 - 1).max() < diff / P, (tv, peak, peak0)
    assert 9 < diffs[0] / diffs[1] < 11
    assert rigid.summary["slip_travel_m"][0] > 0.05


def pulse_record(tmp_path, a: float, t1: float, dt: float, duration: float) -> None:
    """a_z = -a up to t1 (a sample), linear to 0 over the next dt, then 0."""
    t = np.arange(0.0, duration + dt / 2, dt)
    az = np.where(t <= t1 + 1e-12, -a, 0.0)
    (tmp_path / "pulse.txt").write_text("".join(f"{v:.17e}\n" for v in az))


def free_flight(a: float, t1: float, dt: float):
    """The closed form of the support from rest under the pulse: lift-off where
    -(a / wn^2)(1 - cos wn t) = -p / kv, i.e. cos wn tL = 1 - g / a; then the free fall
    z'' = a_z + g, a polynomial on [tL, t1], [t1, t1 + dt] (a_z linear) and after; landing
    where z = -p / kv again. Returns (tL, landing time, peak uplift)."""
    ds = G / WN**2
    tl = np.arccos(1 - G / a) / WN
    z = -(a / WN**2) * (1 - np.cos(WN * tl))
    v = -(a / WN) * np.sin(WN * tl)
    # pieces: (start, end, z'' at the start, its slope)
    pieces = [(tl, t1, G - a, 0.0), (t1, t1 + dt, G - a, a / dt), (t1 + dt, np.inf, G, 0.0)]
    peak = 0.0
    for t0, te, acc, jerk in pieces:
        # z(s) = z + v s + acc s^2 / 2 + jerk s^3 / 6 ; landing: z(s) + ds = 0 with z' > 0
        poly = np.polynomial.Polynomial([z + ds, v, acc / 2, jerk / 6])
        span = te - t0
        turns = [s.real for s in poly.deriv().roots() if abs(s.imag) < 1e-14 and 0 < s.real < span]
        for s in turns:
            peak = max(peak, -poly(s))
        roots = sorted(s.real for s in poly.roots() if abs(s.imag) < 1e-14 and 1e-12 < s.real < span)
        if roots:
            return tl, t0 + roots[0], peak
        z = poly(span) - ds
        v = poly.deriv()(span)
    raise AssertionError("no landing")


@pytest.mark.parametrize("law, technique", [("velocity", "newmark"), ("coulomb", "moreau_jean")])
def test_lift_off_and_landing_follow_the_closed_form(tmp_path, law, technique):
    """A downward pulse of 1.5 g for 0.05 s on a support of 0.05 s: the mass lifts off at
    acos(1 - g / a) / wn = 9.8 ms, rises 14 mm, and lands at 0.139 s; the summary's lift-off time,
    flight duration and peak uplift equal the closed form's to round-off (measured within
    1e-12 s and 1e-12 m), N = 0 at every step inside the flight, the warning given."""
    a, t1, dt = 1.5 * G, 0.05, 0.005
    duration = 0.15                           # the first flight and landing (it lifts off again later)
    pulse_record(tmp_path, a, t1, dt, duration)
    exc3 = {"excitation_type": "record", "record_file": "pulse.txt", "record_format": "values",
            "record_units": "m/s2", "dt_record": dt}
    g = block(KV, 0.0, exc3, law=law, technique=technique, dt=dt, duration=duration, n1=4)
    with pytest.warns(frictiondyn.FrictiondynWarning, match="bearing-uplift"):
        r = run(tmp_path, g)
    tl, td, peak = free_flight(a, t1, dt)
    assert 0.0 < tl < t1 < td < duration
    s = r.summary
    assert s["bearing_uplift_count"] == [1]
    assert s["bearing_uplift_first_time_s"][0] == pytest.approx(tl, abs=1e-10)
    assert s["bearing_uplift_duration_s"][0] == pytest.approx(td - tl, abs=1e-10)
    assert s["bearing_uplift_peak_m"][0] == pytest.approx(peak, rel=1e-9)
    t = r["t"]
    inside = (t > tl + 1e-9) & (t < td - 1e-9)
    assert inside.sum() > 10
    assert np.all(r["N1"][inside] == 0.0)
    assert np.all(r["N1"][(t < tl - 1e-9) | (t > td + 1e-9)] > 0.0)
    assert s["bearing_min_normal_force_N"] == [0.0]


@pytest.mark.parametrize("law, technique, zeta, radius", [
    ("velocity", "newmark", 0.0, 0.0), ("hysteretic", "newmark", 0.05, 1.5), ("velocity", "newmark", 0.05, 1.5),
    ("coulomb", "moreau_jean", 0.0, 1.5), ("coulomb", "moreau_jean", 0.05, 0.0)])
def test_energy_balance_closes_with_elastic_supports_and_uplift(tmp_path, law, technique, zeta, radius):
    """A block sliding under a horizontal harmonic and a vertical one of 1.2 g at 3 Hz on a support
    of 0.05 s: it lifts off; the balance, with the oscillators' kinetic and potential energy, the
    ground's vertical work and the dashpot's, closes to round-off (measured below 1e-14)."""
    g = block(KV, zeta, harmonic(1.2, 3.0, duration=2.0), law=law, technique=technique, horizontal=True,
              duration=2.0, radius=radius)
    with pytest.warns(frictiondyn.FrictiondynWarning, match="bearing-uplift"):
        r = run(tmp_path, g)
    s = r.summary
    assert s["bearing_uplift_count"][0] >= 1 and s["bearing_uplift_peak_m"][0] > 1e-3
    assert s["energy_balance"] == "closed"
    assert abs(s["energy_residual_ratio"]) < 1.0e-10
    assert s["energy_friction_J"] > 0.0
