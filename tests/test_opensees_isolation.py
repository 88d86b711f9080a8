"""A rigid block on four sliding bearings under the table's motion along x: frictiondyn's
&isolators (one DOF, one isolator carrying the block's weight, the hysteretic law) against an
independent OpenSeesPy 3D model of the block on four flatSliderBearing or singleFPBearing
elements with Coulomb friction (bench/opensees_models.py, IsolatedBlockCase). For a flat
slider the two codes solve the same equations; on a concave surface OpenSees adds the shear
force's component along the surface's normal to the normal force (second order in u/R;
measured 0.12 % on the peak here), which frictiondyn's constant normal force leaves out.
The block on elastic vertical supports (kv of &bearings) under three components against
OpenSees's vertical masses on axial springs of the same stiffness. Last, a small isolated
building (bench/isolated_building.py's model, IsolatedBuildingCase) against its OpenSeesPy 3D model, under two components and under three (a vertical one), and
the block on four friction pendulums with velocity-dependent friction (frictiondyn's velocity
law with mu_law 'exponential', OpenSees's frictionModel VelDependent) under two and three.
Skipped when openseespy cannot be imported."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest
from conftest import opensees_models

IsolatedBlockCase = opensees_models().IsolatedBlockCase
IsolatedBuildingCase = opensees_models().IsolatedBuildingCase
G_FD = opensees_models().G_FD


@pytest.mark.parametrize("radius, rel", [(0.0, 2e-4), (2.0, 5e-3)], ids=["flat", "pendulum"])
def test_block_on_four_bearings_along_x_equals_opensees(radius, rel):
    case = IsolatedBlockCase(radius=radius, duration=8.0)
    hist, normal = case.run_opensees()
    np.testing.assert_allclose(normal, case.weight / 4, rtol=1e-6)  # gravity held
    assert np.abs(hist[:, 1]).max() < 1e-12 and np.abs(hist[:, 2]).max() < 1e-12  # no y, no twist
    r = case.run_frictiondyn_1d()
    u_ops = np.abs(hist[:, 0]).max()
    assert r.summary["peak_u_m"][0] == pytest.approx(u_ops, rel=rel)
    # the whole history, not the peak alone (frictiondyn writes a row each record step)
    rows = np.rint(r.time / case.dt).astype(int)
    assert np.abs(r["u1"] - hist[rows, 0]).max() < 3 * rel * u_ops
    # the block slid: friction was at work, not only the elastic range
    assert u_ops > 20 * case.f


@pytest.mark.parametrize("radius, rel", [(0.0, 1e-3), (2.0, 5e-3)], ids=["flat", "pendulum"])
def test_block_on_four_planar_bearings_under_two_components_equals_opensees(radius, rel):
    """The same block as a rigid floor on four &bearings (the hysteretic law carried to the
    plane: a circular yield surface with radial return, as OpenSees's coupled bearings) under
    x and 0.7 y: each bearing's peak resultant displacement as OpenSees's (measured 1.1e-4
    flat, 2.8e-3 pendulum); the symmetric block does not twist."""
    case = IsolatedBlockCase(radius=radius, components=2, duration=8.0)
    hist, _ = case.run_opensees()
    ops_peak = np.hypot(hist[:, 3::2], hist[:, 4::2]).max(axis=0)
    r = case.run_frictiondyn_planar()
    np.testing.assert_allclose(r.summary["bearing_peak_displacement_m"], ops_peak, rtol=rel)
    assert abs(r.summary["peak_u_m"][2]) < 1e-12  # rz
    rows = np.rint(r.time / case.dt).astype(int)
    for dof in (0, 1):  # ux, uy of the centre over the whole history
        assert np.abs(r[f"u{dof + 1}"] - hist[rows, dof]).max() < 3 * rel * ops_peak.max()


def test_isolated_building_on_eight_pendulums_equals_opensees():
    """Three eccentric storeys of rigid floors on a base mat on eight friction pendulum
    bearings (&bearings, the hysteretic law in the plane) under two 4 s components, against
    OpenSees's rigidDiaphragm floors on singleFPBearing elements: each bearing's peak resultant
    displacement and each storey's peak drift along x and y within 2 % (measured 0.16 % and
    0.68 %: OpenSees adds the shear's component along the surface's normal to the bearings'
    forces, second order in u/R); OpenSees's normal forces stay the gravity share."""
    case = IsolatedBuildingCase(3, bearings_x=4, bearings_y=2, duration=4.0, n1=5)
    ops = case.run_opensees()
    np.testing.assert_allclose(ops.peaks["normal"], case.p, rtol=1e-6)
    fd = case.frictiondyn_peaks(case.run_frictiondyn())
    assert fd["bearing"].min() > 20 * case.f  # the bearings slid
    for q in ("bearing", "drift"):
        np.testing.assert_allclose(fd[q], ops.peaks[q], rtol=0.02)


