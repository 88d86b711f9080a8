"""Property-based tests of the Python API (hypothesis): any valid model the strategy draws
runs, balances its energy within the technique's tolerance, gives the same result twice, and
the same result through both interfaces (the extension and the executable).

The strategy draws 1 to 4 masses tied to the table by a chain of springs (so that no model
has a rigid-body mode), up to two more springs, 0 to 3 friction devices of one technique's
laws ('velocity' and 'hysteretic' for Newmark, 'coulomb' for the exact technique), any of
the three damping types ('stiffness' with its period given: the stuck system of a drawn model
may have no free DOF), and a harmonic, recorded or absent table motion (then initial
conditions), for a fraction of a second. Valid means what docs/namelist.md says: in
particular a Newmark device's band is drawn at least four times P mu dt_min / m (section
"Limits of the step control"; a narrower one is an error once its device slides), and P mu
is 0 or at least 1e-30 N ("Magnitudes").

Tolerances of the energy balance, relative to the energy in play (the magnitudes of its terms
and the energy at t = 0): Newmark's average acceleration (beta = 1/4, gamma = 1/2, the
default drawn here) closes it algebraically, to round-off: 1e-9 (tests/test_friction.py
measures 1e-13 on the paper's decks); the exact technique integrates input and viscous work
by 3-point Gauss-Legendre, to the quadrature's error bound (energy_rtol; 1e-12 on the paper's
test 4, 1.0e-9 measured on a stiff, heavily damped drawn model). Plus 1e-24 J for models
that hardly move (a denormal initial velocity: the terms are themselves round-off, 1e-32 J).

Known limitation, left out of the strategy and reported: Coulomb devices that close a loop
(two joining the same two nodes; devices 1-0, 2-0 and 1-2) make the exact technique stop
with "events accumulate (stick-slip chattering)".
"""

from __future__ import annotations

import math
import os

import frictiondyn as fd
import numpy as np
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

ENERGY_TERMS = ("energy_input_J", "energy_kinetic_J", "energy_strain_J", "energy_viscous_J",
                "energy_friction_J", "energy_device_elastic_J")
ENERGY_RTOL = 1e-9
ENERGY_FLOOR = 1e-24  # J: the largest drawn force, 100 N, over 1e-26 m (below round-off)

finite = {"allow_nan": False, "allow_infinity": False}


@st.composite
def analyses(draw) -> fd.Analysis:
    n = draw(st.integers(1, 4))
    masses = [draw(st.floats(0.5, 50.0, **finite)) for _ in range(n)]
    springs = [fd.Spring(i, i - 1, draw(st.floats(100.0, 1.0e5, **finite))) for i in range(1, n + 1)]
    for _ in range(draw(st.integers(0, 2))):
        a, b = draw(st.integers(1, n)), draw(st.integers(0, n))
        if a != b:
            springs.append(fd.Spring(a, b, draw(st.floats(100.0, 1.0e5, **finite))))
    exact = draw(st.booleans())
    dt_record = draw(st.sampled_from([0.005, 0.01]))
    n1 = draw(st.integers(5, 40))
    n2 = draw(st.integers(5, 50))
    dt_min = dt_record / n1 / n2 / 2**10
    devices = []
    for _ in range(draw(st.integers(0, 3))):
        i = draw(st.integers(1, n))
        j = draw(st.integers(0, n).filter(lambda x: x != i))
        if exact and joined(devices, i, j):
            continue  # known: a loop of Coulomb devices chatters in the exact technique (reported)
        p = draw(st.floats(0.0, 200.0, **finite))
        mu = draw(st.floats(0.0, 0.5, **finite))
        if 0 < p * mu < 1e-30:  # P mu is 0 or at least 1e-30 N (docs/namelist.md)
            mu = 0.0
        if exact:
            devices.append(fd.Device(i, j, p=p, mu=mu, law="coulomb"))
            continue
        moved = masses[i - 1] if j == 0 else masses[i - 1] * masses[j - 1] / (masses[i - 1] + masses[j - 1])
        floor = 4 * p * mu * dt_min / moved
        law = draw(st.sampled_from(["velocity", "hysteretic"]))
        band = max(draw(st.floats(1e-4, 1e-2, **finite)), floor)
        if law == "velocity":
            devices.append(fd.Device(i, j, p=p, mu=mu, law=law, eps=band))
        else:
            f = draw(st.floats(1e-6, 1e-4, **finite))
            devices.append(fd.Device(i, j, p=p, mu=mu, law=law, eps1=band, f=f))
    damping = draw(st.sampled_from(["none", "stiffness", "rayleigh"]))
    if damping == "stiffness":
        damping = fd.Damping.stiffness(draw(st.floats(0.0, 0.1, **finite)),
                                       period=draw(st.floats(0.05, 2.0, **finite)))
    elif damping == "rayleigh":
        damping = fd.Damping.rayleigh(draw(st.floats(0.0, 1.0, **finite)),
                                      draw(st.floats(0.0, 1e-3, **finite)))
    else:
        damping = fd.Damping()
    duration = draw(st.floats(0.1, 0.6, **finite))
    motion = draw(st.sampled_from(["harmonic", "record", "none"]))
    u0 = v0 = None
    if motion == "harmonic":
        excitation = fd.Harmonic(draw(st.floats(0.0, 0.01, **finite)),
                                 draw(st.floats(0.5, 8.0, **finite)), dt_record, duration,
                                 ramp_cycles=draw(st.integers(0, 2)))
    elif motion == "record":
        samples = int(duration / dt_record) + 2
        values = [draw(st.floats(-5.0, 5.0, **finite)) for _ in range(min(samples, 8))]
        acc = np.interp(np.linspace(0, len(values) - 1, samples), np.arange(len(values)), values)
        excitation = fd.Record(dt_record, values=acc)
    else:
        excitation = fd.FreeVibration(dt_record, duration)
        u0 = [draw(st.floats(-0.01, 0.01, **finite)) for _ in range(n)]
        v0 = [draw(st.floats(-0.2, 0.2, **finite)) for _ in range(n)]
    integration = fd.Integration(technique="event_driven" if exact else None, n1=n1,
                                 n2=None if exact else n2,
                                 refinement=None if exact else draw(st.sampled_from([None, "nested"])))
    return fd.Analysis(masses=masses, springs=springs, excitation=excitation, damping=damping,
                       devices=devices, integration=integration,
                       output=fd.Output(output_every=1), u0=u0, v0=v0)


