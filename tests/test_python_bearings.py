"""fd.Analysis builds planar bearings (Bearing, &bearings) and the second and third
components of the ground motion (excitation2, excitation3, the vertical one): a model built in
Python runs exactly as its deck, and a bad argument is an error naming it and its value."""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pytest

import frictiondyn as fd
from frictiondyn.model import python_place

ROOT = Path(__file__).resolve().parents[1]
RECORDS = ROOT / "inputs" / "sweeps" / "records"
#: keys that name the deck or the run, not its numbers
NOT_NUMBERS = {"deck", "deck_sha256", "run_time_s", "record", "record2", "record3"}
CORNERS = ((-8.0, -5.0), (8.0, -5.0), (8.0, 5.0), (-8.0, 5.0))


def same_numbers(a: fd.Result, b: fd.Result) -> None:
    """Every number of the summaries and every history column equal, bit for bit."""
    sa, sb = a.summary, b.summary
    assert set(sa) == set(sb)
    for key in set(sa) - NOT_NUMBERS:
        assert sa[key] == sb[key], key
    assert a.names == b.names
    for name in a.names:
        assert np.array_equal(a[name], b[name]), name


def isolated_vertical(duration: float = 20.0, **kw) -> fd.Analysis:
    """examples/isolated_vertical.nml built in Python: a base slab and three floors on four
    friction pendulum bearings under the records s11 (x), s22 (y) and 2/3 s33 (vertical)."""
    masses = (250.0e3, 200.0e3, 200.0e3, 200.0e3)
    labels = ("base slab", "floor 1", "floor 2", "roof")
    args = dict(
        floors=fd.Floors([fd.Floor(m, plan_x=20.0, plan_y=12.0, height=h, label=name)
                          for m, h, name in zip(masses, (0.0, 3.5, 3.5, 3.5), labels, strict=True)]),
        frames=[fd.Frame(s, angle, x, y, 75.0e6) for s in (2, 3, 4)
                for angle, x, y in ((0, 0, -6), (0, 0, 6), (90, -10, 0), (90, 10, 0))],
        damping=fd.Damping.rayleigh_modes(0.02, 1, 2),
        bearings=[fd.Bearing(storey=1, x=x, y=y, law="velocity", mu=0.05, eps=1.0e-3, radius=2.0)
                  for x, y in CORNERS],
        excitation=fd.Record(file=RECORDS / "synthetic_s11.AT2", duration=duration),
        excitation2=fd.Record(file=RECORDS / "synthetic_s22.AT2", duration=duration),
        excitation3=fd.Record(file=RECORDS / "synthetic_s33.AT2", scale=2 / 3, duration=duration),
        integration=fd.Integration(n1=10, n2=50),
    )
    args.update(kw)
    return fd.Analysis(**args)


@pytest.fixture(scope="module")
def example() -> fd.Result:
    return fd.run(ROOT / "examples" / "isolated_vertical.nml")


def test_python_isolated_building_under_three_components_is_the_deck(example):
    """The isolated building of docs/examples.md 6.1 built in Python runs exactly as
    examples/isolated_vertical.nml: its four bearings' normal forces follow the vertical
    record, and every number of the summary and every history column are the deck's."""
    r = isolated_vertical().run()
    same_numbers(r, example)
    for key in ("record", "record2", "record3"):
        assert r.summary[key]["sha256"] == example.summary[key]["sha256"]
    assert example.summary["record3"]["file"].endswith("synthetic_s33.AT2")
    assert example.summary["record3"]["scale"] == pytest.approx(2 / 3, rel=1e-15)
    # each bearing carries a quarter of the weight, p = g 850 t / 4, swung by 2/3 s33
    p = 9.80665 * 850.0e3 / 4
    n_min, n_max = r.summary["bearing_min_normal_force_N"], r.summary["bearing_max_normal_force_N"]
    assert len(n_min) == 4 and max(n_min) < 0.8 * p and min(n_max) > 1.2 * p


