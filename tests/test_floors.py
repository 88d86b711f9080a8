"""Buildings of rigid floors (&floors, &frames, &floor_braces): three DOFs a floor (ux, uy,
rz at its centre of mass), frames and braces at plan positions, the table motion along a
plan direction."""

import numpy as np
import pytest

from conftest import ok

HARMONIC = {"excitation_type": "harmonic", "amplitude": 0.02, "frequency": 2.5, "dt_record": 0.01,
            "duration": 3.0}
K = [400.0e6, 320.0e6, 200.0e6]          # storey stiffness along x (and y) [N/m]
SLIP = [600.0e3, 400.0e3, 200.0e3]       # storey slip load [N]
KB = 300.0e6                             # brace stiffness [N/m]
DAMPING = {"damping_type": "rayleigh", "rayleigh_a0": 0.3, "rayleigh_a1": 8.0e-4}


def planar():
    return {
        "model": {"n_dof": 3, "mass": [3.0e5] * 3},
        "springs": {"n_springs": 3, "node_i": [1, 2, 3], "node_j": [0, 1, 2], "k": K},
        "damping": DAMPING,
        "braces": {"n_braces": 3, "node_i": [1, 2, 3], "node_j": [0, 1, 2], "slip_load": SLIP,
                   "stiffness": [KB] * 3},
        "storeys": {"n_storeys": 3, "node_i": [1, 2, 3], "node_j": [0, 1, 2], "height": [3.0] * 3},
        "excitation": HARMONIC,
        "integration": {"n1": 20, "n2": 50},
    }


def symmetric(angle=0.0):
    """The planar building as rigid floors 20 m x 12 m: along x two frames at y = -6, 6 with
    half the storey's stiffness each and two braces beside them; along y two frames at
    x = -10, 10. Doubly symmetric: the centre of stiffness is the centre of mass."""
    storey = [s for s in (1, 2, 3) for _ in range(4)]
    return {
        "floors": {"n_floors": 3, "mass": [3.0e5] * 3, "plan_x": [20.0] * 3, "plan_y": [12.0] * 3,
                   "height": [3.0] * 3, "excitation_angle": angle},
        "frames": {"n_frames": 12, "storey": storey, "angle": [0.0, 0.0, 90.0, 90.0] * 3,
                   "x": [0.0, 0.0, -10.0, 10.0] * 3, "y": [-6.0, 6.0, 0.0, 0.0] * 3,
                   "k": [k / 2 for k in K for _ in range(4)]},
        "damping": DAMPING,
        "floor_braces": {"n_braces": 6, "storey": [1, 1, 2, 2, 3, 3], "angle": [0.0] * 6, "x": [0.0] * 6,
                         "y": [-6.0, 6.0] * 3, "slip_load": [s / 2 for s in SLIP for _ in range(2)],
                         "stiffness": [KB / 2] * 6},
        "excitation": HARMONIC,
        "integration": {"n1": 20, "n2": 50},
    }


def test_symmetric_building_along_x_is_the_planar_one(run):
    """Excited along x, a doubly symmetric building of rigid floors does not turn and does
    not move along y, and its x motion is the planar shear building's (1e-12)."""
    p = ok(run(planar(), name="planar"))
    f = ok(run(symmetric(), name="floors"))
    hp, hf = p.history(), f.history()
    sp, sf = p.summary(), f.summary()
    up = np.array([hp[f"u{i}"] for i in (1, 2, 3)])
    ux = np.array([hf[f"u{3 * i - 2}"] for i in (1, 2, 3)])
    scale = np.abs(up).max()
    assert scale > 1e-3
    assert np.abs(ux - up).max() <= 1e-12 * scale
    for c in (2, 3):  # uy and rz of every floor
        assert np.abs(np.array([hf[f"u{3 * i - 3 + c}"] for i in (1, 2, 3)])).max() <= 1e-12 * scale
    # the braces slip: a nonlinear run, and the same peaks of force and base shear
    assert max(sp["peak_force_N"]) >= 0.999 * SLIP[0]
    fx = np.array(sf["peak_force_N"]).reshape(3, 2).sum(axis=1)
    assert np.allclose(fx, sp["peak_force_N"], rtol=1e-12)
    assert sf["peak_base_shear_N"] == pytest.approx(sp["peak_base_shear_N"], rel=1e-12)
    # storeys: s along x and along y; the x ones are the planar storeys
    assert sf["storey_labels"] == [f"storey {s} {d}" for s in (1, 2, 3) for d in "xy"]
    for key in ("peak_drift_m", "peak_storey_shear_N", "peak_drift_ratio"):
        got = np.array(sf[key], dtype=float).reshape(3, 2)
        assert np.allclose(got[:, 0], sp[key], rtol=1e-12, atol=0), key
        assert np.abs(got[:, 1]).max() <= 1e-12 * np.abs(got[:, 0]).max(), key
    aabs = np.array(sf["peak_aabs_mps2"]).reshape(3, 3)
    assert np.allclose(aabs[:, 0], sp["peak_aabs_mps2"], rtol=1e-12)
    assert np.abs(aabs[:, 1:]).max() <= 1e-9 * aabs[:, 0].max()


