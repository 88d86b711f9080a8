"""Every technique on devices of any direction b and a stiffness beyond springs (K_x): an
eccentric building of rigid floors with Coulomb friction braces at plan positions, integrated
by the exact event-driven technique (general phase patterns), by Moreau-Jean (its one-step
problem in dense form, the Delassus operator B' W^-1 B) and by Newmark with the regularized
laws at their limits; the same building given as &matrices; the energy balance of each."""

import numpy as np
import pytest

from conftest import ok
from test_floors import frame_stiffness, mtx

HARMONIC = {"excitation_type": "harmonic", "amplitude": 0.02, "frequency": 2.0, "dt_record": 0.01,
            "duration": 1.5}
DAMPING = {"damping_type": "rayleigh", "rayleigh_a0": 0.3, "rayleigh_a1": 8.0e-4}


def eccentric(technique="event_driven", law="coulomb", **integration):
    """Two rigid floors 20 m x 12 m whose centres of mass are off the frames' centre of
    stiffness (unequal x frames), one Coulomb brace along x at y = -6 m and one along y at
    x = 8 m in each storey; the table moves at 30 degrees from x, so the floors twist."""
    storey = [s for s in (1, 2) for _ in range(4)]
    braces = {"n_braces": 4, "storey": [1, 1, 2, 2], "angle": [0.0, 90.0] * 2, "x": [0.0, 8.0] * 2,
              "y": [-6.0, 0.0] * 2, "slip_load": [300.0e3, 200.0e3, 150.0e3, 100.0e3], "law": [law] * 4}
    if law == "velocity":
        braces["eps"] = integration.pop("eps")
    return {
        "floors": {"n_floors": 2, "mass": [3.0e5] * 2, "plan_x": [20.0] * 2, "plan_y": [12.0] * 2,
                   "cm_x": [0.0, 0.5], "height": [3.0] * 2, "excitation_angle": 30.0},
        "frames": {"n_frames": 8, "storey": storey, "angle": [0.0, 0.0, 90.0, 90.0] * 2,
                   "x": [0.0, 0.0, -10.0, 10.0] * 2, "y": [-6.0, 6.0, 0.0, 0.0] * 2,
                   "k": [200.0e6, 260.0e6, 300.0e6, 300.0e6, 160.0e6, 200.0e6, 250.0e6, 250.0e6]},
        "damping": DAMPING,
        "floor_braces": braces,
        "excitation": HARMONIC,
        "integration": {"technique": technique, **integration},
        "output": {"output_every": 1},
    }


def displacements(r, n=6):
    h = r.history()
    return np.array([h[f"u{i}"] for i in range(1, n + 1)])


@pytest.fixture(scope="module")
def exact(tmp_path_factory):
    """The exact technique's run of the eccentric building (the reference)."""
    from conftest import run_deck_file, deck_text
    work = tmp_path_factory.mktemp("exact")
    (work / "ed.nml").write_text(deck_text(eccentric("event_driven", n1=10)))
    return ok(run_deck_file(work / "ed.nml", work))


def test_exact_technique_on_an_eccentric_building(exact):
    """The floors twist, every brace slips and sticks again, and the exact technique's
    energy balance closes to round-off."""
    s = exact.summary()
    u = displacements(exact)
    assert np.abs(u[2]).max() > 1e-5 and np.abs(u[1]).max() > 1e-4   # rotation and y motion
    assert min(s["stick_to_slip"]) > 0 and min(s["slip_to_stick"]) > 0
    assert s["energy_friction_J"] > 0
    assert abs(s["energy_residual_ratio"]) < 1e-12


