"""Worked example (docs/examples.md): the 5-storey building with friction dampers in braces,
built in Python, run with and without its dampers, checked against the decks
inputs/building5_dampers.nml and inputs/building5_bare.nml, and drawn for a report.

    .venv/bin/python examples/building5.py [OUTDIR]      # default docs/examples/
"""

from __future__ import annotations

import sys
from pathlib import Path

import frictiondyn as fd
import numpy as np
from frictiondyn import plots

ROOT = Path(__file__).resolve().parent.parent
INPUTS = ROOT / "inputs"

MASS = [300e3, 300e3, 300e3, 300e3, 250e3]  # kg, floor 1 to roof
K = [400e6, 360e6, 320e6, 260e6, 200e6]  # N/m, storey 1 to 5
HEIGHT = [4.0, 3.5, 3.5, 3.5, 3.5]  # m
FLOORS = ["floor 1", "floor 2", "floor 3", "floor 4", "roof"]
G = 9.81
SLIP = [round(0.05 * G * sum(MASS[i:])) for i in range(5)]  # N: 5 % of the weight above


def building(dampers: bool) -> fd.Analysis:
    """The building under the synthetic record, with or without its dampers."""
    return fd.Analysis(
        masses=MASS,
        labels=FLOORS,
        springs=[fd.Spring(i + 1, i, K[i]) for i in range(5)],
        # 2 % at modes 1 and 3 of the bare frame
        damping=fd.Damping.rayleigh_modes(0.02, 1, 3, "free" if dampers else None),
        braces=[
            fd.FrictionBrace(i + 1, i, SLIP[i], K[i], label=f"damper {i + 1}") for i in range(5)
        ]
        if dampers
        else [],
        storeys=[fd.Storey.of_spring(i + 1, height=HEIGHT[i]) for i in range(5)],
        excitation=fd.Record(
            dt_record=0.01, file=str(INPUTS / "synthetic_pga035.AT2"), duration=30.0
        ),
        integration=fd.Integration(n1=10, n2=50 if dampers else None),
    )


def main(outdir: Path) -> None:
    outdir.mkdir(parents=True, exist_ok=True)
    damped, bare = building(True).run(), building(False).run()
    # the same numbers as the decks
    for mine, deck in ((damped, "building5_dampers"), (bare, "building5_bare")):
        ref = fd.run(INPUTS / f"{deck}.nml")
        assert np.array_equal(mine.data, ref.data), deck
    runs, names = [bare, damped], ["without dampers", "with dampers"]
    s, b = damped.summary, bare.summary
    print("periods [s], bare frame:", np.round(b["periods_free_s"], 3))
    print("periods [s], dampers stuck:", np.round(s["periods_stuck_s"], 3))
    for k in range(5):
        print(
            f"storey {k + 1}: peak drift ratio {100 * b['peak_drift_ratio'][k]:.3f} % -> "
            f"{100 * s['peak_drift_ratio'][k]:.3f} %; "
            f"residual {1e3 * s['residual_drift_m'][k]:.3f} mm"
        )
    vb, vs = b["peak_base_shear_N"] / 1e3, s["peak_base_shear_N"] / 1e3
    print(f"peak base shear {vb:.0f} kN -> {vs:.0f} kN")
    ab, ad = b["peak_aabs_mps2"][4] / G, s["peak_aabs_mps2"][4] / G
    print(f"roof peak acceleration {ab:.3f} g -> {ad:.3f} g")
    units = plots.REPORT_UNITS
    # profiles over the height, side by side
    fig, axes = plots.figure(1, 2, size=(9.0, 4.5))
    plots.plot_drift_profile(runs, ax=axes[0, 0], labels=names)
    plots.plot_acceleration_profile(runs, ax=axes[0, 1], labels=names, units=units)
    fig.suptitle("5-storey building, synthetic record (PGA 0.35 g)")
    plots.save(fig, outdir / "building5_profiles.png", dpi=110)
    # the dampers' loops
    fig, axes = plots.figure(2, 3, size=(12.0, 7.0))
    for d in range(5):
        plots.plot_hysteresis(damped, d + 1, ax=axes.flat[d], units=units)
    plots.plot_storey_loop(runs, 1, ax=axes.flat[5], labels=names, units=units)
    plots.save(fig, outdir / "building5_loops.png", dpi=110)
    # roof acceleration and base shear over time
    fig, axes = plots.figure(2, 1, size=(9.0, 5.5), sharex=True)
    plots.plot_acceleration(runs, 5, ax=axes[0, 0], labels=names, units=units)
    axes[0, 0].set_xlabel("")
    plots.plot_base_shear(runs, ax=axes[1, 0], labels=names, units=units)
    plots.save(fig, outdir / "building5_histories.png", dpi=110)


if __name__ == "__main__":
    main(Path(sys.argv[1]) if len(sys.argv) > 1 else ROOT / "docs" / "examples")
