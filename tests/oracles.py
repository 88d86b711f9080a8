"""Independent references the tests compare frictiondyn with: closed forms (numpy only) and
the paper's published observation. They live here, in the tests, not in the installed
package: a test must not take its expected values from the code it checks.

Copied from driver/frictiondyn/validate.py (``linear_response``, ``den_hartog``) and
driver/frictiondyn/paper.py (``PAPER_OBSERVATION``, which writes the report there); the
copies are the tests' own and are not to be re-imported from the package. The validation
studies (tools/validation/studies.py, not installed either) take ``linear_response`` and
``den_hartog`` from here.
"""

from __future__ import annotations

import numpy as np

#: The paper's observation (Dimova, Table 1 and text): the blocks adhere in tests 1, 2, 5
#: and stick and slip in every cycle in tests 3, 4 (the report's vocabulary).
PAPER_OBSERVATION: dict[int, str] = {
    1: "no sliding",
    2: "no sliding",
    3: "stick-slip",
    4: "stick-slip",
    5: "no sliding",
}


def linear_response(m, k, c, amp, freq, t):
    """Response from rest of M u'' + C u' + K u = -M 1 ag, ag = -amp w^2 sin(w t), by
    eigen-decomposition and the complex frequency response (independent of the solver).
    Returns the states [u, v] at the times t, shape (len(t), 2 n)."""
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


def chain_stiffness(stiffnesses) -> np.ndarray:
    """K of a chain table - 1 - 2 - ... - n with spring i between DOF i - 1 and i."""
    n = len(stiffnesses)
    k = np.zeros((n, n))
    for i, ks in enumerate(stiffnesses):
        k[i, i] += ks
        if i > 0:
            k[i - 1, i - 1] += ks
            k[i, i - 1] -= ks
            k[i - 1, i] -= ks
    return k


def steady_aabs(m, k, c, amp, freq, dt=None) -> np.ndarray:
    """Steady-state amplitudes of the absolute accelerations of M u'' + C u' + K u = -M 1 ag
    under the table motion x0 = amp sin(w t) (complex frequency response).

    With ``dt`` the response of average-acceleration Newmark at that step instead: the
    scheme is the trapezoidal rule, i.e. the bilinear map s = (2/dt)(z - 1)/(z + 1), so its
    sampled steady state is the exact one at the warped frequency w~ = (2/dt) tan(w dt/2),
    with a = -w~^2 u, driven by the exactly sampled ag."""
    m, k, c = np.atleast_2d(m), np.atleast_2d(k), np.atleast_2d(c)
    n = m.shape[0]
    w = 2 * np.pi * freq
    wt = w if dt is None else 2.0 / dt * np.tan(w * dt / 2)
    ag = -amp * w**2
    u = np.linalg.solve(k - wt**2 * m + 1j * wt * c, -m @ np.ones(n) * ag)
    return np.abs(-(wt**2) * u + ag)
