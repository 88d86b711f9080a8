"""What a design engineer reads from a run: storey drifts and shears against the
histories and equilibrium, modes against closed forms, Rayleigh damping from two modes,
velocity-dependent friction against a hand-computed slide, the engineers' devices against
their spelled-out decks, the summary's provenance, the Python conveniences, and the
worked examples."""

from __future__ import annotations

import hashlib
import os
import subprocess
import sys

import frictiondyn as fd
import numpy as np
import pytest
from conftest import INPUTS, K1, K2, M1, M2, MU, ROOT, TABLE1, G, P

# a uniform shear building: n floors of mass m on storeys of stiffness k
M_FLOOR, K_STOREY = 2.0e5, 3.0e8


def chain(n: int, **kw) -> fd.Analysis:
    """n equal floors on equal storeys from the table, free vibration from a displaced roof."""
    defaults = {
        "masses": [M_FLOOR] * n,
        "springs": [fd.Spring(i + 1, i, K_STOREY) for i in range(n)],
        "excitation": fd.FreeVibration(dt_record=0.01, duration=0.5),
        "u0": [0.01 * (i + 1) / n for i in range(n)],
    }
    defaults.update(kw)
    return fd.Analysis(**defaults)


def chain_mode(n: int, r: int) -> tuple[float, np.ndarray]:
    """Closed form: mode r (1-based) of the uniform chain, w_r and phi_r (largest +1)."""
    w = 2 * np.sqrt(K_STOREY / M_FLOOR) * np.sin((2 * r - 1) * np.pi / (2 * (2 * n + 1)))
    phi = np.sin(np.arange(1, n + 1) * (2 * r - 1) * np.pi / (2 * n + 1))
    return w, phi / phi[np.argmax(np.abs(phi))]


def building(law: str = "velocity", duration: float = 6.0, **kw) -> fd.Analysis:
    """A 4-storey building with a friction device in every storey, under the synthetic record,
    rows every dt1."""
    n = 4
    mass, k = [3e5, 3e5, 3e5, 2.5e5], [4e8, 3.6e8, 3.2e8, 2.6e8]
    if law in ("coulomb", "moreau_jean"):  # exact Coulomb friction, two techniques
        integ = {"technique": "event_driven" if law == "coulomb" else "moreau_jean"}
        law = "coulomb"
    else:
        integ = {"n2": 20}
    defaults = {
        "masses": mass,
        "labels": ["floor 1", "floor 2", "floor 3", "roof"],
        "springs": [fd.Spring(i + 1, i, k[i]) for i in range(n)],
        "damping": fd.Damping.rayleigh(0.0, 2e-3),
        "devices": [
            fd.Device(
                i + 1, i, p=0.05 * G * sum(mass[i:]), mu=1.0, law=law, label=f"damper {i + 1}"
            )
            for i in range(n)
        ],
        "storeys": [fd.Storey.of_spring(i + 1, height=3.5) for i in range(n)],
        "excitation": fd.Record(
            dt_record=0.01, file=str(INPUTS / "synthetic_pga035.AT2"), duration=duration
        ),
        "integration": fd.Integration(n1=10, **integ),
        "output": fd.Output(output_every=1),
    }
    defaults.update(kw)
    return fd.Analysis(**defaults)


# --- drifts and shears ------------------------------------------------------------------


@pytest.mark.parametrize("law", ["velocity", "hysteretic", "coulomb", "moreau_jean"])
def test_drifts_and_shears_follow_from_the_histories(law):
    """drift = u_i - u_j, V = springs (with a1 K damping) + devices, row by row; and by
    equilibrium the storey shears are the inertia forces above the storey (a0 = 0): an
    independent check of the whole chain, for every technique."""
    a = building(law)
    r = a.run()
    s = r.summary
    m = np.array(a.masses)
    a1 = s["damping_a1_s"]
    assert s["damping_a0_per_s"] == 0.0 and a1 == 2e-3
    u = np.column_stack([r[f"u{i}"] for i in range(1, 5)])
    v = np.column_stack([r[f"v{i}"] for i in range(1, 5)])
    acc = np.column_stack([r[f"aabs{i}"] for i in range(1, 5)])
    below_u = np.column_stack([np.zeros(len(u)), u[:, :-1]])
    below_v = np.column_stack([np.zeros(len(v)), v[:, :-1]])
    k = np.array([x.k for x in a.springs])
    for st in range(1, 5):
        drift = u[:, st - 1] - below_u[:, st - 1]
        assert np.array_equal(r[f"drift{st}"], drift)
        rate = v[:, st - 1] - below_v[:, st - 1]
        shear = k[st - 1] * (drift + a1 * rate) + r[f"F{st}"]
        np.testing.assert_allclose(r[f"V{st}"], shear, rtol=0, atol=1e-9 * np.abs(shear).max())
        inertia = -(m[st - 1 :] * acc[:, st - 1 :]).sum(axis=1)
        # measured: 3.6e-13 (velocity), 8.1e-13 (hysteretic), 5.4e-14 (coulomb), 7.7e-16
        # (moreau_jean: its end-of-step forces and acceleration are one equilibrium) of the peak
        np.testing.assert_allclose(r[f"V{st}"], inertia, rtol=0, atol=1e-11 * np.abs(inertia).max())
    assert np.array_equal(r["Vb"], r["V1"])  # one storey on the table
    # peaks over every accepted step: at least the rows' (every dt1 here), at most a little more
    for st in range(1, 5):
        top = np.abs(r[f"drift{st}"]).max()
        assert top <= s["peak_drift_m"][st - 1] <= top * (1 + 1e-3)
        assert s["peak_drift_ratio"][st - 1] == s["peak_drift_m"][st - 1] / 3.5
        top = np.abs(r[f"V{st}"]).max()
        assert top <= s["peak_storey_shear_N"][st - 1] <= top * (1 + 1e-2)
    # residual values: those of the last state
    assert s["residual_drift_m"] == [r[f"drift{st}"][-1] for st in range(1, 5)]
    assert s["residual_s_m"] == [r[f"s{d}"][-1] for d in range(1, 5)]
    assert s["residual_storey_shear_N"] == [r[f"V{st}"][-1] for st in range(1, 5)]
    assert s["residual_drift_ratio"] == [x / 3.5 for x in s["residual_drift_m"]]


