"""Modal damping (damping_type = 'modal'): each kept mode of the stuck system decays freely
with its own ratio, the modes above the kept ones not at all, the summary reports those
ratios, a large model runs without an n x n matrix in a time linear in its size, and bad
input is an error naming the variable.

The ratio of a free decay is read from the run to rounding: Newmark's average acceleration
is the trapezoidal rule, so a mode's coordinate q_n = phi' M u_n / phi' M phi follows
q_{n+1} = a q_n - b q_{n-1} with roots mu = (1 + h lam / 2) / (1 - h lam / 2) of the
closed-form damped mode's lam = w (-xi +- i sqrt(1 - xi^2)): a and b fitted to the history,
lam = (2 / h) (mu - 1) / (mu + 1) gives xi = -Re(lam) / |lam| and w = |lam|."""

from __future__ import annotations

import frictiondyn as fd
import numpy as np
import pytest
from frictiondyn import FrictiondynError

MASS = np.array([3.0e5, 2.8e5, 2.6e5, 2.2e5, 2.0e5])
K = np.array([5.0e8, 4.4e8, 3.8e8, 3.0e8, 2.2e8])
H = 1.0e-3  # dt1 [s]


def stiffness(k: np.ndarray) -> np.ndarray:
    n = len(k)
    kmat = np.zeros((n, n))
    for i in range(n):
        kmat[i, i] += k[i]
        if i > 0:
            kmat[i - 1, i - 1] += k[i]
            kmat[i, i - 1] -= k[i]
            kmat[i - 1, i] -= k[i]
    return kmat


