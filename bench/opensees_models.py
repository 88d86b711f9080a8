"""The models of the OpenSeesPy comparison, built once for frictiondyn and once for OpenSees.

Two families of cases (bench/compare_opensees.py runs them; tests/test_bench_opensees.py
cross-checks the 2-storey building):

- ``Test4Case``: the paper's test 4 (inputs/test4_<law>.nml, read with f90nml), shortened to
  10 s. frictiondyn's hysteretic law is OpenSees's ElasticPP material (E = P mu / f, yield
  strain f); its velocity law is OpenSees's CoulombDamper material (tangent 0, friction force
  P mu, velocity band ``-tol`` eps): both are the same force law, not an approximation of it.
- ``BuildingCase``: a shear building of N storeys with a friction damper (slip load Fs in a
  brace of stiffness kb: frictiondyn's hysteretic law with P mu = Fs, f = Fs / kb; an
  ElasticPP zeroLength link in OpenSees) in every storey, under a synthetic ground
  acceleration made by ``synthetic_record``.

Both codes integrate with Newmark's average acceleration method at the same step dt1. The
damping is the same matrix in both: C = a0 M + a1 K (K the springs, not the devices), in
OpenSees as ``rayleigh(a0, 0, 0, 0)`` on the masses and an Elastic material's damping tangent
eta = a1 k in each spring (a global ``rayleigh`` beta would also damp the friction links).

Neither code is imported at module level: a process that runs one code loads only that code
(its memory is measured alone), and the frictiondyn half works without openseespy.
"""

from __future__ import annotations

import math
import tempfile
import time
from dataclasses import dataclass, field
from pathlib import Path

import f90nml
import numpy as np

ROOT = Path(__file__).resolve().parent.parent
INPUTS = ROOT / "inputs"
G = 9.81  # m/s2
G_FD = 9.80665  # frictiondyn's g in N = p (1 + a_z / g) [m/s2]

QUANTITIES = (
    "u",
    "aabs",
    "s",
    "F",
)  # peak |relative displacement|, |abs. acceleration|, |s|, |F|
SUMMARY_KEYS = {
    "u": "peak_u_m",
    "aabs": "peak_aabs_mps2",
    "s": "peak_s_m",
    "F": "peak_force_N",
}


@dataclass
class OpenSeesSettings:
    """How OpenSees solves each step: what a careful OpenSees user would choose for a chain of
    zeroLength links (see docs/performance.md for the measured alternatives)."""

    algorithm: str = "KrylovNewton"
    system: str = "BandGeneral"
    numberer: str = "RCM"
    test: str = "NormDispIncr"
    tol: float = 1e-8  # m
    max_iter: int = 50
    #: 'Plain' for the chains; the 3D building's rigidDiaphragm floors need 'Transformation'
    constraints: str = "Plain"

    def describe(self) -> str:
        return (
            f"Newmark(0.5, 0.25), {self.algorithm}, {self.system}, numberer {self.numberer}, "
            f"test {self.test} {self.tol:g} (max {self.max_iter} iterations), "
            f"constraints {self.constraints}"
        )


# ----------------------------------------------------------------------------- cases


def _list(x) -> list:
    return list(x) if isinstance(x, (list, tuple)) else [x]


@dataclass
class Test4Case:
    """The paper's test 4 from its deck, ``duration`` seconds, with the deck's law."""

    law: str  # 'hysteretic' or 'velocity'
    duration: float = 10.0
    #: frictiondyn's handling of a dt1 step with a phase change: the deck's (the paper's
    #: refinement) or 'implicit' (docs/theory.md section 6)
    refinement: str = "step"

    def __post_init__(self) -> None:
        nml = f90nml.read(INPUTS / f"test4_{self.law}.nml")
        model, springs, damp = nml["model"], nml["springs"], nml["damping"]
        fric, exc, integ = nml["friction"], nml["excitation"], nml["integration"]
        self.masses = [float(m) for m in _list(model["mass"])]
        ni, nj, k = (
            _list(springs["node_i"]),
            _list(springs["node_j"]),
            _list(springs["k"]),
        )
        self.springs = [(int(a), int(b), float(c)) for a, b, c in zip(ni, nj, k)]
        law = str(_list(fric["law"])[0]).strip().lower()
        ok = (
            len(self.masses) == 2
            and int(fric["n_devices"]) == 1
            and law == self.law
            and sorted((int(fric["node_i"]), int(fric["node_j"]))) == [1, 2]
            and all(j == 0 for _, j, _ in self.springs)
            and str(damp["damping_type"]).lower() == "stiffness"
            and str(exc["excitation_type"]).lower() == "harmonic"
            and int(exc.get("ramp_cycles", 0)) == 0
        )
        if not ok:
            raise ValueError(
                f"inputs/test4_{self.law}.nml is not the two-mass model this bench knows"
            )
        self.device = (int(fric["node_i"]), int(fric["node_j"]))
        self.p, self.mu = float(fric["p"]), float(fric["mu"])
        self.eps = float(fric.get("eps", 1e-3))
        self.eps1 = float(fric.get("eps1", 1e-3))
        self.f = float(fric.get("f", 1e-5))
        self.xi, self.period = float(damp["xi"]), float(damp.get("period", 0.0))
        self.amplitude, self.frequency = (
            float(exc["amplitude"]),
            float(exc["frequency"]),
        )
        self.dt_record = float(exc["dt_record"])
        self.n1, self.n2, self.n = int(integ["n1"]), int(integ["n2"]), float(integ["n"])
        self.dt = self.dt_record / self.n1
        self.n_steps = round(self.duration / self.dt)

    @property
    def name(self) -> str:
        suffix = "" if self.refinement == "step" else f"_{self.refinement}"
        return f"test4_{self.law}{suffix}"

    @property
    def opensees_material(self) -> str:
        return "ElasticPP" if self.law == "hysteretic" else "CoulombDamper"

    @property
    def n_dof(self) -> int:
        return 2

    def stuck_period(self) -> float:
        """First period of the stuck system (the device a rigid link: m1 + m2 on k1 + k2), the
        T of the deck's C = psi K, psi = T xi / pi, when the deck does not give it."""
        if self.period > 0:
            return self.period
        return 2 * math.pi * math.sqrt(sum(self.masses) / sum(k for _, _, k in self.springs))

    def analysis(self, duration: float | None = None):
        import frictiondyn as fd

        i, j = self.device
        return fd.Analysis(
            masses=self.masses,
            springs=[fd.Spring(a, b, k) for a, b, k in self.springs],
            damping=fd.Damping.stiffness(self.xi, self.period),
            devices=[
                fd.Device(
                    i,
                    j,
                    self.p,
                    self.mu,
                    law=self.law,
                    eps=self.eps,
                    eps1=self.eps1,
                    f=self.f,
                )
            ],
            excitation=fd.Harmonic(
                self.amplitude,
                self.frequency,
                self.dt_record,
                duration or self.duration,
            ),
            integration=fd.Integration(
                n1=self.n1,
                n2=self.n2,
                n=self.n,
                refinement=None if self.refinement == "step" else self.refinement,
            ),
        )

    def short_analysis(self):
        """The same deck for one record interval: what a run costs besides its steps."""
        return self.analysis(self.dt_record)

    def build_opensees(self, ops, settings: OpenSeesSettings, workdir: Path) -> None:
        psi = self.stuck_period() * self.xi / math.pi
        ops.wipe()
        ops.model("basic", "-ndm", 1, "-ndf", 1)
        for n in range(3):
            ops.node(n, 0.0)
        ops.fix(0, 1)
        for n, m in enumerate(self.masses, start=1):
            ops.mass(n, m)
        for e, (a, b, k) in enumerate(self.springs, start=1):
            ops.uniaxialMaterial("Elastic", e, k, psi * k)  # spring and its dashpot psi k
            ops.element("zeroLength", e, b, a, "-mat", e, "-dir", 1)
        pmu = self.p * self.mu
        if self.law == "hysteretic":
            ops.uniaxialMaterial("ElasticPP", 10, pmu / self.f, self.f)
        else:
            ops.uniaxialMaterial("CoulombDamper", 10, 0.0, pmu, "-tol", self.eps)
        i, j = self.device
        ops.element("zeroLength", 10, j, i, "-mat", 10, "-dir", 1)  # deformation u_i - u_j = s
        w = 2 * math.pi * self.frequency
        # table displacement a0 sin(w t): acceleration -a0 w^2 sin(w t), exact at every step
        ops.timeSeries(
            "Trig",
            1,
            0.0,
            self.duration + 1.0,
            1.0 / self.frequency,
            "-factor",
            -self.amplitude * w * w,
        )
        ops.pattern("UniformExcitation", 1, 1, "-accel", 1)
        _recorders(ops, workdir, [1, 2], [10])
        _analysis(ops, settings)


