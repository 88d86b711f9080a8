"""The design study of docs/examples.md (inputs/sweeps/building8_design.toml), in
small: two slip ratios, one brace stiffness and two of its records over 2 s, through the real
sweep command. The derived slip loads are alpha times the weight above each storey, and each
record's scale brings its 5 %-damped Sa at the structure's T1 to the intensity."""

from __future__ import annotations

import csv
import json
import shutil
import subprocess
import sys
from pathlib import Path

import f90nml
import numpy as np

import frictiondyn

ROOT = Path(__file__).resolve().parent.parent
STUDY = ROOT / "inputs" / "sweeps"
G = 9.80665


def _t1_stuck(deck: f90nml.Namelist) -> float:
    """First period of the shear building with every brace elastic (its sticking spring),
    from K and M built here."""
    m = np.asarray(deck["model"]["mass"], dtype=float)
    k = (np.asarray(deck["springs"]["k"], dtype=float)
         + np.asarray(deck["braces"]["stiffness"], dtype=float))
    n = len(m)
    kk = np.zeros((n, n))
    for s in range(n):  # storey s joins floor s to floor s - 1 (the ground below floor 1)
        kk[s, s] += k[s]
        if s > 0:
            kk[s - 1, s - 1] += k[s]
            kk[s, s - 1] -= k[s]
            kk[s - 1, s] -= k[s]
    w2 = np.linalg.eigvalsh(kk / np.sqrt(np.outer(m, m)))
    return float(2 * np.pi / np.sqrt(w2[0]))


def test_the_small_design_study_derives_slip_loads_and_scales_records_to_sa_t1(tmp_path):
    base = f90nml.read(STUDY / "building8_braces.nml")
    # the spec beside its base deck, as in inputs/sweeps/ (the deck names records/...)
    shutil.copy(STUDY / "building8_braces.nml", tmp_path)
    (tmp_path / "records").mkdir()
    records = [shutil.copy(f, tmp_path / "records")
               for f in sorted((STUDY / "records").glob("*.AT2"))[:2]]
    assert len(records) == 2
    spec = tmp_path / "small.toml"
    spec.write_text(
        'name = "small"\nbase = "building8_braces.nml"\n'
        "write_history = false\n"
        '[cross]\nalpha = [0.05, 0.1]\nbrace = [1.0]\n"excitation.duration" = [2.0]\n'
        '[labels]\nbrace = ["2x"]\n'
        '[derived]\n"braces.slip_load" = "alpha * weight_above"\n'
        '"braces.stiffness" = "brace * springs.k"\n'
        f"[records]\nfiles = {json.dumps(['records/' + Path(r).name for r in records])}\n"
        'scale_to = "sa"\nintensities = [0.4]\n')
    out = tmp_path / "o"
    r = subprocess.run([sys.executable, "-m", "frictiondyn", "sweep", str(spec), "--out", str(out),
                        "-j", "2", "--quiet"], capture_output=True, text=True, timeout=120)
    assert r.returncode == 0, r.stdout + r.stderr
    with open(out / "results.csv", newline="", encoding="utf-8") as fh:
        rows = list(csv.DictReader(fh))
    assert [row["status"] for row in rows] == ["done"] * 4
    assert {row["warnings"] for row in rows} == {"0"}

    # slip load of storey s = alpha g (m_s + ... + m_8), from the base deck's masses
    mass = np.asarray(base["model"]["mass"], dtype=float)
    above = G * np.cumsum(mass[::-1])[::-1]
    frame = np.asarray(base["springs"]["k"], dtype=float)
    for row in rows:
        deck = f90nml.read(out / row["run_deck"])
        alpha = float(row["alpha"])
        np.testing.assert_allclose(deck["braces"]["slip_load"], alpha * above, rtol=1e-12, atol=0)
        np.testing.assert_allclose(json.loads(row["braces.slip_load"]), alpha * above,
                                   rtol=1e-12, atol=0)
        assert row["brace"] == "2x" and float(row["brace [value]"]) == 1.0
        np.testing.assert_allclose(deck["braces"]["stiffness"], frame, rtol=1e-12, atol=0)

    # Sa(T1) of each scaled record = intensity g, T1 the base deck's (braces half as stiff)
    manifest = json.loads((out / "manifest.json").read_text())
    t1 = manifest["records"]["period"]
    assert manifest["records"]["period_of"] == "stuck system"
    assert abs(t1 - _t1_stuck(base)) <= 1e-9 * t1
    assert 0.8 < t1 < 0.85
    for row in rows:
        rec = STUDY / "records" / row["record"]
        sa = frictiondyn.response_spectrum(rec, periods=[t1], xi=0.05).psa[0]
        scale = float(row["excitation.record_scale"])
        assert float(row["record.scale"]) == scale  # the scale the run used
        assert abs(scale * sa - 0.4 * G) <= 1e-6 * 0.4 * G
