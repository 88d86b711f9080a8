"""The verification studies behind docs/validation.md (validate.py writes the report; the
tests in tests/test_validation.py assert the same numbers on reduced versions). Every run
goes through the f2py extension; the model, Table 1 and the steady-state classifier are the
package's (frictiondyn.paper), the closed forms are the tests' (tests/oracles.py: one copy,
independent of the solver and outside the package).

Studies:
1. the exact technique against closed forms (rigid body, free oscillators, Den Hartog);
2. convergence of the velocity and hysteretic laws to the exact solution on the paper's
   test 4 as eps, f and dt shrink, against eps and against cost;
3. the paper's Fig. 3 story, correctness condition off and on, against the exact solution;
4. the energy balance of the three techniques;
5. Table 1 by the three techniques, and the range of the normal force P for which the
   paper's classification holds;
6. the Moreau-Jean technique: its convergence to the exact technique on the paper's tests
   and to Den Hartog's closed form as the step shrinks, Table 1, shear buildings of 5 to 30
   storeys with proportional slip loads against the exact technique and the velocity law,
   and 100 to 1000 storeys (energy balance, cost per step).
"""

from __future__ import annotations

import math
import sys
import time
from dataclasses import dataclass, field, replace
from pathlib import Path

import numpy as np
from frictiondyn import Result, SolverError, newmark_steps
from frictiondyn.model import (
    Analysis,
    Damping,
    Device,
    Harmonic,
    Integration,
    Output,
    Record,
    Spring,
)
from frictiondyn.paper import (
    K1,
    K2,
    M1,
    M2,
    PAPER_OBSERVATION,
    TABLE1,
    XI,
    P,
    SteadyState,
    paper_analysis,
    steady_state,
    steady_window,
)
ROOT = Path(__file__).resolve().parents[2]
sys.path.append(str(ROOT / "tests"))
from oracles import den_hartog, linear_response  # the closed forms, one copy (tests/oracles.py)

sys.path.insert(0, str(ROOT / "bench"))
from opensees_models import BuildingCase  # the benchmark's building, one definition

DELTA = 0.05  # m/s: level of |s'| whose crossings time the slides (above the sticking noise)


def analysis(test: int = 4, law: str = "velocity", *, output_every: int = 1, **kw) -> Analysis:
    """The paper's analysis (frictiondyn.paper.paper_analysis), sampled every dt1 step unless
    ``output_every`` says otherwise: the studies compare histories row by row."""
    return paper_analysis(test, law, output_every=output_every, **kw)


# ----------------------------------------------------------------------------- metrics
@dataclass
class Steady:
    """The steady state of a run (the package's classifier), the instants at which |s'|
    crosses DELTA in it (the starts and ends of the slides), and the run itself."""

    state: SteadyState
    crossings: np.ndarray  # [s]
    result: Result | None = None

    @property
    def peaks(self) -> np.ndarray:
        """Peak |absolute acceleration| per mass [m/s2]: exact for the exact technique (the
        extrema between rows and the one-sided values at transitions), else sampled on the
        run's rows (Result.peak)."""
        return np.array(self.state.peak_aabs)

    def sampled_peaks(self, times: np.ndarray | None = None) -> np.ndarray:
        """Peak |absolute acceleration| per mass over the window's rows (or over the rows at
        the given times, e.g. another run's): the exact solution sampled like an
        approximation is."""
        r = self.result
        w = steady_window(r, TABLE1[self.state.test][0])
        t = r.time[w]
        pick = (
            np.ones(t.size, bool) if times is None else np.isin(np.round(t, 9), np.round(times, 9))
        )
        return np.array([np.max(np.abs(r[f"aabs{i}"][w][pick])) for i in (1, 2)])

    @property
    def classification(self) -> str:
        return self.state.classification


def steady(r: Result, test: int, law: str = "") -> Steady:
    """The steady state (last 10 cycles) of a run of Table 1 test ``test``."""
    w = steady_window(r, TABLE1[test][0])
    g = np.abs(r["sdot1"][w]) - DELTA
    tt = r.time[w]
    i = np.nonzero(np.sign(g[1:]) != np.sign(g[:-1]))[0]
    crossings = tt[i] - g[i] * (tt[i + 1] - tt[i]) / (g[i + 1] - g[i])
    return Steady(steady_state(r, test, law), crossings, r)


