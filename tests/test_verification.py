"""The verification battery: cases with closed-form answers, run by every technique and law.

- Den Hartog's steady state of a harmonically forced oscillator with Coulomb friction
  (non-stop motion): amplitude and phase of the response's fundamental, against the exact
  technique (to round-off), Moreau-Jean (first order in the step) and each regularized law in
  its limit (first order in eps, and in f).
- Free vibration with Coulomb friction from rest: the amplitude falls by 4 F/k a cycle
  (2 F/k a half cycle), the extremes come every half period, and the mass stops at the end
  of the first half cycle that ends within the dead band |u| <= F/k, at the place the closed
  form gives; every technique.

The longer versions, with tables, are in bench/verification.py; the step and law error
estimates of ``frictiondyn converge`` on these cases are in tests/test_convergence.py.
"""

from __future__ import annotations

import warnings

import frictiondyn as fd
import numpy as np
import pytest
from conftest import deck_text
from oracles import den_hartog

# Den Hartog's case: m = 2 kg on k (1 Hz), driven at w / wn = 0.7 by the table (f0 = m amp
# w^2), friction F = 0.3 f0; started on the steady state, so that every cycle is steady.
M, FN, R, RATIO, AMP = 2.0, 1.0, 0.7, 0.3, 0.01
K = M * (2 * np.pi * FN) ** 2
W = R * 2 * np.pi * FN
F0 = M * AMP * W**2
FF = RATIO * F0
CYCLES = 4


def den_hartog_groups(law: str, technique: str, n1: int, **friction) -> dict:
    x0, v0, _ = den_hartog(np.array([0.0]), M, K, FF, F0, W)
    integration = {"technique": technique, "n1": n1}
    if technique == "newmark":
        integration["n2"] = 50
    return {
        "model": {"n_dof": 1, "mass": [M], "u0": [float(x0[0])], "v0": [float(v0[0])]},
        "springs": {"n_springs": 1, "node_i": [1], "node_j": [0], "k": [K]},
        "damping": {"damping_type": "none"},
        "friction": {"n_devices": 1, "node_i": 1, "node_j": 0, "law": law, "p": FF, "mu": 1.0,
                     **friction},
        "excitation": {
            "excitation_type": "harmonic", "amplitude": AMP, "frequency": W / (2 * np.pi),
            "dt_record": 0.01, "duration": CYCLES * 2 * np.pi / W, "ramp_cycles": 0,
        },
        "integration": integration,
        "output": {"output_every": 1},
    }


def fundamental(t: np.ndarray, x: np.ndarray) -> complex:
    """The response's fundamental over the last two cycles, X with x ~ Re(X e^(i w t)):
    |X| its amplitude, arg X its phase (the trapezoidal rule on a whole number of periods)."""
    keep = t >= t[-1] - 2 * 2 * np.pi / W - 1e-9
    t, x = t[keep], x[keep]
    return 2 * np.trapezoid(x * np.exp(-1j * W * t), t) / (t[-1] - t[0])