def modes(kmat: np.ndarray, mass: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """w and the M-orthonormal mode shapes (columns) of K phi = w^2 M phi."""
    s = 1.0 / np.sqrt(mass)
    lam, y = np.linalg.eigh(s[:, None] * kmat * s[None, :])
    return np.sqrt(lam), s[:, None] * y


def decay(r: fd.Result, phi: np.ndarray, mass: np.ndarray, start: int = 0) -> tuple[float, float]:
    """xi and w of the free decay of the mode phi in the run's history (module docstring),
    from row `start` on; about a static offset when start > 0 (q_{n+1} = a q_n - b q_{n-1} + c:
    a device whose elastic range moved)."""
    u = np.column_stack([r[f"u{i + 1}"] for i in range(len(phi))])[start:]
    h = r.time[1] - r.time[0]
    assert h == pytest.approx(H, rel=1e-12)
    q = u @ (mass * phi) / (phi @ (mass * phi))
    rows = [q[1:-1], -q[:-2]] + ([np.ones(len(q) - 2)] if start > 0 else [])
    (a, b, *_), *_ = np.linalg.lstsq(np.column_stack(rows), q[2:], rcond=None)
    mu = (a + np.sqrt(complex(a * a - 4 * b))) / 2
    lam = (2 / h) * (mu - 1) / (mu + 1)
    return -lam.real / abs(lam), abs(lam)


def building(xi, u0, modes_kept=None, devices=(), **kw) -> fd.Analysis:
    n = len(MASS)
    return fd.Analysis(
        masses=list(MASS),
        springs=[fd.Spring(i + 1, i, K[i]) for i in range(n)],
        damping=fd.Damping.modal(xi, modes_kept),
        devices=list(devices),
        excitation=fd.FreeVibration(dt_record=H * 10, duration=0.6),
        integration=fd.Integration(n1=10),
        output=fd.Output(output_every=1),
        u0=list(u0),
        **kw,
    )


@pytest.mark.parametrize("xi", [0.05, [0.02, 0.035, 0.05, 0.08, 0.12]], ids=["one ratio", "a ratio per mode"])
@pytest.mark.parametrize("k", [1, 3, 5])
def test_each_mode_decays_with_its_ratio(xi, k):
    """Free decay from mode k of a 5-storey building (no devices): that mode's ratio and
    frequency to 1e-10, from the history alone."""
    w, phi = modes(stiffness(K), MASS)
    r = building(xi, 0.01 * phi[:, k - 1] / np.abs(phi[:, k - 1]).max()).run()
    want = xi if np.isscalar(xi) else xi[k - 1]
    got_xi, got_w = decay(r, phi[:, k - 1], MASS)
    assert got_xi == pytest.approx(want, abs=1e-10)
    assert got_w == pytest.approx(w[k - 1], rel=1e-10)
    # the summary's modal ratios of the stuck system are the given ones
    assert np.allclose(r.summary["modal_xi_stuck"], np.broadcast_to(xi, 5), rtol=0, atol=1e-12)
    assert r.summary["xi_stuck"] == pytest.approx(xi if np.isscalar(xi) else xi[0], abs=1e-12)


def test_modes_above_the_kept_ones_are_undamped():
    """modal_modes = 2: mode 3 decays not at all (xi = 0 to 1e-10), mode 2 at its ratio."""
    w, phi = modes(stiffness(K), MASS)
    r3 = building(0.05, 0.01 * phi[:, 2] / np.abs(phi[:, 2]).max(), modes_kept=2).run()
    assert decay(r3, phi[:, 2], MASS)[0] == pytest.approx(0.0, abs=1e-10)
    assert r3.summary["modal_xi_stuck"] == pytest.approx([0.05, 0.05, 0, 0, 0], abs=1e-12)
    r2 = building([0.03, 0.04], 0.01 * phi[:, 1] / np.abs(phi[:, 1]).max()).run()
    assert decay(r2, phi[:, 1], MASS)[0] == pytest.approx(0.04, abs=1e-10)


def test_devices_that_stay_stuck_are_part_of_the_modes():
    """Hysteretic devices beside storeys 1 and 3 that never slip are their sticking springs
    P mu / f in the stuck system: its modes, not the bare frame's, decay at their ratios.
    The motion starts from a velocity along the mode: the devices slide at first, then stick
    for good (their elastic range moved: the decay is about a static offset)."""
    kd = 2.0e8
    devices = [fd.Device(1, 0, p=1e9, mu=1.0, law="hysteretic", f=1e9 / kd),
               fd.Device(3, 2, p=1e9, mu=1.0, law="hysteretic", f=1e9 / kd)]
    kmat = stiffness(K)
    kmat[0, 0] += kd
    kmat[2, 2] += kd
    kmat[1, 1] += kd
    kmat[1, 2] -= kd
    kmat[2, 1] -= kd
    w, phi = modes(kmat, MASS)
    xi = [0.02, 0.03, 0.04, 0.06, 0.1]
    for k in (1, 4):
        v0 = 0.05 * phi[:, k - 1] / np.abs(phi[:, k - 1]).max()
        r = building(xi, [0.0] * 5, devices=devices, v0=list(v0)).run()
        assert r.summary["stick_to_slip"] == [0, 0] and r.summary["slip_to_stick"] == [1, 1]
        stuck = 1 + max(np.flatnonzero(r["phase1"] != 0)[-1], np.flatnonzero(r["phase2"] != 0)[-1])
        assert stuck < len(r.time) / 2
        got_xi, got_w = decay(r, phi[:, k - 1], MASS, start=stuck)
        assert got_xi == pytest.approx(xi[k - 1], abs=1e-10)
        assert got_w == pytest.approx(w[k - 1], rel=1e-10)


def test_energy_balance_holds_with_modal_damping():
    """The viscous work is the low-rank term's: the energy balance closes (the summary's
    kinetic and strain energies are changes from the start)."""
    w, phi = modes(stiffness(K), MASS)
    u0 = 0.01 * (phi[:, 0] + phi[:, 3]) / np.abs(phi).max()
    s = building([0.02, 0.035, 0.05, 0.08, 0.12], u0).run().summary
    assert s["energy_balance"] == "closed"
    assert s["energy_viscous_J"] == pytest.approx(-(s["energy_kinetic_J"] + s["energy_strain_J"]), rel=1e-12)
    assert s["energy_viscous_J"] > 0.9 * (0.5 * u0 @ stiffness(K) @ u0)


def chain_analysis(n: int, duration: float, xi=0.05, modes_kept=None) -> fd.Analysis:
    return fd.Analysis(
        masses=[2.0e5] * n,
        springs=[fd.Spring(i + 1, i, 3.0e8) for i in range(n)],
        damping=fd.Damping.modal(xi, modes_kept),
        excitation=fd.FreeVibration(dt_record=0.01, duration=duration),
        integration=fd.Integration(n1=2),
        output=fd.Output(output_every=100, n_modes=3),
        u0=[0.01 * (i + 1) / n for i in range(n)],
    )


def test_large_model_low_rank_and_outside_the_band():
    """Above the dense limit (200 DOFs) the modes come from subspace iteration and C is kept
    low-rank: the summary's stuck modes carry the ratio, and the step's matrix keeps the band
    of K (half-bandwidth 1 for a chain), so no n x n damping matrix is assembled. The time per
    step against the size is measured by bench/modal_damping.py."""
    r = chain_analysis(400, 0.2, modes_kept=20).run()
    assert r.summary["modal_xi_stuck"] == pytest.approx([0.05] * 3, abs=1e-8)
    r = chain_analysis(4000, 0.02, modes_kept=10).run()
    assert r.summary["modal_xi_stuck"] == pytest.approx([0.05] * 3, abs=1e-8)
    assert r.summary["linear_system"] == "banded"
    assert r.summary["half_bandwidth"] == 1
    assert r.summary["factorizations"] == 1


BAD = [
    ({"xi": -0.01}, ["&damping", "xi", "-0.01", "[0"]),
    ({"xi": [0.02, -0.03]}, ["&damping", "xi(2)", "-0.03"]),
    ({"xi": [0.02] * 6}, ["&damping", "xi", "6 values", "5 modes"]),
    ({"xi": [0.02] * 3, "modes": 4}, ["&damping", "xi", "3 values", "4 kept modes"]),
    ({"xi": 0.02, "modes": 6}, ["&damping", "modal_modes", "6", "1..5"]),
    ({"xi": 0.02, "modes": 0}, ["&damping", "modal_modes", "0"]),
]


@pytest.mark.parametrize("values,words", BAD, ids=[str(v) for v, _ in BAD])
def test_bad_modal_damping_is_named(values, words):
    a = building(values["xi"], [0.01] * 5, modes_kept=values.get("modes"))
    with pytest.raises(FrictiondynError) as e:
        a.run()
    for w in words:
        assert w in str(e.value)


def test_other_variables_are_refused_with_modal_damping():
    a = building(0.02, [0.01] * 5)
    a.damping.period = 0.5
    with pytest.raises(FrictiondynError, match="period is given"):
        a.run()


def test_a_ratio_per_mode_is_for_modal_damping_only():
    a = building(0.02, [0.01] * 5)
    a.damping = fd.Damping("stiffness", xi=[0.02, 0.03])
    with pytest.raises(FrictiondynError, match=r"xi = 2 values is invalid.*'modal'"):
        a.run()
    a.damping = fd.Damping("rayleigh", rayleigh_a0=0.1, modal_modes=2)
    with pytest.raises(FrictiondynError, match="modal_modes"):
        a.run()


@pytest.mark.parametrize("technique", ["event_driven", "moreau_jean"])
def test_techniques_without_modal_damping_refuse_it(technique):
    a = building(0.02, [0.01] * 5, devices=[fd.Device(1, 0, p=1e6, mu=0.3, law="coulomb")])
    a.integration = fd.Integration(technique=technique)
    with pytest.raises(FrictiondynError, match=f"'modal' is invalid with technique = '{technique}'"):
        a.run()
