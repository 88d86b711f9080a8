"""The sparse effective stiffness (linear_system = 'sparse', SuiteSparse's CHOLMOD) against the
banded one on 3D frames from Matrix Market files (bench/matrix_scale.py's frame): the same
histories and peaks to 1e-10 on a plan whose band after reverse Cuthill-McKee ordering is
wide and on a tower whose band is a floor; 'auto' takes the sparse path on the plan and the
banded one on the tower, and the summary says which; an indefinite K is refused naming its
DOF. Skipped when the build has no CHOLMOD, where 'sparse' is an error saying so."""

from __future__ import annotations

import sys

import numpy as np
import pytest

from conftest import ROOT, paper_groups

sys.path.insert(0, str(ROOT / "bench"))
import matrix_scale  # noqa: E402  (the frame of the benchmark: 3D beams, six DOFs a node)

NO_CHOLMOD = "this build has no CHOLMOD"


@pytest.fixture(scope="module")
def has_cholmod(tmp_path_factory):
    """Whether the executable was built with CHOLMOD: a two-mass run asking for 'sparse'."""
    from conftest import deck_text, run_deck_file

    work = tmp_path_factory.mktemp("probe")
    groups = paper_groups(4, "velocity")
    groups["excitation"]["duration"] = 0.05
    groups["integration"]["linear_system"] = "sparse"
    (work / "p.nml").write_text(deck_text(groups))
    r = run_deck_file(work / "p.nml", work)
    if r.returncode == 0:
        return True
    assert NO_CHOLMOD in r.stderr, r.stderr
    return False


@pytest.fixture
def cholmod(has_cholmod):
    if not has_cholmod:
        pytest.skip("the build has no CHOLMOD (SuiteSparse): the banded path only")