def test_isolated_building_under_three_components_equals_opensees():
    """The same building under a third, vertical component (PGA 0.2 g: &excitation3). frictiondyn's
    vertical support is rigid, N = p (1 + a_z / g); OpenSees's singleFPBearing takes N from its
    axial force, so each bearing's top carries the vertical mass p / g on an axial spring
    kv = 1e13 N/m: a vertical period of 0.69 ms, a fourteenth of the record step, the rigid limit
    to 0.4 % in N (measured 0.37 %). OpenSees's N follows p (1 + a_z / g), both codes' extremes
    of N agree, and the bearings' peak resultant displacements and the storeys' peak drifts agree
    within 2 % (measured 0.10 % and 0.48 %). k_init = 5e8 N/m (f = 0.12 mm): under a varying N
    frictiondyn keeps f and scales the sticking stiffness mu N / f, OpenSees keeps k_init - N/R
    (its yield displacement follows N), a difference in proportion to f (with the two-component
    test's k_init, f = 1.2 mm, 2.6 % on a drift)."""
    case = IsolatedBuildingCase(3, bearings_x=4, bearings_y=2, duration=4.0, n1=5, vertical=2 / 3,
                                kv=1.0e13, k_init=5.0e8)
    assert 2 * np.pi * np.sqrt(case.p / G_FD / case.kv) < case.dt_record / 10
    ops = case.run_opensees()
    # OpenSees's normal force: the rigid limit p (1 + a_z / g) at each step, to 0.5 %
    nh = ops.peaks["normal_history"]
    t = np.arange(1, nh.shape[0] + 1) * case.dt
    az = np.interp(t, np.arange(len(case.records[2])) * case.dt_record, case.records[2])
    assert np.abs(nh - case.p * (1 + az / G_FD)[:, None]).max() < 5e-3 * case.p
    assert ops.peaks["normal_min"].max() < 0.9 * case.p and ops.peaks["normal_max"].min() > 1.1 * case.p
    fd = case.frictiondyn_peaks(case.run_frictiondyn())
    for q in ("normal_min", "normal_max"):
        np.testing.assert_allclose(fd[q], ops.peaks[q], rtol=5e-3)
    assert fd["bearing"].min() > 20 * case.f  # the bearings slid
    for q in ("bearing", "drift"):
        np.testing.assert_allclose(fd[q], ops.peaks[q], rtol=0.02)


