"""The Moreau-Jean technique (technique = 'moreau_jean'): exact Coulomb impulses
by nonsmooth time stepping. Checked against closed forms (Den Hartog's non-stop motion, a
block stopping on the table), the exact event-driven technique, the velocity law as eps
shrinks, the paper's Table 1, and cases of simultaneous events (identical devices in
parallel, symmetric structures, proportional slip loads). Tolerances are stated here with
the measured values beside them."""

from __future__ import annotations

import numpy as np
import pytest
import studies as v  # tools/validation (conftest puts it on the path)
from conftest import G
from frictiondyn import DeckError
from frictiondyn.model import Analysis, Device, FreeVibration, Integration, Output, Spring
from frictiondyn.paper import PAPER_OBSERVATION, TABLE1, steady_state


def mj(an: Analysis, theta: float | None = None) -> Analysis:
    an.integration.technique = "moreau_jean"
    an.integration.theta = theta
    return an


@pytest.mark.parametrize("test", sorted(TABLE1))
def test_table1_classification(test):
    """The paper's observation (no sliding in tests 1, 2, 5; stick-slip in every cycle of 3
    and 4), by the package's classifier on the Moreau-Jean run at the decks' n1 = 20."""
    r = v.mj_analysis(test).run()
    assert steady_state(r, test).classification == PAPER_OBSERVATION[test]
    assert r.summary["lcp_fallbacks"] == 0


@pytest.mark.parametrize("theta, order", [(1.0, (0.9, 1.1)), (0.5, (0.85, 1.3))])
def test_den_hartog_first_order(theta, order):
    """Errors against Den Hartog's non-stop solution fall at first order in dt1 (least
    squares over n1 = 21, 43, 87; measured 1.04 for theta = 1, 1.16 for theta = 1/2, whose
    errors are 6 times smaller)."""
    rows = v.mj_den_hartog(n1_values=(21, 43, 87), thetas=(theta,))
    dt = [r["dt"] for r in rows]
    u = [r["u_error"] for r in rows]
    assert np.all(np.diff(u) < 0)
    assert order[0] < v.observed_order(dt, u) < order[1]
    assert u[-1] < (1.5e-3 if theta == 1.0 else 2e-4)  # measured 8.7e-4 and 1.2e-4 at n1 = 87


def test_convergence_to_the_exact_technique_on_test4():
    """20 s of test 4 at n1 = 10 and 40: steady peaks, u history and friction dissipation
    approach the exact technique's (measured with theta = 1/2: peaks 1.3e-4 -> 8.5e-6, u
    1.3e-4 -> 8.4e-6: second order, the events being velocity zeros; friction 1.6e-6 at n1 = 40;
    theta = 1: first order, 5.0e-2 -> 1.25e-2)."""
    sweeps = v.mj_convergence(test=4, n1_values=(10, 40), duration=20.0)
    half, one = sweeps
    assert half.peak_error[1] < half.peak_error[0] / 8 and half.peak_error[1] < 3e-5
    assert half.u_error[1] < half.u_error[0] / 8
    assert 3.0 < one.peak_error[0] / one.peak_error[1] < 5.0  # first order: 4 for dt / 4
    assert half.friction_error[1] < 1e-4 and one.friction_error[1] < one.friction_error[0]
    # the same transitions as the exact technique (a reversal through zero counts as one)
    assert half.transitions == half.exact_transitions


def test_block_stops_without_chattering():
    """A block thrown at v0 on the table decelerates at mu g and stops at v0 / (mu g): it
    stops within the step that contains that instant, then stays at rest exactly (v = 0, one
    transition, no chattering); with theta = 1/2 the slide is exact (constant deceleration)
    and friction dissipates exactly the kinetic energy."""
    mu, v0, m, h = 0.3, 0.5, 2.0, 1e-3
    an = Analysis(
        masses=[m],
        springs=[],
        v0=[v0],
        devices=[Device(1, 0, m * G, mu, law="coulomb")],
        excitation=FreeVibration(dt_record=0.01, duration=0.4),
        integration=Integration(technique="moreau_jean", n1=10),
        output=Output(output_every=1),
    )
    r = an.run()
    s = r.summary
    t_stop, d = v0 / (mu * G), v0**2 / (2 * mu * G)
    slide = r.time < t_stop - h
    assert np.allclose(r["v1"][slide], v0 - mu * G * r.time[slide], rtol=0, atol=1e-14)
    assert np.allclose(
        r["u1"][slide], v0 * r.time[slide] - 0.5 * mu * G * r.time[slide] ** 2, rtol=1e-12
    )
    after = r.time > t_stop + h
    assert np.all(r["v1"][after] == 0.0) and np.all(r["phase1"][after] == 0)
    assert abs(r["u1"][-1] - d) < mu * G * h**2  # the last, partial step (measured 1.3e-7 m)
    assert s["slip_to_stick"] == [1] and s["stick_to_slip"] == [0] and s["slip_reversals"] == [0]
    assert s["energy_friction_J"] == pytest.approx(0.5 * m * v0**2, rel=1e-12)


