"""The summary keys that may hold JSON null (an undefined value), read from the one list of
them: docs/namelist.md, section "Undefined values". The fuzz campaign (run.py) allows null
exactly there; tests/test_outputs.py checks the list against the writer."""

from __future__ import annotations

import re
from functools import lru_cache
from pathlib import Path

DOCS = Path(__file__).resolve().parents[2] / "docs" / "namelist.md"


@lru_cache(maxsize=1)
def undefined_keys() -> frozenset[str]:
    """The keys of the table under "### Undefined values" (each row's first cell)."""
    text = DOCS.read_text(encoding="utf-8")
    start = text.index("### Undefined values")
    section = text[start:text.index("\n### ", start + 1)]
    keys: set[str] = set()
    for line in section.splitlines():
        if line.startswith("| `"):
            keys.update(re.findall(r"`([a-z0-9_A-Z]+)`", line.split("|")[1]))
    if not keys:
        raise ValueError(f"{DOCS}: no keys in the section 'Undefined values'")
    return frozenset(keys)


def null_keys(summary: dict) -> set[str]:
    """The top-level keys of a summary whose value is null or holds a null (nested)."""

    def has_null(v: object) -> bool:
        if v is None:
            return True
        if isinstance(v, list):
            return any(has_null(x) for x in v)
        if isinstance(v, dict):
            return any(has_null(x) for x in v.values())
        return False

    return {k for k, v in summary.items() if has_null(v)}