def test_moreau_jean_and_event_driven_report_the_same_drifts_and_shears():
    """Two independent techniques for exact Coulomb friction, one observer: the building's
    peak drifts and storey shears agree to the Moreau-Jean step's first-order error
    (measured at n1 = 20: 6.1e-4 relative in peak drift, 5.1e-4 in peak shear, both at the
    roof; 2.8e-3 in residual drift, storey 3)."""
    ed = building("coulomb").run().summary
    mj = building("moreau_jean").run().summary
    assert mj["technique"] == "moreau_jean" and ed["technique"] == "event_driven"
    np.testing.assert_allclose(mj["residual_drift_m"], ed["residual_drift_m"], rtol=5e-3)
    np.testing.assert_allclose(mj["peak_drift_m"], ed["peak_drift_m"], rtol=1e-3)
    np.testing.assert_allclose(mj["peak_storey_shear_N"], ed["peak_storey_shear_N"], rtol=1e-3)
    assert mj["peak_base_shear_N"] == pytest.approx(ed["peak_base_shear_N"], rel=1e-3)


def test_the_exact_technique_gives_exact_storey_peaks_whatever_the_sampling():
    """Under the exact technique a storey's drift and shear are polynomials between events
    (linear in u, u' and F): the summary's peaks are their exact extrema, the same to
    round-off whether the history keeps every dt1 or every 50th (the events do not depend on
    the sampling); the rows' maxima never exceed them, and the envelope columns give them."""
    fine = building("coulomb").run()
    coarse = building("coulomb", output=fd.Output(output_every=50)).run()
    sf, sc = fine.summary, coarse.summary
    assert sf["peaks_exact"] is True and sc["peaks_exact"] is True
    for key in ("peak_drift_m", "peak_storey_shear_N"):
        np.testing.assert_allclose(sc[key], sf[key], rtol=1e-12)
    assert sc["peak_base_shear_N"] == pytest.approx(sf["peak_base_shear_N"], rel=1e-12)
    below = []
    for r in (fine, coarse):
        s = r.summary
        for st in range(1, 5):
            for col, key in ((f"drift{st}", "peak_drift_m"), (f"V{st}", "peak_storey_shear_N")):
                # the envelope holds the maxima between rows: their largest is the peak
                assert r[f"peak_{col}"].max() == s[key][st - 1]
                assert r.peak(col) == s[key][st - 1]
                assert np.abs(r[col]).max() <= s[key][st - 1]
            below.append(np.abs(r[f"drift{st}"]).max() < s["peak_drift_m"][st - 1] * (1 - 1e-6))
        assert r["peak_Vb"].max() == s["peak_base_shear_N"] == r.peak("Vb")
    # every 50th dt1 (0.05 s) the rows miss the peaks the exact technique finds
    assert any(below)


def test_peaks_of_a_linear_run_are_the_rows_peaks():
    """Without devices every accepted step is a row (output_every = 1): the summary's peaks
    and their times are exactly the history's."""
    r = chain(
        3,
        storeys=[fd.Storey(i + 1, i) for i in range(3)],
        output=fd.Output(output_every=1),
        damping=fd.Damping.rayleigh(0.5, 1e-3),
    ).run()
    s = r.summary
    for st in range(1, 4):
        k = int(np.argmax(np.abs(r[f"drift{st}"])))
        assert s["peak_drift_m"][st - 1] == abs(r[f"drift{st}"][k])
        assert s["peak_drift_time_s"][st - 1] == pytest.approx(r.time[k], rel=1e-12)
    # no height given: 0, and the drift ratio undefined (null: docs/namelist.md)
    assert s["peak_drift_ratio"] == [None] * 3 and s["storey_height_m"] == [0.0] * 3
    assert s["peak_base_shear_N"] == np.abs(r["Vb"]).max()
    # with a0 M damping the base shear is the inertia forces less the a0 M v forces
    m = np.full(3, M_FLOOR)
    acc = np.column_stack([r[f"aabs{i}"] for i in (1, 2, 3)])
    vel = np.column_stack([r[f"v{i}"] for i in (1, 2, 3)])
    expect = -(acc * m).sum(axis=1) - 0.5 * (vel * m).sum(axis=1)
    np.testing.assert_allclose(r["Vb"], expect, rtol=0, atol=1e-8 * np.abs(expect).max())