def test_symmetric_building_along_y_moves_along_y(run):
    """The same building excited along y (excitation_angle = 90): no x motion, no rotation;
    the y frames are stiffer than the x ones, so the motion differs from the x run."""
    f = ok(run(symmetric(angle=90.0), name="floors"))
    h = f.history()
    uy = np.array([h[f"u{3 * i - 1}"] for i in (1, 2, 3)])
    assert np.abs(uy).max() > 1e-4
    for c in (1, 3):
        assert np.abs(np.array([h[f"u{3 * i - 3 + c}"] for i in (1, 2, 3)])).max() <= 1e-12 * np.abs(uy).max()


def eccentric():
    """One rigid floor 20 m x 12 m, frames off the centre of mass: x frames at y = -6 (k)
    and y = 6 (3k), y frames at x = -10 and 10; no devices, no damping."""
    return {
        "floors": {"n_floors": 1, "mass": [2.0e5], "plan_x": [20.0], "plan_y": [12.0],
                   "excitation_angle": 30.0},
        "frames": {"n_frames": 4, "storey": [1] * 4, "angle": [0.0, 0.0, 90.0, 90.0],
                   "x": [0.0, 0.0, -10.0, 10.0], "y": [-6.0, 6.0, 0.0, 0.0],
                   "k": [50.0e6, 150.0e6, 100.0e6, 100.0e6]},
        "damping": {"damping_type": "none"},
        "excitation": {"excitation_type": "harmonic", "amplitude": 0.01, "frequency": 1.3,
                       "dt_record": 0.002, "duration": 2.0},
        "integration": {"n1": 20},
    }


def test_eccentric_floor_equals_modal_closed_form(run):
    """An eccentric floor (coupled x and torsion) under a harmonic table motion at 30 deg from
    rest: the modal closed form of (K, M), q_k = -G_k A (sin W t - (W / w_k) sin w_k t) /
    (w_k^2 - W^2), with K from the frames' directions written out independently here."""
    r = ok(run(eccentric(), name="ecc"))
    h = r.history()
    m, lx, ly = 2.0e5, 20.0, 12.0
    M = np.diag([m, m, m * (lx**2 + ly**2) / 12])
    K = np.zeros((3, 3))
    # b = (cos a, sin a, -cos a (y - 0) + sin a (x - 0)) for each frame
    for a, x, y, k in [(0, 0, -6, 50e6), (0, 0, 6, 150e6), (90, -10, 0, 100e6), (90, 10, 0, 100e6)]:
        c, s = np.cos(np.radians(a)), np.sin(np.radians(a))
        c, s = round(c, 15), round(s, 15)
        b = np.array([c, s, -c * y + s * x])
        K += k * np.outer(b, b)
    w2, phi = np.linalg.eigh(np.linalg.solve(np.sqrt(M), np.linalg.solve(np.sqrt(M), K).T))
    phi = np.linalg.solve(np.sqrt(M), phi)
    w = np.sqrt(w2)
    rr = np.array([np.cos(np.radians(30)), np.sin(np.radians(30)), 0.0])
    W = 2 * np.pi * 1.3
    A = -0.01 * W**2  # the table acceleration a_g = A sin W t
    t = np.asarray(h["t"])
    u = np.zeros((3, t.size))
    for k in range(3):
        g = phi[:, k] @ M @ rr  # phi' M phi = 1
        q = -g * A * (np.sin(W * t) - W / w[k] * np.sin(w[k] * t)) / (w2[k] - W**2)
        u += np.outer(phi[:, k], q)
    got = np.array([h[f"u{i}"] for i in (1, 2, 3)])
    # Newmark's phase error over the run: (w dt)^2 / 12 per radian, at most 2e-4 here
    dt = 0.002 / 20
    bound = (w.max() * dt) ** 2 / 12 * w.max() * t[-1]
    assert bound < 2e-3
    for i in range(3):
        assert np.abs(got[i] - u[i]).max() <= 2 * bound * np.abs(u[i]).max()
    assert np.abs(u[2]).max() > 1e-5  # it turns