def synthetic_record(
    dt: float = 0.01, duration: float = 20.0, pga: float = 0.3 * G, seed: int = 20240613
) -> np.ndarray:
    """A reproducible synthetic ground acceleration [m/s2] sampled at dt, ``duration`` long:
    white noise through a Kanai-Tajimi filter (2.5 Hz, 0.6) and a Clough-Penzien high-pass
    (0.25 Hz, 0.6), under a Jennings envelope (quadratic rise to 2 s, strong phase to 10 s,
    exponential decay), scaled to the peak ground acceleration ``pga``; starts at rest."""
    n = round(duration / dt) + 1
    rng = np.random.default_rng(seed)
    spectrum = np.fft.rfft(rng.standard_normal(n))
    om = 2 * np.pi * np.fft.rfftfreq(n, dt)
    wg, zg, wf, zf = 2 * np.pi * 2.5, 0.6, 2 * np.pi * 0.25, 0.6
    kanai = (wg**2 + 2j * zg * wg * om) / (wg**2 - om**2 + 2j * zg * wg * om)
    clough = om**2 / (wf**2 - om**2 + 2j * zf * wf * om)
    a = np.fft.irfft(spectrum * kanai * clough, n)
    t = np.arange(n) * dt
    a *= np.where(t < 2.0, (t / 2.0) ** 2, np.where(t < 10.0, 1.0, np.exp(-0.25 * (t - 10.0))))
    a *= pga / np.abs(a).max()
    a[0] = 0.0
    return a


@dataclass
class BuildingCase:
    """Shear building, N storeys, a friction damper in a brace in every storey.

    One building discretized with N storeys: total mass ``total_mass`` shared equally by the
    floors; storey stiffness proportional to the weight it carries, scaled so that the bare
    frame's first period is ``period`` for every N; in every storey a brace of the storey's
    stiffness with a friction damper slipping at ``slip_ratio`` times the weight above it;
    Rayleigh damping ``xi`` on the frame's modes 1 and 3. Ground: ``synthetic_record``,
    ``duration`` s sampled at ``dt_record``; step dt1 = dt_record / n1 in both codes.
    """

    n_storeys: int
    duration: float = 20.0
    dt_record: float = 0.01
    n1: int = 10
    period: float = 1.0
    total_mass: float = 1.0e6
    slip_ratio: float = 0.05
    xi: float = 0.02
    record: np.ndarray = field(default=None, repr=False)
    #: 'hysteretic' (OpenSees: ElasticPP link of the brace's stiffness) or 'velocity' (the
    #: paper's velocity law, band eps; OpenSees: CoulombDamper, the same force law)
    law: str = "hysteretic"
    eps: float = 1.0e-3
    #: frictiondyn's refinement of a dt1 step with a phase change: 'step' (the paper's, the
    #: default), 'nested' or 'implicit' (docs/theory.md section 6)
    refinement: str = "step"

    def __post_init__(self) -> None:
        n = self.n_storeys
        if self.record is None:
            self.record = synthetic_record(self.dt_record, 20.0)
        self.m = self.total_mass / n
        above = np.arange(n, 0, -1, dtype=float)  # floors carried by storey i (bottom first)
        lam = _chain_eigenvalues(above, self.m)
        scale = (2 * math.pi / self.period) ** 2 / lam[0]
        self.k = above * scale
        w1 = 2 * math.pi / self.period
        w3 = math.sqrt(lam[min(2, n - 1)] * scale)
        self.a0 = 2 * self.xi * w1 * w3 / (w1 + w3)
        self.a1 = 2 * self.xi / (w1 + w3)
        self.slip = self.slip_ratio * G * self.m * above
        self.kb = self.k.copy()
        self.dt = self.dt_record / self.n1
        self.n_steps = round(self.duration / self.dt)

    @property
    def name(self) -> str:
        suffix = "" if self.law == "hysteretic" else f"_{self.law}"
        if self.refinement != "step":
            suffix += f"_{self.refinement}"
        return f"building{suffix}_{self.n_storeys}"

    @property
    def opensees_material(self) -> str:
        return "ElasticPP" if self.law == "hysteretic" else "CoulombDamper"

    @property
    def n_dof(self) -> int:
        return self.n_storeys

    def analysis(self, duration: float | None = None):
        import frictiondyn as fd

        n = self.n_storeys
        return fd.Analysis(
            masses=[self.m] * n,
            springs=[fd.Spring(i + 1, i, float(self.k[i])) for i in range(n)],
            damping=fd.Damping.rayleigh(self.a0, self.a1),
            devices=[
                fd.Device(
                    i + 1,
                    i,
                    float(self.slip[i]),
                    1.0,
                    law=self.law,
                    f=float(self.slip[i] / self.kb[i]) if self.law == "hysteretic" else None,
                    eps=self.eps if self.law == "velocity" else None,
                )
                for i in range(n)
            ],
            excitation=fd.Record(
                self.dt_record, values=self.record, duration=duration or self.duration
            ),
            integration=fd.Integration(
                n1=self.n1, refinement=None if self.refinement == "step" else self.refinement
            ),
        )

    def short_analysis(self):
        return self.analysis(self.dt_record)

    def build_opensees(self, ops, settings: OpenSeesSettings, workdir: Path) -> None:
        n = self.n_storeys
        ops.wipe()
        ops.model("basic", "-ndm", 1, "-ndf", 1)
        for i in range(n + 1):
            ops.node(i, 0.0)
        ops.fix(0, 1)
        for i in range(1, n + 1):
            ops.mass(i, self.m)
        for i in range(n):
            k, fs, kb = float(self.k[i]), float(self.slip[i]), float(self.kb[i])
            ops.uniaxialMaterial("Elastic", i + 1, k, self.a1 * k)
            ops.element("zeroLength", i + 1, i, i + 1, "-mat", i + 1, "-dir", 1)
            if self.law == "hysteretic":
                ops.uniaxialMaterial("ElasticPP", n + i + 1, kb, fs / kb)
            else:
                ops.uniaxialMaterial("CoulombDamper", n + i + 1, 0.0, fs, "-tol", self.eps)
            ops.element("zeroLength", n + i + 1, i, i + 1, "-mat", n + i + 1, "-dir", 1)
        ops.rayleigh(self.a0, 0.0, 0.0, 0.0)
        ops.timeSeries("Path", 1, "-dt", self.dt_record, "-values", *map(float, self.record))
        ops.pattern("UniformExcitation", 1, 1, "-accel", 1)
        _recorders(ops, workdir, list(range(1, n + 1)), list(range(n + 1, 2 * n + 1)))
        _analysis(ops, settings)


def _chain_eigenvalues(k: np.ndarray, m: float, count: int = 3) -> np.ndarray:
    """The `count` lowest eigenvalues w^2 (ascending) of a fixed-base shear chain, storey
    stiffness k (bottom first), floor mass m: bisection on the Sturm sequence of the
    tridiagonal K / m (O(N) a count, no dense N x N matrix: 10 000 storeys in a second)."""
    n = len(k)
    diag = (k + np.append(k[1:], 0.0)) / m
    off2 = (k[1:] / m) ** 2  # squared off-diagonal (-k[i] / m between i-1 and i)

    def below(x: float) -> int:
        """Eigenvalues below x: the negative pivots of T - x I."""
        c, q = 0, diag[0] - x
        c += q < 0
        for i in range(1, n):
            q = diag[i] - x - off2[i - 1] / (q if q != 0.0 else 1e-300)
            c += q < 0
        return c

    hi = float(np.max(np.abs(diag)) + 2 * np.max(np.sqrt(off2), initial=0.0))
    out = []
    for j in range(min(count, n)):
        a, b = 0.0, hi
        for _ in range(200):
            mid = 0.5 * (a + b)
            if below(mid) > j:
                b = mid
            else:
                a = mid
            if b - a <= 1e-15 * b:
                break
        out.append(0.5 * (a + b))
    return np.array(out)


