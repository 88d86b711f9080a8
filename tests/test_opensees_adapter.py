"""A frame built in OpenSeesPy, analysed by frictiondyn through frictiondyn.opensees: its
K and M assembled by OpenSeesPy, the massless DOFs condensed, a brace added; against the
same frame with the same brace analysed by OpenSeesPy itself. Skipped when openseespy cannot
be imported (it is not a test dependency)."""

import numpy as np
import pytest

import frictiondyn
from frictiondyn import opensees as fo

try:
    import openseespy.opensees as ops
except Exception as exc:  # noqa: BLE001 - any failure to load the library
    pytest.skip(f"openseespy is not importable: {exc}", allow_module_level=True)

DT_RECORD, N1 = 0.01, 10
RECORD = 0.3 * 9.81 * np.sin(2 * np.pi * 1.7 * np.arange(0, 3.0 + 1e-9, DT_RECORD))
KB = 2.0e7   # the brace's stiffness [N/m]


def portal(ops):
    """A two-storey, one-bay steel frame in 2D (ndf 3), floor masses at the beam-column
    nodes along x only: the rotations and vertical DOFs have no mass."""
    ops.wipe()
    ops.model("basic", "-ndm", 2, "-ndf", 3)
    for tag, x, y in [(1, 0, 0), (2, 6, 0), (3, 0, 3.5), (4, 6, 3.5), (5, 0, 7), (6, 6, 7)]:
        ops.node(tag, x, y)
    ops.fix(1, 1, 1, 1)
    ops.fix(2, 1, 1, 1)
    for tag in (3, 4, 5, 6):
        ops.mass(tag, 2.0e4, 0.0, 0.0)
    ops.geomTransf("Linear", 1)
    for e, (i, j, inertia) in enumerate([(1, 3, 2e-4), (2, 4, 2e-4), (3, 5, 1.5e-4), (4, 6, 1.5e-4),
                                          (3, 4, 4e-4), (5, 6, 4e-4)], start=1):
        ops.element("elasticBeamColumn", e, i, j, 0.01, 2.0e11, inertia, 1)


def test_the_adapters_frame_equals_opensees_own_run(tmp_path):
    """A brace from node 3 (floor 1) to the ground along x, stiff enough never to slip: a
    linear run, so frictiondyn on the condensed matrices and OpenSeesPy on its own model
    (the brace a zeroLength spring, Newmark average acceleration at the same step, the same
    record linear between samples) agree to the solvers' round-off."""
    portal(ops)
    mats = fo.opensees_matrices(ops)
    assert len(mats.dofs) == 12
    cond = fo.condense(mats)
    assert sorted(cond.dofs) == [(3, 1), (4, 1), (5, 1), (6, 1)]
    np.savetxt(tmp_path / "rec.txt", RECORD)
    deck = fo.write_deck(
        tmp_path, mats, direction=1, braces=[fo.Brace((3, 1), None, slip_load=1.0e12, stiffness=KB)],
        excitation=f"&excitation\n  excitation_type = 'record'\n  record_file = 'rec.txt'\n"
                   f"  dt_record = {DT_RECORD}\n/\n",
        integration=f"&integration\n  n1 = {N1}\n/\n")
    r = frictiondyn.run(deck)
    assert r.summary["stick_to_slip"] == [0]
    u_fd = np.array([r[f"u{i}"] for i in range(1, 5)])

    # OpenSeesPy's own run of the same frame and brace
    portal(ops)
    ops.node(10, 0.0, 3.5)
    ops.fix(10, 1, 1, 1)
    ops.uniaxialMaterial("Elastic", 1, KB)
    ops.element("zeroLength", 10, 10, 3, "-mat", 1, "-dir", 1)
    ops.timeSeries("Path", 1, "-dt", DT_RECORD, "-values", *RECORD)
    ops.pattern("UniformExcitation", 1, 1, "-accel", 1)
    ops.constraints("Transformation")
    ops.numberer("Plain")
    ops.system("FullGeneral")
    ops.algorithm("Linear")
    ops.integrator("Newmark", 0.5, 0.25)
    ops.analysis("Transient")
    u_os = [[0.0] * 4]
    for _ in range(len(RECORD) - 1):
        for _ in range(N1):
            assert ops.analyze(1, DT_RECORD / N1) == 0
        u_os.append([ops.nodeDisp(tag, 1) for tag in (3, 4, 5, 6)])
    u_os = np.array(u_os).T
    ops.wipe()
    assert np.abs(u_fd).max() > 1e-3
    assert np.abs(u_fd - u_os).max() <= 1e-8 * np.abs(u_os).max()