@pytest.mark.parametrize("change, words", [
    (lambda d: d.update(model={"n_dof": 1, "mass": [1.0]}), "group &model is not for a building of &floors"),
    (lambda d: d["frames"].update(storey=[4] + [1] * 11), "storey(1) = 4"),
    (lambda d: d["floors"].update(inertia=[1.0e6] * 3), "inertia(1)"),
    (lambda d: d["floor_braces"].update(law=["velocity"] * 6), "stiffness(1)"),
    (lambda d: d.pop("frames"), "group &frames is missing"),
])
def test_bad_floors_input(run, change, words):
    deck = symmetric()
    change(deck)
    r = run(deck)
    assert r.returncode != 0
    assert words in r.stderr, r.stderr
    assert not (r.outdir).exists() or not any(r.outdir.iterdir())


def one_storey(p_delta=True, m=2.0e5, k=5.0e6, h=3.0):
    """One floor 20 m x 12 m on four frames: along x at y = -6 and 6, along y at x = -10, 10."""
    return {
        "floors": {"n_floors": 1, "mass": [m], "plan_x": [20.0], "plan_y": [12.0], "height": [h],
                   "p_delta": p_delta},
        "frames": {"n_frames": 4, "storey": [1] * 4, "angle": [0.0, 0.0, 90.0, 90.0],
                   "x": [0.0, 0.0, -10.0, 10.0], "y": [-6.0, 6.0, 0.0, 0.0], "k": [k, 1.5 * k, 2 * k, 2 * k]},
        "damping": {"damping_type": "none"},
        "excitation": {"excitation_type": "harmonic", "amplitude": 0.001, "frequency": 1.0,
                       "dt_record": 0.01, "duration": 0.05},
        "output": {"dir": "out", "n_modes": 3},
    }


def test_p_delta_lowers_each_period_by_the_weight_over_the_height(run):
    """P-Delta of one storey: w^2 = (k - m g / h) / m along x and y, and
    (k_theta - g J / h) / J in torsion, the closed forms of a symmetric storey (here the x
    frames are unequal: x and torsion couple, so the check is on the 3 x 3 problem)."""
    m, k, h, g = 2.0e5, 5.0e6, 3.0, 9.80665
    s = ok(run(one_storey(m=m, k=k, h=h))).summary()
    s0 = ok(run(one_storey(False, m=m, k=k, h=h))).summary()
    J = m * (20.0**2 + 12.0**2) / 12
    K = np.zeros((3, 3))
    for a, x, y, ke in [(0, 0, -6, k), (0, 0, 6, 1.5 * k), (90, -10, 0, 2 * k), (90, 10, 0, 2 * k)]:
        c, sn = (1.0, 0.0) if a == 0 else (0.0, 1.0)
        b = np.array([c, sn, sn * x - c * y])
        K += ke * np.outer(b, b)
    M = np.diag([m, m, J])
    Kg = -np.diag([m * g / h, m * g / h, g * J / h])
    for summary, kk in ((s0, K), (s, K + Kg)):
        w2 = np.sort(np.linalg.eigvals(np.linalg.solve(M, kk)).real)
        assert np.allclose(summary["periods_free_s"], 2 * np.pi / np.sqrt(w2), rtol=1e-10)
    assert all(a > b for a, b in zip(s["periods_free_s"], s0["periods_free_s"]))


def test_p_delta_refuses_a_building_that_buckles(run):
    # m g / h = 6.5e6 N/m > the y frames' 2 x 2 k = 4e6 N/m
    r = run(one_storey(m=2.0e6, k=1.0e6, h=3.0))
    assert r.returncode != 0
    assert "p_delta" in r.stderr and "buckling" in r.stderr


Y_MOTION = {"excitation_type": "harmonic", "amplitude": 0.015, "frequency": 3.1, "dt_record": 0.01,
            "duration": 3.0}


