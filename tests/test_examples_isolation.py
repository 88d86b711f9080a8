"""docs/examples.md, section 6: a building on four planar friction pendulum bearings
(examples/isolated_planar.nml) against the same building on an x and a y slider side by
side at each corner (examples/isolated_side_by_side.nml). The planar bearings' friction
resultant never exceeds mu W and the side-by-side pair's reaches sqrt(2) mu W (both to
1e-9: friction of one magnitude against two), and the figures section 6 quotes are the
runs' own."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import frictiondyn

ROOT = Path(__file__).resolve().parent.parent
EXAMPLES = ROOT / "examples"
G = 9.80665
W = (250.0e3 + 3 * 200.0e3) * G
MU = 0.05


@pytest.fixture(scope="module")
def runs():
    return {k: frictiondyn.run(EXAMPLES / f"isolated_{k}.nml") for k in ("planar", "side_by_side", "vertical")}


def friction_resultant(r, pairs) -> np.ndarray:
    return np.hypot(sum(r[f"F{x}"] for x, _ in pairs), sum(r[f"F{y}"] for _, y in pairs))


def test_one_magnitude_against_two(runs):
    a, b = runs["planar"], runs["side_by_side"]
    # planar: bearing i is devices 2i-1 (x) and 2i (y); side by side: braces in x, y pairs
    fa = friction_resultant(a, [(2 * i + 1, 2 * i + 2) for i in range(4)])
    fb = friction_resultant(b, [(2 * i + 1, 2 * i + 2) for i in range(4)])
    assert a.device_labels[:2] == ["bearing 1 x", "bearing 1 y"]
    assert fa.max() <= MU * W * (1 + 1e-9)
    assert fa.max() == pytest.approx(MU * W, rel=1e-9)
    assert fb.max() == pytest.approx(np.sqrt(2) * MU * W, rel=1e-9)
    # each bearing's own resultant force stays within its disc P mu = mu W / 4
    for i in range(4):
        assert np.hypot(a[f"F{2 * i + 1}"], a[f"F{2 * i + 2}"]).max() <= MU * W / 4 * (1 + 1e-9)


def test_the_figures_section_6_quotes(runs):
    a, b = runs["planar"], runs["side_by_side"]
    sa, sb = a.summary, b.summary
    assert sa["periods_free_s"][0] == pytest.approx(sb["periods_free_s"][0], rel=1e-12)
    assert sa["damping_a0_per_s"] == pytest.approx(sb["damping_a0_per_s"], rel=1e-12)
    text = (ROOT / "docs" / "examples.md").read_text()
    section = text[text.index("## 6. Base isolation"):]
    slab_b = np.hypot(b["u1"], b["u2"]).max()
    quoted = [
        f"| {MU * W / 1e3:.0f} kN = μ W | {np.sqrt(2) * MU * W / 1e3:.0f} kN = √2 μ W |",
        f"| {1e3 * sa['bearing_peak_displacement_m'][0]:.1f} mm | {1e3 * slab_b:.1f} mm |",
        " / ".join(f"{100 * x:.3f}" for x in sa["peak_drift_ratio"][2::2]) + " %",
        " / ".join(f"{100 * x:.3f}" for x in sb["peak_drift_ratio"][2::2]) + " %",
        " / ".join(f"{x / G:.3f}" for x in sa["peak_aabs_mps2"][9:11]) + " g",
        " / ".join(f"{x / G:.3f}" for x in sb["peak_aabs_mps2"][9:11]) + " g",
        f"{sa['periods_free_s'][0]:.3f} s isolated",
        f"{sa['periods_stuck_s'][0]:.3f} s on a fixed base",
    ]
    for q in quoted:
        assert q in section, q
    # the bearings all move with the slab (no twist of a symmetric plan)
    assert max(sa["bearing_peak_displacement_m"]) == pytest.approx(min(sa["bearing_peak_displacement_m"]),
                                                                    rel=1e-9)


def test_the_vertical_component_scales_the_normal_force(runs):
    """Section 6.1: under a vertical record a_z (rigid vertical support) each bearing's normal
    force is p (1 + a_z / g), so its extremes over the run are those of the record, at its
    samples (the steps land on them and a_z is linear between them)."""
    s = runs["vertical"].summary
    lines = (ROOT / "inputs/sweeps/records/synthetic_s33.AT2").read_text().splitlines()[4:]
    az = np.array([float(x) for line in lines for x in line.split()]) * 0.6666666666666666  # in g
    p = W / 4
    assert s["bearing_min_normal_force_N"] == pytest.approx([p * (1 + az.min())] * 4, rel=1e-12)
    assert s["bearing_max_normal_force_N"] == pytest.approx([p * (1 + az.max())] * 4, rel=1e-12)
    assert s["bearing_uplift_count"] == [0] * 4
    assert abs(s["energy_residual_ratio"]) < 1e-10
    text = (ROOT / "docs" / "examples.md").read_text()
    section = text[text.index("### 6.1 A vertical component"):]
    a = runs["planar"].summary
    quoted = [
        f"between {min(s['bearing_min_normal_force_N']) / 1e6:.3f} and {max(s['bearing_max_normal_force_N']) / 1e6:.3f} MN"
        f" about its {p / 1e6:.3f} MN",
        f"| {1e3 * a['bearing_peak_displacement_m'][0]:.1f} mm | {1e3 * s['bearing_peak_displacement_m'][0]:.1f} mm |",
        f"| {a['peak_isolation_shear_N'] / 1e3:.0f} kN | {s['peak_isolation_shear_N'] / 1e3:.0f} kN |",
        f"| {100 * a['peak_drift_ratio'][2]:.3f} % | {100 * s['peak_drift_ratio'][2]:.3f} % |",
        f"vertical\nPGA {az.max() if az.max() > -az.min() else -az.min():.3f} g",
    ]
    for q in quoted:
        assert q.replace("\n", " ") in section.replace("\n", " "), q
