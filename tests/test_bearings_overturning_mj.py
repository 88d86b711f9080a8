"""The overturning of rigid floors on planar Coulomb bearings under the Moreau-Jean technique
(&bearings overturning = .true., technique = 'moreau_jean').

Each bearing's normal force is N = p (1 + a_z / g) + dN, dN the share of the overturning moments
of the floors it carries (fd_overturning), taken from the end-of-step accelerations of the
accepted state (the equilibrium the reported forces are in) and held over the next step: explicit,
one step behind, as Newmark takes it (docs/theory.md 5.7 and 12.8).

- a block at height h on two rows d apart under a held base acceleration a: dN = -+ m a h / (2 d)
  once the block moves with the ground, sum dN = 0 at every step; overturning = .false. is the run
  without it, to the bit;
- a block on skewed friction pendulums under a harmonic base motion along x and y: Moreau-Jean
  tends to Newmark's velocity law (small eps, fine step) at first order in h;
- uplift from the overturning, counted, timed where the closed form puts it and warned; the energy
  balance closes to round-off (theta = 1/2) with N varying.
"""
from __future__ import annotations

import math

import numpy as np
import pytest

import frictiondyn
from test_bearings_overturning import D, DT, G, H, M, M0, X4, Y4, hold, normal_forces, run, write_record
from test_bearings_overturning import block as newmark_block

XS = [-3.0, 4.0, 1.5]      # a skewed triangle: S = sum r' r' not diagonal
YS = [-2.0, -1.0, 3.5]


def block(x, y, ax: str, duration: float, ay: str | None = None, mu: float = 0.3, n1: int = 4,
          overturning: bool | None = True, integration: dict | None = None, **bearing) -> dict:
    """test_bearings_overturning's block on Coulomb bearings, integrated by Moreau-Jean unless
    told."""
    bearing = {"law": ["coulomb"] * len(x), **bearing}
    moreau_jean = {"technique": "moreau_jean", "n1": n1}
    return newmark_block(x, y, ax, duration, ay, mu, n1, overturning,
                         integration if integration is not None else moreau_jean, **bearing)


def test_block_on_two_rows_takes_m_a_h_over_2d(tmp_path):
    """A base acceleration held at a = 0.1 g along x (mu = 0.3: the bearings stick, the block
    moves with the ground): the row at -d/2 takes + m a h / (2 d) each bearing, the row at +d/2
    loses as much, once the frames' vibration has died out (it decays at the rate zeta omega =
    a1 omega^2 / 2 = 20 /s; 2.5e-14 of p left at 1.4 s); sum dN = 0 at every step.
    overturning = .false. is the run without it, to the bit."""
    a = 0.1 * G
    hold(tmp_path, "ax.txt", a, 2.0)
    r = run(tmp_path, block(X4, Y4, "ax.txt", 2.0), "rows.nml")
    n = normal_forces(r, 4)
    p = (M0 + M) * G / 4
    dn = M * a * H / (2 * D)
    steady = r["t"] > 1.4
    expected = np.array([p + dn, p - dn, p - dn, p + dn])
    for b in range(4):
        assert np.allclose(n[b][steady], expected[b], rtol=1e-12, atol=0.0), b
    assert np.allclose(n.sum(axis=0), 4 * p, rtol=1e-13, atol=0.0)
    s = r.summary
    assert s["bearing_max_normal_force_N"][0] == np.max(n[0]) >= (p + dn) * (1.0 - 1e-12)
    assert s["bearing_min_normal_force_N"][1] == np.min(n[1]) <= (p - dn) * (1.0 + 1e-12)
    assert s["bearing_uplift_count"] == [0] * 4
    # overturning = .false. given is the deck without it, to the bit; N stays p
    off = run(tmp_path, block(X4, Y4, "ax.txt", 2.0, overturning=False), "off.nml")
    none = run(tmp_path, block(X4, Y4, "ax.txt", 2.0, overturning=None), "none.nml")
    assert off.names == none.names
    for col in off.names:
        assert np.array_equal(off[col], none[col]), col
    assert np.all(normal_forces(off, 4) == p)


def skewed(tmp_path, n1: int, integration: dict | None = None, overturning: bool = True,
           **bearing) -> frictiondyn.Result:
    g = block(XS, YS, "ax.txt", 2.0, ay="ay.txt", mu=0.05, n1=n1, integration=integration,
              overturning=overturning, radius=[2.0] * 3, **bearing)
    return run(tmp_path, g, f"skew{n1}{'nm' if integration else 'mj'}{overturning}.nml")