def test_two_components_of_a_symmetric_building_are_its_two_one_component_runs(run):
    """&excitation along x and &excitation2 along y: the doubly symmetric building does not
    turn and its braces act along x only, so its x motion is the x-only run's (1e-12). Its y
    motion is the run along y alone (excitation_angle = 90) with the second motion, but
    integrated with the steps the x braces' transitions refine (the refinement is global):
    equal to within Newmark's own error of the y modes, (w dt1)^2 / 12 per radian."""
    both = symmetric()
    both["excitation2"] = Y_MOTION
    xy = ok(run(both, name="xy")).history()
    x = ok(run(symmetric(), name="x")).history()
    only_y = symmetric(angle=90.0)
    only_y["excitation"] = Y_MOTION
    ry = ok(run(only_y, name="y"))
    y = ry.history()
    w = 2 * np.pi / min(p for p in ry.summary()["periods_free_s"] if p)
    t_end, dt1 = 3.0, 0.01 / 20
    newmark = (w * dt1) ** 2 / 12 * w * t_end
    for f in (1, 2, 3):
        for c, ref, tol in ((1, x, 1e-12), (2, y, newmark)):
            got, want = np.asarray(xy[f"u{3 * f - 3 + c}"]), np.asarray(ref[f"u{3 * f - 3 + c}"])
            assert np.abs(want).max() > 1e-5
            assert np.abs(got - want).max() <= tol * np.abs(want).max()
        rz = np.asarray(xy[f"u{3 * f}"])
        assert np.abs(rz).max() <= 1e-12 * np.abs(np.asarray(x[f"u{3 * f - 2}"])).max()


def test_two_components_of_an_eccentric_floor_equal_the_modal_closed_form(run):
    """Two harmonic components at 30 and 120 degrees on the eccentric floor: the sum of
    each component's modal closed form."""
    deck = eccentric()
    deck["excitation2"] = {"excitation_type": "harmonic", "amplitude": 0.006, "frequency": 2.1,
                           "dt_record": 0.002, "duration": 2.0}
    h = ok(run(deck, name="ecc2")).history()
    m, lx, ly = 2.0e5, 20.0, 12.0
    M = np.diag([m, m, m * (lx**2 + ly**2) / 12])
    K = np.zeros((3, 3))
    for c, s, x, y, k in [(1, 0, 0, -6, 50e6), (1, 0, 0, 6, 150e6), (0, 1, -10, 0, 100e6), (0, 1, 10, 0, 100e6)]:
        b = np.array([c, s, -c * y + s * x])
        K += k * np.outer(b, b)
    w2, phi = np.linalg.eigh(np.linalg.solve(np.sqrt(M), np.linalg.solve(np.sqrt(M), K).T))
    phi = np.linalg.solve(np.sqrt(M), phi)
    w = np.sqrt(w2)
    t = np.asarray(h["t"])
    u = np.zeros((3, t.size))
    for angle, amp, freq in ((30.0, 0.01, 1.3), (120.0, 0.006, 2.1)):
        rr = np.array([np.cos(np.radians(angle)), np.sin(np.radians(angle)), 0.0])
        W = 2 * np.pi * freq
        A = -amp * W**2
        for k in range(3):
            g = phi[:, k] @ M @ rr
            u += np.outer(phi[:, k], -g * A * (np.sin(W * t) - W / w[k] * np.sin(w[k] * t)) / (w2[k] - W**2))
    got = np.array([h[f"u{i}"] for i in (1, 2, 3)])
    dt = 0.002 / 20
    bound = (w.max() * dt) ** 2 / 12 * w.max() * t[-1]
    for i in range(3):
        assert np.abs(got[i] - u[i]).max() <= 2 * bound * np.abs(u[i]).max()


def test_a_second_component_needs_rigid_floors_and_the_same_step(run):
    deck = planar()
    deck["excitation2"] = Y_MOTION
    r = run(deck)
    assert r.returncode != 0 and "&excitation2" in r.stderr and "&floors" in r.stderr
    deck = symmetric()
    deck["excitation2"] = dict(Y_MOTION, dt_record=0.02)
    r = run(deck)
    assert r.returncode != 0 and "dt_record" in r.stderr and "&excitation2" in r.stderr