def errors(approx: Steady, exact: Steady) -> tuple[float, float]:
    """Relative error of the steady peak accelerations (max over masses) against the exact
    solution sampled on the approximation's rows (the law's own error: both read on the
    same rows), and the largest error of the slide timing (|s'| = DELTA crossings), NaN when
    the counts differ."""
    rows = approx.result.time[steady_window(approx.result, TABLE1[approx.state.test][0])]
    ref = exact.sampled_peaks(rows)
    peak = float(np.max(np.abs(approx.peaks - ref) / ref))
    if len(approx.crossings) != len(exact.crossings) or len(exact.crossings) == 0:
        return peak, math.nan
    return peak, float(np.max(np.abs(approx.crossings - exact.crossings)))


def true_peak_error(approx: Steady, exact: Steady) -> float:
    """Relative error of the approximation's peaks read on its rows against the exact true
    peaks: the law's error plus the rows' sampling."""
    return float(np.max(np.abs(approx.peaks - exact.peaks) / exact.peaks))


def residual(r: Result) -> float:
    """|energy residual| / input of a run."""
    s = r.summary
    return abs(s["energy_residual_J"]) / s["energy_input_J"]


def history_error(approx: Result, exact: Result, test: int) -> tuple[float, float]:
    """RMS error of the absolute-acceleration histories over the steady state (relative to
    the exact RMS, worst mass), and the share of samples whose friction force has the wrong
    sign (exact history interpolated at the approximation's samples)."""
    w = steady_window(approx, TABLE1[test][0])
    t = approx.time
    worst = 0.0
    for i in (1, 2):
        ref = np.interp(t[w], exact.time, exact[f"aabs{i}"])
        worst = max(
            worst, float(np.sqrt(np.mean((approx[f"aabs{i}"][w] - ref) ** 2) / np.mean(ref**2)))
        )
    fref = np.interp(t[w], exact.time, exact["F1"])
    wrong = float(np.mean(np.sign(approx["F1"][w]) != np.sign(fref)))
    return worst, wrong


def cost(r: Result) -> int:
    return newmark_steps(r.summary)


def observed_order(x, y) -> float:
    """Slope of log(y) against log(x), least squares."""
    x, y = np.log(np.asarray(x, float)), np.log(np.asarray(y, float))
    return float(np.polyfit(x, y, 1)[0])


# ----------------------------------------------------------------------------- 1. closed forms
def closed_forms() -> list[dict]:
    """Errors of the exact technique against closed forms (relative to the response's peak)."""
    rows = []
    freq, amp, _ = TABLE1[3]
    for label, p in (
        ("P mu huge: one rigid body (m1 + m2 on k1 + k2)", 1e6),
        ("P mu = 0: two free oscillators", 0.0),
    ):
        r = analysis(3, "coulomb", p=p, duration=5.0).run()
        psi = r.summary["period_stuck_s"] * XI / np.pi
        if p > 0:
            ex = linear_response(M1 + M2, K1 + K2, psi * (K1 + K2), amp, freq, r.time)
            refs = [(r["u1"], ex[:, 0]), (r["u2"], ex[:, 0])]
        else:
            refs = [
                (r[f"u{i}"], linear_response(m, k, psi * k, amp, freq, r.time)[:, 0])
                for i, (m, k) in enumerate([(M1, K1), (M2, K2)], start=1)
            ]
        err = max(np.max(np.abs(a - b)) / np.max(np.abs(b)) for a, b in refs)
        rows.append({"case": label, "error": err, "tolerance": 1e-8})
    for rr, ratio in ((0.7, 0.3), (1.6, 0.2), (0.45, 0.1)):
        an, exact = den_hartog_case(rr, ratio, Integration(technique="event_driven", n1=10))
        r = an.run()
        x, _, amplitude = exact(r.time)
        rows.append(
            {
                "case": f"Den Hartog non-stop, w/wn = {rr}, F_f/F_0 = {ratio}",
                "error": float(np.max(np.abs(r["u1"] - x)) / amplitude),
                "tolerance": 1e-6,
            }
        )
    return rows