def make_case(spec: str, quick: bool = False):
    """'test4:hysteretic', 'test4:velocity' (and 'test4_implicit:...', with implicit phases),
    'building:N', 'building_velocity:N' or
    'building_nested:N' / 'building_implicit:N' (the hysteretic building with nested
    refinement / implicit phases) (quick: the short smoke versions)."""
    kind, _, arg = spec.partition(":")
    if kind in ("test4", "test4_implicit"):
        refinement = "implicit" if kind == "test4_implicit" else "step"
        return Test4Case(arg, duration=2.0 if quick else 10.0, refinement=refinement)
    if kind in ("building", "building_velocity", "building_nested", "building_implicit"):
        law = "velocity" if kind == "building_velocity" else "hysteretic"
        refinement = {"building_nested": "nested", "building_implicit": "implicit"}.get(kind, "step")
        return BuildingCase(
            int(arg), duration=5.0 if quick else 20.0, law=law, refinement=refinement
        )
    raise ValueError(f"unknown case {spec!r}")


# ----------------------------------------------------------------------------- OpenSees


def _recorders(ops, workdir: Path, nodes: list[int], devices: list[int]) -> None:
    """Envelopes (min, max, max |.|) of what frictiondyn's summary gives: nodal relative
    displacement, absolute acceleration (-timeSeries adds the ground's), the devices'
    deformation and force."""
    prec = ("-precision", 12)
    ops.recorder(
        "EnvelopeNode",
        "-file",
        str(workdir / "u.env"),
        *prec,
        "-node",
        *nodes,
        "-dof",
        1,
        "disp",
    )
    ops.recorder(
        "EnvelopeNode",
        "-file",
        str(workdir / "aabs.env"),
        *prec,
        "-timeSeries",
        1,
        "-node",
        *nodes,
        "-dof",
        1,
        "accel",
    )
    ops.recorder(
        "EnvelopeElement",
        "-file",
        str(workdir / "s.env"),
        *prec,
        "-ele",
        *devices,
        "deformation",
    )
    ops.recorder(
        "EnvelopeElement",
        "-file",
        str(workdir / "F.env"),
        *prec,
        "-ele",
        *devices,
        "basicForce",
    )


def _analysis(ops, s: OpenSeesSettings) -> None:
    ops.constraints(s.constraints)
    ops.numberer(s.numberer)
    ops.system(s.system)
    ops.test(s.test, s.tol, s.max_iter)
    ops.algorithm(s.algorithm)
    ops.integrator("Newmark", 0.5, 0.25)
    ops.analysis("Transient")


def import_opensees():
    import openseespy.opensees as ops

    return ops


@dataclass
class OpenSeesRun:
    seconds: float  # analyze() only, wall clock
    cpu_seconds: float  # analyze() only, CPU time of this process
    build_seconds: float
    peaks: dict[str, np.ndarray]


def run_opensees(case, settings: OpenSeesSettings | None = None) -> OpenSeesRun:
    """Build the case in OpenSees (timed apart), analyze it (timed), read its envelopes."""
    ops = import_opensees()
    settings = settings or OpenSeesSettings()
    with tempfile.TemporaryDirectory(prefix="fd_ops_") as tmp:
        work = Path(tmp)
        t0 = time.perf_counter()
        case.build_opensees(ops, settings, work)
        t1, c1 = time.perf_counter(), time.process_time()
        status = ops.analyze(case.n_steps, case.dt)
        t2, c2 = time.perf_counter(), time.process_time()
        t_now = ops.getTime()
        ops.wipe()  # closes the recorders: the envelopes are written
        if status != 0:
            raise RuntimeError(
                f"{case.name}: OpenSees analyze failed (status {status}) at t = {t_now} s"
            )
        peaks = {q: np.loadtxt(work / f"{q}.env", ndmin=2)[2].copy() for q in QUANTITIES}
    return OpenSeesRun(t2 - t1, c2 - c1, t1 - t0, peaks)


# ----------------------------------------------------------------------------- frictiondyn


def frictiondyn_peaks(result) -> dict[str, np.ndarray]:
    """The peaks of a frictiondyn Result's summary, as arrays."""
    return {q: np.asarray(result.summary[SUMMARY_KEYS[q]], dtype=float) for q in QUANTITIES}


def compare_peaks(a: dict, b: dict, quantities=QUANTITIES) -> dict[str, tuple[float, int]]:
    """For each quantity, the largest relative difference |a - b| / |b| over DOFs (devices)
    and where it is (0-based)."""
    out = {}
    for q in quantities:
        x, y = np.abs(np.asarray(a[q], float)), np.abs(np.asarray(b[q], float))
        if x.shape != y.shape:
            raise ValueError(f"peak {q}: {x.shape} values against {y.shape}")
        rel = np.abs(x - y) / np.maximum(y, 1e-300)
        out[q] = (float(rel.max()), int(rel.argmax()))
    return out


def _floats(xs) -> str:
    """Numbers as a namelist list, exactly (repr)."""
    return ", ".join(repr(float(x)) for x in xs)


def _record_group(group: str, dt_record: float, duration: float, record_file: str) -> str:
    """A namelist group (&excitation or &excitation2) of a record of values in m/s2."""
    return (f"&{group}\n  excitation_type = 'record'\n  record_format = 'values'\n"
            f"  record_units = 'm/s2'\n  dt_record = {dt_record!r}\n  duration = {duration!r}\n"
            f"  record_file = '{record_file}'\n/\n")



def _diaphragm_floors(ops, n: int, cm_x, m: float, inertia: float):
    """A fresh 3D OpenSees model (6 DOFs a node) with the masters of n rigid floors at their
    centres of mass (ux, uy, rz free; mass m, m and the rotational inertia), and ``point``:
    the node of a plan point (x, y) of floor f (0 the ground, fixed), made once, each floor's
    nodes listed in ``slaves`` for its rigidDiaphragm. Returns (masters, slaves, point)."""
    ops.wipe()
    ops.model("basic", "-ndm", 3, "-ndf", 6)
    masters = [1000 * (f + 1) for f in range(n)]
    for f, tag in enumerate(masters):
        ops.node(tag, float(cm_x[f]), 0.0, 0.0)
        ops.fix(tag, 0, 0, 1, 1, 1, 0)
        ops.mass(tag, m, m, 0.0, 0.0, 0.0, inertia)
    points: dict[tuple[int, float, float], int] = {}
    slaves: dict[int, list[int]] = {f: [] for f in range(1, n + 1)}

    def point(floor: int, x: float, y: float) -> int:
        key = (floor, x, y)
        if key not in points:
            tag = 1000 * floor + 1 + len([p for p in points if p[0] == floor])
            if floor == 0:
                tag += 1000 * (n + 1)
            ops.node(tag, x, y, 0.0)
            if floor == 0:
                ops.fix(tag, 1, 1, 1, 1, 1, 1)
            else:
                ops.fix(tag, 0, 0, 1, 1, 1, 0)
                slaves[floor].append(tag)
            points[key] = tag
        return points[key]

    return masters, slaves, point

def _run_with_records(deck: str, name: str, records) -> object:
    """frictiondyn's Result of ``deck``, its records written as ag_x.txt, ag_y.txt, ag_z.txt
    (values, m/s2) in a temporary directory."""
    import frictiondyn as fd

    with tempfile.TemporaryDirectory(prefix="fd_case_") as tmp:
        for file, rec in zip(("ag_x.txt", "ag_y.txt", "ag_z.txt"), records):
            np.savetxt(Path(tmp) / file, rec, fmt="%.17g")
        return fd.run_text(deck, f"{name}.nml", tmp)


# ----------------------------------------------------------------------------- 3D building


