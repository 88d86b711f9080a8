"""frictiondyn: dynamic analysis of structures with friction devices.

The numerics are in the Fortran library. ``run(deck)`` reads a namelist deck with the same
Fortran reader as the ``frictiondyn`` executable and runs it through the f2py extension;
``Analysis`` builds a run in Python; ``Result`` holds what a run produced.
"""

from __future__ import annotations

from ._api import (
    DeckError,
    DeviceResults,
    FrictiondynError,
    FrictiondynWarning,
    Modes,
    OutOfMemoryError,
    OutputError,
    Result,
    RunCancelled,
    Session,
    SolverError,
    newmark_steps,
    read_history,
    read_summary,
    run,
    run_text,
)
from ._exe import ExecutableRun, RunFailed, executable, run_executable
from ._version import __version__
from .spectrum import Spectrum, response_spectrum
from .model import (
    Analysis,
    Bearing,
    Damping,
    Device,
    Floor,
    FloorBrace,
    Floors,
    Frame,
    FreeVibration,
    FrictionBrace,
    Harmonic,
    Integration,
    Matrices,
    Output,
    Record,
    SlidingIsolator,
    Spring,
    Storey,
)
from .tolerance import ToleranceError

__all__ = [
    "Analysis",
    "Bearing",
    "Damping",
    "DeckError",
    "Device",
    "DeviceResults",
    "ExecutableRun",
    "Floor",
    "FloorBrace",
    "Floors",
    "Frame",
    "FreeVibration",
    "FrictionBrace",
    "FrictiondynError",
    "FrictiondynWarning",
    "Harmonic",
    "Integration",
    "Matrices",
    "Modes",
    "OutOfMemoryError",
    "Output",
    "OutputError",
    "Record",
    "Result",
    "RunCancelled",
    "RunFailed",
    "Session",
    "SlidingIsolator",
    "SolverError",
    "Spectrum",
    "Spring",
    "Storey",
    "ToleranceError",
    "__version__",
    "executable",
    "newmark_steps",
    "read_history",
    "read_summary",
    "response_spectrum",
    "run",
    "run_executable",
    "run_text",
]
