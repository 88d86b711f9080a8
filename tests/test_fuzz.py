"""A short fuzz campaign (tests/fuzz/run.py; docs/reliability.md): 300 mutated decks and
records, each run by the executable and by the Python API, with no failure of any kind: no
crash, no interpreter death, no wrong exception type, no hang, no partial output, no message
that names nothing, no disagreement between the two, no null in a summary but where a value
can be undefined (docs/namelist.md, "Undefined values"). The full campaign (10,000 cases) is
run by hand: python tests/fuzz/run.py --count 10000 --seed 1. The time bound of a case (30 s)
is multiplied by $FRICTIONDYN_TIME_SCALE, which the slower checked build sets
(tools/test_checked.sh)."""

from __future__ import annotations

import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent / "fuzz"))
import run as fuzz  # noqa: E402

COUNT, SEED = 300, 2024


def test_a_short_fuzz_campaign_has_no_failure(tmp_path):
    outcomes = fuzz.campaign(COUNT, SEED, timeout=30.0, mem=2048, keep=tmp_path)
    rep = fuzz.report(outcomes, SEED)
    counts = {k: rep[k] for k in fuzz.FAILURES}
    assert rep["runs"] == COUNT
    # the campaign exercises both outcomes (measured: about a quarter run, most are refused)
    assert rep["successes"] > COUNT // 10 and rep["clean errors"] > COUNT // 2
    assert not any(counts.values()), (counts, rep["failures"][:5])


def test_a_short_at2_header_campaign_has_no_failure(tmp_path):
    """The AT2 fuzzer (tests/fuzz/at2_fuzz.py; a long campaign by request: --count 5000):
    60 mutated PEER records (tabs and duplicate keys in line 4, values after DT, NPTS off by
    one, numbers cut inside, values moved out of their fixed-width fields, tabs between
    them, CRLF, units), each read with exactly its values or refused naming the record
    file, the line and the rule it breaks."""
    import at2_fuzz
    import frictiondyn

    rep = at2_fuzz.campaign(60, 2024, frictiondyn.executable(), tmp_path)
    assert rep["failures"] == []
    assert rep["accepted"] >= 10 and rep["refused"] >= 20  # measured: 20 read, 40 refused