def den_hartog_errors(law: str, technique: str, n1: int, **friction) -> tuple[float, float]:
    """(amplitude error relative to Den Hartog's amplitude, phase error of the fundamental in
    rad) of a run over its last two cycles; the closed form is read on the run's own rows, so
    that sampling and quadrature are the same on both sides."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", fd.FrictiondynWarning)
        r = fd.run_text(deck_text(den_hartog_groups(law, technique, n1, **friction)))
    t, u = np.asarray(r["t"]), np.asarray(r["u1"])
    x, _, amplitude = den_hartog(t, M, K, FF, F0, W)
    last = t >= t[-1] - 2 * 2 * np.pi / W - 1e-9
    sampled = np.max(np.abs(x[last]))
    assert abs(sampled / amplitude - 1) < 1e-5  # the rows (every ms) see the peak
    amp_err = abs(np.max(np.abs(u[last])) / sampled - 1)
    return amp_err, abs(np.angle(fundamental(t, u) / fundamental(t, x)))


def test_den_hartog_amplitude_and_phase_exact_technique():
    """The exact technique: amplitude and phase to round-off (measured 2.5e-14 and 4e-15 rad)."""
    amp_err, phase_err = den_hartog_errors("coulomb", "event_driven", 10)
    assert amp_err < 1e-12 and phase_err < 1e-12


def test_den_hartog_moreau_jean_first_order():
    """Moreau-Jean: the amplitude converges at first order in the step (an event inside a
    step is resolved to within the step): halving the step from n1 = 20 to 40 divides its
    error by 1.86 (measured; 2.09 from 40 to 80); at n1 = 40 amplitude 2.1e-4, phase 6.6e-5 rad."""
    coarse, fine = (den_hartog_errors("coulomb", "moreau_jean", n1) for n1 in (20, 40))
    assert 1.6 < coarse[0] / fine[0] < 2.4, (coarse, fine)
    assert fine[0] < 3e-4 and fine[1] < 1e-4, fine


@pytest.mark.parametrize(
    "law, parameter, values, ratio, bound",
    [("velocity", "eps", (1e-3, 1e-4), (8, 12), 2e-4), ("hysteretic", "f", (1e-5, 1e-6), (2.5, 4.5), 5e-3)],
)
def test_den_hartog_each_law_in_its_limit(law, parameter, values, ratio, bound):
    """Each regularized law tends to Den Hartog's closed form as its parameter shrinks (n1 =
    20): the velocity law at first order in eps (eps / 10 divides the amplitude error by 9.5,
    measured; 1.2e-4 at eps = 1e-4 m/s), the hysteretic law (eps1 = 100 f) at order 1/2 in f
    (f / 10 divides it by 3.3; 3.5e-3 at f = 1e-6 m, 1.1e-2 at the paper's 1e-5 m). The phase
    error falls with it (2.1e-5 and 5.3e-4 rad at the smaller values)."""
    errors = []
    for value in values:
        friction = {parameter: value}
        if law == "hysteretic":
            friction["eps1"] = 100 * value
        errors.append(den_hartog_errors(law, "newmark", 20, **friction))
    (amp0, phase0), (amp1, phase1) = errors
    assert ratio[0] < amp0 / amp1 < ratio[1], errors
    assert amp1 < bound and phase1 < phase0 and phase1 < 1e-3, errors


# Free vibration: m = 2 kg on k (T = 1 s), friction F = k a with a = 1 mm, released from
# rest at u0 = 10.3 a. Each half cycle (0.5 s, 500 rows of 1 ms) ends at rest at
# (-1)^n (u0 - 2 n a); the fifth ends at -0.3 a, inside the dead band |u| <= a: it stops there.
FV_M, FV_A = 2.0, 1e-3
FV_K = FV_M * (2 * np.pi) ** 2
FV_U0 = 10.3 * FV_A


def free_vibration(law: str, technique: str, n1: int = 10, **friction) -> fd.Result:
    integration = {"technique": technique, "n1": n1}
    if technique == "newmark":
        integration["n2"] = 50
    groups = {
        "model": {"n_dof": 1, "mass": [FV_M], "u0": [FV_U0]},
        "springs": {"n_springs": 1, "node_i": [1], "node_j": [0], "k": [FV_K]},
        "damping": {"damping_type": "none"},
        "friction": {"n_devices": 1, "node_i": 1, "node_j": 0, "law": law, "p": FV_K * FV_A,
                     "mu": 1.0, **friction},
        "excitation": {"excitation_type": "none", "dt_record": 0.01, "duration": 4.0},
        "integration": integration,
        "output": {"output_every": 1},
    }
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", fd.FrictiondynWarning)
        return fd.run_text(deck_text(groups))


@pytest.mark.parametrize(
    "law, technique, friction, extremes, rest",
    [
        ("coulomb", "event_driven", {}, 1e-12, 1e-12),
        ("coulomb", "moreau_jean", {}, 1e-7, 1e-5),
        ("velocity", "newmark", {"eps": 1e-4}, 1e-4, None),
        ("hysteretic", "newmark", {"f": 1e-6, "eps1": 1e-4}, 2e-3, 2e-3),
    ],
)
def test_free_vibration_with_coulomb_friction(law, technique, friction, extremes, rest):
    """Every technique: the half-cycle extremes fall by 2 a (4 F / k a cycle) and come every
    half period, within ``extremes`` times a (measured: exact 2e-15, Moreau-Jean 9e-9 at n1 =
    10, velocity law 7e-5 at eps = 1e-4 m/s, hysteretic 1.2e-3 at f = 1e-6 m); the mass stops
    in the dead band. The exact technique, Moreau-Jean and the hysteretic law hold it where
    the closed form stops (-0.3 a, within ``rest`` times a, at rest for good: v = 0 exactly for
    the first two); the velocity law's band is a dashpot P mu / eps, so it creeps back towards
    0 with tau = a / eps = 10 s (docs/theory.md, section 15) and never leaves the band."""
    r = free_vibration(law, technique, **friction)
    t, u, v = (np.asarray(r[c]) for c in ("t", "u1", "v1"))
    for n in range(1, 6):
        i = int(np.argmin(np.abs(t - n / 2)))
        assert abs(t[i] - n / 2) < 1e-9
        exact = (-1) ** n * (FV_U0 - 2 * n * FV_A)
        assert abs(u[i] - exact) < extremes * FV_A, (n, u[i], exact)
    after = t >= 2.5 + 1e-9
    assert np.all(np.abs(u[after]) <= FV_A)
    if rest is not None:
        assert np.all(np.abs(u[after] + 0.3 * FV_A) < rest * FV_A)
        if law == "coulomb":
            assert np.all(v[after] == 0.0) and r.summary["slip_to_stick"] == [1]
    else:
        creep = np.abs(u[after])
        assert np.all(np.diff(creep) <= 1e-15) and creep[-1] < 0.3 * FV_A
        # tau = P mu / (eps k) = a / eps: exp(-1.5 s / 10 s) of -0.3 a left at t = 4 s
        assert creep[-1] == pytest.approx(0.3 * FV_A * np.exp(-1.5 / 10.0), rel=0.05)