@dataclass
class Building3DCase:
    """An eccentric building of rigid floors (three DOFs a floor: ux, uy, rz at its centre of
    mass) with four braces with friction dampers a storey, under two ground components.

    Floors ``plan_x`` x ``plan_y`` of mass ``total_mass / n`` and rotational inertia
    m (plan_x² + plan_y²) / 12, their centres of mass ``cm_step`` further east a storey. In
    storey i, along x two frames at y = -plan_y/2 and +plan_y/2 sharing the storey's stiffness
    k_i as ``(1 - ecc, 1 + ecc) / 2``, along y two equal frames at x = -plan_x/2, +plan_x/2
    (k_i proportional to the weight carried, scaled to a first x period ``period`` of the
    planar chain). Four braces a storey, two along x at y = -brace_y, +brace_y and two along
    y at x = -brace_x, +brace_x, each of stiffness k_i / 2 and slip load ``slip_ratio`` times
    half the weight above. Rayleigh a0, a1 (2 % at the chain's modes 1 and 3), given
    explicitly to both codes: C = a0 M + a1 K with K the frames only. Ground: two
    ``synthetic_record`` components (seeds ``seeds``, the second scaled by ``scale2``) along
    x and y; step dt1 = dt_record / n1 in both codes.

    frictiondyn: the deck's &floors, &frames, &floor_braces (hysteretic law, P mu = slip load,
    f = slip load / brace stiffness, end-of-sliding band ``eps1``) and &excitation2 with
    ``refinement``. OpenSees: a 3D model (ndf 6), a node at each floor's centre of mass with
    the mass (m, m, J) and its out-of-plane DOFs fixed, a ``rigidDiaphragm`` (perpendicular z)
    tying to it a node at each frame's and brace's plan point, each frame a ``zeroLength``
    with an ``Elastic`` material (k, damping tangent a1 k) and each brace a ``zeroLength``
    with ``ElasticPP`` (E = brace stiffness, yield strain slip / stiffness), both oriented
    along their plan direction; ``rayleigh(a0, 0, 0, 0)``; ``UniformExcitation`` in x and y.
    """

    n_storeys: int
    duration: float = 10.0
    dt_record: float = 0.01
    n1: int = 10
    n2: int = 50
    refinement: str = "implicit"
    eps1: float = 1.0e-3
    period: float = 1.0
    total_mass: float = 1.0e6
    plan_x: float = 20.0
    plan_y: float = 12.0
    cm_step: float = 0.3
    ecc: float = 0.3
    brace_x: float = 6.0
    brace_y: float = 4.0
    slip_ratio: float = 0.05
    xi: float = 0.02
    pga: float = 0.3 * G
    scale2: float = 0.7
    seeds: tuple[int, int] = (20240613, 20240614)
    records: tuple[np.ndarray, np.ndarray] = field(default=None, repr=False)

    def __post_init__(self) -> None:
        n = self.n_storeys
        if self.records is None:
            a1 = synthetic_record(self.dt_record, self.duration, self.pga, self.seeds[0])
            a2 = synthetic_record(self.dt_record, self.duration, self.pga, self.seeds[1])
            self.records = (a1, self.scale2 * a2)
        self.m = self.total_mass / n
        self.inertia = self.m * (self.plan_x**2 + self.plan_y**2) / 12
        self.cm_x = self.cm_step * np.arange(n, dtype=float)
        above = np.arange(n, 0, -1, dtype=float)
        lam = _chain_eigenvalues(above, self.m)
        scale = (2 * math.pi / self.period) ** 2 / lam[0]
        self.k = above * scale  # storey stiffness along x and along y
        w1 = 2 * math.pi / self.period
        w3 = math.sqrt(lam[min(2, n - 1)] * scale)
        self.a0 = 2 * self.xi * w1 * w3 / (w1 + w3)
        self.a1 = 2 * self.xi / (w1 + w3)
        hx, hy, bx, by = self.plan_x / 2, self.plan_y / 2, self.brace_x, self.brace_y
        # (storey, angle deg, x, y, k): frames; (storey, angle, x, y, slip, kb): braces
        self.frames = []
        self.braces = []
        for i in range(n):
            k = float(self.k[i])
            self.frames += [
                (i + 1, 0.0, 0.0, -hy, k * (1 - self.ecc) / 2),
                (i + 1, 0.0, 0.0, hy, k * (1 + self.ecc) / 2),
                (i + 1, 90.0, -hx, 0.0, k / 2),
                (i + 1, 90.0, hx, 0.0, k / 2),
            ]
            fs = float(self.slip_ratio * G * self.m * above[i] / 2)
            self.braces += [
                (i + 1, 0.0, 0.0, -by, fs, k / 2),
                (i + 1, 0.0, 0.0, by, fs, k / 2),
                (i + 1, 90.0, -bx, 0.0, fs, k / 2),
                (i + 1, 90.0, bx, 0.0, fs, k / 2),
            ]
        self.slip = np.array([b[4] for b in self.braces])
        self.kb = np.array([b[5] for b in self.braces])
        self.dt = self.dt_record / self.n1
        self.n_steps = round(self.duration / self.dt)

    @property
    def name(self) -> str:
        return f"building3d_{self.n_storeys}"

    @property
    def n_dof(self) -> int:
        return 3 * self.n_storeys

    # ------------------------------------------------------------------ frictiondyn

    def deck(self, record_files: tuple[str, str] = ("ag_x.txt", "ag_y.txt")) -> str:
        """The frictiondyn deck; its records are read from ``record_files`` (values, m/s2)."""
        arr = _floats
        n, fr, br = self.n_storeys, self.frames, self.braces
        return (
            f"&floors\n  n_floors = {n}\n  mass = {n}*{self.m!r}\n"
            f"  inertia = {n}*{self.inertia!r}\n"
            f"  cm_x = {arr(self.cm_x)}\n  height = {n}*3.0\n/\n"
            f"&frames\n  n_frames = {len(fr)}\n  storey = {', '.join(str(f[0]) for f in fr)}\n"
            f"  angle = {arr(f[1] for f in fr)}\n  x = {arr(f[2] for f in fr)}\n"
            f"  y = {arr(f[3] for f in fr)}\n  k = {arr(f[4] for f in fr)}\n/\n"
            f"&damping\n  damping_type = 'rayleigh'\n  rayleigh_a0 = {self.a0!r}\n"
            f"  rayleigh_a1 = {self.a1!r}\n/\n"
            f"&floor_braces\n  n_braces = {len(br)}\n"
            f"  storey = {', '.join(str(b[0]) for b in br)}\n"
            f"  angle = {arr(b[1] for b in br)}\n  x = {arr(b[2] for b in br)}\n"
            f"  y = {arr(b[3] for b in br)}\n  slip_load = {arr(b[4] for b in br)}\n"
            f"  stiffness = {arr(b[5] for b in br)}\n  eps1 = {len(br)}*{self.eps1!r}\n/\n"
            + _record_group("excitation", self.dt_record, self.duration, record_files[0])
            + _record_group("excitation2", self.dt_record, self.duration, record_files[1])
            + f"&integration\n  n1 = {self.n1}\n  n2 = {self.n2}\n"
            f"  refinement = '{self.refinement}'\n/\n"
        )

    def _friction(self, nb: int) -> str:
        """The &bearings' friction: the hysteretic law (Coulomb) or the velocity law with
        mu_law 'exponential' (``mu_min`` given)."""
        if self.mu_min is None:
            return (f"  law = {nb}*'hysteretic'\n  mu = {nb}*{self.mu!r}\n"
                    f"  f = {nb}*{self.f!r}\n  eps1 = {nb}*{self.eps1!r}\n")
        return (f"  law = {nb}*'velocity'\n  eps = {nb}*{self.eps!r}\n"
                f"  mu_law = {nb}*'exponential'\n  mu_max = {nb}*{self.mu!r}\n"
                f"  mu_min = {nb}*{self.mu_min!r}\n  mu_rate = {nb}*{self.mu_rate!r}\n")

    def run_frictiondyn(self):
        """frictiondyn's Result of the deck (records written to a temporary directory)."""
        return _run_with_records(self.deck(), self.name, self.records)

    # ------------------------------------------------------------------ OpenSees

    def build_opensees(self, ops, settings: OpenSeesSettings, workdir: Path) -> None:
        n = self.n_storeys
        masters, slaves, point = _diaphragm_floors(ops, n, self.cm_x, self.m, self.inertia)

        def link(tag: int, storey: int, angle: float, x: float, y: float, mat: int) -> None:
            c, s = math.cos(math.radians(angle)), math.sin(math.radians(angle))
            i, j = point(storey - 1, x, y), point(storey, x, y)
            # deformation u_j - u_i along (c, s): the storey's motion at (x, y) along angle
            ops.element("zeroLength", tag, i, j, "-mat", mat, "-dir", 1,
                        "-orient", c, s, 0.0, -s, c, 0.0)

        for e, (st, ang, x, y, k) in enumerate(self.frames, start=1):
            ops.uniaxialMaterial("Elastic", e, k, self.a1 * k)
            link(e, st, ang, x, y, e)
        first = len(self.frames) + 1
        for b, (st, ang, x, y, fs, kb) in enumerate(self.braces, start=first):
            ops.uniaxialMaterial("ElasticPP", b, kb, fs / kb)
            link(b, st, ang, x, y, b)
        for f, tag in enumerate(masters, start=1):
            ops.rigidDiaphragm(3, tag, *slaves[f])
        ops.rayleigh(self.a0, 0.0, 0.0, 0.0)
        for d, rec in enumerate(self.records, start=1):
            ops.timeSeries("Path", d, "-dt", self.dt_record, "-values", *map(float, rec))
            ops.pattern("UniformExcitation", d, d, "-accel", d)
        prec = ("-precision", 12)
        devices = list(range(first, first + len(self.braces)))
        ops.recorder("EnvelopeNode", "-file", str(workdir / "u.env"), *prec, "-node", *masters,
                     "-dof", 1, 2, 6, "disp")
        ops.recorder("Node", "-file", str(workdir / "u.out"), *prec, "-node", *masters,
                     "-dof", 1, 2, "disp")
        ops.recorder("EnvelopeElement", "-file", str(workdir / "s.env"), *prec, "-ele",
                     *devices, "deformation")
        ops.recorder("EnvelopeElement", "-file", str(workdir / "F.env"), *prec, "-ele",
                     *devices, "basicForce")
        if settings.constraints != "Transformation":
            raise ValueError("the rigidDiaphragm floors need constraints 'Transformation'")
        ops.constraints(settings.constraints)
        ops.numberer(settings.numberer)
        ops.system(settings.system)
        ops.test(settings.test, settings.tol, settings.max_iter)
        ops.algorithm(settings.algorithm)
        ops.integrator("Newmark", 0.5, 0.25)
        ops.analysis("Transient")


