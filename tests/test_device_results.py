"""Per-device results: each friction device's dissipated energy, slip travel and slip
excursions (with its peak force and residual slip), in the summary, the Python Result and
the sweep's tables; checked against the energy balance's total under every technique, a
closed form and the history's phases."""

from __future__ import annotations

import numpy as np
import pytest
from conftest import INPUTS, G, block, ok, paper_groups

import frictiondyn


def _building(law: str, technique: str | None, duration: float = 3.0) -> str:
    """inputs/building5_friction.nml's model (five storeys, a damper in each) for `duration`
    seconds of its record, with its devices of `law` and that technique."""
    text = (INPUTS / "building5_friction.nml").read_text()
    text = text.replace("law = 5*'hysteretic'", f"law = 5*'{law}'")
    text = text.replace("record_file = 'synthetic_pga035.AT2'",
                        f"record_file = '{INPUTS / 'synthetic_pga035.AT2'}'\n  duration = {duration}")
    if technique:
        text = text.replace("&integration", f"&integration\n  technique = '{technique}'")
    return text


CASES = {
    "newmark hysteretic": ("hysteretic", None),
    "newmark velocity": ("velocity", None),
    "event_driven": ("coulomb", "event_driven"),
    "moreau_jean": ("coulomb", "moreau_jean"),
}


@pytest.mark.parametrize("case", CASES)
def test_the_devices_energies_sum_to_the_total(case):
    """Five dampers under a record: each device's dissipated energy is positive, and they sum
    to energy_friction_J to 1e-12 of it (measured: below 3e-15) under every technique."""
    law, technique = CASES[case]
    r = frictiondyn.run_text(_building(law, technique))
    s = r.summary
    e = np.array(s["dissipated_energy_J"])
    assert len(e) == 5 and np.all(e > 0.0)
    assert abs(e.sum() - s["energy_friction_J"]) <= 1e-12 * abs(s["energy_friction_J"])
    travel = np.array(s["slip_travel_m"])
    assert np.all(travel > 0.0)
    if law == "coulomb":
        # an exact Coulomb device dissipates P mu over each metre it slides: under the exact
        # technique to round-off; Moreau-Jean takes the step's mean force over the step
        pmu = np.array([2369940.4, 1879608.0, 1389275.4, 898942.9, 408610.4]) * 0.3
        tol = 1e-12 if technique == "event_driven" else 2e-3
        assert np.allclose(e, pmu * travel, rtol=tol, atol=0.0)


def test_devices_in_parallel_share_their_edges_work():
    """Moreau-Jean joins devices between the same two nodes into one edge: each device's
    share of its work is its P mu over theirs, and the shares sum to the total."""
    g = paper_groups(4, "coulomb")
    g["friction"].update({"n_devices": 2, "node_i": [1, 2], "node_j": [2, 1], "p": [P1, P2], "law": ["coulomb"] * 2,
                          "mu": [0.22, 0.22]})
    g["integration"] = {"technique": "moreau_jean", "n1": 20}
    g["excitation"]["duration"] = 4.0
    r = frictiondyn.run_text(_text(g))
    s = r.summary
    e = np.array(s["dissipated_energy_J"])
    assert abs(e.sum() - s["energy_friction_J"]) <= 1e-12 * s["energy_friction_J"]
    assert e[0] / e[1] == pytest.approx(P1 / P2, rel=1e-12)
    assert s["slip_travel_m"][0] == s["slip_travel_m"][1] > 0.0


P1, P2 = 40.0, 21.81  # N: the paper's P = 61.81 N in two devices


def _text(groups: dict) -> str:
    from conftest import deck_text

    return deck_text(groups)


def _pulse_slide(a: float, mu: float, dt: float, k: int) -> float:
    """Where a block from rest on a Coulomb interface (mu) comes to rest when the table
    accelerates at -a (a > mu g) for k samples of a record at dt, then stops (the record
    is linear between its samples: a ramp from -a to 0 over the (k+1)-th interval)."""
    b = a - mu * G
    t1 = k * dt
    v1, x1 = b * t1, 0.5 * b * t1**2
    # the ramp: u'' = a (1 - tau / dt) - mu g
    v2 = v1 + b * dt - 0.5 * a * dt
    x2 = x1 + v1 * dt + 0.5 * b * dt**2 - a * dt**2 / 6.0
    assert v2 > 0.0
    return x2 + v2**2 / (2 * mu * G)