def den_hartog_case(rr: float, ratio: float, integration: Integration):
    """A 2 kg block on a 1 Hz spring on the table moving 10 mm at w = rr wn, with Coulomb
    friction F_f = ratio F_0, started on Den Hartog's steady non-stop orbit, 6 cycles: the
    analysis, and exact(t) -> (x, v, amplitude) of the closed form (oracles.den_hartog)."""
    m, fn, amp = 2.0, 1.0, 0.01
    k = m * (2 * np.pi * fn) ** 2
    w = rr * 2 * np.pi * fn
    f0 = m * amp * w**2  # -m ag = m amp w^2 sin(w t)
    ff = ratio * f0
    x0, v0, _ = den_hartog(np.array([0.0]), m, k, ff, f0, w)
    an = Analysis(
        masses=[m],
        springs=[Spring(1, 0, k)],
        u0=[float(x0[0])],
        v0=[float(v0[0])],
        devices=[Device(1, 0, ff, 1.0, law="coulomb")],
        excitation=Harmonic(amp, w / (2 * np.pi), 0.01, 6 * 2 * np.pi / w),
        integration=integration,
        output=Output(output_every=1),
    )
    return an, lambda t: den_hartog(t, m, k, ff, f0, w)


# ----------------------------------------------------------------------------- 2. convergence
@dataclass
class Sweep:
    name: str
    parameter: str
    values: list[float]
    peak_error: list[float] = field(default_factory=list)
    true_peak_error: list[float] = field(default_factory=list)
    residual: list[float] = field(default_factory=list)
    exact_residual: list[float] = field(default_factory=list)
    timing_error: list[float] = field(default_factory=list)
    rms_error: list[float] = field(default_factory=list)
    steps: list[int] = field(default_factory=list)
    violations: list[int] = field(default_factory=list)

    def order(self, which: str = "peak") -> float:
        y = self.peak_error if which == "peak" else self.timing_error
        ok = [(x, e) for x, e in zip(self.values, y) if np.isfinite(e) and e > 0]
        return observed_order([x for x, _ in ok], [e for _, e in ok])


def convergence(
    test: int = 4,
    duration: float = 40.0,
    eps_values=(1e-2, 3e-3, 1e-3, 3e-4, 1e-4),
    f_values=((1e-4, 1e-2), (3e-5, 3e-3), (1e-5, 1e-3), (3e-6, 3e-4), (1e-6, 1e-4)),
    n1_values=(5, 10, 20, 40, 80),
) -> tuple[Steady, list[Sweep]]:
    """Errors of the regularized laws against the exact technique on one Table 1 test."""
    ex_run = analysis(test, "coulomb", duration=duration).run()
    exact = steady(ex_run, test)
    sweeps = []
    sv = Sweep("velocity law", "eps [m/s]", list(eps_values))
    for eps in eps_values:
        _add(sv, analysis(test, "velocity", eps=eps, duration=duration), ex_run, test)
    sweeps.append(sv)
    sh = Sweep("hysteretic law", "f [m] (eps1 = 100 f)", [f for f, _ in f_values])
    for f, e1 in f_values:
        _add(sh, analysis(test, "hysteretic", f=f, eps1=e1, duration=duration), ex_run, test)
    sweeps.append(sh)
    sd = Sweep("velocity law, eps = 1e-4", "dt1 [s]", [])
    for n1 in n1_values:
        sd.values.append(TABLE1[test][2] / n1)
        ex_n1 = analysis(test, "coulomb", n1=n1, duration=duration).run()
        _add(sd, analysis(test, "velocity", eps=1e-4, n1=n1, duration=duration), ex_n1, test)
    sweeps.append(sd)
    return exact, sweeps


def _add(sweep: Sweep, an: Analysis, ex_run: Result, test: int) -> None:
    r = an.run()
    st, ex = steady(r, test), steady(ex_run, test)
    pe, te = errors(st, ex)
    sweep.peak_error.append(pe)
    sweep.true_peak_error.append(true_peak_error(st, ex))
    sweep.residual.append(residual(r))
    sweep.exact_residual.append(residual(ex_run))
    sweep.timing_error.append(te)
    sweep.rms_error.append(history_error(r, ex_run, test)[0])
    sweep.steps.append(cost(r))
    sweep.violations.append(int(r.summary["correctness_violations"]))