def test_storeys_named_by_nodes_by_springs_and_reversed_elements():
    """A storey given by its nodes and one given by a spring are the same storey; an element
    written from the lower node counts with its sign."""
    a = chain(2, storeys=[fd.Storey(1, 0, label="ground"), fd.Storey.of_spring(2)])
    b = chain(
        2,
        springs=[fd.Spring(0 + 1, 0, K_STOREY), fd.Spring(1, 2, K_STOREY)],
        storeys=[fd.Storey.of_spring(1), fd.Storey(2, 1)],
    )
    ra, rb = a.run(), b.run()
    assert np.array_equal(ra.data, rb.data)
    assert ra.summary["storey_nodes"] == [[1, 0], [2, 1]] == rb.summary["storey_nodes"]
    assert ra.storey_labels == ["ground", "storey 2"]
    assert ra.summary["peak_storey_shear_N"] == rb.summary["peak_storey_shear_N"]


# --- modes ------------------------------------------------------------------------------


def test_modes_of_a_uniform_chain_equal_the_closed_form():
    n = 6
    r = chain(n).run()
    for system in ("stuck", "free"):  # no devices: both are the chain
        modes = r.modes(system)
        assert modes.status == "flexible" and len(modes) == n
        for j in range(n):
            w, phi = chain_mode(n, j + 1)
            assert modes.periods[j] == pytest.approx(2 * np.pi / w, rel=1e-12)
            np.testing.assert_allclose(modes.shapes[j], phi, rtol=0, atol=1e-10)
        assert modes.mass_ratios.sum() == pytest.approx(1.0, rel=1e-12)
    # n_modes limits what is reported
    r = chain(n, output=fd.Output(n_modes=2)).run()
    assert len(r.summary["periods_free_s"]) == 2
    r = chain(n, output=fd.Output(n_modes=0)).run()
    assert r.summary["modes_free_status"] == "not computed" and r.summary["periods_free_s"] == []


def test_a_rigid_stuck_system_is_reported_rigid_not_as_zero_seconds():
    a = chain(2, devices=[fd.Device(i, 0, p=1e6, mu=0.5, law="velocity") for i in (1, 2)])
    s = a.run().summary
    assert s["modes_stuck_status"] == "rigid" and s["periods_stuck_s"] == []
    assert s["period_stuck_s"] is None and s["xi_stuck"] is None  # undefined: null, not 0
    assert s["modes_free_status"] == "flexible" and len(s["periods_free_s"]) == 2
    # a flat slider with nothing to the table: the free system has a rigid-body mode
    b = fd.Analysis(
        masses=[M_FLOOR, M_FLOOR],
        springs=[fd.Spring(2, 1, K_STOREY)],
        isolators=[fd.SlidingIsolator(1, 0, weight=2 * M_FLOOR * G, mu=0.05, law="velocity")],
        excitation=fd.FreeVibration(0.01, 0.1),
    )
    rb = b.run()
    # the summary: null for the rigid-body mode's period and damping ratio (undefined)
    assert rb.summary["periods_free_s"][0] is None and rb.summary["modal_xi_free"][0] is None
    modes = rb.modes("free")
    assert modes.status == "unrestrained" and modes.periods[0] == np.inf
    assert modes.mass_ratios[0] == pytest.approx(1.0, rel=1e-12) and np.isnan(modes.xi[0])


def test_hysteretic_devices_are_their_sticking_springs_in_the_stuck_modes():
    """Stuck, a hysteretic device beside every storey is a spring P mu / f: with P mu / f = k
    the chain has storeys 2k, periods / sqrt(2); the paper's period_stuck_s stays rigid-link."""
    n = 3
    dev = [fd.Device(i + 1, i, p=1e5, mu=1.0, law="hysteretic", f=1e5 / K_STOREY) for i in range(n)]
    s = chain(n, devices=dev).run().summary
    for j in range(n):
        w, _ = chain_mode(n, j + 1)
        assert s["periods_stuck_s"][j] == pytest.approx(2 * np.pi / w / np.sqrt(2), rel=1e-12)
    assert s["period_stuck_s"] is None  # every device a rigid link to the table: rigid, none


# --- Rayleigh damping from modes -------------------------------------------------------