def test_moreau_jean_converges_to_the_exact_technique_at_first_order(run, exact):
    """Moreau-Jean (dense one-step problem) converges to the exact run as its step goes to
    zero: with theta = 1 at first order (measured orders 0.95 and 0.99 for n1 = 20, 40, 80);
    with theta = 1/2 within 3e-4 of the peak displacement at n1 = 40 (measured 2.3e-4)."""
    ref = displacements(exact)
    scale = np.abs(ref).max()
    err = []
    for n1 in (20, 40, 80):
        r = ok(run(eccentric("moreau_jean", n1=n1, theta=1.0), name=f"mj{n1}"))
        err.append(np.abs(displacements(r)[:, ::n1 // 10] - ref).max() / scale)
    order = np.log2(np.array(err[:-1]) / np.array(err[1:]))
    assert err[-1] < 0.01, err
    assert np.all(np.abs(order - 1.0) < 0.1), (err, order)
    r = ok(run(eccentric("moreau_jean", n1=40, theta=0.5), name="mj_half"))
    assert np.abs(displacements(r)[:, ::4] - ref).max() / scale < 3e-4


def test_newmark_velocity_law_tends_to_the_exact_technique(run, exact):
    """Newmark with the velocity law approaches the exact Coulomb run as its band eps falls:
    3.0 % of the peak displacement at eps = 1e-2 m/s, 0.51 % at 1e-4 (measured). Below that
    it does not fall further on this building (0.52 % at eps = 1e-5, at n1 = 10 to 80): its
    sticking devices are not rigid links (with slip loads too high to slip, its response
    still changes by 0.34 % between 1e7 and 1e9 N, where the exact technique's and
    Moreau-Jean's do not change at all)."""
    ref = displacements(exact)
    scale = np.abs(ref).max()
    err = []
    for eps in (1.0e-2, 1.0e-4):
        r = ok(run(eccentric("newmark", "velocity", n1=10, n2=50, eps=eps), name="nm"))
        err.append(np.abs(displacements(r) - ref).max() / scale)
    assert err[1] < 0.01 and err[0] > 3 * err[1], err


@pytest.mark.parametrize("technique, n1", [("event_driven", 10), ("moreau_jean", 20)])
def test_matrices_reproduce_the_rigid_floors_under_the_coulomb_techniques(run, technique, n1):
    """The eccentric building's frames (the x frames unequal) without braces, a Coulomb damper
    from floor 1's ux to the ground (&friction), given as &matrices (K of its frames and M in Matrix Market files,
    r at 30 degrees): the same run as the floor shorthand under each Coulomb technique (1e-12
    of the peak displacement)."""
    floors = eccentric(technique, n1=n1)
    floors.pop("floor_braces")
    floors["friction"] = {"n_devices": 1, "node_i": 1, "node_j": 0, "law": "coulomb", "p": 2.0e5, "mu": 1.0}
    floors["floors"]["cm_x"] = [0.0, 0.0]   # centres of mass on one vertical: frame_stiffness's b
    a = ok(run(floors, name="floors"))
    J = 3.0e5 * (20.0**2 + 12.0**2) / 12
    c, s = float(np.cos(np.radians(30.0))), float(np.sin(np.radians(30.0)))
    K = frame_stiffness(floors["frames"], 2)
    deck = {"matrices": {"k_file": "K.mtx", "m_file": "M.mtx", "influence": [c, s, 0.0] * 2}}
    deck.update({k: v for k, v in floors.items() if k not in ("floors", "frames")})
    files = {"K.mtx": mtx(K), "M.mtx": mtx(np.diag([3.0e5, 3.0e5, J] * 2))}
    b = ok(run(deck, name="matrices", files=files))
    if np.abs(displacements(a) - displacements(b)).max() > 1e-12 * np.abs(displacements(a)).max():
        pytest.fail("floors and matrices differ")
    assert a.summary()["stick_to_slip"][0] > 0
    assert b.summary()["peak_base_shear_N"] == pytest.approx(a.summary()["peak_base_shear_N"], rel=1e-12)


@pytest.mark.parametrize("technique, integration, tol", [
    ("event_driven", {"n1": 10}, 1e-12),
    ("moreau_jean", {"n1": 20, "theta": 0.5}, 1e-12),
    ("newmark", {"n1": 10, "n2": 50, "eps": 1.0e-3}, 1e-12),
])
def test_energy_balance_closes_in_3d(run, technique, integration, tol):
    """Input = kinetic + strain + viscous + friction energy for the twisting building under
    each technique, to round-off (1e-12 of the input; measured 2e-16 exact, 4e-15 Moreau-Jean
    with theta = 1/2, 7e-16 Newmark's average acceleration with the velocity law)."""
    law = "velocity" if technique == "newmark" else "coulomb"
    r = ok(run(eccentric(technique, law, **integration), name=technique))
    s = r.summary()
    assert s["energy_friction_J"] > 0.05 * s["energy_input_J"] > 0
    assert abs(s["energy_residual_ratio"]) < tol, s["energy_residual_ratio"]


@pytest.mark.parametrize("technique", ["event_driven"])
def test_a_second_component_is_refused_by_the_coulomb_techniques(run, technique):
    """Two horizontal components are integrated by Newmark and Moreau-Jean: the event-driven
    technique refuses &excitation2 with a message naming it, and writes nothing."""
    deck = eccentric(technique, n1=10)
    deck["excitation2"] = dict(HARMONIC, amplitude=0.01)
    r = run(deck)
    assert r.returncode != 0
    assert "&excitation2" in r.stderr and "'newmark'" in r.stderr, r.stderr
    assert not (r.outdir / "case.csv").exists()


def test_a_hysteretic_floor_brace_is_refused_naming_its_group(run):
    """A brace of &floor_braces with the hysteretic law under the exact technique: an error
    naming &floor_braces, the brace's law and what to set."""
    deck = eccentric("event_driven", n1=10)
    deck["floor_braces"]["law"] = ["hysteretic"] * 4
    deck["floor_braces"]["stiffness"] = [150.0e6] * 4
    r = run(deck)
    assert r.returncode != 0
    assert "&floor_braces: law(1) = 'hysteretic'" in r.stderr and "law = 'coulomb'" in r.stderr, r.stderr


@pytest.mark.parametrize("technique", ["event_driven", "moreau_jean"])
def test_symmetric_floors_along_x_are_the_planar_building(run, technique):
    """A doubly symmetric building of rigid floors with Coulomb braces through the centres of
    mass, excited along x (general patterns, dense Moreau-Jean), is the planar shear building
    with node-pair devices (groups of nodes, band solver) to 1e-12 (measured 4e-13 and 1e-13)."""
    from test_floors import planar, symmetric, SLIP
    p = planar()
    p.pop("braces")
    p["friction"] = {"n_devices": 3, "node_i": [1, 2, 3], "node_j": [0, 1, 2], "law": ["coulomb"] * 3,
                     "p": SLIP, "mu": [1.0] * 3}
    p["integration"] = {"technique": technique, "n1": 20}
    f = symmetric()
    f["floor_braces"]["law"] = ["coulomb"] * 6
    del f["floor_braces"]["stiffness"]
    f["integration"] = {"technique": technique, "n1": 20}
    a, b = ok(run(p, name="planar")), ok(run(f, name="floors"))
    up = np.array([a.history()[f"u{i}"] for i in (1, 2, 3)])
    uf = np.array([b.history()[f"u{3 * i - 2}"] for i in (1, 2, 3)])
    assert min(a.summary()["stick_to_slip"]) > 0
    assert np.abs(up - uf).max() <= 1e-12 * np.abs(up).max()