def frame_deck(nx, ny, nz, n_devices, law="hysteretic", system="auto", k_scale=1.0):
    """A frame of nx x ny columns and nz storeys; n_devices interstorey dampers on ux (x
    component along x, every other one on uy) of the nodes in turn, floors in turn; a 0.05 m,
    2 Hz table motion for 0.1 s, history of a few DOFs and every device."""
    ent, node, n = matrix_scale.frame(nx, ny, nz)
    if k_scale != 1.0:
        ent = {key: k_scale * v for key, v in ent.items()}
    nodes = [(ix, iy) for iy in range(ny) for ix in range(nx)]
    ni, nj = [], []
    for k in range(n_devices):
        z = 1 + k % nz
        ix, iy = nodes[(k // nz) % len(nodes)]
        comp = (k // (nz * len(nodes))) % 2
        ni.append(6 * node[(ix, iy, z)] + comp + 1)
        nj.append(6 * node[(ix, iy, z - 1)] + comp + 1 if z > 1 else 0)
    mass = {(i, i): (matrix_scale.NODE_MASS if i % 6 < 3 else matrix_scale.NODE_INERTIA) for i in range(n)}

    def mtx(entries):
        lines = ["%%MatrixMarket matrix coordinate real symmetric", f"{n} {n} {len(entries)}"]
        lines += [f"{i + 1} {j + 1} {float(v)!r}" for (i, j), v in sorted(entries.items())]
        return "\n".join(lines) + "\n"

    nd = len(ni)
    groups = {
        "matrices": {"k_file": "K.mtx", "m_file": "M.mtx", "influence": [1.0 if i % 6 == 0 else 0.0 for i in range(n)]},
        "friction": {"n_devices": nd, "node_i": ni, "node_j": nj, "law": [law] * nd, "p": [1.5e5] * nd,
                     "mu": [1.0] * nd, "eps": [1.0e-3] * nd, "f": [1.0e-4] * nd},
        "damping": {"damping_type": "rayleigh", "rayleigh_a0": 0.3, "rayleigh_a1": 1.0e-3},
        "excitation": {"excitation_type": "harmonic", "amplitude": 0.05, "frequency": 2.0, "dt_record": 0.01,
                       "duration": 0.1},
        "integration": {"n1": 5, "n2": 10, "linear_system": system},
        "output": {"n_modes": 0, "history_dofs": [1, 2, n // 2, n - 5]},
    }
    return groups, {"K.mtx": mtx(ent), "M.mtx": mtx(mass)}


# the plan: 7 x 7 columns, 2 storeys (588 DOFs, half-bandwidth 87 after ordering: the band
# is a floor of 294 DOFs); the tower: 3 x 3 columns, 10 storeys (540 DOFs, half-bandwidth 62)
PLAN = (7, 7, 2, 24)
TOWER = (3, 3, 10, 24)


def run_pair(run, shape, law):
    out = {}
    for system in ("banded", "sparse", "auto"):
        groups, files = frame_deck(*shape, law=law, system=system)
        r = run(groups, files=files)
        assert r.returncode == 0, r.stderr
        out[system] = (r.summary(), r.history())
    return out


def assert_same(a, b, tol=1e-10):
    """Histories and the summary's peak lists agree to tol relative to each column's largest."""
    (sa, ha), (sb, hb) = a, b
    assert ha.names == hb.names
    assert ha.data.shape == hb.data.shape and ha.data.shape[0] > 10
    scale = np.maximum(np.abs(ha.data).max(axis=0), 1e-300)
    err = (np.abs(ha.data - hb.data) / scale).max()
    assert err <= tol, f"histories differ by {err:.2e} of a column's largest value"
    for key in ("peak_u_m", "peak_aabs_mps2", "peak_s_m", "peak_force_N", "stick_to_slip", "steps_dt1",
                "steps_dt2"):
        x, y = np.asarray(sa[key], float), np.asarray(sb[key], float)
        assert np.allclose(x, y, rtol=tol, atol=tol * np.abs(x).max()), key


@pytest.mark.parametrize("law", ["hysteretic", "velocity"])
def test_sparse_equals_banded_on_a_wide_plan_and_auto_takes_it(run, cholmod, law):
    out = run_pair(run, PLAN, law)
    assert out["banded"][0]["linear_system"] == "banded"
    assert out["sparse"][0]["linear_system"] == "sparse"
    assert out["auto"][0]["linear_system"] == "sparse"
    assert out["sparse"][0]["half_bandwidth"] == out["banded"][0]["half_bandwidth"] > 80
    assert sum(out["sparse"][0]["stick_to_slip"]) > 0, "no phase change: the updates are not exercised"
    assert_same(out["banded"], out["sparse"])
    assert_same(out["sparse"], out["auto"], tol=0.0)


def test_sparse_equals_banded_on_a_tower_and_auto_keeps_the_band(run, cholmod):
    out = run_pair(run, TOWER, "hysteretic")
    assert out["auto"][0]["linear_system"] == "banded"
    assert out["sparse"][0]["linear_system"] == "sparse"
    assert 32 < out["banded"][0]["half_bandwidth"] < 100
    assert sum(out["sparse"][0]["stick_to_slip"]) > 0
    assert_same(out["banded"], out["sparse"])
    assert_same(out["banded"], out["auto"], tol=0.0)


def test_indefinite_k_is_refused_on_the_sparse_path(run, cholmod):
    """K of the plan with its sign turned: the message names the DOF where it fails."""
    groups, files = frame_deck(*PLAN, system="sparse", k_scale=-1.0)
    r = run(groups, files=files)
    assert r.returncode != 0
    assert "positive definite" in r.stderr and "DOF" in r.stderr, r.stderr
    assert not r.outdir.exists()


def test_sparse_without_cholmod_is_an_error(run, has_cholmod):
    if has_cholmod:
        pytest.skip("the build has CHOLMOD")
    groups = paper_groups(4, "velocity")
    groups["excitation"]["duration"] = 0.05
    groups["integration"]["linear_system"] = "sparse"
    r = run(groups)
    assert r.returncode != 0
    assert "&integration" in r.stderr and "linear_system = 'sparse'" in r.stderr and NO_CHOLMOD in r.stderr
    assert not r.outdir.exists()


@pytest.mark.parametrize("technique", ["moreau_jean", "event_driven"])
def test_sparse_is_newmarks_alone(run, technique):
    """Moreau-Jean's and the exact technique's systems have no sparse path: asking for one is
    an error naming the group, the variable and what the technique takes, with or without
    CHOLMOD in the build (not a silent banded or dense run)."""
    groups = paper_groups(4, "coulomb")
    groups["excitation"]["duration"] = 0.05
    groups["integration"] = {"technique": technique, "linear_system": "sparse"}
    r = run(groups)
    assert r.returncode != 0
    assert "group &integration: linear_system = 'sparse'" in r.stderr, r.stderr
    assert f"technique = '{technique}' takes 'auto', 'dense' or 'banded'" in r.stderr
    assert not r.outdir.exists()