def _split_device(an: Analysis, parts: int) -> Analysis:
    d = an.devices[0]
    an.devices = [
        Device(d.node_i, d.node_j, d.p / parts, d.mu, law="coulomb") for _ in range(parts)
    ]
    return an


@pytest.mark.parametrize("parts", [2, 3])
def test_identical_devices_in_parallel(parts):
    """Test 4 with its device split into identical devices in parallel (redundant: only
    their sum is determined) runs as the single device: same histories to round-off, each
    device carrying its share; the exact technique needs a least-squares split for this."""
    one = v.mj_analysis(4, duration=10.0, output_every=20).run()
    many = _split_device(v.mj_analysis(4, duration=10.0, output_every=20), parts).run()
    for q in ("u1", "u2", "v1", "aabs1", "aabs2"):
        assert np.max(np.abs(many[q] - one[q])) <= 1e-12 * np.max(np.abs(one[q])), q
    for k in range(1, parts + 1):
        assert np.allclose(
            many[f"F{k}"], one["F1"] / parts, rtol=1e-12, atol=1e-12 * np.max(np.abs(one["F1"]))
        )
        assert np.array_equal(many[f"phase{k}"], one["phase1"])
    s1, sn = one.summary, many.summary
    assert sn["stick_to_slip"] == s1["stick_to_slip"] * parts
    assert sn["energy_friction_J"] == pytest.approx(s1["energy_friction_J"], rel=1e-12)


def _twin_towers(n: int, duration: float) -> tuple[Analysis, Analysis]:
    """One building of n storeys, and two identical copies of it side by side on the table."""
    one = v.building(n, duration=duration, output_every=10)
    two = v.building(n, duration=duration, output_every=10)
    two.masses = one.masses * 2
    two.springs = one.springs + [
        Spring(s.node_i + n, s.node_j + n if s.node_j else 0, s.k) for s in one.springs
    ]
    two.devices = one.devices + [
        Device(d.node_i + n, d.node_j + n if d.node_j else 0, d.p, d.mu, law="coulomb")
        for d in one.devices
    ]
    return one, two


def test_symmetric_structure():
    """Two identical 5-storey buildings on the table under the record (every event happens
    twice at once, in towers that do not see each other): each tower moves as the building
    alone, to round-off, with the same transitions."""
    one, two = _twin_towers(5, 10.0)
    r1, r2 = one.run(), two.run()
    for i in range(1, 6):
        for q in ("u", "aabs"):
            a, b, c = r2[f"{q}{i}"], r2[f"{q}{i + 5}"], r1[f"{q}{i}"]
            scale = np.max(np.abs(c))
            assert np.max(np.abs(a - b)) <= 1e-12 * scale and np.max(np.abs(a - c)) <= 1e-10 * scale
    s1, s2 = r1.summary, r2.summary
    assert s2["stick_to_slip"] == s1["stick_to_slip"] * 2
    assert s2["energy_friction_J"] == pytest.approx(2 * s1["energy_friction_J"], rel=1e-10)


def test_proportional_slip_loads_5_storeys_against_the_exact_technique():
    """5 storeys, slip loads proportional to the weight carried, 10 s of harmonic table
    motion, both techniques on the grid n1 = 40: peaks within 2e-4 (measured 6.3e-5), floor
    displacements within 5e-4 of their peak (measured 1.4e-4), transitions within 3 %."""
    rows = v.mj_buildings_exact(storeys=(5,), n1_values=(40,), harmonic=True)
    (r,) = rows
    assert not r["exact_failure"]
    assert r["peak_difference"] < 2e-4 and r["u_history"] < 5e-4
    assert abs(r["transitions"] - r["exact_transitions"]) <= 0.03 * r["exact_transitions"]
    assert r["friction"] == pytest.approx(r["exact_friction"], rel=1e-3)