def test_records_from_arrays_with_units_and_scale_are_the_files(example):
    """The three components given as arrays of the AT2 files' values (in g, with their
    units and the vertical's scale, as the deck's groups take them) run exactly as the
    files: the arrays go to a temporary directory under three names."""

    def values(name: str) -> np.ndarray:
        lines = (RECORDS / name).read_text().splitlines()[4:]
        return np.array([float(v) for line in lines for v in line.split()])

    def record(name: str, **kw) -> fd.Record:
        return fd.Record(values=values(name), dt_record=0.01, units="g", duration=20.0, **kw)

    a = isolated_vertical(excitation=record("synthetic_s11.AT2"), excitation2=record("synthetic_s22.AT2"),
                          excitation3=record("synthetic_s33.AT2", scale=2 / 3))
    r = a.run()
    same_numbers(r, example)
    assert r.summary["record2"]["units"] == "g" and r.summary["record2"]["format"] == "values"


def test_write_deck_writes_the_vertical_record_beside_it(tmp_path):
    """write_deck puts each component's values next to the deck (<stem>.record.txt,
    .record2.txt, .record3.txt), and the executable's reader of that deck gives run()'s
    numbers."""
    t = np.arange(201) * 0.01
    comp = [fd.Record(values=a * np.sin(w * t), dt_record=0.01, units=u)
            for a, w, u in ((0.3, 9.0, "g"), (0.2, 7.0, "g"), (150.0, 23.0, "cm/s2"))]
    a = isolated_vertical(excitation=comp[0], excitation2=comp[1], excitation3=comp[2])
    path = a.write_deck(tmp_path / "iso.nml")
    assert sorted(p.name for p in tmp_path.iterdir()) == [
        "iso.nml", "iso.record.txt", "iso.record2.txt", "iso.record3.txt"]
    text = path.read_text()
    assert "&bearings" in text and "&excitation3" in text and "record_units = 'cm/s2'" in text
    same_numbers(a.run(), fd.run(path))


def block_on_a_bearing(**kw) -> fd.Analysis:
    """A block (ux DOF 1, uy DOF 2) on one friction pendulum on the table, under a harmonic
    table motion and a harmonic vertical motion."""
    args = dict(
        masses=[2.0e4, 2.0e4],
        damping=fd.Damping(type="none"),
        bearings=[fd.Bearing(dof_xi=1, dof_yi=2, dof_xj=0, dof_yj=0, law="hysteretic", p=196133.0,
                             mu=0.08, f=1.0e-4, radius=1.5, label="pendulum")],
        excitation=fd.Harmonic(amplitude=0.05, frequency=1.2, dt_record=0.005, duration=3.0),
        excitation3=fd.Harmonic(amplitude=0.004, frequency=3.1, dt_record=0.005, duration=3.0),
        integration=fd.Integration(n1=4),
    )
    args.update(kw)
    return fd.Analysis(**args)


BLOCK_DECK = """
&model
    n_dof = 2
    mass = 2.0e4, 2.0e4
/
&springs
    n_springs = 0
/
&damping
    damping_type = 'none'
/
&bearings
    n_bearings = 1
    dof_xi = 1
    dof_yi = 2
    dof_xj = 0
    dof_yj = 0
    law = 'hysteretic'
    p = 196133.0
    mu = 0.08
    f = 1.0e-4
    radius = 1.5
    label = 'pendulum'
/
&excitation
    excitation_type = 'harmonic'
    amplitude = 0.05
    frequency = 1.2
    dt_record = 0.005
    duration = 3.0
/
&excitation3
    excitation_type = 'harmonic'
    amplitude = 0.004
    frequency = 3.1
    dt_record = 0.005
    duration = 3.0
/
&integration
    n1 = 4
/
"""