@pytest.mark.parametrize("n", [5, 250])
@pytest.mark.parametrize("i,j,system", [(1, 3, "stuck"), (2, 4, "free"), (1, 1, "stuck")])
def test_rayleigh_from_xi_at_two_modes_gives_xi_there(i, j, system, n):
    """The summary's a0, a1 give xi at modes i and j of the system, checked with numpy's
    eigenvalues of the same M, K (for 'free': a damper building's bare frame). 250 DOFs:
    the modes come from the subspace iteration (no n x n matrix), in the deck reader's
    Rayleigh set-up and in the summary's modes."""
    xi = 0.03
    dev = [fd.Device(3, 2, p=1e5, mu=0.5, law="velocity")] if system == "free" else []
    r = chain(n, devices=dev, damping=fd.Damping.rayleigh_modes(xi, i, j, system)).run()
    s = r.summary
    a0, a1 = s["damping_a0_per_s"], s["damping_a1_s"]
    kmat = K_STOREY * (2 * np.eye(n) - np.eye(n, k=1) - np.eye(n, k=-1))
    kmat[-1, -1] = K_STOREY
    w = np.sqrt(np.linalg.eigvalsh(kmat / M_FLOOR))
    for mode in (i, j):
        assert a0 / (2 * w[mode - 1]) + a1 * w[mode - 1] / 2 == pytest.approx(xi, rel=1e-12)
        assert s[f"modal_xi_{system}"][mode - 1] == pytest.approx(xi, rel=1e-10)
    if i != j:  # between the two modes less damping
        assert all(x < xi for x in s[f"modal_xi_{system}"][i : j - 1])


def test_rayleigh_from_modes_damps_a_free_vibration_at_xi():
    """One mass: xi at mode 1 twice; the free vibration decays by exp(-xi w t) (peaks of the
    history at dt1 = 0.1 ms, 1e-3 relative)."""
    xi, k, m = 0.04, 4e6, 1e3
    a = fd.Analysis(
        masses=[m],
        springs=[fd.Spring(1, 0, k)],
        damping=fd.Damping.rayleigh_modes(xi, 1, 1),
        excitation=fd.FreeVibration(dt_record=1e-3, duration=0.5),
        integration=fd.Integration(n1=10),
        output=fd.Output(output_every=1),
        u0=[0.01],
    )
    r = a.run()
    t, u = r.time, r["u1"]
    peaks = [q for q in range(1, len(u) - 1) if u[q] > u[q - 1] and u[q] >= u[q + 1]]
    w = np.sqrt(k / m)
    ratio = u[peaks[3]] / u[peaks[0]]
    assert ratio == pytest.approx(np.exp(-xi * w * (t[peaks[3]] - t[peaks[0]])), rel=1e-3)


# --- velocity-dependent friction -------------------------------------------------------


def _paper4(device: fd.Device) -> fd.Analysis:
    freq, amp, dtr = TABLE1[4]
    return fd.Analysis(
        masses=[M1, M2],
        springs=[fd.Spring(1, 0, K1), fd.Spring(2, 0, K2)],
        damping=fd.Damping.stiffness(0.015),
        devices=[device],
        excitation=fd.Harmonic(amp, freq, dtr, 3.0),
    )


def test_mu_of_v_with_mu_max_equal_mu_min_is_the_constant_law():
    const = _paper4(fd.Device(1, 2, p=P, mu=MU, law="velocity")).run()
    expo = _paper4(fd.Device.exponential(1, 2, P, MU, MU, 25.0)).run()
    table = _paper4(fd.Device.table(1, 2, P, [(0.0, MU), (0.5, MU)])).run()
    assert const.summary["stick_to_slip"][0] > 10  # it slides
    assert np.array_equal(expo.data, const.data) and np.array_equal(table.data, const.data)


def _slide(device: fd.Device, v0: float, n1: int, duration: float) -> fd.Result:
    """A block of 100 kg sliding on the table from v0, no spring: m v' = -P mu(v) sgn(v)."""
    return fd.Analysis(
        masses=[100.0],
        springs=[],
        devices=[device],
        excitation=fd.FreeVibration(dt_record=0.01, duration=duration),
        integration=fd.Integration(n1=n1),
        output=fd.Output(output_every=1),
        v0=[v0],
    ).run()


def exponential_slide_time(v: np.ndarray, v0: float, mu_max, mu_min, rate) -> np.ndarray:
    """Hand-computed: the time at which the block's velocity is v,
    t(v) = (v0 - v + ln((a - b e^{-r v0}) / (a - b e^{-r v})) / r) / (a g), a = mu_max,
    b = mu_max - mu_min (from dv/dt = -g (a - b e^{-r v}))."""
    a, b, r = mu_max, mu_max - mu_min, rate
    return (v0 - v + np.log((a - b * np.exp(-r * v0)) / (a - b * np.exp(-r * v))) / r) / (a * G)


