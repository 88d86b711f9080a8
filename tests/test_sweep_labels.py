"""Names of a sweep key's values ([labels]): the table's column holds the name and the
value beside it, the run's deck holds the value, and the plot's legend the name."""

from __future__ import annotations

import csv
import json
import subprocess
import sys

import pytest
from conftest import deck_text
from test_sweep import tiny

from frictiondyn import sweep as sw

SWEEP = [sys.executable, "-m", "frictiondyn", "sweep"]


def spec_with(tmp_path, labels: str):
    (tmp_path / "base.nml").write_text(deck_text(tiny()))
    spec = tmp_path / "s.toml"
    spec.write_text('base = "base.nml"\nwrite_history = false\n[cross]\n'
                    '"friction.p" = [49.05, 98.1, 196.2]\n"excitation.frequency" = [2.0, 3.0]\n'
                    + labels)
    return spec


def test_names_in_the_table_decks_and_legend(tmp_path):
    spec = spec_with(tmp_path, '[labels]\n"friction.p" = ["half", "1x", "2x"]\n')
    out = tmp_path / "o"
    r = subprocess.run([*SWEEP, str(spec), "--out", str(out), "--quiet"], capture_output=True,
                       text=True)
    assert r.returncode == 0, r.stderr
    with open(out / "results.csv", newline="") as fh:
        rows = list(csv.DictReader(fh))
    assert [r["friction.p"] for r in rows] == ["half", "half", "1x", "1x", "2x", "2x"]
    assert [float(r["friction.p [value]"]) for r in rows] == [49.05] * 2 + [98.1] * 2 + [196.2] * 2
    # the deck holds the value: the force never exceeds P mu (mu = 0.3), and at the
    # smallest P the device slides, so its peak force is P mu
    for row in rows:
        cap = 0.3 * float(row["friction.p [value]"])
        assert float(row["peak_force_N[1]"]) <= cap * (1 + 1e-9)
        if row["friction.p"] == "half":
            assert float(row["peak_force_N[1]"]) == pytest.approx(cap, rel=1e-9)
    deck = (out / "decks" / "r0002.nml").read_text()
    assert 'friction.p = "1x"' in deck.splitlines()[0]
    assert "98.1" in deck
    p = subprocess.run([*SWEEP, "plot", str(out), "excitation.frequency", "peak_u_m[1]", "--by",
                        "friction.p", "--out", str(tmp_path / "p.png")], capture_output=True, text=True)
    assert p.returncode == 0, p.stderr
    manifest = json.loads((out / "manifest.json").read_text())
    assert manifest["labels"]["friction.p"]["names"] == ["half", "1x", "2x"]
    assert sw.load(out).labels == manifest["labels"]


def test_sweep_plot_shows_its_axes_in_units(tmp_path, monkeypatch):
    """sweep plot --units: each axis in its column's unit (from the summary key's suffix), a
    drift ratio in %, a count as it is; the values plotted are the table's times the factor."""
    from matplotlib.figure import Figure

    assert sw.column_axis("peak_aabs_mps2[5]", "mm,kN,g") == (pytest.approx(1 / 9.80665, rel=1e-15),
                                                               "peak_aabs_mps2[5] [g]")
    assert sw.column_axis("peak_storey_shear_N[1]", "kN") == (1e-3, "peak_storey_shear_N[1] [kN]")
    assert sw.column_axis("peak_drift_ratio[2]") == (100.0, "peak_drift_ratio[2] [%]")
    assert sw.column_axis("peak_u_m[1]") == (1.0, "peak_u_m[1] [m]")
    assert sw.column_axis("stick_to_slip[1]", "mm") == (1.0, "stick_to_slip[1]")
    with pytest.raises(sw.SweepError, match="--units furlong"):
        sw.column_axis("peak_u_m[1]", "furlong")
    spec = spec_with(tmp_path, "")
    out = tmp_path / "o"
    r = subprocess.run([*SWEEP, str(spec), "--out", str(out), "--quiet"], capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    seen = {}
    real = Figure.savefig

    def savefig(self, *args, **kw):
        ax = self.axes[0]
        seen["y"], seen["x"] = ax.get_ylabel(), ax.get_xlabel()
        seen["data"] = sorted(float(v) for line in ax.get_lines() for v in line.get_ydata())
        return real(self, *args, **kw)

    monkeypatch.setattr(Figure, "savefig", savefig)
    sw.plot(out, "excitation.frequency", "peak_u_m[1]", out=tmp_path / "p.png", units="mm,kN,g")
    assert seen["y"] == "peak_u_m[1] [mm]" and seen["x"] == "excitation.frequency"
    with open(out / "results.csv", newline="") as fh:
        table = sorted(1000.0 * float(r["peak_u_m[1]"]) for r in csv.DictReader(fh))
    assert seen["data"] == table
    monkeypatch.undo()
    p = subprocess.run([*SWEEP, "plot", str(out), "excitation.frequency", "peak_force_N[1]",
                        "--units", "kN", "--out", str(tmp_path / "q.png")], capture_output=True, text=True)
    assert p.returncode == 0 and (tmp_path / "q.png").stat().st_size > 3000, p.stderr


@pytest.mark.parametrize("labels, words", [
    ('[labels]\n"friction.mu" = ["a"]\n', "not a key of [cross] or [zip]"),
    ('[labels]\n"friction.p" = ["a", "b"]\n', "one name"),
    ('[labels]\n"friction.p" = ["a", "a", "b"]\n', "a name given twice"),
    ('[labels]\n"friction.p" = ["a", "", "b"]\n', "one name"),
])
def test_bad_labels(tmp_path, labels, words):
    spec = spec_with(tmp_path, labels)
    with pytest.raises(sw.SweepError) as err:
        sw.expand(spec, tmp_path / "o")
    assert words in str(err.value)
