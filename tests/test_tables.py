"""Long tables of a sweep (one row per run and storey, device or DOF) and Parquet copies of
tables and histories: the same values as the wide table and the CSV history."""

from __future__ import annotations

import csv
import subprocess
import sys

import numpy as np
import pytest
from conftest import INPUTS

import frictiondyn as fd
from frictiondyn import sweep as sw

pa = pytest.importorskip("pyarrow")
import pyarrow.parquet as pq  # noqa: E402

ROOT = INPUTS.parent
SWEEP = [sys.executable, "-m", "frictiondyn", "sweep"]


def test_every_long_table_key_is_in_the_summaries():
    """The keys the long tables take are those the library writes, one value an item."""
    for name, count in (("isolated_fps", "n_storeys"), ("building5_friction", "n_devices")):
        summ = fd.run(INPUTS / f"{name}.nml").summary
        for entity, (labels, keys) in sw.LONG_TABLES.items():
            n = len(summ[labels])
            for k in keys:
                assert k in summ, (name, k)
                assert len(summ[k]) == n, (name, k)


def test_long_tables_equal_the_wide_one(tmp_path):
    spec = tmp_path / "s.toml"
    spec.write_text(f'base = "{INPUTS}/isolated_fps.nml"\nwrite_history = false\n[cross]\n'
                    '"excitation.duration" = [2.0, 3.0]\n')
    out = tmp_path / "o"
    r = subprocess.run([*SWEEP, str(spec), "--out", str(out), "--quiet"], capture_output=True,
                       text=True)
    assert r.returncode == 0, r.stderr
    with open(out / "results.csv", newline="") as fh:
        wide = {row["run"]: row for row in csv.DictReader(fh)}
    with open(out / "results_storeys.csv", newline="") as fh:
        storeys = list(csv.DictReader(fh))
    assert len(storeys) == 2 * 4
    for row in storeys:
        s = int(row["storey"])
        w = wide[row["run"]]
        assert row["excitation.duration"] == w["excitation.duration"]
        for k in ("peak_drift_m", "peak_storey_shear_N", "residual_drift_m"):
            assert float(row[k]) == float(w[f"{k}[{s}]"])
    with open(out / "results_devices.csv", newline="") as fh:
        devices = list(csv.DictReader(fh))
    assert len(devices) == 2 and devices[0]["device_label"] == "isolators"
    assert float(devices[0]["peak_force_N"]) == float(wide[devices[0]["run"]]["peak_force_N[1]"])
    # each device's dissipated energy, slip travel and excursions, in both tables
    for row in devices:
        w = wide[row["run"]]
        for k in ("dissipated_energy_J", "slip_travel_m", "slip_excursions"):
            assert float(row[k]) == float(w[f"{k}[1]"]), k
        assert float(row["dissipated_energy_J"]) == pytest.approx(float(w["energy_friction_J"]), rel=1e-12)
        assert float(row["slip_travel_m"]) > 0.0 and int(row["slip_excursions"]) >= 1
    # the Parquet copies hold the same rows
    t = pq.read_table(out / "results_storeys.parquet").to_pylist()
    assert [r["peak_drift_m"] for r in t] == [float(r["peak_drift_m"]) for r in storeys]
    assert pq.read_table(out / "results.parquet").num_rows == 2


def test_history_to_parquet_and_back(tmp_path):
    r = fd.run(INPUTS / "test1_velocity.nml")
    path = r.to_parquet(tmp_path / "h.parquet")
    back = fd.Result.from_parquet(path)
    assert back.names == r.names and back.units == r.units
    np.testing.assert_array_equal(back.data, r.data)
    assert back.summary == r.summary
    with pytest.raises(fd.OutputError):
        r.to_parquet(tmp_path / "no" / "such" / "h.parquet")
    plain = tmp_path / "plain.parquet"
    pq.write_table(pa.table({"x": [1.0]}), plain)
    with pytest.raises(fd.FrictiondynError, match="not a history"):
        fd.Result.from_parquet(plain)


def test_run_writes_the_history_as_parquet_from_the_command_line(tmp_path):
    """``python -m frictiondyn run DECK --parquet``: the history also as <name>.parquet, the
    CSV's values exactly, with the summary; ``plot`` and ``compare`` read it back."""
    from frictiondyn.cli import load_result
    from frictiondyn.cli import main as cli

    out = tmp_path / "out"
    assert cli(["run", str(INPUTS / "test1_velocity.nml"), "--parquet", "--out", str(out),
                "--quiet"]) == 0
    csv_result = fd.Result.from_files(out / "test1_velocity.csv")
    back = load_result(out / "test1_velocity.parquet")
    assert back.names == csv_result.names and back.units == csv_result.units
    np.testing.assert_array_equal(back.data, csv_result.data)
    assert back.summary == csv_result.summary


def test_envelope_over_the_storeys(tmp_path):
    """Envelopes of a sweep with storeys: per run, and per value of a parameter (the median
    and the percentile band); an unknown parameter named."""
    spec = tmp_path / "s.toml"
    spec.write_text(f'base = "{INPUTS}/isolated_fps.nml"\nwrite_history = false\n[cross]\n'
                    '"excitation.duration" = [2.0, 3.0]\n"isolators.mu_max" = [0.05, 0.08]\n')
    out = tmp_path / "o"
    r = subprocess.run([*SWEEP, str(spec), "--out", str(out), "--quiet"], capture_output=True,
                       text=True)
    assert r.returncode == 0, r.stderr
    r = subprocess.run([*SWEEP, "envelope", str(out), "--dpi", "60"], capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    assert (out / "envelope_drift_ratio.png").stat().st_size > 3000
    r = subprocess.run([*SWEEP, "envelope", str(out), "--quantity", "shear", "--units", "kN",
                        "--by", "isolators.mu_max", "--out", str(tmp_path / "v.png"), "--dpi", "60"],
                       capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    assert (tmp_path / "v.png").stat().st_size > 3000
    with pytest.raises(sw.SweepError, match="nosuch"):
        sw.envelope(out, by="nosuch")