def test_profiles_of_rigid_floors_draw_x_and_y_apart(run, tmp_path):
    """The drift and acceleration profiles of a building of rigid floors: one curve along x
    and one along y, each through its own storeys (their values the summary's)."""
    from frictiondyn import plots

    r = ok(run(symmetric(), name="floors"))
    res = r.history()
    fig = plots.plot_drift_profile(res, tmp_path / "drift.png")
    lines = [ln for ln in fig.axes[0].get_lines() if ln.get_label() in ("x", "y")]
    assert sorted(ln.get_label() for ln in lines) == ["x", "y"]
    ratio = np.array(r.summary()["peak_drift_ratio"], dtype=float).reshape(3, 2) * 100
    for ln, col in zip(sorted(lines, key=lambda ln: ln.get_label()), (0, 1)):
        assert np.allclose(ln.get_xdata()[::2], ratio[:, col], rtol=1e-12)
        assert np.allclose(ln.get_ydata(), [0, 3, 3, 6, 6, 9])
    fig = plots.plot_acceleration_profile(res, tmp_path / "acc.png")
    aabs = np.array(r.summary()["peak_aabs_mps2"]).reshape(3, 3)
    got = {ln.get_label(): ln.get_xdata() for ln in fig.axes[0].get_lines()}
    assert np.allclose(got["x"], aabs[:, 0]) and np.allclose(got["y"], aabs[:, 1])


def frame_stiffness(frames: dict, n_floors: int, cm=None) -> np.ndarray:
    """K of the frames of a &frames group, written out here from their directions
    (b = (cos a, sin a, sin a x - cos a y) on the floor above minus the floor below)."""
    K = np.zeros((3 * n_floors, 3 * n_floors))
    for s, a, x, y, k in zip(frames["storey"], frames["angle"], frames["x"], frames["y"], frames["k"]):
        c, sn = (round(np.cos(np.radians(a)), 15), round(np.sin(np.radians(a)), 15))
        b = np.zeros(3 * n_floors)
        b[3 * s - 3:3 * s] = [c, sn, sn * x - c * y]
        if s > 1:
            b[3 * s - 6:3 * s - 3] = [-c, -sn, -(sn * x - c * y)]
        K += k * np.outer(b, b)
    return K


def mtx(a: np.ndarray, symmetric: bool = True) -> str:
    """A Matrix Market coordinate file of a (its lower triangle when symmetric)."""
    n = a.shape[0]
    entries = [(i, j, a[i, j]) for j in range(n) for i in range(n)
               if a[i, j] != 0 and (i >= j or not symmetric)]
    kind = "symmetric" if symmetric else "general"
    lines = [f"%%MatrixMarket matrix coordinate real {kind}", f"{n} {n} {len(entries)}"]
    lines += [f"{i + 1} {j + 1} {float(v)!r}" for i, j, v in entries]
    return "\n".join(lines) + "\n"


def test_matrices_reproduce_the_rigid_floors(run):
    """The symmetric building without braces but with a velocity-law damper from floor 1's
    ux to the ground (&friction), given as &matrices: K of its frames and M (m, m, J) in
    Matrix Market files, r along x; the same run (1e-12)."""
    floors = symmetric()
    floors.pop("floor_braces")
    floors["friction"] = {"n_devices": 1, "node_i": 1, "node_j": 0, "law": "velocity", "p": 2.0e5,
                          "mu": 1.0, "eps": 1.0e-3}
    floors["excitation"] = dict(HARMONIC, amplitude=0.05)
    a = ok(run(floors, name="floors"))
    J = 3.0e5 * (20.0**2 + 12.0**2) / 12
    deck = {k: v for k, v in floors.items() if k not in ("floors", "frames")}
    deck["matrices"] = {"k_file": "K.mtx", "m_file": "M.mtx", "influence": [1.0, 0.0, 0.0] * 3}
    deck = {"matrices": deck.pop("matrices"), **deck}
    files = {"K.mtx": mtx(frame_stiffness(floors["frames"], 3)), "M.mtx": mtx(np.diag([3.0e5, 3.0e5, J] * 3))}
    b = ok(run(deck, name="matrices", files=files))
    ha, hb = a.history(), b.history()
    u = np.array([ha[f"u{i}"] for i in range(1, 10)])
    v = np.array([hb[f"u{i}"] for i in range(1, 10)])
    assert a.summary()["stick_to_slip"][0] > 0
    assert np.abs(u - v).max() <= 1e-12 * np.abs(u).max()
    assert b.summary()["peak_base_shear_N"] == pytest.approx(a.summary()["peak_base_shear_N"], rel=1e-12)