# ----------------------------------------------------------------------------- 3. Fig. 3
def fig3(duration: float = 40.0) -> tuple[list[dict], dict[str, Result]]:
    """The paper's Fig. 3 decks against the exact solution (test 4, hysteretic law)."""
    runs = {
        "exact": analysis(4, "coulomb", duration=duration),
        "coarse, check off (Fig. 3)": analysis(4, "hysteretic", coarse=True, duration=duration),
        "coarse, check on": analysis(4, "hysteretic", n1=2, n2=2, duration=duration),
        "corrected (n1 = 20, n2 = 50)": analysis(4, "hysteretic", duration=duration),
        "velocity law (eps = 1e-3)": analysis(4, "velocity", duration=duration),
    }
    results = {k: a.run() for k, a in runs.items()}
    ex = steady(results["exact"], 4)
    rows = []
    for k, r in results.items():
        st = steady(r, 4)
        pe, te = errors(st, ex) if k != "exact" else (0.0, 0.0)
        tpe = true_peak_error(st, ex)
        rms, wrong = history_error(r, results["exact"], 4) if k != "exact" else (0.0, 0.0)
        s = r.summary
        rows.append(
            {
                "run": k,
                "peak1": st.peaks[0],
                "peak2": st.peaks[1],
                "peak_error": pe,
                "true_peak_error": tpe,
                "timing_error": te,
                "rms_error": rms,
                "wrong_sign": wrong,
                "violations": s["correctness_violations"],
                "reversals": s["slip_reversals"][0],
                "steps": cost(r) if k != "exact" else 0,
                "events": s["events"],
                "residual": residual(r),
            }
        )
    return rows, results


# ----------------------------------------------------------------------------- 4. energy
ENERGY_KEYS = (
    "energy_input_J",
    "energy_kinetic_J",
    "energy_strain_J",
    "energy_viscous_J",
    "energy_friction_J",
    "energy_device_elastic_J",
    "energy_residual_J",
)


def energy(test: int = 4, duration: float = 40.0) -> list[dict]:
    rows = []
    for law in ("coulomb", "velocity", "hysteretic"):
        s = analysis(test, law, duration=duration, output_every=20).run().summary
        rows.append(
            {
                "technique": law,
                **{k: s[k] for k in ENERGY_KEYS},
                "relative_residual": abs(s["energy_residual_J"]) / s["energy_input_J"],
            }
        )
    return rows


# ----------------------------------------------------------------------------- 5. Table 1
def table1(duration: float = 40.0) -> list[dict]:
    rows = []
    for test, (freq, _, _) in TABLE1.items():
        row = {"test": test, "freq": freq, "observed": PAPER_OBSERVATION[test]}
        for law in ("coulomb", "velocity", "hysteretic"):
            row[law] = steady(analysis(test, law, duration=duration).run(), test, law)
        rows.append(row)
    return rows


def classify_p(test: int, p: float, duration: float) -> str:
    """The exact technique's steady state of Table 1 test ``test`` with normal force p."""
    r = analysis(test, "coulomb", p=p, duration=duration).run()
    return steady_state(r, test, "coulomb").classification


def critical_p(
    test: int, duration: float = 40.0, lo: float = 1.0, hi: float = 400.0, rel: float = 1e-3
) -> float:
    """Normal force above which test `test` no longer slides in steady state (bisection)."""
    if classify_p(test, hi, duration) != "no sliding" or classify_p(test, lo, duration) == (
        "no sliding"
    ):
        return math.nan
    while hi - lo > rel * hi:
        mid = 0.5 * (lo + hi)
        if classify_p(test, mid, duration) == "no sliding":
            hi = mid
        else:
            lo = mid
    return 0.5 * (lo + hi)


def p_range(duration: float = 40.0, rel: float = 1e-3) -> tuple[float, float, dict[int, float]]:
    """Range (P_lo, P_hi) of P in which tests 1, 2, 5 do not slide and 3, 4 do, with the
    critical P of each test."""
    pc = {test: critical_p(test, duration, rel=rel) for test in TABLE1}
    lo = max(pc[t] for t in TABLE1 if PAPER_OBSERVATION[t] == "no sliding")
    hi = min(pc[t] for t in TABLE1 if PAPER_OBSERVATION[t] != "no sliding")
    return lo, hi, pc


