"""The outputs of a building of rigid floors that a three-dimensional design check reads:
base shears along x and y and the base torque, modal mass ratios per direction, floor
rotations, absolute accelerations at the floors' corners, and the braces' plan positions."""

import numpy as np
import pytest

from conftest import ok

M = [2.0e5, 1.5e5]                     # floor masses [kg]
LX, LY = 20.0, 12.0                    # plan [m]
CM_X, CM_Y = [0.0, 1.5], [0.0, -0.5]   # centres of mass [m]


def building(angle=30.0, slip=5.0e7, plan=True):
    """Two eccentric rigid floors (x frames at y = -6 (k) and 6 (3k), y frames at x = -10,
    10), a brace along 30 deg in each storey that stays stuck (no refinement: the history at
    every step holds every accepted state), damping without a mass term (a0 = 0), so that
    the forces passed to the table equal the inertia forces of the masses."""
    floors = {"n_floors": 2, "mass": M, "cm_x": CM_X, "cm_y": CM_Y, "excitation_angle": angle}
    if plan:
        floors.update(plan_x=[LX] * 2, plan_y=[LY] * 2)
    else:
        floors["inertia"] = [m * (LX**2 + LY**2) / 12 for m in M]
    return {
        "floors": floors,
        "frames": {"n_frames": 8, "storey": [1] * 4 + [2] * 4, "angle": [0.0, 0.0, 90.0, 90.0] * 2,
                   "x": [0.0, 0.0, -10.0, 10.0] * 2, "y": [-6.0, 6.0, 0.0, 0.0] * 2,
                   "k": [50.0e6, 150.0e6, 100.0e6, 100.0e6, 40.0e6, 120.0e6, 80.0e6, 80.0e6]},
        "floor_braces": {"n_braces": 2, "storey": [1, 2], "angle": [30.0, 30.0], "x": [4.0, -3.0],
                         "y": [2.0, 1.0], "slip_load": [slip] * 2, "stiffness": [60.0e6] * 2},
        "damping": {"damping_type": "rayleigh", "rayleigh_a0": 0.0, "rayleigh_a1": 2.0e-3},
        "excitation": {"excitation_type": "harmonic", "amplitude": 0.01, "frequency": 1.7,
                       "dt_record": 0.002, "duration": 2.0},
        "integration": {"n1": 4},
        "output": {"output_every": 1, "n_modes": 6},
    }


def floor_series(h, f):
    """ux, uy, rz and their absolute accelerations of floor f (1-based)."""
    return [np.asarray(h[f"{q}{3 * f - 3 + c}"]) for q in ("u", "aabs") for c in (1, 2, 3)]


def test_base_shears_and_torque_are_the_inertia_forces(run):
    """With a0 = 0 the forces the frames and braces pass to the table along x, along y and
    about the vertical axis through the plan origin are -sum m aabs_x, -sum m aabs_y and
    -sum (J aabs_rz + m (x_f aabs_y - y_f aabs_x)): their peaks and times equal those of the
    history (a row at every step), and the base shear along the table motion is the x and
    y shears combined along it."""
    r = ok(run(building(), name="b"))
    s, h = r.summary(), r.history()
    vx = vy = tz = 0.0
    for f, m in enumerate(M, start=1):
        *_, ax, ay, arz = floor_series(h, f)
        j = m * (LX**2 + LY**2) / 12
        vx = vx - m * ax
        vy = vy - m * ay
        tz = tz - (j * arz + m * (CM_X[f - 1] * ay - CM_Y[f - 1] * ax))
    t = np.asarray(h["t"])
    for key, series in (("base_shear_x_N", vx), ("base_shear_y_N", vy), ("base_torque_Nm", tz)):
        k = int(np.argmax(np.abs(series)))
        assert s[f"peak_{key}"] == pytest.approx(abs(series[k]), rel=1e-9), key
        time_key = "peak_" + key.rsplit("_", 1)[0] + "_time_s"
        assert s[time_key] == pytest.approx(t[k], abs=1e-12), key
        assert s[f"residual_{key}"] == pytest.approx(series[-1], rel=1e-8, abs=1e-9 * abs(series).max())
    assert s["peak_base_torque_Nm"] > 0.05 * s["peak_base_shear_x_N"] * LY   # the building turns
    c, sn = np.cos(np.radians(30.0)), np.sin(np.radians(30.0))
    assert s["peak_base_shear_N"] == pytest.approx(np.abs(c * vx + sn * vy).max(), rel=1e-9)


def test_base_shear_x_is_the_base_shear_when_the_table_moves_along_x(run):
    s = ok(run(building(angle=0.0), name="b")).summary()
    assert s["peak_base_shear_x_N"] == s["peak_base_shear_N"]
    assert s["peak_base_shear_x_time_s"] == s["peak_base_shear_time_s"]