@pytest.mark.parametrize("k, m, words", [
    (np.array([[2.0, 1.0], [0.5, 2.0]]), np.eye(2), "K(2, 1) = 0.5"),
    (np.array([[1.0, -1.0], [-1.0, 1.0]]), np.eye(2), "not positive definite at DOF 2 'b'"),
    (np.eye(2), np.array([[1.0, 0.1], [0.1, 1.0]]), "diagonal (lumped) mass"),
    (np.eye(2), np.diag([1.0, 0.0]), "M(2, 2) = 0"),
    (np.eye(3), np.eye(2), "of K's size"),
])
def test_bad_matrices(run, k, m, words):
    deck = {"matrices": {"k_file": "K.mtx", "m_file": "M.mtx", "influence": [1.0, 1.0], "label": ["a", "b"]},
            "damping": {"damping_type": "none"}, "excitation": HARMONIC}
    r = run(deck, files={"K.mtx": mtx(k, symmetric=False), "M.mtx": mtx(m, symmetric=False)})
    assert r.returncode != 0
    assert "&matrices" in r.stderr and words in r.stderr, r.stderr


def test_corner_drifts_of_a_turning_floor(run):
    """The eccentric floor (one storey, 20 m x 12 m): the drift along x at the corners is
    ux - rz (y_c) with y_c = +-6 m, along y uy + rz x_c with x_c = +-10 m; its peak over
    the corners and time is at least the centre's and at most the centre's plus the arm times
    the peak rotation. From the history at every step: the summary's peak equals the
    largest corner value the history holds when the history keeps every step."""
    deck = eccentric()
    deck["floors"]["height"] = [3.0]
    deck["output"] = {"output_every": 1}
    r = ok(run(deck, name="ecc"))
    s, h = r.summary(), r.history()
    ux, uy, rz = (np.asarray(h[f"u{i}"]) for i in (1, 2, 3))
    cx = max(np.abs(ux - rz * yc).max() for yc in (-6.0, 6.0))
    cy = max(np.abs(uy + rz * xc).max() for xc in (-10.0, 10.0))
    assert s["peak_corner_drift_m"] == pytest.approx([cx, cy], rel=1e-12)
    assert s["peak_corner_drift_ratio"] == pytest.approx([cx / 3.0, cy / 3.0], rel=1e-12)
    assert cx > 1.05 * s["peak_drift_m"][0]   # the floor turns: the edges drift more


def test_corner_drifts_are_undefined_without_a_plan(run):
    deck = eccentric()
    deck["floors"].pop("plan_x")
    deck["floors"].pop("plan_y")
    deck["floors"]["inertia"] = [2.0e5 * (20.0**2 + 12.0**2) / 12]
    s = ok(run(deck, name="ecc")).summary()
    assert s["peak_corner_drift_m"] == [None, None]


@pytest.mark.parametrize("n", [3005, 40])
def test_matrices_mechanism_named_at_every_size(run, n):
    """K of a chain of n DOFs to the table whose second half floats free (a mechanism: no
    spring joins DOF n/2 to n/2 + 1): refused at every size, above 3000 DOFs as below, by
    the banded factor's first non-positive pivot, the free chain's last DOF by its label
    (its pivots are k, k, ..., exactly 0 at its end); no output is left."""
    h, k = n // 2, 1.0e6
    ent = [(i, i, 2 * k) for i in range(1, h)] + [(h, h, k)]            # grounded chain 1..h
    ent += [(i, i, 2 * k if h + 1 < i < n else k) for i in range(h + 1, n + 1)]  # free chain h+1..n
    ent += [(i + 1, i, -k) for i in range(1, n) if i != h]
    kfile = "%%MatrixMarket matrix coordinate real symmetric\n" + f"{n} {n} {len(ent)}\n" + \
        "".join(f"{i} {j} {v!r}\n" for i, j, v in ent)
    mfile = "%%MatrixMarket matrix coordinate real symmetric\n" + f"{n} {n} {n}\n" + \
        "".join(f"{i} {i} 1000.0\n" for i in range(1, n + 1))
    deck = {"matrices": {"k_file": "K.mtx", "m_file": "M.mtx", "influence": [1.0] * n,
                         "label": [f"x{i}" for i in range(1, n + 1)]},
            "damping": {"damping_type": "none"},
            "excitation": dict(HARMONIC, duration=0.02), "output": {"n_modes": 0}}
    r = run(deck, files={"K.mtx": kfile, "M.mtx": mfile})
    assert r.returncode != 0
    assert f"K not positive definite at DOF {n} 'x{n}'" in r.stderr, r.stderr
    assert not (r.workdir / "out").exists() or not any((r.workdir / "out").iterdir())