#: peak |ux, uy, rz| of each floor, |drift x, y| of each storey, |s| and |F| of each brace
QUANTITIES_3D = ("u", "drift", "s", "F")


def frictiondyn_peaks_3d(result) -> dict[str, np.ndarray]:
    """Peaks of a frictiondyn Result of a Building3DCase: 'u' (ux, uy, rz of each floor),
    'drift' (x, y of each storey, between the centres of mass), 's' and 'F' of each brace."""
    s = result.summary
    keys = {"u": "peak_u_m", "drift": "peak_drift_m", "s": "peak_s_m", "F": "peak_force_N"}
    return {q: np.abs(np.asarray(s[k], dtype=float)) for q, k in keys.items()}


def run_opensees_3d(case: Building3DCase, settings: OpenSeesSettings | None = None) -> OpenSeesRun:
    """Build the 3D case in OpenSees (timed apart), analyze it (timed), read its peaks (the
    drifts from the centres of mass' histories). Settings: ``OpenSeesSettings`` with
    constraints 'Transformation' by default."""
    ops = import_opensees()
    settings = settings or OpenSeesSettings(constraints="Transformation")
    with tempfile.TemporaryDirectory(prefix="fd_ops3d_") as tmp:
        work = Path(tmp)
        t0 = time.perf_counter()
        case.build_opensees(ops, settings, work)
        t1, c1 = time.perf_counter(), time.process_time()
        status = ops.analyze(case.n_steps, case.dt)
        t2, c2 = time.perf_counter(), time.process_time()
        t_now = ops.getTime()
        ops.wipe()
        if status != 0:
            raise RuntimeError(
                f"{case.name}: OpenSees analyze failed (status {status}) at t = {t_now} s"
            )
        peaks = {q: np.loadtxt(work / f"{q}.env", ndmin=2)[2].copy() for q in ("u", "s", "F")}
        hist = np.loadtxt(work / "u.out", ndmin=2)  # ux, uy of each floor, a row a step
        xy = np.concatenate([np.zeros((hist.shape[0], 2)), hist], axis=1)
        drift = np.abs(np.diff(xy.reshape(hist.shape[0], -1, 2), axis=1)).max(axis=0)
        peaks["drift"] = drift.reshape(-1)  # storey 1 x, 1 y, 2 x, ...
    peaks = {q: np.abs(v) for q, v in peaks.items()}
    return OpenSeesRun(t2 - t1, c2 - c1, t1 - t0, peaks)


def compare_peaks_3d(a: dict, b: dict) -> dict[str, tuple[float, int]]:
    """As ``compare_peaks``, over QUANTITIES_3D."""
    return compare_peaks(a, b, QUANTITIES_3D)


# ----------------------------------------------------------------------------- isolated block


