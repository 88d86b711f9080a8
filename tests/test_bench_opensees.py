"""Cross-check of two independent codes: frictiondyn against OpenSeesPy on the benchmark's
2-storey shear building with a friction damper in each storey (bench/opensees_models.py).

frictiondyn's hysteretic law (P mu = slip load, f = slip load / brace stiffness) and an
OpenSees ElasticPP zeroLength link are the same force law; both codes integrate with Newmark's
average acceleration at the same dt1, frictiondyn with its own step control at phase changes,
OpenSees with Newton iterations on the links. Their peaks must agree within 3 %.

openseespy is in the test extra; this file is skipped where it cannot be imported. No timing here: speed is measured by the bench.
"""

from __future__ import annotations


import numpy as np
from conftest import opensees_models



def test_two_storey_friction_building_peaks_agree_with_opensees():
    om = opensees_models()
    case = om.BuildingCase(2)  # 20 s of the synthetic record, dt1 = 1 ms
    result = case.analysis().run()
    fd_peaks = om.frictiondyn_peaks(result)
    ops = om.run_opensees(case)

    # the comparison exercises friction, not only the linear frame: both dampers slip in
    # frictiondyn, and OpenSees's links reach their slip load (ElasticPP caps |F| at it)
    s = result.summary
    assert len(s["stick_to_slip"]) == 2 and min(s["stick_to_slip"]) > 0
    np.testing.assert_allclose(ops.peaks["F"], case.slip, rtol=1e-9)
    np.testing.assert_allclose(fd_peaks["F"], case.slip, rtol=1e-9)
    # and they slip far: each storey's peak drift exceeds its elastic limit f by more than f
    assert np.all(ops.peaks["s"] > 2 * case.slip / case.kb)

    for q in ("u", "aabs", "s"):
        np.testing.assert_allclose(fd_peaks[q], ops.peaks[q], rtol=0.03, err_msg=f"peak |{q}|")