# ----------------------------------------------------------------------------- 6. Moreau-Jean
MJ = "moreau_jean"


def mj_analysis(test: int = 4, *, n1: int = 20, theta: float | None = None, **kw) -> Analysis:
    """The paper's analysis with its 'coulomb' device integrated by Moreau-Jean."""
    return analysis(test, "coulomb", n1=n1, technique=MJ, theta=theta, **kw)


def history_errors(approx: Result, exact: Result, test: int) -> dict[str, float]:
    """Largest error of the u, v, s histories over the steady state, relative to the exact
    peak (worst mass), and the RMS error of the absolute accelerations (as history_error);
    the two runs share their sampling grid."""
    w = steady_window(approx, TABLE1[test][0])
    out = {}
    for q in ("u", "v"):
        out[q] = max(
            float(np.max(np.abs(approx[f"{q}{i}"][w] - exact[f"{q}{i}"][w])))
            / float(np.max(np.abs(exact[f"{q}{i}"][w])))
            for i in (1, 2)
        )
    out["s"] = float(
        np.max(np.abs(approx["s1"][w] - exact["s1"][w])) / np.max(np.abs(exact["s1"][w]))
    )
    out["a_rms"] = history_error(approx, exact, test)[0]
    return out


@dataclass
class MJSweep:
    """Errors of the Moreau-Jean technique against the exact one as dt1 shrinks."""

    theta: float
    test: int
    dt: list[float] = field(default_factory=list)
    peak_error: list[float] = field(default_factory=list)
    timing_error: list[float] = field(default_factory=list)
    u_error: list[float] = field(default_factory=list)
    v_error: list[float] = field(default_factory=list)
    a_rms: list[float] = field(default_factory=list)
    friction_error: list[float] = field(default_factory=list)
    transitions: list[int] = field(default_factory=list)
    exact_transitions: list[int] = field(default_factory=list)
    patterns: list[float] = field(default_factory=list)

    def order(self, which: str) -> float:
        y = getattr(self, which)
        ok = [(x, e) for x, e in zip(self.dt, y) if np.isfinite(e) and e > 0]
        return observed_order([x for x, _ in ok], [e for _, e in ok])


def mj_convergence(
    test: int = 4,
    n1_values=(5, 10, 20, 40, 80, 160),
    thetas=(0.5, 1.0),
    duration: float = 40.0,
) -> list[MJSweep]:
    """Moreau-Jean against the exact technique on one Table 1 test, both sampled every dt1."""
    exact = {n1: analysis(test, "coulomb", n1=n1, duration=duration).run() for n1 in n1_values}
    sweeps = []
    for theta in thetas:
        sw = MJSweep(theta, test)
        for n1 in n1_values:
            ex = exact[n1]
            r = mj_analysis(test, n1=n1, theta=theta, duration=duration).run()
            pe, te = errors(steady(r, test), steady(ex, test))
            he = history_errors(r, ex, test)
            s, se = r.summary, ex.summary
            sw.dt.append(TABLE1[test][2] / n1)
            sw.peak_error.append(pe)
            sw.timing_error.append(te)
            sw.u_error.append(he["u"])
            sw.v_error.append(he["v"])
            sw.a_rms.append(he["a_rms"])
            sw.friction_error.append(
                abs(s["energy_friction_J"] - se["energy_friction_J"]) / se["energy_friction_J"]
            )
            sw.transitions.append(int(s["stick_to_slip"][0] + s["slip_to_stick"][0]))
            sw.exact_transitions.append(int(se["stick_to_slip"][0] + se["slip_to_stick"][0]))
            sw.patterns.append(s["patterns_solved"] / s["steps_dt1"])
        sweeps.append(sw)
    return sweeps