def test_proportional_slip_loads_under_the_record_against_the_exact_technique():
    """Under the record every storey starts and stops sliding at the same instants. The
    velocity law approaches Moreau-Jean as eps shrinks (first order: measured 1.2e-1, 1.7e-2,
    1.8e-3 on 5 storeys; 4.5e-1, 3.5e-2, 7.1e-3 on 20). The event-driven technique runs
    (its phase decision solves the LCP of every event, so accumulating events do not stop
    it), and Moreau-Jean converges to it as the step shrinks: peak
    differences 7.0e-4, 3.4e-4, 1.2e-4, 8.9e-5 for n1 = 10, 20, 40, 80, the same 428
    transitions from n1 = 40 on, friction work within 1e-4 (measured 7.4e-5)."""
    for n, last in ((5, 4e-3), (20, 1.5e-2)):
        rows = v.mj_buildings_velocity(storeys=(n,), eps_values=(1e-2, 1e-3, 1e-4))
        diff = [r["peak_difference"] for r in rows]
        assert np.all(np.diff(diff) < 0) and diff[-1] < last, (n, diff)
        assert v.observed_order([1e-2, 1e-3, 1e-4], diff) > 0.8
    rows = v.mj_buildings_exact(storeys=(5,), n1_values=(10, 20, 40, 80))
    assert not any(r["exact_failure"] for r in rows)
    diff = [r["peak_difference"] for r in rows]
    assert np.all(np.diff(diff) < 0) and diff[2] < 2e-4, diff
    for r in rows[2:]:
        assert r["transitions"] == r["exact_transitions"]
        assert r["friction"] == pytest.approx(r["exact_friction"], rel=1e-4)


@pytest.mark.parametrize("n", [5, 20])
def test_proportional_slip_loads_energy_and_no_fallback(n):
    """Simultaneous stops and starts of every storey are resolved by the active set, not by
    Lemke's fallback, and the energy balance closes to round-off (theta = 1/2)."""
    s = v.building(n, duration=10.0, output_every=1000).run().summary
    assert s["lcp_fallbacks"] == 0
    assert abs(s["energy_residual_J"]) < 1e-11 * s["energy_input_J"]  # measured 1e-14
    assert s["energy_friction_J"] > 0.5 * s["energy_input_J"]


def test_energy_balance_and_theta():
    """Test 4, 20 s: with theta = 1/2 the balance input = kinetic + strain + viscous + friction
    closes to round-off (measured 2e-14 of the input) and friction dissipation is the exact
    technique's within 1e-4 (measured 1.8e-5 at n1 = 20); with theta = 1 the residual is the
    method's numerical dissipation: positive, and it shrinks with the step (measured 2.4 % of
    the input at n1 = 20, 0.6 % at n1 = 80)."""
    ex = v.analysis(4, "coulomb", duration=20.0, output_every=100).run().summary
    half = v.mj_analysis(4, duration=20.0, output_every=100).run().summary
    assert abs(half["energy_residual_J"]) < 1e-11 * half["energy_input_J"]
    assert half["energy_friction_J"] == pytest.approx(ex["energy_friction_J"], rel=1e-4)
    res = []
    for n1 in (20, 80):
        s = v.mj_analysis(4, n1=n1, theta=1.0, duration=20.0, output_every=100).run().summary
        res.append(s["energy_residual_J"] / s["energy_input_J"])
    assert res[0] > res[1] > 0


def test_input_errors():
    """theta outside [1/2, 1] and a regularized law under 'moreau_jean' are refused with the
    group, the variable and the value."""
    with pytest.raises(DeckError, match=r"(?s)integration.*theta.*0\.4"):
        v.mj_analysis(4, theta=0.4, duration=1.0).run()
    an = mj(v.analysis(4, "velocity", duration=1.0))
    with pytest.raises(DeckError, match=r"(?s)law\(1\) = 'velocity'.*moreau_jean.*'coulomb'"):
        an.run()
