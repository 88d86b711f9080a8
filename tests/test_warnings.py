"""Warnings as a user meets them: each names its section of docs/warnings.md, which exists,
and a Python warning points at the user's line, not at the package's."""

from __future__ import annotations

import re
from pathlib import Path

import frictiondyn as fd
import pytest

ROOT = Path(__file__).resolve().parent.parent

# a hysteretic oscillator on a table whose step resolves nothing (omega_max dt1 = 6.3):
# the highest-mode warning
DECK = """
&model n_dof = 1, mass = 1.0 /
&springs n_springs = 1, node_i = 1, node_j = 0, k = 3948.0 /
&damping damping_type = 'none' /
&excitation excitation_type = 'harmonic', amplitude = 0.01, frequency = 1.0, dt_record = 0.1,
  duration = 2.0 /
&integration n1 = 1 /
&output write_history = .false. /
"""


def test_every_warning_names_a_section_of_the_warnings_page():
    source = (ROOT / "fortran/result/fd_warnings.f90").read_text()
    anchors = set(re.findall(r"see\('([a-z-]+)'\)", source))
    headings = set(re.findall(r"^## ([a-z-]+)$", (ROOT / "docs/warnings.md").read_text(), re.M))
    assert len(anchors) == 12
    assert anchors == headings


def test_a_python_warning_points_at_the_callers_line():
    with pytest.warns(fd.FrictiondynWarning, match="does not resolve the highest modes") as seen:
        line = _line() + 1
        fd.run_text(DECK)
    (w,) = [x for x in seen if issubclass(x.category, fd.FrictiondynWarning)]
    assert (Path(w.filename).resolve(), w.lineno) == (Path(__file__).resolve(), line)
    assert "; see docs/warnings.md#mode-resolution" in str(w.message)
    assert "\n" not in str(w.message) and len(str(w.message)) < 260


def _line() -> int:
    import inspect

    return inspect.currentframe().f_back.f_lineno