@pytest.mark.parametrize("components", [2, 3], ids=["two", "three"])
def test_block_on_four_pendulums_with_velocity_dependent_friction_equals_opensees(components):
    """The block on four friction pendulum bearings (R = 2 m) with friction that rises with the
    sliding speed, mu(v) = 0.10 - 0.06 exp(-20 |v|): frictiondyn's &bearings with the velocity law
    (mu_law 'exponential' at the resultant speed) against OpenSees's singleFPBearing with
    frictionModel VelDependent (muSlow 0.04, muFast 0.10, transRate 20 s/m), under x and 0.7 y,
    and under a third, vertical component (PGA 0.2 g: frictiondyn's rigid support N = W/4 (1 +
    a_z / g); OpenSees's vertical mass W / (4 g) on an axial spring kv = 1e13 N/m, a vertical
    period of 0.3 ms). Each bearing's peak resultant displacement within 0.5 % (the issue asks
    2 %; measured 0.12 % and 0.07 %).

    The band eps = 1e-4 m/s: the peaks move by 6e-5 (relative) from eps = 1e-4 to 1e-5, so the
    band's error is about 6e-5, far below 2 %; at 1e-5 and below the velocity law's force
    alternates in the band at this step (a warning). OpenSees's friction is elastic-plastic:
    k_init = 1e11 N/m (yield displacement 0.1 um) puts its sticking error at 0.13 %; its
    difference from the rigid-plastic limit falls about as the square root of k_init (3.8 %,
    1.2 %, 0.4 %, 0.13 % at 1e8 ... 1e11 N/m). Velocity dependence matters: the same
    frictiondyn run with mu constant, mu_max or mu_min, is off OpenSees's peaks by more than
    10 % (measured -17 % and +109 % under two components, -11 % and +101 % under three); those
    runs take eps = 1e-3 m/s (at mu_max = 0.10 the band of 1e-4 alternates)."""
    case = IsolatedBlockCase(radius=2.0, components=components, duration=6.0, mu=0.10,
                             mu_min=0.04, mu_rate=20.0, eps=1.0e-4, k_init=1.0e11,
                             kv=1.0e13 if components == 3 else 1.0e10)
    hist, _ = case.run_opensees()
    ops_peak = np.hypot(hist[:, 3::2], hist[:, 4::2]).max(axis=0)
    r = case.run_frictiondyn_planar()
    fd_peak = np.asarray(r.summary["bearing_peak_displacement_m"], float)
    np.testing.assert_allclose(fd_peak, ops_peak, rtol=5e-3)
    assert fd_peak.min() > 0.02  # the bearings slid well beyond the band's creep
    if components == 3:  # the vertical component moved the normal forces
        assert max(r.summary["bearing_min_normal_force_N"]) < 0.9 * case.weight / 4
        assert min(r.summary["bearing_max_normal_force_N"]) > 1.1 * case.weight / 4
    for mu in (case.mu, case.mu_min):
        constant = replace(case, mu=mu, mu_min=None, eps=1.0e-3)
        peak = constant.run_frictiondyn_planar().summary["bearing_peak_displacement_m"]
        peak = np.asarray(peak, float)
        assert np.abs(peak / ops_peak - 1).min() > 0.10


@pytest.mark.parametrize("radius", [0.0, 2.0], ids=["flat", "pendulum"])
def test_block_on_four_bearings_on_elastic_vertical_supports_equals_opensees(radius):
    """The block on four bearings (the hysteretic law in the plane) under x, 0.7 y and a vertical
    component of PGA 0.2 g, each bearing's top on a finite vertical spring: frictiondyn's kv of
    &bearings (the share W / (4 g) on a vertical oscillator, advanced by its exact step map)
    against OpenSees's vertical mass W / (4 g) on the bearing's top node on an axial spring of the
    same kv, a vertical period of 0.07 s (undamped in both). Each bearing's peak resultant
    displacement within 2 % (measured 0.21 % flat, 0.32 % pendulum; the rigid support's run is off
    these OpenSees peaks by 0.36 % and -0.72 %); the support amplifies the largest N 23 % beyond
    the rigid support's p (1 + a_z / g) max."""
    case = IsolatedBlockCase(radius=radius, components=3, duration=6.0)
    m = case.weight / 4 / G_FD
    case = replace(case, kv=m * (2 * np.pi / 0.07) ** 2)
    hist, _ = case.run_opensees()
    ops_peak = np.hypot(hist[:, 3::2], hist[:, 4::2]).max(axis=0)
    deck = case.deck_planar().replace("  radius = 4*", f"  kv = 4*{case.kv!r}\n  radius = 4*")
    assert "kv = 4*" in deck
    run_with_records = opensees_models()._run_with_records
    r = run_with_records(deck, case.name, case.records)
    s = r.summary
    fd_peak = np.asarray(s["bearing_peak_displacement_m"], float)
    np.testing.assert_allclose(fd_peak, ops_peak, rtol=0.02)
    assert fd_peak.min() > 20 * case.f  # the bearings slid
    rigid = case.run_frictiondyn_planar().summary
    assert max(s["bearing_max_normal_force_N"]) > max(rigid["bearing_max_normal_force_N"]) * 1.1
    assert s["bearing_uplift_count"] == [0, 0, 0, 0]