@dataclass
class IsolatedBlockCase:
    """A rigid block on four sliding bearings at the corners of its plan, under the table's
    motion along x (one component) or along x and y (two).

    The block: mass ``mass``, plan ``2 a`` x ``2 b`` about its centre of mass (rotational
    inertia m ((2a)² + (2b)²) / 12), each bearing carrying a quarter of its weight W. Bearings:
    friction coefficient ``mu`` (Coulomb), a concave surface of radius ``radius`` (0: flat),
    initial stiffness ``k_init`` each. Ground: ``synthetic_record`` components (seeds
    ``seeds``, the second scaled by ``scale2``).

    OpenSees: ndf 6; a node at the block's centre with its mass and its out-of-plane DOFs
    fixed, a ``rigidDiaphragm`` (perpendicular z) tying to it a node above each bearing;
    each bearing a zero-length ``singleFPBearing`` (frictionModel Coulomb, Reff = radius, or
    ``flatSliderBearing`` when flat) with a stiff axial material, oriented with its local x
    along z; the gravity load W/4 on each bearing's node by a static step held constant
    (``loadConst``); Newmark's average acceleration at dt_record / n1, one ``analyze`` a step
    (the histories read from the domain).

    frictiondyn, one component: ``&isolators`` in the 1D model of the block along x (one DOF,
    one isolator carrying W: the four bearings' sum), hysteretic law with P mu = mu W and
    the sticking displacement f = mu (W/4) / (k_init - (W/4)/R): OpenSees's k_init is the
    bearing's whole initial stiffness, the friction part's spring and the pendulum's N/R
    together (SingleFPSimple3d::update, k0 = kInit - N/R).

    A difference to know: OpenSees's singleFPBearing adds to the normal force the shear
    force's component along the curved surface's normal, N = W/4 + q . u / R (large-angle
    geometry, second order in u/R), where frictiondyn's &isolators keeps N = W/4: for a
    curved surface the two codes differ by about (mu + u/R) u/R (0.1 % here); for a flat
    slider they solve the same equations.

    Velocity-dependent friction (``mu_min`` given, ``eps`` the velocity law's band): frictiondyn's
    &bearings with the velocity law and mu_law 'exponential' (mu_max = ``mu``), OpenSees's
    frictionModel VelDependent; its elastic-plastic friction approaches the velocity law's
    rigid-plastic limit as ``k_init`` grows. ``components`` = 3 adds a vertical component.
    """

    mass: float = 1.0e5
    a: float = 5.0
    b: float = 3.0
    mu: float = 0.06
    radius: float = 2.0
    k_init: float = 1.0e8
    components: int = 1
    duration: float = 10.0
    dt_record: float = 0.01
    n1: int = 10
    pga: float = 0.3 * G
    scale2: float = 0.7
    seeds: tuple[int, int] = (1, 2)
    eps1: float = 1.0e-6
    records: tuple = field(default=None, repr=False)
    #: velocity-dependent friction mu(v) = mu - (mu - mu_min) exp(-mu_rate |v|) (``mu`` the fast
    #: value; OpenSees's frictionModel VelDependent muSlow = mu_min, muFast = mu, transRate =
    #: mu_rate [s/m]); None: Coulomb, mu constant
    mu_min: float | None = None
    mu_rate: float = 20.0
    #: frictiondyn's planar bearings with the velocity law of band ``eps`` [m/s] (mu_law
    #: 'exponential' with ``mu_min``); None: the hysteretic law (f, eps1)
    eps: float | None = None
    #: a third, vertical component of PGA vertical * pga (``components`` = 3): frictiondyn's
    #: &excitation3 (N = W/4 (1 + a_z / g)); OpenSees: the mass W / (4 g) on each bearing's
    #: top node, carried by its axial spring ``kv`` [N/m]
    vertical: float = 2 / 3
    seed_z: int = 3
    kv: float = 1.0e10

    def __post_init__(self) -> None:
        if self.records is None:
            recs = [synthetic_record(self.dt_record, self.duration, self.pga, self.seeds[0])]
            if self.components >= 2:
                recs.append(self.scale2 * synthetic_record(self.dt_record, self.duration,
                                                           self.pga, self.seeds[1]))
            if self.components == 3:
                recs.append(self.vertical * synthetic_record(self.dt_record, self.duration,
                                                             self.pga, self.seed_z))
            self.records = tuple(recs)
        self.weight = self.mass * G
        self.dt = self.dt_record / self.n1
        self.n_steps = round(self.duration / self.dt)
        self.corners = [(-self.a, -self.b), (self.a, -self.b), (self.a, self.b), (-self.a, self.b)]

    @property
    def name(self) -> str:
        kind = "flat" if self.radius == 0 else f"R{self.radius:g}"
        return f"isolated_block_{kind}_{self.components}c"

    @property
    def f(self) -> float:
        """The hysteretic law's sticking displacement of a bearing (the class docstring)."""
        n = self.weight / 4
        k2 = n / self.radius if self.radius > 0 else 0.0
        return self.mu * n / (self.k_init - k2)

    # ------------------------------------------------------------------ frictiondyn

    def deck_1d(self, record_file: str = "ag_x.txt") -> str:
        """The frictiondyn deck of the block along x: one DOF on one isolator carrying W."""
        if self.components != 1:
            raise ValueError("deck_1d is the model of one component along x")
        return (
            f"&model\n  n_dof = 1\n  mass = {self.mass!r}\n/\n&springs\n  n_springs = 0\n/\n"
            "&damping\n  damping_type = 'none'\n/\n"
            f"&isolators\n  n_isolators = 1\n  node_i = 1\n  node_j = 0\n"
            f"  weight = {self.weight!r}\n  radius = {self.radius!r}\n  law = 'hysteretic'\n"
            f"  mu = {self.mu!r}\n  f = {self.f!r}\n  eps1 = {self.eps1!r}\n/\n"
            + _record_group("excitation", self.dt_record, self.duration, record_file)
            + f"&integration\n  n1 = {self.n1}\n  refinement = 'implicit'\n/\n"
        )

    def deck_planar(self, record_files: tuple[str, ...] = ("ag_x.txt", "ag_y.txt",
                                                           "ag_z.txt")) -> str:
        """The frictiondyn deck of the block as a rigid floor (ux, uy, rz at its centre) on
        four planar bearings (&bearings) at the corners of its plan, each carrying W/4."""
        deck = (
            f"&floors\n  n_floors = 1\n  mass = {self.mass!r}\n  plan_x = {2 * self.a!r}\n"
            f"  plan_y = {2 * self.b!r}\n/\n&frames\n  n_frames = 0\n/\n"
            "&damping\n  damping_type = 'none'\n/\n"
            f"&bearings\n  n_bearings = 4\n  storey = 4*1\n"
            f"  x = {_floats(c[0] for c in self.corners)}\n  y = {_floats(c[1] for c in self.corners)}\n"
            f"  p = 4*{self.weight / 4!r}\n"
        )
        if self.eps is None:
            deck += (f"  law = 4*'hysteretic'\n  mu = 4*{self.mu!r}\n"
                     f"  f = 4*{self.f!r}\n  eps1 = 4*{self.eps1!r}\n")
        elif self.mu_min is None:
            deck += f"  law = 4*'velocity'\n  mu = 4*{self.mu!r}\n  eps = 4*{self.eps!r}\n"
        else:
            deck += (f"  law = 4*'velocity'\n  eps = 4*{self.eps!r}\n  mu_law = 4*'exponential'\n"
                     f"  mu_max = 4*{self.mu!r}\n  mu_min = 4*{self.mu_min!r}\n"
                     f"  mu_rate = 4*{self.mu_rate!r}\n")
        deck += f"  radius = 4*{self.radius!r}\n/\n"
        for c in range(self.components):
            deck += _record_group(("excitation", "excitation2", "excitation3")[c], self.dt_record,
                                  self.duration, record_files[c])
        return deck + f"&integration\n  n1 = {self.n1}\n  refinement = 'implicit'\n/\n"

    def run_frictiondyn_1d(self):
        """frictiondyn's Result of ``deck_1d`` (its record written to a temporary directory)."""
        return _run_with_records(self.deck_1d(), self.name, self.records[:1])

    def run_frictiondyn_planar(self):
        """frictiondyn's Result of ``deck_planar`` (its records written to a temporary
        directory)."""
        return _run_with_records(self.deck_planar(), self.name, self.records)

    # ------------------------------------------------------------------ OpenSees

    def run_opensees(self) -> tuple[np.ndarray, np.ndarray]:
        """(history, normal forces): the history a row a step (t = 0 included) of the block's
        ux, uy, rz and each bearing's ux, uy; the bearings' normal forces at the end [N]."""
        ops = import_opensees()
        ops.wipe()
        ops.model("basic", "-ndm", 3, "-ndf", 6)
        inertia = self.mass * ((2 * self.a) ** 2 + (2 * self.b) ** 2) / 12
        centre = 100
        ops.node(centre, 0.0, 0.0, 0.0)
        ops.fix(centre, 0, 0, 1, 1, 1, 0)
        ops.mass(centre, self.mass, self.mass, 0.0, 0.0, 0.0, inertia)
        if self.mu_min is None:
            ops.frictionModel("Coulomb", 1, self.mu)
        else:
            ops.frictionModel("VelDependent", 1, self.mu_min, self.mu, self.mu_rate)
        ops.uniaxialMaterial("Elastic", 1, self.kv)  # axial: stiff
        ops.uniaxialMaterial("Elastic", 2, 1.0e-6)   # torsion: none
        ops.uniaxialMaterial("Elastic", 3, 1.0e6)    # rocking: both ends' rotations are fixed
        tops = []
        for k, (x, y) in enumerate(self.corners, start=1):
            ops.node(k, x, y, 0.0)
            ops.fix(k, 1, 1, 1, 1, 1, 1)
            ops.node(10 + k, x, y, 0.0)
            ops.fix(10 + k, 0, 0, 0, 1, 1, 0)
            if self.components == 3:  # the vertical mass its normal force carries, W / (4 g)
                ops.mass(10 + k, 0.0, 0.0, self.weight / 4 / G_FD, 0.0, 0.0, 0.0)
            tops.append(10 + k)
            kind = ("flatSliderBearing", 1) if self.radius == 0 else ("singleFPBearing", 1,
                                                                       self.radius)
            ops.element(kind[0], k, k, 10 + k, *kind[1:], self.k_init, "-P", 1, "-T", 2,
                        "-My", 3, "-Mz", 3, "-orient", 0.0, 0.0, 1.0, 1.0, 0.0, 0.0,
                        "-iter", 100, 1.0e-6)
        ops.rigidDiaphragm(3, centre, *tops)
        ops.timeSeries("Linear", 10)
        ops.pattern("Plain", 10, 10)
        for t in tops:
            ops.load(t, 0.0, 0.0, -self.weight / 4, 0.0, 0.0, 0.0)
        ops.constraints("Transformation")
        ops.numberer("RCM")
        ops.system("BandGeneral")
        ops.test("NormDispIncr", 1.0e-12, 50)
        ops.algorithm("Newton")
        ops.integrator("LoadControl", 1.0)
        ops.analysis("Static")
        if ops.analyze(1) != 0:
            raise RuntimeError(f"{self.name}: OpenSees gravity step failed")
        ops.loadConst("-time", 0.0)
        ops.wipeAnalysis()
        for d, rec in enumerate(self.records, start=1):
            ops.timeSeries("Path", d, "-dt", self.dt_record, "-values", *map(float, rec))
            ops.pattern("UniformExcitation", d, d, "-accel", d)
        ops.constraints("Transformation")
        ops.numberer("RCM")
        ops.system("BandGeneral")
        ops.test("NormDispIncr", 1.0e-8, 100)
        ops.algorithm("Newton")
        ops.integrator("Newmark", 0.5, 0.25)
        ops.analysis("Transient")
        hist = np.zeros((self.n_steps + 1, 3 + 2 * len(tops)))
        for s in range(1, self.n_steps + 1):
            if ops.analyze(1, self.dt) != 0:
                t_now = ops.getTime()
                ops.wipe()
                raise RuntimeError(f"{self.name}: OpenSees analyze failed at t = {t_now} s")
            row = [ops.nodeDisp(centre, 1), ops.nodeDisp(centre, 2), ops.nodeDisp(centre, 6)]
            for t in tops:
                row += [ops.nodeDisp(t, 1), ops.nodeDisp(t, 2)]
            hist[s] = row
        normal = np.array([-ops.eleResponse(k, "basicForce")[0] for k in range(1, 5)])
        ops.wipe()
        return hist, normal


# ----------------------------------------------------------------------------- isolated building