def test_moreau_jean_tends_to_newmarks_velocity_law_at_first_order(tmp_path):
    """Skewed friction pendulums (R = 2 m, mu = 0.05) under a harmonic base motion along x and
    y: the overturning sets the bearings' N apart (by 25 % of p) and twists the block. Moreau-
    Jean tends to Newmark's velocity law (eps = 1e-5 m/s, dt1 = DT / 40) at first order in h: the
    mat's displacements (ux, uy, rz), the normal forces, and the overturning's own effect on the
    mat's translation (the run with it less the run without, 0.05 % and 0.3 % of the peaks)."""
    t = np.arange(0.0, 2.0 + DT / 2, DT)
    write_record(tmp_path, "ax.txt", 3.0 * np.sin(2 * np.pi * 1.5 * t))
    write_record(tmp_path, "ay.txt", 2.0 * np.cos(2 * np.pi * 1.1 * t))
    newmark = {"integration": {"n1": 40, "n2": 10}, "law": ["velocity"] * 3, "eps": [1.0e-5] * 3}
    ref = skewed(tmp_path, 40, **newmark)
    ref_off = skewed(tmp_path, 40, overturning=False, **newmark)
    assert ref.summary["energy_balance"] == "closed"
    n_ref = normal_forces(ref, 3)
    p = (M0 + M) * G / 3
    assert np.max(np.abs(n_ref - p)) > 0.2 * p
    assert min(ref.summary["bearing_slip_travel_m"]) > 0.5
    effect = {c: ref[c] - ref_off[c] for c in ("u1", "u2")}
    errors = []
    for n1 in (2, 4, 8):
        r = skewed(tmp_path, n1)
        off = skewed(tmp_path, n1, overturning=False)
        assert np.array_equal(r["t"][::n1], ref["t"][::40])
        err = max(np.max(np.abs(r[c][::n1] - ref[c][::40])) / np.max(np.abs(ref[c])) for c in ("u1", "u2", "u3"))
        err_n = np.max(np.abs(normal_forces(r, 3)[:, ::n1] - n_ref[:, ::40])) / p
        err_e = max(np.max(np.abs((r[c] - off[c])[::n1] - effect[c][::40])) / np.max(np.abs(effect[c]))
                    for c in ("u1", "u2"))
        errors.append((err, err_n, err_e))
    for j in range(3):
        e = [x[j] for x in errors]
        orders = [math.log2(e[k] / e[k + 1]) for k in range(2)]
        assert all(0.7 < q < 1.4 for q in orders), (j, errors, orders)
    assert errors[-1][0] < 1.0e-2 and errors[-1][1] < 5.0e-3 and errors[-1][2] < 5.0e-2, errors


def test_uplift_from_overturning_is_counted_timed_and_warned(tmp_path):
    """A base acceleration ramping to 0.5 g on a block twice as high as its rows are apart: the
    row at +d/2 lifts off where m a h / (2 d) reaches its share (m0 + m) g / 4 (within the steps
    the lag and the transient take); the other row never does."""
    t_end, a_end, h = 2.0, 0.5 * G, 2.0 * D
    t = np.arange(0.0, t_end + DT / 2, DT)
    write_record(tmp_path, "ramp.txt", a_end * t / t_end)
    g = block(X4, Y4, "ramp.txt", t_end, mu=0.6)
    g["floors"]["height"] = [0.0, h]
    with pytest.warns(frictiondyn.FrictiondynWarning, match="bearing-uplift"):
        r = run(tmp_path, g, "lift.nml")
    s = r.summary
    t_lift = t_end * ((M0 + M) * G * D / (2 * M * h)) / a_end
    assert s["bearing_uplift_count"] == [0, 1, 1, 0]
    for b in (1, 2):
        assert s["bearing_uplift_first_time_s"][b] == pytest.approx(t_lift, abs=2 * DT)
        assert s["bearing_min_normal_force_N"][b] < 0.0
    assert s["bearing_uplift_duration_s"][1] == pytest.approx(t_end - t_lift, abs=2 * DT)
    warning = [w for w in s["warnings"] if "lifted off" in w]
    assert len(warning) == 1 and len(warning[0]) <= 220 and "docs/warnings.md#bearing-uplift" in warning[0]
    # lifted at a step's start (the disc's N, one step behind the row's), bearing 2 carries no
    # force; it did before
    lifted = r["N2"] <= 0.0
    held = lifted[1:] & lifted[:-1]
    assert np.count_nonzero(held) > 100
    assert np.all(r["F3"][1:][held] == 0.0) and np.all(r["F4"][1:][held] == 0.0)
    assert np.max(np.abs(r["F3"])) > 0.1 * 0.6 * (M0 + M) * G / 4
    assert abs(s["energy_residual_ratio"]) < 1.0e-10


def test_energy_balance_closes_with_the_overturning(tmp_path):
    """A harmonic base motion along x and y on friction pendulums, sliding, the overturning on:
    the friction term holds the impulses' and the pendulum excess's work and the balance closes
    to round-off (theta = 1/2); each bearing's N column's extremes are the summary's."""
    t = np.arange(0.0, 2.0 + DT / 2, DT)
    write_record(tmp_path, "ax.txt", 3.0 * np.sin(2 * np.pi * 1.5 * t))
    write_record(tmp_path, "ay.txt", 2.0 * np.cos(2 * np.pi * 1.1 * t))
    r = run(tmp_path, block(X4, Y4, "ax.txt", 2.0, ay="ay.txt", mu=0.1, radius=[2.0] * 4), "energy.nml")
    s = r.summary
    assert s["energy_balance"] == "closed"
    assert abs(s["energy_residual_ratio"]) < 1.0e-10
    assert s["energy_friction_J"] > 0.0
    n = normal_forces(r, 4)
    assert list(n.min(axis=1)) == s["bearing_min_normal_force_N"]
    assert list(n.max(axis=1)) == s["bearing_max_normal_force_N"]
    assert np.ptp(n[0]) > 0.05 * (M0 + M) * G / 4
