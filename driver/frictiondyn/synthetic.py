"""A synthetic ground acceleration in PEER AT2 format, for tests and examples.

Gaussian white noise filtered by the Clough-Penzien filter (a Kanai-Tajimi ground filter
followed by a second-order high-pass that removes the long-period content a filtered white
noise would otherwise carry), shaped by the Jennings (1968) envelope (quadratic build-up,
strong-motion plateau, exponential decay) and scaled to the requested peak ground
acceleration. It is **not** a recorded ground motion: the header says so.

    python -m frictiondyn.synthetic OUT.AT2 [--pga 0.35] [--duration 20] [--dt 0.01] [--seed 2024]

``inputs/synthetic_pga035.AT2`` was made with the defaults.
"""

from __future__ import annotations

import argparse
import math
import os
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np

__all__ = ["SyntheticRecord", "synthetic_record", "write_at2", "main"]


@dataclass
class SyntheticRecord:
    """Samples of a synthetic table acceleration (in g) and how they were made."""

    acc_g: np.ndarray  #: acceleration at k*dt, k = 0..n-1 [g]
    dt: float  #: sampling step [s]
    pga_g: float  #: peak |acceleration| asked for [g] (= max |acc_g|)
    seed: int
    description: str


def jennings_envelope(t: np.ndarray, t1: float, t2: float, decay: float) -> np.ndarray:
    """(t/t1)^2 before t1, 1 until t2, exp(-decay (t - t2)) after."""
    env = np.ones_like(t)
    env[t < t1] = (t[t < t1] / t1) ** 2
    env[t > t2] = np.exp(-decay * (t[t > t2] - t2))
    return env


def synthetic_record(
    duration: float = 20.0,
    dt: float = 0.01,
    pga_g: float = 0.35,
    seed: int = 2024,
    wg: float = 15.0,
    zg: float = 0.6,
    wf: float = 1.5,
    zf: float = 0.6,
    t1: float = 2.0,
    t2: float = 10.0,
    decay: float = 0.4,
) -> SyntheticRecord:
    """Clough-Penzien filtered white noise (ground filter wg [rad/s], zg; high-pass wf
    [rad/s], zf) under the Jennings envelope (t1, t2 [s], decay [1/s]), scaled so that
    max |a| = pga_g exactly."""
    if not (duration > 0 and dt > 0 and pga_g > 0):
        raise ValueError("duration, dt and pga_g must be > 0")
    n = int(round(duration / dt)) + 1
    t = np.arange(n) * dt
    noise = np.random.default_rng(seed).standard_normal(n)
    m = 1 << (2 * n - 1).bit_length()  # zero padding: no wrap-around of the filter
    om = 2.0 * np.pi * np.fft.rfftfreq(m, dt)
    kanai_tajimi = (wg**2 + 2j * zg * wg * om) / (wg**2 - om**2 + 2j * zg * wg * om)
    high_pass = om**2 / (wf**2 - om**2 + 2j * zf * wf * om)
    a = np.fft.irfft(np.fft.rfft(noise, m) * kanai_tajimi * high_pass, m)[:n]
    a *= jennings_envelope(t, t1, t2, decay)
    a *= pga_g / np.max(np.abs(a))
    text = (
        f"SYNTHETIC (frictiondyn.synthetic, seed {seed}): Clough-Penzien filtered white noise, "
        f"wg {wg:g} rad/s zg {zg:g}, wf {wf:g} rad/s zf {zf:g}; Jennings envelope "
        f"{t1:g}/{t2:g} s decay {decay:g}/s; PGA {pga_g:g} g"
    )
    return SyntheticRecord(acc_g=a, dt=dt, pga_g=pga_g, seed=seed, description=text)


def write_at2(rec: SyntheticRecord, path: str | os.PathLike) -> Path:
    """Write the record in PEER NGA AT2 format (units of g, 5 values a line, E15.7),
    labelled synthetic; to a temporary name, then renamed."""
    path = Path(path)
    vals = [f"{x:15.7E}" for x in rec.acc_g]
    dt_text = f"{rec.dt:.6f}".rstrip("0")
    if dt_text.startswith("0"):
        dt_text = dt_text[1:]
    lines = [
        "SYNTHETIC GROUND MOTION IN PEER NGA FORMAT - NOT A RECORDED EARTHQUAKE",
        rec.description,
        "ACCELERATION TIME SERIES IN UNITS OF G",
        f"NPTS= {len(vals):6d}, DT= {dt_text:>8s} SEC",
    ]
    lines += ["".join(vals[i : i + 5]) for i in range(0, len(vals), 5)]
    tmp = path.with_name(f".{path.name}.{os.getpid()}.tmp")
    tmp.write_text("\n".join(lines) + "\n")
    tmp.replace(path)
    return path


def main(argv: Sequence[str] | None = None) -> int:
    p = argparse.ArgumentParser(
        prog="python -m frictiondyn.synthetic",
        description="Write a synthetic ground acceleration (filtered white noise) as PEER AT2.",
    )
    p.add_argument("out", help="the .AT2 file to write")
    p.add_argument("--pga", type=float, default=0.35, help="peak ground acceleration [g]")
    p.add_argument("--duration", type=float, default=20.0, help="length [s]")
    p.add_argument("--dt", type=float, default=0.01, help="sampling step [s]")
    p.add_argument("--seed", type=int, default=2024, help="random seed")
    a = p.parse_args(argv)
    rec = synthetic_record(a.duration, a.dt, a.pga, a.seed)
    out = write_at2(rec, a.out)
    pgv = float(np.max(np.abs(np.cumsum(rec.acc_g) * rec.dt * 9.80665)))
    print(f"record: {out} ({len(rec.acc_g)} samples, dt {rec.dt:g} s, PGA {rec.pga_g:g} g, "
          f"PGV about {pgv:.3g} m/s)")
    return 0 if math.isfinite(pgv) else 1


if __name__ == "__main__":
    raise SystemExit(main())