def test_exponential_mu_reproduces_a_hand_computed_slide():
    """The velocity history of the slide against the closed form t(v), while v > 10 eps.
    mu is taken at the velocity at each step's end (the step iterates its sliding force to
    that velocity), so the error is Newmark's own, second order: measured 1.16e-7 s at
    dt1 = 1 ms, 2.91e-8 s at 0.5 ms (7.3e-9, 1.8e-9 at 0.25, 0.125 ms). mu taken at the
    step's start would give 4.29e-4 s and 2.15e-4 s, first order."""
    v0, mu_max, mu_min, rate = 1.0, 0.12, 0.05, 4.0
    dev = fd.Device.exponential(1, 0, 100.0 * G, mu_max, mu_min, rate, eps=1e-4)
    errors = []
    for n1 in (10, 20):
        r = _slide(dev, v0, n1, 1.2)
        v, t = r["v1"], r.time
        m = v > 1e-3
        t_exact = exponential_slide_time(v[m], v0, mu_max, mu_min, rate)
        errors.append(np.abs(t[m] - t_exact).max())
        stop = exponential_slide_time(np.array([0.0]), v0, mu_max, mu_min, rate)[0]
        assert abs(t[np.argmax(v < 1e-3)] - stop) < 0.01
        # the energy balance closes: the forces at both ends of each step are those of its
        # equilibria
        assert abs(r.summary["energy_residual_J"]) < 1e-10 * 0.5 * 100.0 * v0**2
        assert r.summary["mu_unconverged_steps"] == 0 and r.summary["mu_passes"] > 0
    assert errors[0] < 1.5e-7
    assert 0.22 < errors[1] / errors[0] < 0.28  # second order


def test_table_mu_reproduces_a_hand_computed_slide():
    """mu linear in v between two points, mu = c0 + c1 v:
    v(t) = (v0 + c0/c1) e^{-g c1 t} - c0/c1. Second order (mu at each step's end): measured
    3.54e-10 m/s at dt1 = 0.1 ms, 1.42e-9 at 0.2 ms; mu at the step's start gave 2.17e-5 m/s
    at 0.1 ms."""
    v0, c0, c1 = 0.8, 0.04, 0.1
    dev = fd.Device.table(1, 0, 100.0 * G, [(0.0, c0), (1.0, c0 + c1)], eps=1e-4)
    errors = []
    for n1 in (100, 50):
        r = _slide(dev, v0, n1, 1.5)
        v, t = r["v1"], r.time
        m = v > 1e-3
        exact = (v0 + c0 / c1) * np.exp(-G * c1 * t[m]) - c0 / c1
        errors.append(np.abs(v[m] - exact).max())
        assert r.summary["energy_residual_J"] == pytest.approx(0.0, abs=1e-10 * 0.5 * 100 * v0**2)
    assert errors[0] < 5e-10
    assert 3.6 < errors[1] / errors[0] < 4.4  # second order


def _pull(n1: int, check: bool | None) -> fd.Analysis:
    """A block of 100 kg pulled by a constant table acceleration of -0.3 g over a table
    mu rising steeply from 0.1 at 0.100 m/s to 0.5 at 0.101 m/s (400 s/m), from rest: it
    slides steadily where mu(v) = 0.3, v_s = 0.1005 m/s. At dt1 = 2 ms the fixed point of
    the step's sliding force contracts by rho = P |dmu/dv| gamma h / m = 3.9 > 1 a pass."""
    return fd.Analysis(
        masses=[100.0],
        springs=[],
        devices=[fd.Device.table(1, 0, 100.0 * G, [(0.1, 0.1), (0.101, 0.5)], eps=1e-3)],
        excitation=fd.Record(dt_record=0.01, values=np.full(51, -0.3 * G)),
        integration=fd.Integration(n1=n1, check_correctness=check),
        output=fd.Output(output_every=1),
    )