def mj_den_hartog(
    n1_values=(10, 21, 43, 87, 175, 351), thetas=(0.5, 1.0), rr: float = 0.7, ratio: float = 0.3
) -> list[dict]:
    """Moreau-Jean on Den Hartog's non-stop motion (a block on a spring, on a moving table,
    started on the steady orbit): largest errors of u and v over 6 cycles, relative to the
    amplitude (and to amplitude * w). The step counts avoid powers of two, which land the
    velocity reversals on the same fractions of a step."""
    rows = []
    for theta in thetas:
        for n1 in n1_values:
            an, exact = den_hartog_case(rr, ratio, Integration(technique=MJ, n1=n1, theta=theta))
            r = an.run()
            x, v, amplitude = exact(r.time)
            w = 2 * np.pi * an.excitation.frequency
            rows.append(
                {
                    "theta": theta,
                    "n1": n1,
                    "dt": 0.01 / n1,
                    "u_error": float(np.max(np.abs(r["u1"] - x)) / amplitude),
                    "v_error": float(np.max(np.abs(r["v1"] - v)) / (amplitude * w)),
                    "reversals": int(r.summary["slip_reversals"][0]),
                    "stops": int(r.summary["slip_to_stick"][0]),
                }
            )
    return rows


def mj_table1(duration: float = 40.0) -> list[SteadyState]:
    """Table 1 by the Moreau-Jean technique (n1 = 20, as the decks)."""
    return [steady_state(mj_analysis(t, duration=duration).run(), t, MJ) for t in TABLE1]


def building(
    n: int,
    *,
    technique: str = MJ,
    law: str = "coulomb",
    eps: float | None = None,
    n1: int = 10,
    duration: float = 10.0,
    theta: float | None = None,
    output_every: int = 10,
    harmonic: bool = False,
) -> Analysis:
    """The benchmark's shear building (bench/opensees_models.BuildingCase: 1000 t, first
    period 1 s, storey stiffness and slip load proportional to the weight carried, slip at
    5 % of it, Rayleigh 2 % on modes 1 and 3, synthetic ground motion of PGA 0.3 g) with a
    rigid friction damper per storey: Coulomb devices (or a regularized law) between floors.
    ``harmonic``: the table moves 20 mm at 1.5 Hz (one cycle of ramp) instead."""
    c = BuildingCase(n, duration=duration, n1=n1)
    if harmonic:
        excitation = Harmonic(0.02, 1.5, c.dt_record, duration, ramp_cycles=1)
    else:
        excitation = Record(c.dt_record, values=c.record, duration=duration)
    return Analysis(
        masses=[c.m] * n,
        springs=[Spring(i + 1, i, float(c.k[i])) for i in range(n)],
        damping=Damping.rayleigh(c.a0, c.a1),
        devices=[Device(i + 1, i, float(c.slip[i]), 1.0, law=law, eps=eps) for i in range(n)],
        excitation=excitation,
        integration=Integration(technique=technique, n1=n1, theta=theta),
        output=Output(output_every=output_every),
    )


def building_peaks(r: Result) -> dict[str, np.ndarray]:
    s = r.summary
    return {
        "aabs": np.array(s["peak_aabs_mps2"]),
        "u": np.array(s["peak_u_m"]),
        "s": np.array(s["peak_s_m"]),
    }


def peak_difference(a: Result, b: Result) -> float:
    """Largest difference of the peaks (floor accelerations, displacements, storey slips),
    relative to the largest peak of each kind in b."""
    pa, pb = building_peaks(a), building_peaks(b)
    return max(float(np.max(np.abs(pa[k] - pb[k])) / np.max(np.abs(pb[k]))) for k in pa)