def test_bearing_between_dofs_under_a_harmonic_vertical_motion_is_the_deck():
    """A bearing of a model of masses (dof_xi, dof_yi on dof_xj, dof_yj) and a harmonic
    vertical component: the run equals the hand-written deck's, and its normal force
    swings by the harmonic's peak acceleration a0 (2 pi f)^2 / g (15 %) about p."""
    r = block_on_a_bearing().run()
    same_numbers(r, fd.run_text(BLOCK_DECK, "block.nml"))
    assert r.device_labels == ["pendulum x", "pendulum y"]
    p, swing = 196133.0, 0.004 * (2 * np.pi * 3.1) ** 2 / 9.80665
    assert r.summary["bearing_max_normal_force_N"][0] == pytest.approx(p * (1 + swing), rel=1e-3)
    assert r.summary["bearing_min_normal_force_N"][0] == pytest.approx(p * (1 - swing), rel=1e-3)


def test_bearing_on_an_elastic_vertical_support_is_the_deck():
    """Bearing(kv=..., zeta_v=...) writes the &bearings' kv and zeta_v: the run equals the
    hand-written deck's with them, its support (a vertical period of 0.06 s, 3 % damping)
    amplifies the normal force's swing beyond the rigid support's, and the summary reports the
    peak uplift (0: it stays down)."""
    kv = 2.0e4 * (2 * np.pi / 0.06) ** 2
    bearing = fd.Bearing(dof_xi=1, dof_yi=2, dof_xj=0, dof_yj=0, law="hysteretic", p=196133.0, mu=0.08,
                         f=1.0e-4, radius=1.5, label="pendulum", kv=kv, zeta_v=0.03)
    r = block_on_a_bearing(bearings=[bearing]).run()
    deck = BLOCK_DECK.replace("    radius = 1.5\n", f"    radius = 1.5\n    kv = {kv!r}\n    zeta_v = 0.03\n")
    assert "zeta_v" in deck
    same_numbers(r, fd.run_text(deck, "block.nml"))
    rigid = block_on_a_bearing().run()
    assert r.summary["bearing_max_normal_force_N"][0] > rigid.summary["bearing_max_normal_force_N"][0]
    assert r.summary["bearing_uplift_peak_m"] == [0.0]
    with pytest.raises(fd.DeckError, match=r"Analysis.bearings\[0\].kv must be a number, not 'stiff'"):
        block_on_a_bearing(bearings=[fd.Bearing(dof_xi=1, dof_yi=2, p=1.0, mu=0.1, kv="stiff")]).run()


def test_python_place_of_bearing_and_vertical_messages():
    assert python_place("a.nml, group &bearings: mu(3) = -1 is invalid: must be >= 0") == "bearings[2].mu"
    assert python_place("a.nml, group &bearings: mu_table_v(:, 2) must increase") == "bearings[1].mu_table"
    assert python_place("a.nml, group &excitation3: record_scale = 0 is invalid") == "excitation3.scale"
    assert python_place("a.nml, group &excitation2: dt_record = 0.02 is invalid") == "excitation2.dt_record"