def test_a_steep_mu_is_refined_until_the_step_converges():
    """Checked (the default), a step whose sliding force cannot converge (rho = 3.9) is
    refined to dt2 (rho = 0.39): the steady velocity is the closed form's to round-off, and
    nothing is left unconverged."""
    r = _pull(5, None).run()
    s, v = r.summary, r["v1"]
    assert s["mu_unconverged_steps"] == 0
    assert s["steps_dt2"] >= 2500  # every dt1 step of the steady slide is refined
    assert np.abs(v[len(v) // 2 :] - 0.1005).max() < 1e-12


def test_an_unconverged_steep_mu_is_reported(run, tmp_path):
    """With check_correctness off no step is refined: the steps whose force did not converge
    hold mu at their start (the explicit lag, which here leaves the slide 1.7e-3 m/s, 1.7 %,
    off v_s), and are counted and reported by the executable and by Python alike."""
    a = _pull(5, False)
    with pytest.warns(fd.FrictiondynWarning, match="could not take a speed-dependent mu") as w:
        r = a.run()
    s, v = r.summary, r["v1"]
    assert s["mu_unconverged_steps"] > 200 and s["mu_unconverged_misfit"] > 0.5
    assert np.abs(v[len(v) // 2 :] - 0.1005).max() > 1e-3  # what the warning is about
    assert f"{s['mu_unconverged_steps']} step(s)" in str(w[0].message)
    text = a.deck_text(tmp_path).replace(str(tmp_path) + "/", "")
    exe = run(text, files={"record.txt": (tmp_path / "record.txt").read_text()})
    assert exe.returncode == 0, exe.stderr
    assert "could not take a speed-dependent mu" in exe.stderr
    assert exe.summary()["mu_unconverged_steps"] == s["mu_unconverged_steps"]


# --- the engineers' devices against their spelled-out decks -----------------------------


def test_friction_braces_equal_the_spelled_out_hysteretic_devices():
    slip, kb = [3.0e5, 2.0e5], [4.0e8, 2.5e8]
    braces = [fd.FrictionBrace(i + 1, i, slip[i], kb[i], eps1=2e-3) for i in range(2)]
    spelled = [
        fd.Device(
            i + 1,
            i,
            p=slip[i],
            mu=1.0,
            law="hysteretic",
            f=slip[i] / kb[i],
            eps1=2e-3,
            label=f"brace {i + 1}",
        )
        for i in range(2)
    ]
    rec = fd.Record(dt_record=0.01, file=str(INPUTS / "synthetic_pga035.AT2"), duration=5.0)
    common = {
        "excitation": rec,
        "storeys": [fd.Storey(1, 0), fd.Storey(2, 1)],
        "damping": fd.Damping.rayleigh_modes(0.02, 1, 2, "free"),
    }
    a = chain(2, braces=braces, **common).run()
    b = chain(2, devices=spelled, **common).run()
    assert a.summary["stick_to_slip"][0] > 0  # the dampers slip
    assert np.array_equal(a.data, b.data)
    skip = {"deck", "deck_sha256", "run_time_s"}
    assert {k: v for k, v in a.summary.items() if k not in skip} == {
        k: v for k, v in b.summary.items() if k not in skip
    }


@pytest.mark.parametrize("radius", [0.0, 2.5])
def test_sliding_isolators_equal_the_spelled_out_device_and_spring(radius):
    w = 3 * M_FLOOR * G
    iso = fd.SlidingIsolator(
        1,
        0,
        weight=w,
        mu=None,
        law="velocity",
        radius=radius,
        eps=1e-3,
        mu_law="exponential",
        mu_max=0.08,
        mu_min=0.04,
        mu_rate=20.0,
    )
    dev = fd.Device.exponential(1, 0, w, 0.08, 0.04, 20.0, eps=1e-3, label="isolator 1")
    frame = [fd.Spring(2, 1, K_STOREY), fd.Spring(3, 2, K_STOREY)]
    spring = [fd.Spring(1, 0, w / radius)] if radius > 0 else []
    rec = fd.Record(dt_record=0.01, file=str(INPUTS / "synthetic_pga035.AT2"), duration=6.0)
    a = chain(3, springs=frame, isolators=[iso], excitation=rec, u0=None).run()
    b = chain(3, springs=frame + spring, devices=[dev], excitation=rec, u0=None).run()
    assert a.summary["stick_to_slip"][0] > 0
    assert np.array_equal(a.data, b.data)
    if radius > 0:  # the pendulum: T = 2 pi sqrt(R / g) for the isolated mass as a rigid body
        assert a.summary["periods_free_s"][0] == pytest.approx(
            2 * np.pi * np.sqrt(radius / G), rel=0.02
        )


# --- provenance --------------------------------------------------------------------------


def test_the_summary_names_the_version_the_deck_and_the_record_with_their_hashes(tmp_path):
    s = fd.run(INPUTS / "building5_bare.nml").summary
    assert s["frictiondyn_version"] == fd.__version__
    deck, record = INPUTS / "building5_bare.nml", INPUTS / "synthetic_pga035.AT2"
    assert s["deck_sha256"] == hashlib.sha256(deck.read_bytes()).hexdigest()
    assert s["record"]["file"] == "synthetic_pga035.AT2"  # as the deck gives it
    assert s["record"]["sha256"] == hashlib.sha256(record.read_bytes()).hexdigest()
    assert s["excitation_type"] == "record" and s["excitation_frequency_Hz"] is None
    # a deck given as text: the hash of the text; the same text written to a file: the same
    a = chain(2)
    text = a.deck_text()
    deck = a.write_deck(tmp_path / "chain.nml")
    assert a.run().summary["deck_sha256"] == hashlib.sha256(text.encode()).hexdigest()
    exe = fd.run_executable(deck, cwd=tmp_path).summary()
    assert exe["deck_sha256"] == hashlib.sha256(deck.read_bytes()).hexdigest()
    assert "record" not in exe


# --- Python conveniences -----------------------------------------------------------------


def test_a_relative_record_file_is_the_callers(tmp_path, monkeypatch):
    (tmp_path / "motions").mkdir()
    (tmp_path / "motions" / "rec.AT2").write_bytes((INPUTS / "synthetic_pga035.AT2").read_bytes())
    monkeypatch.chdir(tmp_path)
    rel = chain(2, excitation=fd.Record(dt_record=0.01, file="motions/rec.AT2", duration=2.0))
    absolute = chain(
        2,
        excitation=fd.Record(
            dt_record=0.01, file=str(INPUTS / "synthetic_pga035.AT2"), duration=2.0
        ),
    )
    assert np.array_equal(rel.run().data, absolute.run().data)
    # the deck written for the executable keeps the path as given (relative to the deck)
    assert "record_file = 'motions/rec.AT2'" in rel.deck_text()


def test_to_dataframe():
    pd = pytest.importorskip("pandas")
    r = building("velocity", duration=1.0).run()
    df = r.to_dataframe()
    assert isinstance(df, pd.DataFrame) and df.index.name == "t"
    assert list(df.columns) == r.names[1:] and np.array_equal(df["u3"].to_numpy(), r["u3"])
    assert np.array_equal(df.index.to_numpy(), r.time)
    assert df.attrs["units"]["V2"] == "N" and df.attrs["labels"]["device"][1] == "damper 2"
    assert list(r.to_dataframe(index=None).columns) == r.names


def test_labels_reach_the_result():
    r = building("velocity", duration=0.5).run()
    assert r.dof_labels == ["floor 1", "floor 2", "floor 3", "roof"]
    assert r.device_labels == [f"damper {i}" for i in range(1, 5)]
    assert r.storey_labels == [f"storey {i}" for i in range(1, 5)]
    assert r.storey(2)["drift"] is not None and len(r.base_shear) == len(r.time)
    plain = chain(2).run()
    assert plain.dof_labels == ["DOF 1", "DOF 2"] and plain.storey_labels == []


# --- bad input for the new variables ----------------------------------------------------


@pytest.mark.parametrize(
    "analysis,words",
    [
        (
            lambda: chain(2, damping=fd.Damping.rayleigh_modes(0.05, 1, 3)),
            ["&damping", "mode_j", "<= 2"],
        ),
        (
            lambda: chain(
                2,
                devices=[
                    fd.Device(
                        1,
                        0,
                        p=1e3,
                        mu=None,
                        law="hysteretic",
                        mu_law="exponential",
                        mu_max=0.1,
                        mu_min=0.05,
                        mu_rate=5.0,
                    )
                ],
            ),
            ["&friction", "mu_law(1)", "velocity law only"],
        ),
        (
            lambda: chain(2, devices=[fd.Device(1, 0, p=1e3, mu=0.1, law="velocity", mu_min=0.05)]),
            ["&friction", "mu_min(1)", "mu_law(1) = 'exponential'"],
        ),
        (
            lambda: chain(2, devices=[fd.Device.table(1, 0, 1e3, [(0.2, 0.1), (0.1, 0.2)])]),
            ["&friction", "mu_table_v(2, 1)", "increase"],
        ),
        (
            lambda: chain(
                2,
                braces=[fd.FrictionBrace(1, 0, 1e3, 1e6)],
                integration=fd.Integration(technique="event_driven"),
            ),
            ["&braces", "brace 1", "technique = 'newmark'"],
        ),
        (
            lambda: chain(
                2,
                braces=[fd.FrictionBrace(1, 0, 1e3, 1e6)],
                integration=fd.Integration(technique="moreau_jean"),
            ),
            ["&braces", "brace 1", "technique = 'moreau_jean'", "technique = 'newmark'"],
        ),
        (
            lambda: chain(
                2,
                devices=[fd.Device.exponential(1, 0, 1e3, 0.1, 0.05, 5.0)],
                integration=fd.Integration(technique="moreau_jean"),
            ),
            ["&friction", "law(1)", "moreau_jean"],
        ),
        (
            lambda: chain(
                2,
                devices=[
                    fd.Device(
                        1,
                        0,
                        p=1e3,
                        mu=None,
                        law="coulomb",
                        mu_law="exponential",
                        mu_max=0.1,
                        mu_min=0.05,
                        mu_rate=5.0,
                    )
                ],
                integration=fd.Integration(technique="moreau_jean"),
            ),
            ["&friction", "mu_law(1)", "velocity law only"],
        ),
        (
            lambda: chain(
                2, isolators=[fd.SlidingIsolator(1, 0, 1e3, 0.1, "velocity", radius=-2.0)]
            ),
            ["&isolators", "radius(1)", "-2"],
        ),
        (lambda: chain(2, storeys=[fd.Storey(2, 2)]), ["&storeys", "node_j(1)", "= 2 "]),
        (lambda: chain(2, labels=["a", "b", "c"]), ["&model", "label(3)"]),
    ],
    ids=[
        "mode beyond the system",
        "mu(v) not velocity law",
        "forgotten mu_law",
        "table order",
        "brace exact technique",
        "brace moreau_jean",
        "mu(v) velocity law under moreau_jean",
        "mu(v) coulomb under moreau_jean",
        "negative radius",
        "storey on one node",
        "too many labels",
    ],
)
def test_bad_engineering_input_is_named(analysis, words):
    with pytest.raises(fd.DeckError) as exc:
        analysis().run()
    for w in words:
        assert w in str(exc.value), str(exc.value)


def _deck_with(extra: str, *, devices: bool = False) -> str:
    """The deck of a 2-floor chain with groups added (a velocity-law device at the roof)."""
    text = chain(2).deck_text()
    if devices:
        text += (
            "\n&friction\n  n_devices = 1, node_i = 2, node_j = 1, law = 'velocity',"
            " p = 1e3, mu = 0.1\n/\n"
        )
    return text + "\n" + extra + "\n"


@pytest.mark.parametrize(
    "extra,devices,words",
    [
        (
            "&storeys\n  n_storeys = 1, node_i = 1, node_j = 0, height = 1e-31\n/",
            False,
            ["&storeys", "height(1)", "at least"],
        ),
        (
            (
                "&isolators\n  n_isolators = 1, node_i = 1, node_j = 0, law = 'velocity',"
                " weight = 1e3, mu = 0.1, radius = 1e-29\n/"
            ),
            False,
            ["&isolators", "weight(1) / radius(1)", "at most"],
        ),
        (
            (
                "&isolators\n  n_isolators = 1, node_i = 1, node_j = 0, law = 'velocity',"
                " weight = 1e-20, mu = 1e-20\n/"
            ),
            False,
            ["&isolators", "weight(1) * mu(1)", "at least"],
        ),
        (
            (
                "&braces\n  n_braces = 1, node_i = 1, node_j = 0, slip_load = 1e-20,"
                " stiffness = 1e20\n/"
            ),
            False,
            ["&braces", "slip_load(1) / stiffness(1)", "at least"],
        ),
        (
            "&braces\n  n_braces = 1, node_i = 1, node_j = 0, slip_load = 1e31, stiffness = 1e6\n/",
            False,
            ["&braces", "slip_load(1)", "at most"],
        ),
        (
            "&storeys\n  n_storeys = 1, node_i = 1, node_j = 0, label = '" + "x" * 32 + "'\n/",
            False,
            ["&storeys", "label", "32 characters", "at most 31"],
        ),
        (
            "&storeys\n  n_storeys = 1, node_i = 1, node_j = 0\n  label = 'a'\n  label = 'b'\n/",
            False,
            ["&storeys", "'label'", "assigned again"],
        ),
        (
            "&output\n  n_modes = -1\n/",
            False,
            ["&output", "n_modes", "-1"],
        ),
    ],
    ids=[
        "tiny storey height",
        "isolator stiffness W/R too large",
        "isolator W mu too small",
        "brace f too small",
        "brace slip load too large",
        "label too long",
        "label given twice",
        "negative n_modes",
    ],
)
def test_limits_of_the_engineering_groups_are_checked_up_front(extra, devices, words):
    """The deck's magnitude limits, string capacities and single assignment hold for the
    variables of &storeys, &braces, &isolators and the labels too, and for what they derive
    (a brace's f, an isolator's W / R and W mu): a message naming the group, the variable
    and the value, before any run."""
    with pytest.raises(fd.DeckError) as exc:
        fd.run_text(_deck_with(extra, devices=devices), "limits.nml")
    for w in words:
        assert w in str(exc.value), str(exc.value)


def test_mu_of_v_and_rayleigh_from_modes_are_held_to_the_limits():
    """mu(v) parameters and the a0, a1 found from xi at two modes obey the magnitude limits."""
    text = chain(2).deck_text() + (
        "\n&friction\n  n_devices = 1, node_i = 2, node_j = 1, law = 'velocity', p = 1e3,"
        " mu_law = 'exponential', mu_max = 1e31, mu_min = 0.05, mu_rate = 5.0\n/\n"
    )
    with pytest.raises(fd.DeckError, match=r"&friction: mu_max\(1\) = .* at most"):
        fd.run_text(text, "mu.nml")
    text = chain(2).deck_text() + (
        "\n&friction\n  n_devices = 1, node_i = 2, node_j = 1, law = 'velocity', p = 1e3,"
        " mu_law = '" + "e" * 33 + "'\n/\n"
    )
    with pytest.raises(fd.DeckError, match=r"&friction, line \d+: mu_law is a string of 33"):
        fd.run_text(text, "mu.nml")
    # a stiff, light chain: w ~ 1e17 rad/s, a0 = xi w ~ 1e16 is within the limits and runs
    light = fd.Analysis(
        masses=[1e-20, 1e-20],
        springs=[fd.Spring(1, 0, 1e14), fd.Spring(2, 1, 1e14)],
        damping=fd.Damping.rayleigh_modes(0.05, 1, 2),
        excitation=fd.FreeVibration(dt_record=1e-18, duration=1e-17),
        u0=[1e-3, 2e-3],
    )
    s = light.run().summary
    w = 2 * np.pi / np.array(s["periods_stuck_s"])
    assert s["damping_a0_per_s"] == pytest.approx(2 * 0.05 * w[0] * w[1] / (w[0] + w[1]), rel=1e-9)


# --- worked examples --------------------------------------------------------------------


@pytest.mark.parametrize("script", ["building5.py", "isolated.py"])
def test_worked_examples_run_from_python_equal_their_decks(script, tmp_path):
    """Each example builds its model in Python, asserts the same numbers as its deck in
    inputs/, prints the design figures and writes its figures."""
    proc = subprocess.run(
        [sys.executable, str(ROOT / "examples" / script), str(tmp_path)],
        capture_output=True,
        text=True,
        timeout=300,
        env={**os.environ, "MPLBACKEND": "Agg"},
        check=False,
    )
    assert proc.returncode == 0, proc.stderr
    pngs = sorted(tmp_path.glob("*.png"))
    assert pngs and all(p.stat().st_size > 10000 for p in pngs)
    assert "peak drift ratio" in proc.stdout