@pytest.mark.parametrize("technique", ["event_driven", "moreau_jean"])
def test_a_block_pushed_one_way_slides_its_displacement(run, technique):
    """A block (2 kg, mu 0.3) at rest on the table, which accelerates at 5 m/s2 for 0.2 s and
    stops: the block slides one way and comes to rest at the closed form's distance. Its slip
    travel is its displacement, and its dissipated energy P mu times the travel (the exact
    technique to round-off; Moreau-Jean, first order, reaches the closed form's distance
    within its step, but travel and energy keep their relation)."""
    a, mu, m, dt, k = 5.0, 0.3, 2.0, 0.01, 20
    record = "\n".join([str(-a)] * (k + 1) + ["0.0"] * 49) + "\n"
    excitation = {"excitation_type": "record", "record_file": "pulse.txt", "record_format": "values",
                  "record_units": "m/s2", "dt_record": dt, "duration": 0.6}
    g = block("coulomb", mu, m, excitation, n1=10)
    g["integration"]["technique"] = technique
    r = ok(run(g, files={"pulse.txt": record}))
    h, s = r.history(), r.summary()
    x = _pulse_slide(a, mu, dt, k)
    u_end = h["u1"][-1]
    travel, energy = s["slip_travel_m"][0], s["dissipated_energy_J"][0]
    assert np.all(np.diff(h["u1"]) >= 0.0)  # one way
    assert travel == pytest.approx(u_end, rel=1e-12)
    pmu = m * G * mu
    if technique == "event_driven":
        assert energy == pytest.approx(pmu * travel, rel=1e-12)
    else:  # the step it stops in takes less than P mu h of impulse over its du
        du = np.diff(h["u1"])
        assert 0.0 <= pmu * travel - energy <= pmu * du[du > 0][-1]
    # it slides from t = 0 (5 m/s2 exceed mu g at once): one excursion, no stick before it
    assert s["slip_excursions"] == [1] and s["stick_to_slip"] == [0] and s["slip_to_stick"] == [1]
    if technique == "event_driven":
        assert u_end == pytest.approx(x, rel=1e-12)
    else:
        assert u_end == pytest.approx(x, rel=2e-2)


def _slip_phases(phase: np.ndarray) -> int:
    """Slip phases seen in a history's phase column: runs of rows with phase != 0."""
    sliding = phase != 0
    return int(sliding[0]) + int(np.count_nonzero(sliding[1:] & ~sliding[:-1]))


@pytest.mark.parametrize("law", ["coulomb", "hysteretic"])
def test_slip_excursions_are_the_slip_phases_of_the_history(law):
    """The paper's test 4 (harmonic, stick-slip, two slides in most cycles) for 5 s, every
    dt1 step in the history: the device's slip excursions are the slip phases its phase
    column shows."""
    g = paper_groups(4, law)
    g["excitation"]["duration"] = 5.0
    g["output"] = {"output_every": 1}
    r = frictiondyn.run_text(_text(g))
    n = r.device_results().slip_excursions[0]
    assert n == _slip_phases(r["phase1"])
    assert n >= 1.5 * 5.0 * 4.104  # it slides both ways in most of the 20.5 cycles


def test_the_result_gives_each_devices_results():
    """Result.device_results(): the summary's per-device values, labelled, one row each."""
    r = frictiondyn.run_text(_building("hysteretic", None, 1.0))
    d = r.device_results()
    s = r.summary
    assert len(d) == 5 and d.labels == r.device_labels
    assert list(d.dissipated_energy) == s["dissipated_energy_J"]
    assert list(d.slip_travel) == s["slip_travel_m"]
    assert list(d.slip_excursions) == s["slip_excursions"]
    assert list(d.peak_force) == s["peak_force_N"]
    assert list(d.residual_slip) == s["residual_s_m"]
    rows = d.rows()
    assert rows[2]["device"] == 3 and rows[2]["dissipated_energy_J"] == s["dissipated_energy_J"][2]
