"""fd.Analysis builds what a deck builds beyond masses and springs: a building of rigid
floors (Floors, Frame, FloorBrace), a structure from its matrices (Matrices) and a second
component of the table motion (excitation2)."""

from pathlib import Path

import numpy as np
import pytest

import frictiondyn as fd

ROOT = Path(__file__).resolve().parents[1]
RECORD = ROOT / "inputs" / "synthetic_pga035.AT2"
#: keys that name the deck or the run, not its numbers
NOT_NUMBERS = {"deck", "deck_sha256", "run_time_s", "record", "record2"}


def building3d() -> fd.Analysis:
    """inputs/building3d.nml, built in Python."""
    storeys = [1, 1, 1, 1, 2, 2, 2, 2, 3, 3, 3, 3]
    angle = [0, 0, 90, 90] * 3
    x = [0, 0, -10, 10] * 3
    y = [-6, 6, 0, 0] * 3
    k = [200.0e6, 260.0e6, 300.0e6, 300.0e6, 160.0e6, 200.0e6, 250.0e6, 250.0e6, 100.0e6, 130.0e6,
         150.0e6, 150.0e6]
    slip = [300.0e3, 300.0e3, 200.0e3, 200.0e3, 100.0e3, 100.0e3]
    return fd.Analysis(
        floors=fd.Floors([fd.Floor(300.0e3, plan_x=20.0, plan_y=12.0, cm_x=cx, height=3.0)
                          for cx in (0.0, 0.5, 1.0)], p_delta=True),
        frames=[fd.Frame(*e) for e in zip(storeys, angle, x, y, k, strict=True)],
        damping=fd.Damping.rayleigh_modes(0.02, 1, 4),
        floor_braces=[fd.FloorBrace(s, a, bx, by, p, stiffness=150.0e6)
                      for s, a, bx, by, p in zip([1, 1, 2, 2, 3, 3], [0, 90] * 3, [0, 8] * 3, [-6, 0] * 3,
                                                 slip, strict=True)],
        excitation=fd.Record(file=RECORD, duration=8.0),
        excitation2=fd.Record(file=RECORD, scale=0.7, duration=8.0),
        integration=fd.Integration(n1=20, n2=50),
    )


def same_numbers(a: fd.Result, b: fd.Result) -> None:
    sa, sb = a.summary, b.summary
    assert set(sa) == set(sb)
    for key in set(sa) - NOT_NUMBERS:
        assert sa[key] == sb[key], key
    assert sa["record2"]["sha256"] == sb["record2"]["sha256"]
    assert a.names == b.names
    for name in a.names:
        assert np.array_equal(a[name], b[name]), name


def test_python_building_of_rigid_floors_is_the_deck():
    """The Python-built building3d runs exactly as inputs/building3d.nml: every number of
    the summary and every history column equal, bit for bit."""
    deck = fd.run(ROOT / "inputs" / "building3d.nml")
    same_numbers(building3d().run(), deck)


def test_python_building_writes_the_deck_groups(tmp_path):
    a = building3d()
    groups = dict(a.groups())
    assert "model" not in groups and "springs" not in groups
    assert groups["floors"]["n_floors"] == 3 and groups["floors"]["p_delta"] is True
    assert groups["frames"]["n_frames"] == 12
    assert groups["floor_braces"]["stiffness"] == [150.0e6] * 6
    assert groups["excitation2"]["record_scale"] == 0.7
    path = a.write_deck(tmp_path / "b3.nml")
    assert "&floor_braces" in path.read_text()


def test_matrices_from_arrays_reproduce_the_floors():
    """Matrices given as arrays (written as Matrix Market files for the run): a one-storey
    building of rigid floors without devices and its K and M give the same run."""
    floors = fd.Analysis(
        floors=fd.Floors([fd.Floor(2.0e5, plan_x=20.0, plan_y=12.0)], excitation_angle=0.0),
        frames=[fd.Frame(1, 0.0, 0.0, -6.0, 50.0e6), fd.Frame(1, 0.0, 0.0, 6.0, 150.0e6),
                fd.Frame(1, 90.0, -10.0, 0.0, 100.0e6), fd.Frame(1, 90.0, 10.0, 0.0, 100.0e6)],
        damping=fd.Damping.rayleigh(0.3, 1.0e-3),
        excitation=fd.Harmonic(0.01, 1.3, 0.002, 1.0),
        excitation2=fd.Harmonic(0.005, 0.9, 0.002, 1.0),
    )
    j = 2.0e5 * (20.0**2 + 12.0**2) / 12
    kx, ky = 200.0e6, 200.0e6
    ktz = 50.0e6 * 36 + 150.0e6 * 36 + 2 * 100.0e6 * 100
    kxz = -(50.0e6 * -6.0 + 150.0e6 * 6.0)    # b = (1, 0, -y) of an x frame at y
    k = np.array([[kx, 0.0, kxz], [0.0, ky, 0.0], [kxz, 0.0, ktz]])
    mats = fd.Analysis(
        matrices=fd.Matrices(k, np.diag([2.0e5, 2.0e5, j]), influence=[1.0, 0.0, 0.0],
                             influence2=[0.0, 1.0, 0.0]),
        damping=fd.Damping.rayleigh(0.3, 1.0e-3),
        excitation=fd.Harmonic(0.01, 1.3, 0.002, 1.0),
        excitation2=fd.Harmonic(0.005, 0.9, 0.002, 1.0),
    )
    a, b = floors.run(), mats.run()
    scale = np.abs(a["u3"]).max()
    assert scale > 1e-5                                   # it turns
    for i in (1, 2, 3):
        assert np.abs(a[f"u{i}"] - b[f"u{i}"]).max() <= 1e-10 * np.abs(a[f"u{i}"]).max()


def test_one_structure_is_given():
    with pytest.raises(fd.DeckError, match="masses, floors or matrices"):
        fd.Analysis(excitation=fd.Harmonic(0.01, 1.0, 0.01, 1.0)).deck_text()
    with pytest.raises(fd.DeckError, match="not masses and floors"):
        fd.Analysis(masses=[1.0], floors=fd.Floors([fd.Floor(1.0, inertia=1.0)]),
                    excitation=fd.Harmonic(0.01, 1.0, 0.01, 1.0)).deck_text()


def test_a_bad_floor_value_names_its_attribute():
    a = building3d()
    a.floors.floors[1].mass = -1.0
    with pytest.raises(fd.DeckError, match=r"Analysis\.floors\.floors\[1\]\.mass"):
        a.run()
    b = building3d()
    b.frames[4].k = -1.0
    with pytest.raises(fd.DeckError, match=r"Analysis\.frames\[4\]\.k"):
        b.run()
