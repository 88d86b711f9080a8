"""Worked example (docs/examples.md): a 3-storey frame on friction pendulum isolators with
velocity-dependent (PTFE-like) friction, built in Python, checked against the deck
inputs/isolated_fps.nml, compared with the same frame on a fixed base, and drawn.

    .venv/bin/python examples/isolated.py [OUTDIR]      # default docs/examples/
"""

from __future__ import annotations

import sys
from pathlib import Path

import frictiondyn as fd
import numpy as np
from frictiondyn import plots

ROOT = Path(__file__).resolve().parent.parent
INPUTS = ROOT / "inputs"
G = 9.81

MASS = [250e3, 200e3, 200e3, 200e3]  # kg: base slab, floors 1-3
K_FRAME = 150e6  # N/m, each storey of the frame
LABELS = ["base slab", "floor 1", "floor 2", "roof"]
RECORD = fd.Record(dt_record=0.01, file=str(INPUTS / "synthetic_pga035.AT2"), duration=30.0)


def isolated() -> fd.Analysis:
    """The frame on one lumped friction pendulum: W = the whole weight, R = 2 m, PTFE-like
    mu(v) = 0.06 - 0.03 exp(-30 |v|)."""
    return fd.Analysis(
        masses=MASS,
        labels=LABELS,
        springs=[fd.Spring(i + 1, i, K_FRAME) for i in range(1, 4)],
        damping=fd.Damping.rayleigh_modes(0.02, 1, 2),  # stuck: the frame on a fixed base
        isolators=[
            fd.SlidingIsolator(
                1,
                0,
                weight=sum(MASS) * G,
                mu=None,
                law="velocity",
                radius=2.0,
                eps=1e-3,
                mu_law="exponential",
                mu_max=0.06,
                mu_min=0.03,
                mu_rate=30.0,
                label="isolators",
            )
        ],
        storeys=[
            fd.Storey(i + 1, i, height=h, label=lab)
            for i, (h, lab) in enumerate(
                zip([0.0, 3.5, 3.5, 3.5], ["isolation", "storey 1", "storey 2", "storey 3"])
            )
        ],
        excitation=RECORD,
        integration=fd.Integration(n1=10, n2=50),
    )


def fixed_base() -> fd.Analysis:
    """The same frame on a fixed base: the slab held to the ground (its mass then moves
    with the ground and does not matter); the storeys above it."""
    return fd.Analysis(
        masses=MASS[1:],
        labels=LABELS[1:],
        springs=[fd.Spring(i + 1, i, K_FRAME) for i in range(3)],
        damping=fd.Damping.rayleigh_modes(0.02, 1, 2),
        storeys=[fd.Storey(i + 1, i, height=3.5, label=f"storey {i + 1}") for i in range(3)],
        excitation=RECORD,
        integration=fd.Integration(n1=10),
    )


def main(outdir: Path) -> None:
    outdir.mkdir(parents=True, exist_ok=True)
    iso = isolated().run()
    ref = fd.run(INPUTS / "isolated_fps.nml")
    assert np.array_equal(iso.data, ref.data), "the Python model differs from the deck"
    fixed = fixed_base().run()
    s, f = iso.summary, fixed.summary
    print("periods [s], isolators stuck (fixed base):", np.round(s["periods_stuck_s"], 3))
    print("periods [s], isolators free (pendulum):", np.round(s["periods_free_s"], 3))
    print(
        f"isolator: peak displacement {1e3 * s['peak_drift_m'][0]:.1f} mm, residual "
        f"{1e3 * s['residual_drift_m'][0]:.1f} mm, peak force {s['peak_force_N'][0] / 1e3:.0f} kN"
    )
    for k in range(3):
        print(
            f"storey {k + 1}: peak drift ratio fixed {100 * f['peak_drift_ratio'][k]:.3f} % -> "
            f"isolated {100 * s['peak_drift_ratio'][k + 1]:.3f} %"
        )
    print(
        f"roof peak acceleration fixed {f['peak_aabs_mps2'][2] / G:.3f} g -> "
        f"isolated {s['peak_aabs_mps2'][3] / G:.3f} g"
    )
    units = plots.REPORT_UNITS
    fig, axes = plots.figure(1, 3, size=(13.0, 4.3))
    plots.plot_hysteresis(
        iso, 1, ax=axes[0, 0], units=units, title="isolators: force vs displacement"
    )
    plots.plot_acceleration_profile(
        [fixed, iso], ax=axes[0, 1], labels=["fixed base", "isolated"], units=units
    )
    plots.plot_relative_velocity(
        iso, 1, ax=axes[0, 2], units=units, t_range=(2.0, 12.0), title="isolators: sliding velocity"
    )
    plots.save(fig, outdir / "isolated_fps.png", dpi=110)
    fig, axes = plots.figure(2, 1, size=(9.0, 5.5), sharex=True)
    plots.plot_drift(iso, 1, ax=axes[0, 0], units=units, title="isolator displacement")
    axes[0, 0].set_xlabel("")
    plots.plot_acceleration(
        [fixed, iso],
        3,
        ax=axes[1, 0],
        labels=["fixed base", "isolated"],
        units=units,
        title="roof: absolute acceleration",
    )
    plots.save(fig, outdir / "isolated_histories.png", dpi=110)


if __name__ == "__main__":
    main(Path(sys.argv[1]) if len(sys.argv) > 1 else ROOT / "docs" / "examples")
