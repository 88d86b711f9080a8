"""Nested refinement (`refinement = 'nested'`, docs/theory.md section 6) against the paper's
(`'step'`): a dt1 step with a phase change is split by the prime factors of n2 and only the
pieces with a change are split further, so transitions are still taken in steps of dt2.

- A prime n2 has one level: the nested refinement is the paper's, bit for bit.
- On the paper's test 4 (both laws) the two refinements see the same transitions, and their
  peaks differ by less than a tenth of the run's own discretization error (the change of the
  peaks when dt1 is halved): the steps the nested refinement takes between transitions are
  steps of a linear system in fixed phases, as accurate as the dt1 steps around them. The
  energy balance closes to round-off, and fewer dt2 steps are taken.
- On a 10-storey building with a damper per storey the same holds, transition by transition.
Speed is measured in bench/scale.py, never here.
"""

from __future__ import annotations

import frictiondyn as fd
import numpy as np
import pytest
from conftest import deck_text, paper_groups
from test_scale import building

PEAKS = ("peak_u_m", "peak_aabs_mps2", "peak_s_m")


def paper_test4(law: str, refinement: str, n1: int = 20, n2: int = 50) -> fd.Result:
    g = paper_groups(4, law)
    g["excitation"]["duration"] = 10.0
    g["integration"].update(n1=n1, n2=n2, refinement=refinement)
    return fd.run_text(deck_text(g), name="test4.nml")


def peaks(r: fd.Result) -> np.ndarray:
    return np.concatenate([r.summary[k] for k in PEAKS])


@pytest.mark.parametrize("law", ["hysteretic", "velocity"])
def test_prime_n2_nested_is_the_papers_refinement_bit_for_bit(law):
    step = paper_test4(law, "step", n2=53)
    nested = paper_test4(law, "nested", n2=53)
    assert step.summary["steps_dt2"] > 0  # the refinement is used
    assert nested.summary["steps_nested"] == 0
    assert np.array_equal(step.data, nested.data)
    for key in (*PEAKS, "peak_force_N", "energy_input_J", "stick_to_slip", "steps_dt2"):
        assert step.summary[key] == nested.summary[key], key


@pytest.mark.parametrize("law", ["hysteretic", "velocity"])
def test_nested_refinement_agrees_with_the_papers_on_test4(law):
    step = paper_test4(law, "step")
    nested = paper_test4(law, "nested")
    finer = paper_test4(law, "step", n1=40)  # dt1 halved: the size of the run's own error
    s, n = step.summary, nested.summary
    assert s["stick_to_slip"] == n["stick_to_slip"] and s["slip_to_stick"] == n["slip_to_stick"]
    assert sum(s["stick_to_slip"]) > 50  # stick-slip in every cycle (Table 1, test 4)
    change = np.linalg.norm(peaks(nested) - peaks(step))
    discretization = np.linalg.norm(peaks(finer) - peaks(step))
    assert change < 0.1 * discretization, (change, discretization)
    assert abs(n["energy_residual_J"]) < 1e-10 * n["energy_input_J"]
    # transitions still in steps of dt2, the rest of the refined dt1 steps in larger pieces
    assert n["steps_dt1"] == s["steps_dt1"]
    assert 0 < n["steps_dt2"] < s["steps_dt2"] / 4 and n["steps_nested"] > 0


def test_nested_refinement_on_a_building_of_dampers():
    """10 storeys, a hysteretic damper per storey, harmonic table motion (tests/test_scale):
    the same transitions per damper, peaks within a tenth of the dt1 error."""

    def go(refinement: str, n1: int = 5) -> fd.Result:
        g = building(duration=2.0)
        g["integration"].update(n1=n1, n2=30, refinement=refinement)  # 30 = 2 * 3 * 5
        return fd.run_text(deck_text(g), name="building.nml")

    step, nested, finer = go("step"), go("nested"), go("step", n1=10)
    s, n = step.summary, nested.summary
    assert min(s["stick_to_slip"]) > 0  # every damper slips
    assert s["stick_to_slip"] == n["stick_to_slip"] and s["slip_to_stick"] == n["slip_to_stick"]
    change = np.linalg.norm(peaks(nested) - peaks(step))
    discretization = np.linalg.norm(peaks(finer) - peaks(step))
    assert change < 0.1 * discretization, (change, discretization)
    assert abs(n["energy_residual_J"]) < 1e-10 * n["energy_input_J"]
    assert n["steps_dt2"] < s["steps_dt2"] / 2