@dataclass
class IsolatedBuildingCase:
    """An eccentric building of rigid floors on a rigid base mat carried by friction pendulum
    bearings, under two ground components (three with ``vertical``).

    Floors (frictiondyn's &floors): floor 1 the base mat, floors 2 ... n + 1 the superstructure,
    each of mass ``floor_mass`` and rotational inertia m (plan_x² + plan_y²) / 12 over a
    ``plan_x`` x ``plan_y`` plan, the superstructure's centres of mass ``cm_step`` further east
    a storey. Storey 1 holds the bearings alone: ``bearings_x`` x ``bearings_y`` of them on a
    grid over the plan, each carrying an equal share N of the whole weight (``p``), with
    friction coefficient ``mu`` (Coulomb), a concave surface of radius ``radius`` and the
    initial stiffness ``k_init``. Storeys 2 ... n + 1 as ``Building3DCase``'s frames: along x
    two frames at y = -plan_y/2, +plan_y/2 sharing the storey's stiffness as (1 - ecc, 1 + ecc)/2,
    along y two equal frames at x = -plan_x/2, +plan_x/2, scaled to a fixed-base first period
    ``period``. Rayleigh C = a0 M + a1 K (2 % at the fixed-base chain's modes 1 and 3), K the
    frames and the pendulums' N/R. Ground: two ``synthetic_record`` components (the second
    scaled by ``scale2``); step dt1 = dt_record / n1 in both codes.

    frictiondyn: the hysteretic law carried to the plane (a circular yield surface with radial
    return) with P = N, f = mu N / (k_init - N/R) (OpenSees's k_init is the friction spring and
    the pendulum's N/R together), ``refinement = 'implicit'``, end of sliding ``eps1``.

    OpenSees: ndf 6; a node at each floor's centre of mass with its mass (m, m, J) and its
    out-of-plane DOFs fixed, a ``rigidDiaphragm`` tying to it the nodes of the frames' ends
    and, for the base mat, the top node of each bearing (its vertical DOF free); each bearing a
    zero-length ``singleFPBearing`` (frictionModel Coulomb, Reff = radius, k_init, a stiff
    axial material) with the gravity load N on its top node by a static step held constant
    (``loadConst``), and a dashpot a1 N/R along x and y beside it (frictiondyn's C = a1 K damps
    the pendulum's stiffness); each frame a ``zeroLength`` Elastic link (k, damping tangent
    a1 k); ``rayleigh(a0, 0, 0, 0)``; Newmark's average acceleration, Newton iterations.

    Where the two differ: OpenSees's singleFPBearing takes its normal force from its own axial
    response and adds the shear's component along the surface's normal (second order in u/R,
    as ``IsolatedBlockCase`` says): the stiff axial material keeps N at the gravity share to
    1e-6, the geometric term changes the friction and restoring forces by about (mu + u/R) u/R.

    ``vertical`` > 0 adds a third, vertical component (a ``synthetic_record`` of seed ``seed_z``
    scaled to ``vertical`` pga): frictiondyn's &excitation3 (a rigid vertical support, N = p (1 +
    a_z / g)); in OpenSees the vertical base motion on the mass p / g (g = 9.80665 m/s2, so that
    the rigid limits agree) at each bearing's top node, carried by the bearing's axial spring
    ``kv``: the vertical period 2 pi sqrt(p / (g kv)) must be well below the record step for N
    to be the rigid limit (1e13 N/m: 0.5 to 0.7 ms here). Under a varying N the regularized
    friction differs in proportion to f: frictiondyn keeps f and scales the sticking stiffness
    mu N / f with N, OpenSees keeps k_init - N/R and scales the yield displacement; a stiffer
    ``k_init`` makes the difference small.
    """

    n_storeys: int
    bearings_x: int = 8
    bearings_y: int = 5
    duration: float = 30.0
    dt_record: float = 0.01
    n1: int = 10
    floor_mass: float = 2.4e5
    plan_x: float = 20.0
    plan_y: float = 12.0
    cm_step: float = 0.3
    ecc: float = 0.3
    period: float = 1.0
    xi: float = 0.02
    mu: float = 0.05
    radius: float = 2.5
    k_init: float = 5.0e7
    eps1: float = 1.0e-6
    pga: float = 0.3 * G
    scale2: float = 0.7
    seeds: tuple[int, int] = (20240613, 20240614)
    records: tuple = field(default=None, repr=False)
    vertical: float = 0.0  # a third, vertical component of PGA vertical * pga (0: none)
    seed_z: int = 20240615
    kv: float = 1.0e12  # OpenSees: a bearing's axial stiffness [N/m]
    #: velocity-dependent friction as IsolatedBlockCase's: mu(v) = mu - (mu - mu_min)
    #: exp(-mu_rate |v|), frictiondyn's velocity law of band ``eps`` [m/s] with mu_law
    #: 'exponential', OpenSees's frictionModel VelDependent; None: Coulomb, the hysteretic law
    mu_min: float | None = None
    mu_rate: float = 20.0
    eps: float = 1.0e-4

    def __post_init__(self) -> None:
        n = self.n_storeys
        if self.records is None:
            a1 = synthetic_record(self.dt_record, self.duration, self.pga, self.seeds[0])
            a2 = synthetic_record(self.dt_record, self.duration, self.pga, self.seeds[1])
            self.records = (a1, self.scale2 * a2)
            if self.vertical:
                az = synthetic_record(self.dt_record, self.duration, self.pga, self.seed_z)
                self.records += (self.vertical * az,)
        self.m = self.floor_mass
        self.inertia = self.m * (self.plan_x**2 + self.plan_y**2) / 12
        self.n_floors = n + 1
        # the base mat at the plan origin, the superstructure's floors further east
        self.cm_x = np.concatenate([[0.0], self.cm_step * np.arange(n, dtype=float)])
        above = np.arange(n, 0, -1, dtype=float)
        lam = _chain_eigenvalues(above, self.m)
        scale = (2 * math.pi / self.period) ** 2 / lam[0]
        self.k = above * scale  # superstructure storey stiffness along x and along y
        w1 = 2 * math.pi / self.period
        w3 = math.sqrt(lam[min(2, n - 1)] * scale)
        self.a0 = 2 * self.xi * w1 * w3 / (w1 + w3)
        self.a1 = 2 * self.xi / (w1 + w3)
        hx, hy = self.plan_x / 2, self.plan_y / 2
        self.frames = []  # (storey, angle deg, x, y, k); storey 1 is the bearings'
        for i in range(n):
            k = float(self.k[i])
            self.frames += [
                (i + 2, 0.0, 0.0, -hy, k * (1 - self.ecc) / 2),
                (i + 2, 0.0, 0.0, hy, k * (1 + self.ecc) / 2),
                (i + 2, 90.0, -hx, 0.0, k / 2),
                (i + 2, 90.0, hx, 0.0, k / 2),
            ]
        xs = np.linspace(-hx, hx, self.bearings_x)
        ys = np.linspace(-hy, hy, self.bearings_y)
        self.bearings = [(float(x), float(y)) for y in ys for x in xs]
        self.weight = self.n_floors * self.m * G
        self.p = self.weight / len(self.bearings)
        self.dt = self.dt_record / self.n1
        self.n_steps = round(self.duration / self.dt)

    @property
    def name(self) -> str:
        return f"isolated_building_{self.n_storeys}_{len(self.bearings)}"

    @property
    def f(self) -> float:
        """The hysteretic law's sticking displacement of a bearing (the class docstring)."""
        return self.mu * self.p / (self.k_init - self.p / self.radius)

    # ------------------------------------------------------------------ frictiondyn

    def deck(self, record_files: tuple[str, ...] = ("ag_x.txt", "ag_y.txt", "ag_z.txt")) -> str:
        """The frictiondyn deck; its records are read from ``record_files`` (values, m/s2),
        a third (vertical) one as &excitation3."""
        arr = _floats
        nf, fr, nb = self.n_floors, self.frames, len(self.bearings)
        return (
            f"&floors\n  n_floors = {nf}\n  mass = {nf}*{self.m!r}\n"
            f"  inertia = {nf}*{self.inertia!r}\n"
            f"  cm_x = {arr(self.cm_x)}\n  height = {nf}*3.0\n/\n"
            f"&frames\n  n_frames = {len(fr)}\n  storey = {', '.join(str(f[0]) for f in fr)}\n"
            f"  angle = {arr(f[1] for f in fr)}\n  x = {arr(f[2] for f in fr)}\n"
            f"  y = {arr(f[3] for f in fr)}\n  k = {arr(f[4] for f in fr)}\n/\n"
            f"&damping\n  damping_type = 'rayleigh'\n  rayleigh_a0 = {self.a0!r}\n"
            f"  rayleigh_a1 = {self.a1!r}\n/\n"
            f"&bearings\n  n_bearings = {nb}\n  storey = {nb}*1\n"
            f"  x = {arr(b[0] for b in self.bearings)}\n  y = {arr(b[1] for b in self.bearings)}\n"
            f"  p = {nb}*{self.p!r}\n" + self._friction(nb) + f"  radius = {nb}*{self.radius!r}\n/\n"
            + _record_group("excitation", self.dt_record, self.duration, record_files[0])
            + _record_group("excitation2", self.dt_record, self.duration, record_files[1])
            + (_record_group("excitation3", self.dt_record, self.duration, record_files[2])
               if len(self.records) > 2 else "")
            + f"&integration\n  n1 = {self.n1}\n  refinement = 'implicit'\n/\n"
        )

    def _friction(self, nb: int) -> str:
        """The &bearings' friction: the hysteretic law (Coulomb) or the velocity law with
        mu_law 'exponential' (``mu_min`` given)."""
        if self.mu_min is None:
            return (f"  law = {nb}*'hysteretic'\n  mu = {nb}*{self.mu!r}\n"
                    f"  f = {nb}*{self.f!r}\n  eps1 = {nb}*{self.eps1!r}\n")
        return (f"  law = {nb}*'velocity'\n  eps = {nb}*{self.eps!r}\n"
                f"  mu_law = {nb}*'exponential'\n  mu_max = {nb}*{self.mu!r}\n"
                f"  mu_min = {nb}*{self.mu_min!r}\n  mu_rate = {nb}*{self.mu_rate!r}\n")

    def run_frictiondyn(self):
        """frictiondyn's Result of the deck (records written to a temporary directory)."""
        return _run_with_records(self.deck(), self.name, self.records)

    def frictiondyn_peaks(self, result) -> dict[str, np.ndarray]:
        """'bearing': each bearing's peak |(s_x, s_y)|; 'drift': |drift| of every storey along
        x and y (storey 1 x, 1 y, 2 x, ...; storey 1 the base mat over the ground)."""
        s = result.summary
        return {"bearing": np.asarray(s["bearing_peak_displacement_m"], float),
                "drift": np.abs(np.asarray(s["peak_drift_m"], float)),
                "normal_min": np.asarray(s["bearing_min_normal_force_N"], float),
                "normal_max": np.asarray(s["bearing_max_normal_force_N"], float)}

    # ------------------------------------------------------------------ OpenSees

    def build_opensees(self, ops, workdir: Path) -> list[int]:
        """The model, its gravity step held and its transient analysis set up, with recorders
        of the floors' and the bearings' tops' ux, uy in ``workdir``; returns the masters."""
        nf = self.n_floors
        masters, slaves, point = _diaphragm_floors(ops, nf, self.cm_x, self.m, self.inertia)

        for e, (st, ang, x, y, k) in enumerate(self.frames, start=1):
            c, s = math.cos(math.radians(ang)), math.sin(math.radians(ang))
            ops.uniaxialMaterial("Elastic", e, k, self.a1 * k)
            ops.element("zeroLength", e, point(st - 1, x, y), point(st, x, y), "-mat", e, "-dir", 1,
                        "-orient", c, s, 0.0, -s, c, 0.0)
        # the bearings: ground node, top node (vertical free) slaved to the base mat
        base = 100000
        if self.mu_min is None:
            ops.frictionModel("Coulomb", 1, self.mu)
        else:
            ops.frictionModel("VelDependent", 1, self.mu_min, self.mu, self.mu_rate)
        mats = base + 1
        ops.uniaxialMaterial("Elastic", mats, self.kv)         # axial: stiff
        ops.uniaxialMaterial("Elastic", mats + 1, 1.0e-6)      # torsion: none
        ops.uniaxialMaterial("Elastic", mats + 2, 1.0e6)       # rocking: both ends' rotations fixed
        eta = self.a1 * self.p / self.radius
        ops.uniaxialMaterial("Elastic", mats + 3, 0.0, eta)    # the pendulum's a1 N/R dashpot
        tops = []
        for b, (x, y) in enumerate(self.bearings, start=1):
            lo, hi = base + 2 * b, base + 2 * b + 1
            ops.node(lo, x, y, 0.0)
            ops.fix(lo, 1, 1, 1, 1, 1, 1)
            ops.node(hi, x, y, 0.0)
            ops.fix(hi, 0, 0, 0, 1, 1, 0)
            if len(self.records) > 2:  # the vertical mass its normal force carries, p / g
                ops.mass(hi, 0.0, 0.0, self.p / G_FD, 0.0, 0.0, 0.0)
            tops.append(hi)
            ops.element("singleFPBearing", base + b, lo, hi, 1, self.radius, self.k_init, "-P", mats,
                        "-T", mats + 1, "-My", mats + 2, "-Mz", mats + 2,
                        "-orient", 0.0, 0.0, 1.0, 1.0, 0.0, 0.0, "-iter", 100, 1.0e-8)
            ops.element("zeroLength", 2 * base + b, lo, hi, "-mat", mats + 3, mats + 3, "-dir", 1, 2)
        for f, tag in enumerate(masters, start=1):
            ops.rigidDiaphragm(3, tag, *(slaves[f] + (tops if f == 1 else [])))
        # gravity, held
        ops.timeSeries("Linear", 100)
        ops.pattern("Plain", 100, 100)
        for t in tops:
            ops.load(t, 0.0, 0.0, -self.p, 0.0, 0.0, 0.0)
        ops.constraints("Transformation")
        ops.numberer("RCM")
        ops.system("BandGeneral")
        ops.test("NormDispIncr", 1.0e-12, 50)
        ops.algorithm("Newton")
        ops.integrator("LoadControl", 1.0)
        ops.analysis("Static")
        if ops.analyze(1) != 0:
            raise RuntimeError(f"{self.name}: OpenSees gravity step failed")
        ops.loadConst("-time", 0.0)
        ops.wipeAnalysis()
        ops.rayleigh(self.a0, 0.0, 0.0, 0.0)
        for d, rec in enumerate(self.records, start=1):
            ops.timeSeries("Path", d, "-dt", self.dt_record, "-values", *map(float, rec))
            ops.pattern("UniformExcitation", d, d, "-accel", d)
        prec = ("-precision", 12)
        ops.recorder("Node", "-file", str(workdir / "u.out"), *prec, "-node", *masters, "-dof", 1, 2, "disp")
        ops.recorder("Node", "-file", str(workdir / "b.out"), *prec, "-node", *tops, "-dof", 1, 2, "disp")
        ops.recorder("Element", "-file", str(workdir / "n.out"), *prec, "-ele",
                     *(base + b for b in range(1, len(self.bearings) + 1)), "basicForce")
        ops.constraints("Transformation")
        ops.numberer("RCM")
        ops.system("BandGeneral")
        ops.test("NormDispIncr", 1.0e-8, 100)
        ops.algorithm("Newton")
        ops.integrator("Newmark", 0.5, 0.25)
        ops.analysis("Transient")
        return masters

    def run_opensees(self) -> OpenSeesRun:
        """Build (timed apart), analyze (timed), read the peaks: each bearing's |(ux, uy)| of its
        top and each storey's |drift| along x and y between the centres of mass ('normal': the
        bearings' normal forces at the end)."""
        ops = import_opensees()
        with tempfile.TemporaryDirectory(prefix="fd_opsiso_") as tmp:
            work = Path(tmp)
            t0 = time.perf_counter()
            self.build_opensees(ops, work)
            t1, c1 = time.perf_counter(), time.process_time()
            status = ops.analyze(self.n_steps, self.dt)
            t2, c2 = time.perf_counter(), time.process_time()
            t_now = ops.getTime()
            base = 100000
            normal = np.array([-ops.eleResponse(base + b, "basicForce")[0]
                               for b in range(1, len(self.bearings) + 1)])
            ops.wipe()
            if status != 0:
                raise RuntimeError(f"{self.name}: OpenSees analyze failed (status {status}) at t = {t_now} s")
            hist = np.loadtxt(work / "u.out", ndmin=2)
            tops = np.loadtxt(work / "b.out", ndmin=2)
            forces = -np.loadtxt(work / "n.out", ndmin=2)[:, 0::6]  # each bearing's N, a row a step
        xy = np.concatenate([np.zeros((hist.shape[0], 2)), hist], axis=1)
        drift = np.abs(np.diff(xy.reshape(hist.shape[0], -1, 2), axis=1)).max(axis=0).reshape(-1)
        bearing = np.hypot(tops[:, 0::2], tops[:, 1::2]).max(axis=0)
        return OpenSeesRun(t2 - t1, c2 - c1, t1 - t0, {
            "bearing": bearing, "drift": drift, "normal": normal, "normal_history": forces,
            "normal_min": forces.min(axis=0), "normal_max": forces.max(axis=0)})