def test_modal_mass_ratios_per_direction(run):
    """Over every mode each direction's ratios sum to 1; along the table motion's x
    (excitation_angle 0) the x ratios are the summary's ratios along r."""
    s = ok(run(building(angle=0.0), name="b")).summary()
    for system in ("stuck", "free"):
        ratios = np.array([s[f"modal_mass_ratio_{system}_{a}"] for a in ("x", "y", "rz")])
        assert ratios.shape == (3, 6)
        assert ratios.sum(axis=1) == pytest.approx([1.0] * 3, rel=1e-12)
        assert s[f"modal_mass_ratio_{system}_x"] == pytest.approx(s[f"modal_mass_ratio_{system}"], rel=1e-12)


def test_modal_mass_ratios_of_a_symmetric_floor_separate_the_directions(run):
    deck = building(angle=0.0)
    deck["floors"].update(n_floors=1, mass=[M[0]], cm_x=[0.0], cm_y=[0.0], plan_x=[LX], plan_y=[LY])
    deck["frames"] = {"n_frames": 4, "storey": [1] * 4, "angle": [0.0, 0.0, 90.0, 90.0],
                      "x": [0.0, 0.0, -10.0, 10.0], "y": [-6.0, 6.0, 0.0, 0.0],
                      "k": [50.0e6, 50.0e6, 90.0e6, 90.0e6]}
    deck.pop("floor_braces")
    s = ok(run(deck, name="b")).summary()
    ratios = np.array([s[f"modal_mass_ratio_stuck_{a}"] for a in ("x", "y", "rz")])
    # each mode is along one direction alone: x (w^2 = 1e8 / m = 500), y (900), torsion (2380)
    assert ratios == pytest.approx(np.eye(3), abs=1e-12)


def test_corner_accelerations_and_floor_rotations(run):
    """The absolute acceleration along x at the corners (y_c = +-6 m from the centre of
    mass) is aabs_x - aabs_rz y_c, along y aabs_y + aabs_rz x_c (x_c = +-10 m): the
    summary's peaks over the corners (floor 1 x, floor 1 y, floor 2 x, ...) are the
    history's; the floors' peak rotations are those of their rz."""
    r = ok(run(building(), name="b"))
    s, h = r.summary(), r.history()
    t = np.asarray(h["t"])
    want, when, rot, rot_t = [], [], [], []
    for f in (1, 2):
        _, _, rz, ax, ay, arz = floor_series(h, f)
        for series in ([ax - arz * yc for yc in (-LY / 2, LY / 2)], [ay + arz * xc for xc in (-LX / 2, LX / 2)]):
            peak = np.max(np.abs(series), axis=0)
            want.append(peak.max())
            when.append(t[int(np.argmax(peak))])
        rot.append(np.abs(rz).max())
        rot_t.append(t[int(np.argmax(np.abs(rz)))])
    assert s["peak_corner_aabs_mps2"] == pytest.approx(want, rel=1e-12)
    assert s["peak_corner_aabs_time_s"] == pytest.approx(when, abs=1e-12)
    assert s["peak_floor_rotation_rad"] == pytest.approx(rot, rel=1e-12)
    assert s["peak_floor_rotation_time_s"] == pytest.approx(rot_t, abs=1e-12)
    assert min(rot) > 1e-5                       # the floors turn
    aabs = np.array(s["peak_aabs_mps2"]).reshape(2, 3)[:, :2].reshape(-1)
    assert np.all(np.array(want) > aabs)         # so the corners accelerate more than the centres


def test_corner_accelerations_are_undefined_without_a_plan(run):
    s = ok(run(building(plan=False), name="b")).summary()
    assert s["peak_corner_aabs_mps2"] == [None] * 4
    assert s["floor_plan_x_m"] == [None] * 2
    assert s["floor_cm_x_m"] == CM_X and s["floor_cm_y_m"] == CM_Y


def test_brace_plan_positions(run):
    """Each brace of &floor_braces: its storey, its angle and the point of its line nearest
    its floor's centre of mass (on the line through the given point, the offset from the
    centre of mass perpendicular to the brace); other devices have none (null, storey 0)."""
    deck = building()
    deck["friction"] = {"n_devices": 1, "node_i": [1], "node_j": [0], "law": ["velocity"], "p": [1.0e3],
                        "mu": [0.1]}
    s = ok(run(deck, name="b")).summary()
    assert s["device_storey"] == [0, 1, 2]
    assert s["device_plan_x_m"][0] is None and s["device_angle_deg"][0] is None
    assert s["device_angle_deg"][1:] == pytest.approx([30.0, 30.0], rel=1e-12)
    d = np.array([np.cos(np.radians(30.0)), np.sin(np.radians(30.0))])
    for k, (x, y) in enumerate([(4.0, 2.0), (-3.0, 1.0)]):
        p = np.array([s["device_plan_x_m"][k + 1], s["device_plan_y_m"][k + 1]])
        cm = np.array([CM_X[k], CM_Y[k]])
        offset = p - np.array([x, y])
        assert abs(offset[0] * d[1] - offset[1] * d[0]) <= 1e-12 * 10   # on the brace's line
        assert abs((p - cm) @ d) <= 1e-12 * 10                            # nearest the centre of mass