def mj_buildings_exact(
    storeys=(5, 10), n1_values=(10, 40), duration: float = 10.0, harmonic: bool = False
) -> list[dict]:
    """Moreau-Jean against the exact technique on buildings with proportional slip loads
    (where the exact technique runs: its message when it does not)."""
    rows = []
    for n in storeys:
        for n1 in n1_values:
            # the exact run on the same step grid: peaks are taken over the same instants
            t0 = time.perf_counter()
            try:
                ex = building(
                    n,
                    technique="event_driven",
                    n1=n1,
                    duration=duration,
                    output_every=n1,
                    harmonic=harmonic,
                ).run()
                failure = ""
            except SolverError as exc:
                ex, failure = None, str(exc)
            t_ex = time.perf_counter() - t0
            r = building(n, n1=n1, duration=duration, output_every=n1, harmonic=harmonic).run()
            s = r.summary
            row = {
                "excitation": "harmonic" if harmonic else "record",
                "storeys": n,
                "n1": n1,
                "transitions": int(sum(s["stick_to_slip"]) + sum(s["slip_to_stick"])),
                "friction": s["energy_friction_J"],
                "time_s": s["run_time_s"],
                "exact_failure": failure,
                "exact_time_s": t_ex,
            }
            if ex is not None:
                se = ex.summary
                ex_u = np.vstack([ex[f"u{i}"] for i in range(1, n + 1)])
                r_u = np.vstack([r[f"u{i}"] for i in range(1, n + 1)])
                row.update(
                    peak_difference=peak_difference(r, ex),
                    u_history=float(np.max(np.abs(r_u - ex_u)) / np.max(np.abs(ex_u))),
                    exact_transitions=int(sum(se["stick_to_slip"]) + sum(se["slip_to_stick"])),
                    exact_friction=se["energy_friction_J"],
                    exact_events=int(se["events"]),
                )
            rows.append(row)
    return rows


def mj_buildings_velocity(
    storeys=(5, 10, 20, 30), eps_values=(1e-2, 1e-3, 1e-4), duration: float = 10.0
) -> list[dict]:
    """The velocity law as eps -> 0 against Moreau-Jean (n1 = 40) on the same buildings."""
    rows = []
    for n in storeys:
        ref = building(n, n1=40, duration=duration, output_every=40).run()
        for eps in eps_values:
            r = building(
                n, technique="newmark", law="velocity", eps=eps, duration=duration, n1=10
            ).run()
            rows.append(
                {
                    "storeys": n,
                    "eps": eps,
                    "peak_difference": peak_difference(r, ref),
                    "violations": int(r.summary["correctness_violations"]),
                    "time_s": r.summary["run_time_s"],
                    "mj_time_s": ref.summary["run_time_s"],
                }
            )
    return rows


def mj_scaling(storeys=(100, 300, 1000), duration: float = 20.0) -> list[dict]:
    """Energy balance and cost of the Moreau-Jean technique on tall buildings (20 s record);
    cost per step: processor time of the run less that of a run of one record interval (the
    set-up: deck, modes, summary), over the difference in steps, as bench/moreau_jean.py
    measures it (there with medians); the set-up is given apart."""
    rows = []
    for n in storeys:
        an = building(n, duration=duration, output_every=100000)
        short = replace(an, excitation=replace(an.excitation, duration=an.excitation.dt_record))
        # processor time: steadier than the clock on a shared machine
        c0 = time.process_time()
        s0 = short.run().summary
        setup = time.process_time() - c0
        c0 = time.process_time()
        s = an.run().summary
        cpu = time.process_time() - c0
        steps = s["steps_dt1"]
        rows.append(
            {
                "storeys": n,
                "steps": steps,
                "us_per_step": 1e6 * (cpu - setup) / (steps - s0["steps_dt1"]),
                "setup_s": setup,
                "patterns_per_step": s["patterns_solved"] / steps,
                "factorizations_per_step": s["factorizations"] / steps,
                "fallbacks": int(s["lcp_fallbacks"]),
                "input": s["energy_input_J"],
                "friction": s["energy_friction_J"],
                "residual": s["energy_residual_J"] / s["energy_input_J"],
                "transitions": int(sum(s["stick_to_slip"]) + sum(s["slip_to_stick"])),
            }
        )
    return rows


__all__ = [
    "DELTA",
    "MJ",
    "MJSweep",
    "P",
    "Steady",
    "Sweep",
    "analysis",
    "building",
    "classify_p",
    "closed_forms",
    "convergence",
    "cost",
    "critical_p",
    "energy",
    "errors",
    "fig3",
    "history_error",
    "mj_analysis",
    "mj_buildings_exact",
    "mj_buildings_velocity",
    "mj_convergence",
    "mj_den_hartog",
    "mj_scaling",
    "mj_table1",
    "observed_order",
    "p_range",
    "residual",
    "steady",
    "table1",
    "true_peak_error",
]
