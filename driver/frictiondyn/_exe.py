"""Running the installed frictiondyn executable on a deck, from Python."""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
import sysconfig
from dataclasses import dataclass
from pathlib import Path

from ._api import Result, read_history, read_summary


class RunFailed(RuntimeError):
    """The executable stopped with a non-zero exit status; ``stderr`` holds its message."""

    def __init__(self, returncode: int, stderr: str):
        super().__init__(stderr.strip() or f"frictiondyn exited with status {returncode}")
        self.returncode = returncode
        self.stderr = stderr


def executable() -> str:
    """Path of the frictiondyn executable: $FRICTIONDYN_EXE, the one installed with this
    package (the environment's scripts directory), or the first on PATH."""
    env = os.environ.get("FRICTIONDYN_EXE")
    if env:
        return env
    candidate = Path(sysconfig.get_path("scripts")) / "frictiondyn"
    if candidate.is_file():
        return str(candidate)
    found = shutil.which("frictiondyn") or shutil.which(
        "frictiondyn", path=os.path.dirname(sys.executable)
    )
    if found is None:
        raise FileNotFoundError("the frictiondyn executable is not installed (pip install .)")
    return found


@dataclass
class ExecutableRun:
    """What one run of the executable printed and wrote."""

    stdout: str
    stderr: str
    history_path: Path | None
    summary_path: Path

    def history(self) -> Result:
        if self.history_path is None:
            raise ValueError("this run wrote no history (write_history = .false.)")
        return read_history(self.history_path)

    def summary(self) -> dict:
        return read_summary(self.summary_path)


def run_executable(deck: str | Path, cwd: str | Path | None = None) -> ExecutableRun:
    """Run ``frictiondyn DECK`` and return where its outputs went.

    Raises RunFailed (with the executable's message) when the deck is rejected.
    """
    proc = subprocess.run([executable(), str(deck)], cwd=cwd, capture_output=True, text=True)
    if proc.returncode != 0:
        raise RunFailed(proc.returncode, proc.stderr)
    base = Path(cwd) if cwd is not None else Path.cwd()
    hist = summ = None
    for line in proc.stdout.splitlines():
        key, _, value = line.strip().partition(": ")
        if key == "history":
            hist = base / value
        elif key == "summary":
            summ = base / value
    if summ is None:
        raise RunFailed(
            proc.returncode, "frictiondyn did not report its summary file:\n" + proc.stdout
        )
    return ExecutableRun(proc.stdout, proc.stderr, hist, summ)
