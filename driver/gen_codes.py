"""Write frictiondyn/_codes.py, the status codes of the extension's entry points and the ids
of a session's texts, from their one source: the `status_*` and `text_*` parameters of
fortran/fd_session.f90 (run by driver/meson.build when the package is built).

    python3 driver/gen_codes.py fortran/fd_session.f90 _codes.py
"""

from __future__ import annotations

import re
import sys
from pathlib import Path

PARAMETER = re.compile(
    r"^\s*integer,\s*parameter(?:,\s*public)?\s*::\s*((?:status|text)_\w+)\s*=\s*(\d+)\s*(?:!!\s*(.*))?$",
    re.IGNORECASE | re.MULTILINE,
)


def main(source: str, output: str) -> int:
    found = PARAMETER.findall(Path(source).read_text())
    names = [name.lower() for name, _, _ in found]
    if len(set(names)) != len(names) or not any(n.startswith("status_") for n in names) or not any(
        n.startswith("text_") for n in names
    ):
        print(f"gen_codes: no or repeated status_/text_ parameters in {source}", file=sys.stderr)
        return 1
    lines = [
        f'"""The status codes of the extension\'s entry points and the ids of a session\'s texts:',
        f"generated from {Path(source).name}'s status_* and text_* parameters by driver/gen_codes.py",
        '(edit those, not this file)."""',
        "",
    ]
    for name, value, comment in found:
        lines.append(f"{name.upper()} = {int(value)}" + (f"  # {comment.strip()}" if comment else ""))
    Path(output).write_text("\n".join(lines) + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main(*sys.argv[1:]))
