"""Write the synthetic ground acceleration of the worked examples (inputs/synthetic_kt.txt).

Gaussian white noise filtered by a Kanai-Tajimi ground filter (wg = 15 rad/s, zeta_g = 0.6)
and a second-order high-pass (wf = 1.5 rad/s, zeta_f = 0.6; Clough-Penzien), shaped by the
Jennings envelope (quadratic build-up to 2 s, strong motion to 10 s, exponential decay at
0.4 /s), baseline-corrected (the ground ends at rest where it started) and scaled to a peak
of 0.35 g: 20 s at dt = 0.01 s, one value [m/s2] a line, the record format of
docs/namelist.md. It is NOT a recorded earthquake; the file says so.

    .venv/bin/python tools/make_record.py [OUT] [--pga 0.35] [--seed 2024]

The filters are integrated exactly for a piecewise-constant input over each step (matrix
exponential of the 4-state linear system), so the record does not depend on a step size.
"""

from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np

G = 9.80665


def _expm(a: np.ndarray) -> np.ndarray:
    """exp(a) by scaling and squaring with a Taylor series (small, well-scaled matrices)."""
    norm = np.linalg.norm(a, 1)
    s = max(0, int(np.ceil(np.log2(norm))) + 1) if norm > 0 else 0
    a = a / 2**s
    term, out = np.eye(len(a)), np.eye(len(a))
    for k in range(1, 30):
        term = term @ a / k
        out = out + term
    for _ in range(s):
        out = out @ out
    return out


def synthetic(
    duration=20.0,
    dt=0.01,
    pga_g=0.35,
    seed=2024,
    wg=15.0,
    zg=0.6,
    wf=1.5,
    zf=0.6,
    t1=2.0,
    t2=10.0,
    decay=0.4,
) -> np.ndarray:
    """Ground acceleration samples [m/s2] at k dt, k = 0 .. duration / dt."""
    n = round(duration / dt) + 1
    t = np.arange(n) * dt
    w = np.random.default_rng(seed).standard_normal(n)
    # states: x, x' (ground filter x'' + 2 zg wg x' + wg^2 x = -w), y, y' (high-pass driven
    # by the ground filter's acceleration u = wg^2 x + 2 zg wg x')
    a = np.zeros((4, 4))
    a[0, 1] = 1.0
    a[1, 0], a[1, 1] = -(wg**2), -2 * zg * wg
    a[2, 3] = 1.0
    a[3, 0], a[3, 1] = wg**2, 2 * zg * wg  # the ground filter's output drives the high-pass
    a[3, 2], a[3, 3] = -(wf**2), -2 * zf * wf
    b = np.array([0.0, -1.0, 0.0, 0.0])
    m = np.zeros((5, 5))
    m[:4, :4], m[:4, 4] = a * dt, b * dt
    e = _expm(m)
    phi, gam = e[:4, :4], e[:4, 4]
    x = np.zeros(4)
    out = np.empty(n)
    for k in range(n):
        # the high-pass output y'' = u - 2 zf wf y' - wf^2 y, u = wg^2 x + 2 zg wg x'
        out[k] = wg**2 * x[0] + 2 * zg * wg * x[1] - wf**2 * x[2] - 2 * zf * wf * x[3]
        x = phi @ x + gam * w[k]
    env = np.ones(n)
    env[t < t1] = (t[t < t1] / t1) ** 2
    env[t > t2] = np.exp(-decay * (t[t > t2] - t2))
    acc = out * env

    # baseline: subtract env (c0 + c1 t) so that the ground ends at rest where it started
    # (final velocity and displacement zero, trapezoidal integration)
    def final(x):
        v = np.concatenate([[0.0], np.cumsum(0.5 * (x[1:] + x[:-1])) * dt])
        d = np.concatenate([[0.0], np.cumsum(0.5 * (v[1:] + v[:-1])) * dt])
        return np.array([v[-1], d[-1]])

    basis = [env, env * t]
    c = np.linalg.solve(np.column_stack([final(b) for b in basis]), final(acc))
    acc = acc - c[0] * basis[0] - c[1] * basis[1]
    return acc * (pga_g * G / np.max(np.abs(acc)))


def main(argv=None) -> int:
    root = Path(__file__).resolve().parent.parent
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("out", nargs="?", default=root / "inputs" / "synthetic_kt.txt")
    p.add_argument("--pga", type=float, default=0.35, help="peak ground acceleration [g]")
    p.add_argument("--seed", type=int, default=2024)
    args = p.parse_args(argv)
    acc = synthetic(pga_g=args.pga, seed=args.seed)
    header = (
        "# SYNTHETIC ground acceleration, NOT a recorded earthquake (tools/make_record.py):\n"
        "# Clough-Penzien filtered white noise (wg 15 rad/s, zg 0.6; wf 1.5 rad/s, zf 0.6),\n"
        f"# Jennings envelope (2 s, 10 s, 0.4 /s), seed {args.seed}, PGA {args.pga} g;\n"
        f"# {len(acc)} samples at dt = 0.01 s, one value a line, in m/s2\n"
    )
    Path(args.out).write_text(header + "".join(f"{x:.8e}\n" for x in acc))
    print(f"record: {args.out} ({len(acc)} samples, PGA {np.max(np.abs(acc)) / G:.3f} g)")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
