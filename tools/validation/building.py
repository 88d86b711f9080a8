"""How the regularized laws' parameters act on a building: eps (velocity law) and f
(hysteretic law) measured against the exact Coulomb technique on the 5-storey building of
the worked examples with rigid-plastic friction dampers (docs/theory.md, section 15).

    .venv/bin/python tools/validation/building.py          # prints the markdown tables

The building (inputs/building5_dampers.nml without its braces): floors 300 t (roof 250 t),
storeys 400 ... 200 MN/m, Rayleigh 2 % at the bare frame's modes 1 and 3, a friction device
in every storey slipping at 5 % of the weight above it, the synthetic record
inputs/synthetic_pga035.AT2 (20 s, PGA 0.35 g), then 10 s at rest; rows every dt1 = 1 ms.
Errors are against the exact technique (devices rigid while stuck): peak drift and peak
floor acceleration (largest relative error over the storeys / floors), the RMS of the roof
acceleration error over the record, the roof acceleration's content above 30 Hz (RMS of
the part of the spectrum above 30 Hz over the exact RMS: the ringing of section 5.2), and
the residual drift at 30 s.
"""

from __future__ import annotations

import time
from pathlib import Path

import frictiondyn as fd
import numpy as np

ROOT = Path(__file__).resolve().parents[2]
MASS = [300e3, 300e3, 300e3, 300e3, 250e3]
K = [400e6, 360e6, 320e6, 260e6, 200e6]
HEIGHT = [4.0, 3.5, 3.5, 3.5, 3.5]
G = 9.81
SLIP = [0.05 * G * sum(MASS[i:]) for i in range(5)]
EPS = [1e-2, 3e-3, 1e-3, 3e-4, 1e-4]
F_STICK = [1e-3, 3e-4, 1e-4, 3e-5, 1e-5]
RECORD_END = 20.0


def building(law: str, **device) -> fd.Analysis:
    if law == "coulomb":
        integ = fd.Integration(technique="event_driven", n1=10)
    else:
        integ = fd.Integration(n1=10, n2=50)
    return fd.Analysis(
        masses=MASS,
        springs=[fd.Spring(i + 1, i, K[i]) for i in range(5)],
        damping=fd.Damping.rayleigh_modes(0.02, 1, 3, "free"),
        devices=[fd.Device(i + 1, i, p=SLIP[i], mu=1.0, law=law, **device) for i in range(5)],
        storeys=[fd.Storey.of_spring(i + 1, height=HEIGHT[i]) for i in range(5)],
        excitation=fd.Record(
            0.01, file=str(ROOT / "inputs" / "synthetic_pga035.AT2"), duration=30.0
        ),
        integration=integ,
        output=fd.Output(output_every=1),
    )


def high_frequency(t: np.ndarray, a: np.ndarray, above: float = 30.0) -> float:
    """RMS of the part of a (uniformly sampled) signal above a frequency [Hz]."""
    spec = np.fft.rfft(a)
    freq = np.fft.rfftfreq(len(a), t[1] - t[0])
    spec[freq <= above] = 0.0
    return float(np.sqrt(np.mean(np.fft.irfft(spec, len(a)) ** 2)))


def measure(r: fd.Result, exact: fd.Result, seconds: float) -> dict:
    s, e = r.summary, exact.summary
    m = r.time <= RECORD_END
    roof, roof_x = r["aabs5"][m], exact["aabs5"][m]
    rms_x = np.sqrt(np.mean(roof_x**2))
    return {
        "drift": max(abs(a - b) / b for a, b in zip(s["peak_drift_m"], e["peak_drift_m"])),
        "acc": max(abs(a - b) / b for a, b in zip(s["peak_aabs_mps2"], e["peak_aabs_mps2"])),
        "rms": float(np.sqrt(np.mean((roof - roof_x) ** 2)) / rms_x),
        "hf": high_frequency(r.time[m], roof) / rms_x,
        "residual": max(abs(x) for x in s["residual_drift_m"]),
        "steps": fd.newmark_steps(s),
        "time": seconds,
    }


def run(a: fd.Analysis) -> tuple[fd.Result, float]:
    t0 = time.perf_counter()
    r = a.run()
    return r, time.perf_counter() - t0


def main() -> int:
    exact, t_exact = run(building("coulomb"))
    e = exact.summary
    m = exact.time <= RECORD_END
    roof = exact["aabs5"][m]
    hf = high_frequency(exact.time[m], roof) / np.sqrt(np.mean(roof**2))
    print(f"exact (event-driven): {t_exact:.2f} s, {e['events']} events")
    print(f"  peak drifts [mm]: {np.round(1e3 * np.array(e['peak_drift_m']), 3)}")
    print(f"  residual drifts [mm]: {np.round(1e3 * np.array(e['residual_drift_m']), 3)}")
    print(f"  roof acceleration above 30 Hz: {hf:.2e} of its RMS (the jumps at stick-slip)")
    head = (
        "| {p} | peak drift error | peak floor acc. error | RMS roof acc. error | "
        "roof acc. above 30 Hz | largest residual drift [mm] | steps | run time [s] |"
    )
    rule = "|---|---|---|---|---|---|---|---|"

    def row(label, x):
        return (
            f"| {label} | {x['drift']:.2e} | {x['acc']:.2e} | {x['rms']:.2e} | {x['hf']:.2e} | "
            f"{1e3 * x['residual']:.3f} | {x['steps']} | {x['time']:.2f} |"
        )

    print()
    print(head.format(p="velocity law, eps [m/s]"))
    print(rule)
    for eps in EPS:
        r, sec = run(building("velocity", eps=eps))
        print(row(f"{eps:g}", measure(r, exact, sec)))
    print()
    print(head.format(p="hysteretic law, f [m] (eps1 = 1e-3 m/s)"))
    print(rule)
    for f in F_STICK:
        r, sec = run(building("hysteretic", f=f))
        print(row(f"{f:g}", measure(r, exact, sec)))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