def joined(devices, i: int, j: int) -> bool:
    """Nodes i and j already joined by a path of devices (node 0 the table)."""
    reach, frontier = {i}, [i]
    while frontier:
        a = frontier.pop()
        for d in devices:
            for x, y in ((d.node_i, d.node_j), (d.node_j, d.node_i)):
                if x == a and y not in reach:
                    reach.add(y)
                    frontier.append(y)
    return j in reach


def energy_rtol(a: fd.Analysis) -> float:
    """The technique's tolerance on the energy balance, relative to the energy in play.
    Newmark's average acceleration closes it algebraically: round-off, ENERGY_RTOL. The exact
    technique integrates input and viscous work by 3-point Gauss-Legendre over each step h
    (docs/theory.md, section 9): an error of h**7 f(6) / 2016000 a step for an integrand
    of frequency 2 w (a product of two motions of frequency w), i.e. (2 w h)**6 / 2016000 of
    its size, summed over the steps; w is bounded by Gershgorin's circles of M^-1 (K + C d/dt),
    taken here with the springs (damping only adds decay). A factor 10 covers the constant."""
    if not a.integration.technique:
        return ENERGY_RTOL
    n = len(a.masses)
    row = [0.0] * (n + 1)
    for sp in a.springs:
        for node in (sp.node_i, sp.node_j):
            row[node] += 2 * sp.k
    w = max(math.sqrt(row[i + 1] / a.masses[i]) for i in range(n))
    h = a.excitation.dt_record / a.integration.n1
    duration = a.excitation.duration
    if duration is None:  # a record: its length
        duration = (len(a.excitation.values) - 1) * a.excitation.dt_record
    steps = duration / h
    return ENERGY_RTOL + 10 * steps * (2 * w * h) ** 6 / 2016000


def initial_energy(a: fd.Analysis) -> float:
    """Kinetic and strain energy at t = 0 (relative frame)."""
    u0 = [0.0] + list(a.u0 or [0.0] * len(a.masses))
    v0 = a.v0 or [0.0] * len(a.masses)
    kinetic = 0.5 * sum(m * v * v for m, v in zip(a.masses, v0))
    strain = 0.5 * sum(s.k * (u0[s.node_i] - u0[s.node_j]) ** 2 for s in a.springs)
    return kinetic + strain


def without_run_time(summary: dict) -> dict:
    return {k: v for k, v in summary.items() if k not in ("run_time_s", "deck")}


PROPERTIES = settings(max_examples=int(os.environ.get("FRICTIONDYN_HYPOTHESIS_EXAMPLES", "60")), deadline=None, derandomize=True, database=None,
                      suppress_health_check=[HealthCheck.too_slow])


@PROPERTIES
@given(a=analyses())
def test_a_valid_model_runs_and_balances_its_energy(a):
    r = a.run()
    s = r.summary
    assert np.all(np.isfinite(r.data))
    scale = sum(abs(s[k]) for k in ENERGY_TERMS) + initial_energy(a)
    assert math.isfinite(s["energy_residual_J"])
    assert abs(s["energy_residual_J"]) <= energy_rtol(a) * scale + ENERGY_FLOOR, (s, a)
    assert s["technique"] == ("event_driven" if a.integration.technique else "newmark")


@PROPERTIES
@given(a=analyses())
def test_the_same_result_twice_and_through_both_interfaces(a, tmp_path_factory):
    first = a.run()
    second = a.run()
    assert np.array_equal(first.data, second.data)
    assert without_run_time(first.summary) == without_run_time(second.summary)
    work = tmp_path_factory.mktemp("exe")
    deck = a.write_deck(work / "analysis.nml")
    exe = fd.run_executable(deck, cwd=work)
    assert np.array_equal(exe.history().data, first.data)
    assert without_run_time(exe.summary()) == without_run_time(first.summary)
