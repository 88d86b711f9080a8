"""Derived sweep values ([derived]): a deck variable computed in each run from the run's
parameters and the base deck's quantities, without Python's eval of the spec's text."""

from __future__ import annotations

import csv
import json
import subprocess
import sys

import numpy as np
import pytest
from conftest import INPUTS

from frictiondyn import sweep as sw
from frictiondyn.spectrum import G

SWEEP = [sys.executable, "-m", "frictiondyn", "sweep"]
MASS = np.array([300.0e3, 300.0e3, 300.0e3, 300.0e3, 250.0e3])  # building5_friction.nml


def spec(tmp_path, body: str):
    s = tmp_path / "s.toml"
    s.write_text(f'base = "{INPUTS}/building5_friction.nml"\nwrite_history = false\n' + body)
    return s


def test_slip_load_is_alpha_times_the_weight_above(tmp_path):
    """The slip load of each storey's damper, P mu = alpha W_above: the deck's P is
    alpha W_above / mu, W_above the weight of the floors above the damper's storey."""
    s = spec(tmp_path, '[cross]\nalpha = [0.02, 0.05]\n"friction.mu" = [[0.3, 0.3, 0.3, 0.3, 0.3]]\n'
                       '[derived]\n"friction.p" = "alpha * device_weight_above / friction.mu"\n'
                       'slip_total = "sum(friction.p * friction.mu)"\n'
                       '"excitation.duration" = "2.0"\n')
    out = tmp_path / "o"
    r = subprocess.run([*SWEEP, str(s), "--out", str(out), "--quiet"], capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    with open(out / "results.csv", newline="") as fh:
        rows = list(csv.DictReader(fh))
    above = G * np.cumsum(MASS[::-1])[::-1]  # storey i carries floors i..5
    for row in rows:
        alpha = float(row["alpha"])
        p = np.array(json.loads(row["friction.p"]))
        np.testing.assert_allclose(p * 0.3, alpha * above, rtol=1e-14)
        assert float(row["slip_total"]) == pytest.approx(alpha * above.sum(), rel=1e-14)
        # the run used them: the first storey's damper never carries more than its slip load
        assert float(row["peak_force_N[1]"]) <= alpha * above[0] * (1 + 1e-9)
    deck = (out / "decks" / "r0001.nml").read_text()
    assert "duration = 2.0" in deck


@pytest.mark.parametrize("derived, words", [
    ('"friction.p" = "__import__(\'os\').system(\'true\')"', "not allowed"),
    ('"friction.p" = "alpha.__class__"', "not a parameter"),
    ('"friction.p" = "open(\'x\')"', "not allowed"),
    ('"friction.p" = "alpha * nosuch"', "'nosuch' is not a parameter"),
    ('"friction.p" = "mass[1]"', "not allowed"),
    ('"friction.p" = "alpha / 0.0"', "not finite"),
    ('"friction.p" = "mass + [1, 2]"', "not allowed"),
    ('"friction.p" = "alpha * mass + springs.k[0:2]"', "not allowed"),
    ('alpha = "1.0"', "give it once"),
    ('"friction.nosuch" = "1.0"', "no variable"),
])
def test_bad_expressions(tmp_path, derived, words):
    s = spec(tmp_path, f'[cross]\nalpha = [0.02]\n[derived]\n{derived}\n')
    with pytest.raises(sw.SweepError) as err:
        sw.expand(s, tmp_path / "o")
    assert words in str(err.value)
    assert not (tmp_path / "o").exists()


def test_t1_is_the_base_decks_first_period(tmp_path):
    """T1 in an expression: the base deck's first period, here that of the bare 5-storey
    frame with its braces stuck (the stuck system's, with the hysteretic devices' sticking
    springs), as the base deck's own run reports it in periods_stuck_s."""
    import frictiondyn

    s = spec(tmp_path, '[cross]\nk = [1.0, 2.0]\n[derived]\nperiod_x = "k * T1"\n'
                       '"excitation.duration" = "0.05"\n')
    out = tmp_path / "o"
    r = subprocess.run([*SWEEP, str(s), "--out", str(out), "--quiet"], capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    t1 = frictiondyn.run(INPUTS / "building5_friction.nml").summary["periods_stuck_s"][0]
    with open(out / "results.csv", newline="") as fh:
        rows = list(csv.DictReader(fh))
    assert sorted(float(r["period_x"]) / float(r["k"]) for r in rows) == pytest.approx([t1, t1], rel=1e-12)


def test_weight_above_of_storeys_given_by_springs_and_of_rigid_floors(tmp_path):
    """weight_above where &storeys names springs (storey s is spring s's two nodes) equals
    the one given by nodes; for rigid floors it is the weight of floors s and above, and
    brace_weight_above that of each brace's storey (inputs/building3d.nml: 3 floors of 300 t,
    braces two a storey)."""
    import f90nml

    by_nodes = f90nml.read(INPUTS / "building5_friction.nml")
    by_nodes["storeys"] = {"n_storeys": 5, "node_i": [1, 2, 3, 4, 5], "node_j": [0, 1, 2, 3, 4]}
    q_nodes = sw._base_quantities(by_nodes)
    by_spring = f90nml.read(INPUTS / "building5_friction.nml")
    springs = by_spring["springs"]
    by_spring["storeys"] = {"n_storeys": 5}
    st = by_spring["storeys"]
    # the same storeys named by their springs, in reverse order of the springs' list
    order = list(range(len(springs["node_i"])))[::-1]
    springs["node_i"] = [springs["node_i"][k] for k in order]
    springs["node_j"] = [springs["node_j"][k] for k in order]
    springs["k"] = [springs["k"][k] for k in order]
    st["spring"] = [len(order) - s for s in range(5)]
    q_spring = sw._base_quantities(by_spring)
    above = G * np.cumsum(MASS[::-1])[::-1]
    np.testing.assert_allclose(q_nodes["weight_above"], above, rtol=1e-14)
    np.testing.assert_allclose(q_spring["weight_above"], above, rtol=1e-14)

    q = sw._base_quantities(f90nml.read(INPUTS / "building3d.nml"))
    np.testing.assert_allclose(q["weight_above"], G * np.array([900e3, 600e3, 300e3]), rtol=1e-14)
    np.testing.assert_allclose(q["brace_weight_above"],
                               G * np.array([900e3, 900e3, 600e3, 600e3, 300e3, 300e3]), rtol=1e-14)
    assert q["total_mass"] == pytest.approx(900e3, rel=1e-15)
    assert q["storey_height"] == [3.0, 3.0, 3.0]


def test_sweep_plot_draws_one_line_across_a_derived_value(tmp_path, monkeypatch):
    """A derived key follows the parameter it is computed from: sweep plot against alpha
    draws one line through both alphas (not a line per value of friction.p), and the
    manifest names the derived keys."""
    from matplotlib.figure import Figure

    s = spec(tmp_path, '[cross]\nalpha = [0.02, 0.05]\n[derived]\n'
                       '"friction.p" = "alpha * device_weight_above / friction.mu"\n'
                       '"excitation.duration" = "1.0"\n')
    out = tmp_path / "o"
    r = subprocess.run([*SWEEP, str(s), "--out", str(out), "--quiet"], capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    assert json.loads((out / "manifest.json").read_text())["derived"] == [
        "friction.p", "excitation.duration"]
    drawn = []
    monkeypatch.setattr(Figure, "savefig", lambda fig, *a, **k: drawn.append(fig))
    sw.plot(out, "alpha", "peak_force_N[1]")
    (ax,) = drawn[0].axes
    assert [len(line.get_xdata()) for line in ax.lines] == [2]
