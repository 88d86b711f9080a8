"""Closed-form solutions the exact technique is checked against (independent of the solver):
the linear response of a stuck or free structure, and Den Hartog's steady non-stop solution
of a Coulomb oscillator."""

from __future__ import annotations

import numpy as np

__all__ = ["den_hartog", "linear_response"]


def linear_response(m, k, c, amp, freq, t):
    """Response from rest of M u'' + C u' + K u = -M 1 ag, ag = -amp w^2 sin(w t), by
    eigen-decomposition and the complex frequency response (independent of the solver)."""
    m, k, c = np.atleast_2d(m), np.atleast_2d(k), np.atleast_2d(c)
    n = m.shape[0]
    minv = np.linalg.inv(m)
    a = np.block([[np.zeros((n, n)), np.eye(n)], [-minv @ k, -minv @ c]])
    b = np.concatenate([np.zeros(n), -np.ones(n)])
    w = 2 * np.pi * freq
    big_x = np.linalg.solve(1j * w * np.eye(2 * n) - a, b * (-amp * w**2))
    xp = np.imag(np.outer(np.exp(1j * w * t), big_x))
    lam, vec = np.linalg.eig(a)
    coef = np.linalg.solve(vec, -xp[0].astype(complex))
    xh = np.real(
        (vec[None, :, :] * (np.exp(np.outer(t, lam))[:, None, :] * coef[None, None, :])).sum(axis=2)
    )
    return xh + xp


def den_hartog(t, m, k, ff, f0, w):
    """Den Hartog's steady non-stop solution of m x'' + k x + ff sgn(x') = f0 sin(w t):
    displacement, velocity and amplitude."""
    wn = np.sqrt(k / m)
    r = w / wn
    xp, a = (f0 / k) / (1 - r**2), ff / k
    beta = np.pi / r
    sin_th = (a / (r * xp)) * np.tan(beta / 2)
    th = np.pi - np.arcsin(sin_th) if xp > 0 else np.arcsin(sin_th)  # x(0) = xp cos th < 0
    c2 = a * np.sin(beta) / (1 + np.cos(beta))
    half = np.pi / w
    tp = t - 0.5 * np.pi / w  # f0 sin(w t) = f0 cos(w t'), t' = t - T/4
    t0 = th / w
    kh = np.floor((tp - t0) / half)
    tau = tp - t0 - kh * half
    x = a * np.cos(wn * tau) + c2 * np.sin(wn * tau) + xp * np.cos(w * tau + th) - a
    v = -a * wn * np.sin(wn * tau) + c2 * wn * np.cos(wn * tau) - xp * w * np.sin(w * tau + th)
    sgn = np.where(kh % 2 == 0, 1.0, -1.0)
    return sgn * x, sgn * v, abs(xp) * np.sqrt(1 - sin_th**2)
