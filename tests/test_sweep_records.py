"""Record suites in sweeps ([records]): every record is scaled to each intensity (its PGA,
or its 5 %-damped pseudo-acceleration at a period), read as the base deck reads it; the
statistics over records per intensity (intensity.csv) are those of the runs' summaries."""

from __future__ import annotations

import csv
import json
import math
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from conftest import INPUTS

from frictiondyn import response_spectrum
from frictiondyn import sweep as sw
from frictiondyn.spectrum import G

SWEEP = [sys.executable, "-m", "frictiondyn", "sweep"]
AT2 = INPUTS / "synthetic_pga035.AT2"

BASE = """&model
  n_dof = 1, mass = 1000.0
/
&springs
  n_springs = 1, node_i = 1, node_j = 0, k = 4.0e5
/
&damping
  damping_type = 'stiffness', xi = 0.02, period = 0.31
/
&friction
  n_devices = 1, node_i = 1, node_j = 0, law = 'velocity', p = 9810.0, mu = 0.1, eps = 1.0e-3
/
&excitation
  excitation_type = 'record', record_file = 'rec/a.AT2', duration = 4.0
/
&integration
  n1 = 4, n2 = 10
/
&output
  write_history = .false.
/
"""


def suite(tmp_path: Path, records: str) -> Path:
    """A base deck and two AT2 records: the bundled one and a copy at 0.6 of it, reversed
    in sign (so the two need different scales)."""
    (tmp_path / "rec").mkdir()
    text = AT2.read_text().splitlines()
    (tmp_path / "rec" / "a.AT2").write_text("\n".join(text) + "\n")
    body = [" ".join(f"{-0.6 * float(x):.7e}" for x in line.split()) for line in text[4:]]
    (tmp_path / "rec" / "b.AT2").write_text("\n".join(text[:4] + body) + "\n")
    (tmp_path / "base.nml").write_text(BASE)
    spec = tmp_path / "suite.toml"
    spec.write_text('name = "suite"\nbase = "base.nml"\n[cross]\n"friction.mu" = [0.05, 0.1]\n'
                    + records)
    return spec


def table(path: Path) -> list[dict[str, str]]:
    with open(path, newline="") as f:
        return list(csv.DictReader(f))


def test_scaled_to_pga(tmp_path):
    spec = suite(tmp_path, '[records]\nfiles = ["rec/*.AT2"]\nintensities = [0.1, 0.3]\n')
    out = tmp_path / "s"
    p = subprocess.run([*SWEEP, str(spec), "--out", str(out), "-j", "2", "--quiet"],
                       capture_output=True, text=True)
    assert p.returncode == 0, p.stderr
    rows = table(out / "results.csv")
    assert len(rows) == 2 * 2 * 2 and all(r["status"] == "done" for r in rows)
    for r in rows:
        # the run's table motion peaks at the intensity: the library's own figure
        assert float(r["record.peak_acc_mps2"]) == pytest.approx(float(r["intensity_g"]) * G,
                                                                 rel=1e-6)
    scales = {(r["record"], r["intensity_g"]): float(r["excitation.record_scale"]) for r in rows}
    assert scales[("b.AT2", "0.1")] == pytest.approx(scales[("a.AT2", "0.1")] / 0.6, rel=1e-6)
    # the IDA plot: the response against the intensity, one curve per record
    p = subprocess.run([*SWEEP, "plot", str(out), "peak_u_m[1]", "intensity_g", "--by", "record",
                        "--out", str(tmp_path / "ida.png")], capture_output=True, text=True)
    assert p.returncode == 0, p.stderr
    assert (tmp_path / "ida.png").stat().st_size > 5000
    stats = table(out / "intensity.csv")
    assert len(stats) == 2 * 2  # mu x intensity
    for s in stats:
        members = [r for r in rows if r["intensity_g"] == s["intensity_g"]
                   and r["friction.mu"] == s["friction.mu"]]
        assert int(s["records"]) == len(members) == 2
        for key in ("peak_u_m[1]", "peak_force_N[1]", "record.peak_acc_mps2"):
            x = np.array([float(m[key]) for m in members])
            assert float(s[f"{key}.median"]) == pytest.approx(np.median(x), rel=1e-12)
            assert float(s[f"{key}.p16"]) == pytest.approx(np.percentile(x, 16), rel=1e-12)
            assert float(s[f"{key}.p84"]) == pytest.approx(np.percentile(x, 84), rel=1e-12)


def test_scaled_to_sa(tmp_path):
    spec = suite(tmp_path, '[records]\nfiles = ["rec/a.AT2", "rec/b.AT2"]\nscale_to = "sa"\n'
                           'period = 0.6\nintensities = [0.5]\n')
    with sw.expand(spec, tmp_path / "s") as sweep:
        assert sweep.parameters[-4:] == list(sw.SUITE_KEYS)
        for run in sweep.runs:
            rec = tmp_path / "rec" / run.params["record"]
            s = response_spectrum(rec, periods=[0.6], scale=run.params["excitation.record_scale"])
            assert s.psa[0] == pytest.approx(0.5 * G, rel=1e-9)
    loaded = sw.load(tmp_path / "s")
    assert loaded.records["scale_to"] == "sa" and loaded.records["period"] == 0.6