@pytest.mark.parametrize("change, message", [
    # what only Python can say: the type of each argument, and where a bearing stands
    (dict(bearings=fd.Bearing(storey=1, x=0.0, y=0.0, mu=0.05)),
     "Analysis.bearings must be a list of Bearing, not Bearing("),
    (dict(bearings=[{"storey": 1, "x": 0.0, "y": 0.0, "mu": 0.05}]),
     "Analysis.bearings[0] must be a Bearing, not {'storey': 1"),
    (dict(bearings=[fd.Bearing(storey=1, x=0.0, y=0.0, mu=0.05), fd.Bearing(dof_xi=1, dof_yi=2, mu=0.05)]),
     "Analysis.bearings[1].dof_xi = 1: a bearing of a building of rigid floors is placed by storey, x, y"),
    (dict(bearings=[fd.Bearing(storey=1.5, x=0.0, y=0.0, mu=0.05)]),
     "Analysis.bearings[0].storey must be an integer, not 1.5"),
    (dict(bearings=[fd.Bearing(storey=1, x=0.0, y=0.0, mu="0.05")]),
     "Analysis.bearings[0].mu must be a number, not '0.05'"),
    (dict(bearings=[fd.Bearing(storey=1, x=0.0, y=0.0, mu=0.05, radius=True)]),
     "Analysis.bearings[0].radius must be a number, not True"),
    (dict(bearings=[fd.Bearing(storey=1, x=0.0, y=0.0, mu=0.05, law=2)]),
     "Analysis.bearings[0].law must be a string, not 2"),
    (dict(bearings=[fd.Bearing(storey=1, x=0.0, y=0.0, mu_law="table", mu_table=[0.1, 0.05])]),
     "Analysis.bearings[0].mu_table must be a list of points (v, mu), not [0.1, 0.05]"),
    (dict(excitation3=np.zeros(5)),
     "Analysis.excitation3 must be a Harmonic or a Record (the vertical ground motion), not array("),
    # the reader's checks, named as the Analysis's attributes
    (dict(bearings=[fd.Bearing(storey=1, x=0.0, y=0.0, mu=0.05), fd.Bearing(storey=1, x=1.0, y=0.0, mu=-0.1)]),
     "Analysis.bearings[1].mu: group &bearings: mu(2) = -0.1"),
    (dict(bearings=[fd.Bearing(storey=1, x=0.0, y=0.0, mu=0.05, law="elastic")]),
     "Analysis.bearings[0].law: group &bearings: law(1) = 'elastic'"),
    (dict(bearings=[fd.Bearing(storey=5, x=0.0, y=0.0, mu=0.05)]),
     "Analysis.bearings[0].storey: group &bearings: storey(1) = 5"),
    (dict(bearings=[fd.Bearing(storey=1, x=0.0, y=0.0, mu=0.05, radius=-2.0)]),
     "Analysis.bearings[0].radius: group &bearings: radius(1) = -2"),
    (dict(excitation3=fd.Record(file=RECORDS / "synthetic_s33.AT2", scale=0.0)),
     "Analysis.excitation3.scale: group &excitation3: record_scale = 0"),
    (dict(excitation3=fd.Harmonic(amplitude=0.01, frequency=2.0, dt_record=0.02, duration=1.0)),
     "Analysis.excitation3.dt_record: group &excitation3: dt_record = 0.02"),
])
def test_bad_arguments_name_the_argument_and_the_value(change, message):
    """Nothing runs: the error names the attribute of the Analysis and its value."""
    with pytest.raises(fd.DeckError) as err:
        isolated_vertical(duration=1.0, **change).run()
    text = str(err.value)
    assert text.startswith(message), text
    assert "analysis.nml" not in text


def test_a_bearing_of_masses_is_not_placed_by_a_plan_point():
    with pytest.raises(fd.DeckError, match=re.escape(
            "Analysis.bearings[0].storey = 1: a bearing of a model of masses or matrices is placed by "
            "dof_xi, dof_yi, dof_xj, dof_yj")):
        block_on_a_bearing(bearings=[fd.Bearing(storey=1, x=0.0, y=0.0, p=1.0e5, mu=0.05)]).run()


def test_a_vertical_component_without_bearings_is_refused():
    """The reader's message, naming &excitation3: nothing else takes a vertical motion."""
    with pytest.raises(fd.DeckError, match=r"^Analysis: group &excitation3 is the vertical ground motion"):
        block_on_a_bearing(bearings=[]).run()


def test_bearing_takes_keywords_only():
    with pytest.raises(TypeError):
        fd.Bearing(1, 0.0, 0.0)  # type: ignore[misc]


def test_the_documented_python_example_is_the_deck(example, monkeypatch, capsys):
    """docs/examples.md 6.2's code, run as shown (from the repository's root), is
    examples/isolated_vertical.nml bit for bit, and prints the figures its comments quote."""
    text = (ROOT / "docs" / "examples.md").read_text()
    section = text[text.index("### 6.2 From Python"):]
    code = section[section.index("```python\n") + 10:section.index("```\n", section.index("```python"))]
    monkeypatch.chdir(ROOT)
    scope: dict = {}
    exec(compile(code, "docs/examples.md 6.2", "exec"), scope)  # noqa: S102 - the docs' own code
    same_numbers(scope["r"], example)
    peak, n_min = (float(x) for x in capsys.readouterr().out.split())
    assert f"{peak:.4f} m" in code and f"{n_min / 1e6:.3f}e6 N" in code