def test_scaled_to_sa_at_the_structures_first_period(tmp_path):
    """Without a period, 'sa' is taken at the base deck's T1: here its stuck system is rigid
    (the device holds the mass to the table), so the free system's, 2 pi sqrt(m / k)."""
    spec = suite(tmp_path, '[records]\nfiles = ["rec/a.AT2"]\nscale_to = "sa"\nintensities = [0.4]\n')
    t1 = 2 * math.pi * math.sqrt(1000.0 / 4.0e5)
    with sw.expand(spec, tmp_path / "s") as sweep:
        for run in sweep.runs:
            s = response_spectrum(tmp_path / "rec" / "a.AT2", periods=[t1],
                                  scale=run.params["excitation.record_scale"])
            assert s.psa[0] == pytest.approx(0.4 * G, rel=1e-9)
    loaded = sw.load(tmp_path / "s")
    assert loaded.records["period"] == pytest.approx(t1, rel=1e-12)
    assert loaded.records["period_of"] == "free system"


@pytest.mark.parametrize("records, words", [
    ('[records]\nfiles = ["rec/none*.AT2"]\nintensities = [0.1]\n', "names no file"),
    ('[records]\nfiles = ["rec/a.AT2"]\nscale_to = "sa"\nperiod = -1.0\nintensities = [0.1]\n', "> 0"),
    ('[records]\nfiles = ["rec/a.AT2"]\nintensities = [0.0]\n', "numbers > 0"),
    ('[records]\nfiles = ["rec/a.AT2"]\nscale_to = "pgv"\nintensities = [0.1]\n', "'pga' or 'sa'"),
    ('[records]\nfiles = ["rec/a.AT2", "rec/a.AT2"]\nintensities = [0.1]\n', "named twice"),
    ('[records]\nfiles = ["rec/a.AT2"]\nintensities = [0.1]\n[zip]\n'
     '"excitation.record_scale" = [2.0]\n', "[records] sets it"),
])
def test_bad_records(tmp_path, records, words):
    spec = suite(tmp_path, records)
    with pytest.raises(sw.SweepError, match=None) as err:
        sw.expand(spec, tmp_path / "s")
    assert words in str(err.value)
    assert not (tmp_path / "s").exists()


def test_ida_curves_are_the_medians_of_the_runs(tmp_path):
    """sweep ida: per intensity, the median and the 16th/84th percentiles over the records of
    each run's largest peak drift ratio, as the runs' own summaries give it; and the PNG."""
    spec = suite(tmp_path, '[records]\nfiles = ["rec/a.AT2", "rec/b.AT2"]\nintensities = [0.2, 0.4]\n')
    base = (tmp_path / "base.nml").read_text().replace(
        "&output", "&storeys\n  n_storeys = 1, node_i = 1, node_j = 0, height = 3.0\n/\n&output")
    (tmp_path / "base.nml").write_text(base)
    out = tmp_path / "s"
    r = subprocess.run([*SWEEP, str(spec), "--out", str(out), "--quiet"], capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    curves = sw.ida_curves(out, by="friction.mu")
    loaded = sw.load(out)
    assert sorted(curves) == ["friction.mu = 0.05", "friction.mu = 0.1"]
    for run in loaded.runs:
        summary = json.loads((out / run.summary).read_text())
        drift = 100 * max(summary["peak_drift_ratio"])
        c = curves[f"friction.mu = {run.params['friction.mu']}"]
        assert (run.params["intensity_g"], pytest.approx(drift, rel=1e-12)) in [
            (i, pytest.approx(x, rel=1e-12)) for i, x in c["records"][run.params["record"]]]
    for c in curves.values():
        for k, level in enumerate(c["intensity"]):
            xs = [dict(p)[level] for p in c["records"].values()]
            assert c["median"][k] == pytest.approx(np.median(xs), rel=1e-12)
            assert c["p16"][k] == pytest.approx(np.percentile(xs, 16), rel=1e-12)
    # without --by, a record's point would pool the two mu's runs: refused, naming mu
    with pytest.raises(sw.SweepError, match="friction.mu"):
        sw.ida_curves(out)
    one = sw.ida_curves(out, where={"friction.mu": "0.1"})
    assert one[""]["median"] == curves["friction.mu = 0.1"]["median"]
    # the intensity axis names the measure the records were scaled to
    assert one[""]["intensity_axis"] == "PGA [g]"
    assert sw.intensity_label({"scale_to": "sa", "period": 0.8139690061706273, "damping": 0.05}) \
        == "Sa(0.814 s, 5 % damped) [g]"
    r = subprocess.run([*SWEEP, "ida", str(out), "--by", "friction.mu", "--dpi", "60"], capture_output=True,
                       text=True)
    assert r.returncode == 0, r.stderr
    assert (out / "ida_drift_ratio.png").stat().st_size > 3000


def test_sweep_plot_of_a_suite_at_a_resolution(tmp_path):
    """sweep plot of a record suite at --dpi: the image's width doubles with the dpi."""
    import matplotlib.image as mpimg

    spec = suite(tmp_path, '[records]\nfiles = ["rec/a.AT2", "rec/b.AT2"]\nintensities = [0.2, 0.4]\n')
    out = tmp_path / "s"
    r = subprocess.run([*SWEEP, str(spec), "--out", str(out), "--quiet"], capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    sizes = []
    for dpi in (50, 100):
        png = sw.plot(out, "friction.mu", "peak_u_m[1]", out=tmp_path / f"p{dpi}.png", dpi=dpi)
        sizes.append(mpimg.imread(png).shape[1])
    assert sizes[1] == pytest.approx(2 * sizes[0], rel=0.05)
