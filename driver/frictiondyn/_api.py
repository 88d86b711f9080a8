"""Running decks through the f2py extension, and the Result of a run.

A ``Session`` holds one deck read once by the library's Fortran reader (the same as the
executable's): it is solved, its history and texts are fetched into buffers of the sizes the
library reports, and its outputs are written by the library's writer. The session lives in
the library until it is closed; ``Session`` closes it on every path (use it as a context
manager). Every non-zero status becomes an exception here, in one place.

The history is held once: the library writes its rows straight into a numpy array this module
allocates (``Result.data`` is a view of it), and only the DOFs and devices selected are kept
(``Session.select``, ``run(dofs=..., devices=...)``); ``Session.stream`` writes it to its file
as the run goes instead. A solve runs in a worker thread when called from the main thread:
Ctrl-C (in a terminal or a notebook) asks the library to stop, which it does within a poll
(about 10 ms), and KeyboardInterrupt is raised; a ``progress(t, duration)`` callback is called
about twenty times a second meanwhile. The Fortran work runs without the GIL: runs in several
threads overlap.
"""

from __future__ import annotations

import contextlib
import json
import os
import sys
import threading
import time
import warnings
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from . import _codes, _core

__all__ = [
    "DeckError",
    "DeviceResults",
    "FrictiondynError",
    "FrictiondynWarning",
    "Modes",
    "OutOfMemoryError",
    "OutputError",
    "OutputSettings",
    "Result",
    "RunCancelled",
    "Session",
    "SolverError",
    "read_history",
    "read_summary",
    "run",
    "run_text",
]


class FrictiondynError(RuntimeError):
    """Base of the package's exceptions; the message names the offending input."""


class DeckError(FrictiondynError, ValueError):
    """The deck (or a record file it names) is missing, malformed or invalid."""


class SolverError(FrictiondynError):
    """The analysis failed (singular system, divergence)."""


class OutputError(FrictiondynError, OSError):
    """An output file or directory cannot be created or written."""


class RunCancelled(FrictiondynError):
    """The solve was cancelled (``Session.cancel`` from another thread)."""


class OutOfMemoryError(FrictiondynError, MemoryError):
    """Memory for what the deck asks (its matrices, its history) cannot be had; the message
    says what and how large. Also a MemoryError."""


class FrictiondynWarning(UserWarning):
    """A run that finished but whose answer needs care, as the executable warns on standard
    error: steps that violate the correctness condition (eqs. 9, 12), steps that could not
    take a speed-dependent mu at the velocity at their end (summary
    ``mu_unconverged_steps``), a step dt1 that does
    not resolve the structure's highest modes (summary ``mode_resolution``), or one that
    dephases the ringing of a sticking spring on which a device's stick-slip decisions rest
    (summary ``stick_resolution``), a velocity-law band whose force the step leaves
    alternating from step to step (summary ``band_resolution``), a step that moves the linear
    steady state under a harmonic table motion by more than 5 % (summary
    ``harmonic_resolution``), one that moves
    the peak linear response to a record by more than 5 % (summary ``record_resolution``), an
    integration that dissipated or created more than 5 % of the energy, or, with the average
    acceleration rule, whose energy balance misses by more than round-off (1e-8: digits
    lost) (summary ``energy_balance``). Issued when the
    Result is made (``Session.result``, ``run``, ``Analysis.run``); the summary holds the
    figures. Filter it with the ``warnings`` module like any other warning."""


def newmark_steps(summary: dict) -> int:
    """The steps a Newmark run solved, from its summary: the accepted dt1, nested, dt2 and
    finer steps, and with implicit phases the settled dt1 steps and their redone trials (the
    rejected first trial of a refined dt1 step is not counted). The exact technique's
    summary counts dt1 intervals in steps_dt1, which this adds as they are."""
    keys = ("steps_dt1", "steps_nested", "steps_dt2", "steps_finer", "steps_implicit", "implicit_redos")
    return int(sum(summary.get(k, 0) for k in keys))


def summary_warnings(summary: dict) -> list[str]:
    """The warnings a run calls for, as the executable prints them on standard error (without
    its "frictiondyn: warning: " prefix): the summary's ``warnings``, worded once by the
    library (fortran/result/fd_warnings.f90): correctness violations, steps whose
    speed-dependent mu did not converge, a step dt1 that does not resolve the highest modes,
    one that misses a harmonic table motion's steady state or a record's peak linear response,
    one that dephases a sticking spring's ringing, a velocity-law band whose force alternates
    from step to step, an integration that dissipated (or created) more than 5 % of the
    energy, and one by the average acceleration rule whose energy balance misses round-off
    (digits lost). A summary written by an older build, without the key, has none."""
    return [str(w) for w in summary.get("warnings", [])]


def _user_stacklevel() -> int:
    """The ``stacklevel`` for a warning issued by the caller of this function that points at
    the first frame outside this package: the user's line (``fd.run(...)``, a script or a
    notebook cell), not the package's own call."""
    here = Path(__file__).resolve().parent
    frame = sys._getframe(1)  # the function that issues the warning: stacklevel 1
    level = 1
    while frame is not None and Path(frame.f_code.co_filename).resolve().parent == here:
        frame = frame.f_back
        level += 1
    return level


# the status codes of the extension (fortran/fd_session.f90's status_*, generated into _codes)
_ERRORS = {
    _codes.STATUS_INPUT: DeckError,
    _codes.STATUS_SOLVER: SolverError,
    _codes.STATUS_MISUSE: FrictiondynError,
    _codes.STATUS_OUTPUT: OutputError,
    _codes.STATUS_NO_MEMORY: OutOfMemoryError,
    _codes.STATUS_CANCELLED: RunCancelled,
}
#: seconds between looks at a solve running in the worker thread (Ctrl-C, progress)
_POLL = 0.05
#: seconds a thread that was started is given to say it runs (_stop_solve)
_LAUNCH_WAIT = 2.0
#: the progress callback: (time reached [s], duration [s])
ProgressCallback = Callable[[float, float], object]


def _stop_solve(h: int, begun: threading.Event, done: threading.Event) -> None:
    """Stop a solve that may be running in its thread and wait until it has ended; Ctrl-C
    meanwhile is ignored. A thread whose start was interrupted may not have been launched: a
    launched one says so at once (``begun``; the waiting main thread holds no GIL). The cancel
    is repeated at every poll: a solve that had not started yet clears a cancel made before
    it, and was then waited for to its end."""
    deadline = time.monotonic() + _LAUNCH_WAIT
    while not begun.is_set() and time.monotonic() < deadline:
        try:
            begun.wait(0.01)
        except KeyboardInterrupt:
            continue
    if not begun.is_set():
        return
    while not done.is_set():
        _core.fd_session_cancel(h)
        try:
            done.wait(_POLL)
        except KeyboardInterrupt:
            continue


def _no_history() -> np.ndarray:
    return np.zeros((1, 1), dtype=np.float64, order="F")


def _text_bytes(text: str, what: str) -> np.ndarray:
    """Text for the extension: its UTF-8 bytes (lone surrogates, as os.fsdecode makes them,
    back to their bytes), as the int16 array (one byte an element) the extension takes."""
    try:
        data = text.encode("utf-8", "surrogateescape")
    except UnicodeEncodeError as exc:
        raise DeckError(f"{what}: character {exc.start + 1} cannot be encoded as UTF-8") from None
    return np.frombuffer(data, dtype=np.uint8).astype(np.int16)


def _path_bytes(path: str | os.PathLike) -> np.ndarray:
    """A path for the extension: its bytes in the file system's encoding (as above)."""
    try:
        data = os.fsencode(path)
    except UnicodeEncodeError as exc:
        raise DeckError(f"{os.fspath(path)!r}: cannot be encoded as a file name ({exc.reason})") from None
    return np.frombuffer(data, dtype=np.uint8).astype(np.int16)


def _history_array(ncol: int, nout: int) -> np.ndarray:
    """The history buffer the library writes its rows into, (columns, samples), Fortran order."""
    return np.empty((ncol, nout), dtype=np.float64, order="F")


def _index_list(values: object, arg: str, what: str, n: int) -> np.ndarray:
    """A history selection (``dofs``, ``devices``) as an int32 array, checked before any
    conversion: a sequence (not a string) of integers (not bools; integral floats are
    refused too) in 1..n, increasing without repeats, as a deck must give it."""
    if isinstance(values, (str, bytes)) or np.ndim(values) != 1:
        raise DeckError(
            f"history selection: {arg} must be a list of {what} numbers, not {values!r}"
        )
    items = values.tolist() if isinstance(values, np.ndarray) else list(values)
    out = []
    for x in items:
        if isinstance(x, np.generic):
            x = x.item()
        if isinstance(x, bool) or not isinstance(x, int):
            raise DeckError(f"history selection: {arg}: {x!r} is not a {what} number (an integer)")
        if not 1 <= x <= n:
            raise DeckError(f"history selection: {arg}: {what} {x} is not in 1..{n}")
        if out and x <= out[-1]:
            raise DeckError(
                f"history selection: {arg}: the {what}s must be given in increasing order "
                f"without repeats ({out[-1]} then {x})"
            )
        out.append(x)
    return np.array(out, dtype=np.int32)


def _summary_path(csv: str | os.PathLike) -> Path:
    """The summary JSON that goes with a history CSV: a ``.csv`` suffix (any case) replaced by
    ``.summary.json``, any other name with ``.summary.json`` appended (``h.dat`` ->
    ``h.dat.summary.json``), as the executable and ``to_csv`` name it."""
    csv = Path(csv)
    stem = csv.name[: -len(".csv")] if csv.name.lower().endswith(".csv") else csv.name
    return csv.with_name(stem + ".summary.json")


# the texts a session gives (fortran/fd_session.f90's text_*, generated into _codes)
_HEADER, _SUMMARY = _codes.TEXT_HEADER, _codes.TEXT_SUMMARY
_OUTPUT_DIR, _OUTPUT_NAME = _codes.TEXT_OUTPUT_DIR, _codes.TEXT_OUTPUT_NAME
_HISTORY_PATH, _SUMMARY_PATH = _codes.TEXT_HISTORY_PATH, _codes.TEXT_SUMMARY_PATH
_DECK, _ERROR = _codes.TEXT_DECK, _codes.TEXT_ERROR
_PATHS = (_OUTPUT_DIR, _OUTPUT_NAME, _HISTORY_PATH, _SUMMARY_PATH, _DECK)


@dataclass
class OutputSettings:
    """The deck's &output settings, as the Fortran reader read them."""

    dir: str = "out"
    name: str = "deck"
    write_history: bool = True


class Session:
    """One deck, read once by the library, and its run: ``solve()``, then ``result()`` and
    ``write()``; ``close()`` frees it (a ``with`` block closes it on every path).

    ``Session(deck)`` reads a deck file, ``Session.from_text(text, name, base_dir)`` a deck
    given as text. A DeckError is raised (and nothing is left open) when the deck is bad.
    Before ``solve``: ``select`` the DOFs and devices the history keeps, ``stream`` the
    history to its file as the run goes. The methods may be called from any thread; ``solve``
    releases the GIL, so sessions run side by side in threads, and ``cancel`` stops a solve
    running in another thread.
    """

    def __init__(self, deck: str | os.PathLike) -> None:
        self._open(_path_bytes(deck), _text_bytes("", "deck"), 0)

    @classmethod
    def from_text(
        cls, text: str, name: str = "deck.nml", base_dir: str | os.PathLike = "."
    ) -> Session:
        """A session of a deck given as text; ``name`` names it in messages, a relative
        record_file is looked up in ``base_dir``."""
        self = cls.__new__(cls)
        if not isinstance(text, str):
            raise TypeError(f"the deck text must be a str, not {type(text).__name__}")
        path = os.path.join(os.fspath(base_dir), os.fspath(name))
        self._open(_path_bytes(path), _text_bytes(text, path), 1)
        return self

    @classmethod
    def _adopt(cls, data: np.ndarray, header: str, summary: str) -> Session:
        """A solved session holding a history and texts given here (to write them)."""
        self = cls.__new__(cls)
        self._init_state()
        empty = np.zeros((np.shape(data)[1], 0), dtype=np.float64, order="F")
        handle, status = _core.fd_session_adopt(
            empty, _text_bytes(header, "header"), _text_bytes(summary, "summary")
        )
        self._started(handle, status)
        return self

    def _init_state(self) -> None:
        self._handle, self._lock = 0, threading.Lock()
        self._hist: np.ndarray | None = None  # the history, (columns, samples), Fortran order
        self._streamed = False

    def _open(self, path: np.ndarray, text: np.ndarray, from_text: int) -> None:
        self._init_state()
        handle, _, _, status = _core.fd_session_open(path, text, from_text)
        self._started(handle, status)

    def _started(self, handle: int, status: int) -> None:
        self._handle = int(handle)
        if status != 0:
            exc = self._exception(status)
            self.close()
            raise exc

    # --- the handle -----------------------------------------------------------------------

    def _exception(self, status: int) -> BaseException:
        """The exception of a non-zero status, with the message the session keeps."""
        kind = _ERRORS.get(int(status), FrictiondynError)
        if self._handle == 0:
            return kind("not enough memory for a session")
        n, st = _core.fd_session_text_length(self._handle, _ERROR)
        message = self._fetch_text(_ERROR, n) if st == 0 else ""
        return kind(message or f"frictiondyn: status {int(status)}")

    def _check(self, status: int) -> None:
        if status != 0:
            raise self._exception(status)

    def _live(self) -> int:
        if self._handle == 0:
            raise FrictiondynError("the session is closed")
        return self._handle

    def _fetch_text(self, which: int, length: int) -> str:
        if length == 0:
            return ""
        buf, status = _core.fd_session_text(self._handle, which, length)
        self._check(status)
        data = np.asarray(buf).tobytes()
        if which in _PATHS:  # paths as the file system names them (any bytes round-trip)
            return os.fsdecode(data)
        return data.decode("utf-8", errors="replace")

    def _text(self, which: int) -> str:
        n, status = _core.fd_session_text_length(self._live(), which)
        self._check(status)
        return self._fetch_text(which, n)

    def close(self) -> None:
        """Free the session (waits for a solve running in another thread). Idempotent. A
        streamed history that was not written (``write``) is removed."""
        with self._lock:
            if self._handle != 0:
                handle, self._handle = self._handle, 0
                _core.fd_session_close(handle)
            self._hist = None

    @property
    def closed(self) -> bool:
        return self._handle == 0

    def __enter__(self) -> Session:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    def __del__(self) -> None:  # a safety net; close() or a with block is the rule
        if getattr(self, "_handle", 0) and _core is not None:
            _core.fd_session_close(self._handle)
            self._handle = 0

    # --- what the deck says ---------------------------------------------------------------

    @property
    def shape(self) -> tuple[int, int]:
        """(samples, columns) of the history the run gives (``Result.data.shape``)."""
        with self._lock:
            ncol, nout, _, status = _core.fd_session_shape(self._live())
            self._check(status)
        return int(nout), int(ncol)

    @property
    def output(self) -> OutputSettings:
        """The deck's &output settings (the directory as set by ``write(out=...)``)."""
        with self._lock:
            _, _, history, status = _core.fd_session_shape(self._live())
            self._check(status)
            return OutputSettings(self._text(_OUTPUT_DIR), self._text(_OUTPUT_NAME), bool(history))

    @property
    def deck(self) -> str:
        """The deck's path (or name, for a deck given as text)."""
        with self._lock:
            return self._text(_DECK)

    # --- running and results --------------------------------------------------------------

    def select(
        self, dofs: Sequence[int] | None = None, devices: Sequence[int] | None = None
    ) -> Session:
        """Keep only these DOFs and devices (1-based, increasing, no repeats) in the history;
        None keeps the current selection of that kind (the deck's ``&output`` one, or the last
        ``select``'s; every one when neither chose), an empty list none. Before ``solve``; the
        summary still covers every DOF and device. A number that is not an integer (a bool, a
        float, a string) or out of range, or a list out of order, raises DeckError."""
        with self._lock:
            h = self._live()
            n_dof, n_dev = self._sizes()
            cur_d, cur_v = self._selection(n_dof, n_dev)
            d = cur_d if dofs is None else _index_list(dofs, "dofs", "DOF", n_dof)
            v = cur_v if devices is None else _index_list(devices, "devices", "device", n_dev)
            _, status = _core.fd_session_select(h, d, v)
            self._check(status)
        return self

    def _selection(self, n_dof: int, n_dev: int) -> tuple[np.ndarray, np.ndarray]:
        """The DOFs and devices the history keeps now (int32 arrays)."""
        d, nd, v, nv, status = _core.fd_session_selection(
            self._handle, max(n_dof, 1), max(n_dev, 1)
        )
        self._check(status)
        return np.array(d[: int(nd)], dtype=np.int32), np.array(v[: int(nv)], dtype=np.int32)

    @property
    def selection(self) -> tuple[list[int], list[int]]:
        """(DOFs, devices) the history keeps now (the deck's, or ``select``'s)."""
        with self._lock:
            self._live()
            d, v = self._selection(*self._sizes())
        return [int(x) for x in d], [int(x) for x in v]

    def _sizes(self) -> tuple[int, int]:
        """(DOFs, devices) of the deck."""
        n_dof, n_dev, status = _core.fd_session_sizes(self._handle)
        self._check(status)
        return int(n_dof), int(n_dev)

    def stream(self, out: str | os.PathLike | None = None) -> Session:
        """Write the history CSV to ``<dir>/<name>.csv`` as the run goes (a temporary name,
        renamed by ``write``; removed when the run fails, is cancelled or the session is
        closed unwritten), so that memory does not grow with the duration. ``out`` replaces
        the deck's directory. Before ``solve``."""
        with self._lock:
            h = self._live()
            if out is not None:
                self._check(_core.fd_session_set_output_dir(h, _path_bytes(out)))
            self._check(_core.fd_session_stream(h))
            self._streamed = True
        return self

    def cancel(self) -> None:
        """Ask a solve running in another thread to stop: it raises RunCancelled there
        (KeyboardInterrupt when the stop came from Ctrl-C). Harmless when nothing runs."""
        h = self._handle
        if h != 0:
            _core.fd_session_cancel(h)

    def progress(self) -> tuple[float, float]:
        """(time reached, duration) of a solve running in another thread [s]."""
        h = self._handle
        if h == 0:
            return 0.0, 0.0
        t, duration = _core.fd_session_progress(h)
        return float(t), float(duration)

    def solve(self, progress: ProgressCallback | None = None, history: bool = True) -> Session:
        """Run the deck (once). ``history``: keep the history (the columns selected) in
        memory, in one numpy array that ``result`` wraps; False keeps only the summary (and
        the streamed file). ``progress(t, duration)`` is called about twenty times a second.
        Ctrl-C stops the run within about 10 ms of the solver and raises KeyboardInterrupt.
        Raises SolverError when the analysis fails."""
        with self._lock:
            h = self._live()
            ncol, nout, _, status = _core.fd_session_shape(h)
            self._check(status)
            if history:
                try:
                    buf = _history_array(int(ncol), int(nout))
                except MemoryError:
                    raise OutOfMemoryError(
                        f"{self._text(_DECK)}: not enough memory for the history in Python: "
                        f"{nout} samples of {ncol} columns ({8 * nout * ncol / 2**20:.0f} MiB); "
                        "raise output_every in &output, keep fewer DOFs and devices "
                        "(Session.select), or stream the history to its file (Session.stream) "
                        "and solve(history=False)"
                    ) from None
            else:
                buf = _no_history()
            status = self._run(h, 1 if history else 0, buf, progress)
            self._check(status)
            self._hist = buf if history else None
        return self

    @staticmethod
    def _run(h: int, mode: int, buf: np.ndarray, progress: ProgressCallback | None) -> int:
        """fd_session_solve, in a worker thread when this is the main thread (where Ctrl-C
        arrives) or a progress callback is given; else here (the GIL is released either way)."""
        if threading.current_thread() is not threading.main_thread() and progress is None:
            return int(_core.fd_session_solve(h, mode, buf))
        out: list[int] = []
        # Completion is told by an Event the worker sets, not by Thread.is_alive(): a
        # KeyboardInterrupt that lands inside Thread.join can leave is_alive() False while
        # the thread still runs (CPython 3.11), and the session was then freed under the
        # running solve (a segmentation fault in 2 of 6 Ctrl-C runs).
        begun, done = threading.Event(), threading.Event()

        def work() -> None:
            begun.set()
            try:
                out.append(int(_core.fd_session_solve(h, mode, buf)))
            finally:
                done.set()

        worker = threading.Thread(target=work, name="frictiondyn-solve", daemon=True)
        try:
            worker.start()
            while not done.wait(_POLL):
                if progress is not None:
                    t, duration = _core.fd_session_progress(h)
                    progress(float(t), float(duration))
        except BaseException:
            # Ctrl-C, or a progress callback that raised: the solve is stopped and waited
            # for before the exception goes on, so that the session is never freed under it
            # (a callback's exception did so, and the process died)
            _stop_solve(h, begun, done)
            raise
        if progress is not None:
            t, duration = _core.fd_session_progress(h)
            progress(float(t), float(duration))
        return out[0] if out else 3

    def result(self) -> Result:
        """The Result of the solved run: history (the columns kept; none when ``solve`` was
        told not to keep it), header and summary (no file written). The Result's data is a
        view of the one history array, not a copy."""
        with self._lock:
            h = self._live()
            ncol, nout, history, status = _core.fd_session_shape(h)
            self._check(status)
            summary = self._text(_SUMMARY)
            if self._hist is not None:
                data = self._hist.T
            else:
                data = np.zeros((0, int(ncol)))
            result = Result.from_arrays(self._text(_HEADER), data, summary)
            result.output = OutputSettings(
                self._text(_OUTPUT_DIR), self._text(_OUTPUT_NAME), bool(history)
            )
            deck = self._text(_DECK)
        for message in summary_warnings(result.summary):
            warnings.warn(f"{deck}: {message}", FrictiondynWarning, stacklevel=_user_stacklevel())
        return result

    def write(self, out: str | os.PathLike | None = None) -> tuple[Path | None, Path]:
        """Write ``<dir>/<name>.csv`` (unless ``write_history = .false.``) and
        ``<dir>/<name>.summary.json`` exactly as the executable does (the library's writer;
        the directory is created when missing); ``out`` replaces the deck's directory (not
        for a streamed history, whose directory was set by ``stream``). Returns the paths
        written. Raises OutputError when a file cannot be written."""
        with self._lock:
            h = self._live()
            if out is not None:
                if self._streamed:
                    raise FrictiondynError(
                        "the history was streamed to the directory given to stream(); "
                        "write() takes no other directory"
                    )
                self._check(_core.fd_session_set_output_dir(h, _path_bytes(out)))
            use = self._hist is not None and not self._streamed
            self._check(_core.fd_session_write(h, int(use), self._hist if use else _no_history()))
            _, _, history, status = _core.fd_session_shape(h)
            self._check(status)
            csv = Path(self._text(_HISTORY_PATH)) if history else None
            return csv, Path(self._text(_SUMMARY_PATH))

    def _write_files(self, csv: Path | None, summary: Path, data: np.ndarray | None) -> None:
        with self._lock:
            hist = _no_history() if data is None else np.asfortranarray(data.T, dtype=np.float64)
            status = _core.fd_session_write_files(
                self._live(),
                _path_bytes(csv or ""),
                _path_bytes(summary),
                int(csv is not None),
                int(data is not None),
                hist,
            )
            self._check(status)


def run(
    deck: str | os.PathLike,
    dofs: Sequence[int] | None = None,
    devices: Sequence[int] | None = None,
    progress: ProgressCallback | None = None,
    tolerance: float | None = None,
    tolerance_floor: float | None = None,
) -> Result:
    """Run a namelist deck file and return its Result (no output file is written).

    ``dofs``, ``devices``: keep only these (1-based, increasing) in the history (each None:
    the deck's ``&output`` selection of that kind, all by default; the summary covers all). ``progress(t, duration)``: called about twenty times a second. Ctrl-C stops
    the run and raises KeyboardInterrupt. Raises DeckError for a missing, malformed or
    invalid deck, SolverError when the analysis fails.

    ``tolerance`` (or ``tolerance`` in the deck's &integration), with ``tolerance_floor``: a
    tolerance run (``frictiondyn.tolerance``): the technique and its steps chosen and refined
    until every estimated peak's error is below it; the summary carries ``estimated_error``,
    ``estimate_method`` and ``tolerance_run``. Raises ToleranceError when it cannot be met.
    """
    if tolerance is not None or tolerance_floor is not None:
        return _tolerance_run(tolerance, tolerance_floor, deck=deck, dofs=dofs, devices=devices)
    try:
        session = Session(deck)
    except DeckError as exc:
        if _TOLERANCE_RUN not in str(exc):
            raise
        return _tolerance_run(None, None, deck=deck, dofs=dofs, devices=devices)
    with session:
        if dofs is not None or devices is not None:
            session.select(dofs, devices)
        return session.solve(progress).result()


def run_text(
    text: str,
    name: str = "deck.nml",
    base_dir: str | os.PathLike = ".",
    dofs: Sequence[int] | None = None,
    devices: Sequence[int] | None = None,
    progress: ProgressCallback | None = None,
    tolerance: float | None = None,
    tolerance_floor: float | None = None,
) -> Result:
    """Run a deck given as text. ``name`` names it in messages; a relative record_file is
    looked up in ``base_dir``; ``dofs``, ``devices``, ``progress``, ``tolerance`` and
    ``tolerance_floor`` as for ``run``."""
    kw = {"text": text, "name": name, "base_dir": base_dir, "dofs": dofs, "devices": devices}
    if tolerance is not None or tolerance_floor is not None:
        return _tolerance_run(tolerance, tolerance_floor, **kw)
    try:
        session = Session.from_text(text, name, base_dir)
    except DeckError as exc:
        if _TOLERANCE_RUN not in str(exc):
            raise
        return _tolerance_run(None, None, **kw)
    with session:
        if dofs is not None or devices is not None:
            session.select(dofs, devices)
        return session.solve(progress).result()


#: the library's words for a deck that gives &integration tolerance (fortran/io/fd_deck.f90)
_TOLERANCE_RUN = "is a tolerance run"


def _tolerance_run(tolerance: float | None, floor: float | None, **deck) -> Result:
    from .tolerance import tolerance_run

    result, _, session = tolerance_run(tolerance=tolerance, tolerance_floor=floor, **deck)
    session.close()
    return result


_UNITS_LABEL = {"m/s2": "m/s²"}


@dataclass
class Modes:
    """Natural modes of one system of a run (docs/namelist.md, "Natural modes").

    ``system`` 'stuck' or 'free'; ``status`` 'flexible', 'rigid' (no free DOF: no mode),
    'unrestrained' (a rigid-body mode, period inf) or 'not computed'; ``periods`` [s]
    (lowest first), ``shapes`` (modes, n_dof) scaled to a largest component of +1,
    ``mass_ratios`` (effective modal mass over the total mass), ``xi`` (damping ratios;
    nan for a rigid-body mode)."""

    system: str
    status: str
    periods: np.ndarray
    shapes: np.ndarray
    mass_ratios: np.ndarray
    xi: np.ndarray

    @property
    def frequencies(self) -> np.ndarray:
        """Natural frequencies [Hz] (0 for a rigid-body mode)."""
        return np.where(np.isfinite(self.periods), 1.0 / self.periods, 0.0)

    def __len__(self) -> int:
        return len(self.periods)


def _floats(values) -> np.ndarray:
    """A JSON list as a float array: null (an undefined value, docs/namelist.md) is nan."""
    return np.array([np.nan if v is None else float(v) for v in values], dtype=float)


@dataclass
class DeviceResults:
    """What each friction device did over a run, one entry per device (docs/python.md).

    ``labels`` the devices' labels; ``dissipated_energy`` [J] the work of its friction force
    over its relative motion less the elastic energy it stores (end minus start: the entries
    sum to the summary's ``energy_friction_J``); ``slip_travel`` [m] the integral of |ds|
    while it slides; ``slip_excursions`` its slides (stick-to-slip transitions, and one for a
    slide at t = 0); ``peak_force`` [N] max |F|; ``residual_slip`` [m] its relative
    displacement s at the end."""

    labels: list[str]
    dissipated_energy: np.ndarray
    slip_travel: np.ndarray
    slip_excursions: np.ndarray
    peak_force: np.ndarray
    residual_slip: np.ndarray

    def __len__(self) -> int:
        return len(self.labels)

    def rows(self) -> list[dict]:
        """One dict per device: its number (from 1), label and values under the summary's keys."""
        return [
            {"device": d + 1, "device_label": self.labels[d],
             "dissipated_energy_J": float(self.dissipated_energy[d]),
             "slip_travel_m": float(self.slip_travel[d]),
             "slip_excursions": int(self.slip_excursions[d]),
             "peak_force_N": float(self.peak_force[d]),
             "residual_s_m": float(self.residual_slip[d])}
            for d in range(len(self.labels))
        ]


@dataclass
class Result:
    """Time histories and summary of one run.

    ``result["u1"]`` is a column by name (see ``names``, ``units``); ``time`` is ``t``;
    ``dof(i)`` and ``device(d)`` group the series of one DOF or device (1-based);
    ``summary`` is the run's summary (peaks, transitions, steps, correctness violations,
    energy) as a dict, an undefined value (JSON null: docs/namelist.md, "Undefined values")
    as None, whole or as an item of a list; ``peak(name, t_range)`` the peak of a series (exact for the exact
    technique, whose peaks include the extrema between rows and the one-sided values at
    events).
    """

    names: list[str]
    units: dict[str, str]
    data: np.ndarray  # (samples, columns)
    summary: dict = field(default_factory=dict)
    output: OutputSettings = field(default_factory=OutputSettings)
    #: the summary as the library wrote it (what to_csv writes while ``summary`` is unchanged)
    summary_text: str | None = field(default=None, repr=False, compare=False)

    @classmethod
    def from_arrays(cls, header: str, data: np.ndarray, summary: dict | str) -> Result:
        """A Result from a header ``name[unit],...``, the data (samples, columns) and the
        summary (a dict, or the summary JSON text, which is kept)."""
        names, units = [], {}
        for item in header.split(","):
            name, _, unit = item.partition("[")
            names.append(name)
            units[name] = unit.rstrip("]")
        if data.shape[1] != len(names):
            raise FrictiondynError(f"history has {data.shape[1]} columns but {len(names)} names")
        if isinstance(summary, str):
            parsed = json.loads(summary) if summary else {}
            return cls(names, units, data, parsed, summary_text=summary)
        return cls(names, units, data, summary)

    @classmethod
    def from_files(
        cls, csv: str | os.PathLike, summary: str | os.PathLike | None | bool = None
    ) -> Result:
        """A Result from the executable's (or to_csv's) CSV and its summary JSON: ``summary``
        None reads the one next to the CSV (``_summary_path``: ``h.csv`` ->
        ``h.summary.json``, ``h.dat`` -> ``h.dat.summary.json``) and raises
        FileNotFoundError when it is missing; False reads none (``summary`` is then {})."""
        csv = Path(csv)
        with csv.open(encoding="utf-8") as fh:
            header = fh.readline().strip()
        data = np.loadtxt(csv, delimiter=",", skiprows=1, ndmin=2)
        if summary is False:
            return cls.from_arrays(header, data, {})
        if summary is None or summary is True:
            summary = _summary_path(csv)
            if not summary.exists():
                raise FileNotFoundError(
                    f"{csv}: no summary {summary.name} next to it (pass summary=False to read "
                    "the history alone, or the summary's path)"
                )
        text = Path(summary).read_text(encoding="utf-8").removesuffix("\n")
        return cls.from_arrays(header, data, text)

    @classmethod
    def from_parquet(cls, path: str | os.PathLike) -> Result:
        """A Result from a Parquet file written by to_parquet (needs pyarrow:
        ``pip install frictiondyn[parquet]``)."""
        pq = _pyarrow_parquet()
        table = pq.read_table(path)
        meta = table.schema.metadata or {}
        try:
            units = json.loads(meta[b"frictiondyn.units"].decode("utf-8"))
            text = meta[b"frictiondyn.summary"].decode("utf-8")
        except KeyError:
            raise FrictiondynError(f"{path}: not a history written by Result.to_parquet "
                                   "(no frictiondyn metadata)") from None
        names = list(table.column_names)
        data = np.column_stack([table.column(n).to_numpy() for n in names]) if names else \
            np.zeros((table.num_rows, 0))
        return cls(names, units, np.asarray(data, dtype=np.float64), json.loads(text),
                   summary_text=text)

    @classmethod
    def from_npz(cls, path: str | os.PathLike) -> Result:
        """A Result from a .npz written by to_npz."""
        with np.load(path, allow_pickle=False) as z:
            names = [str(x) for x in z["names"]]
            units = dict(zip(names, (str(x) for x in z["units"])))
            text = str(z["summary"])
            return cls(names, units, z["data"], json.loads(text), summary_text=text)

    def __getitem__(self, name: str) -> np.ndarray:
        try:
            return self.data[:, self.names.index(name)]
        except ValueError:
            raise KeyError(f"no column {name!r}; columns are {', '.join(self.names)}") from None

    def __contains__(self, name: str) -> bool:
        return name in self.names

    @property
    def time(self) -> np.ndarray:
        return self["t"]

    @property
    def n_dof(self) -> int:
        return int(self.summary.get("n_dof", sum(n.startswith("aabs") for n in self.names)))

    @property
    def n_devices(self) -> int:
        return int(self.summary.get("n_devices", sum(n.startswith("phase") for n in self.names)))

    def dof(self, i: int) -> dict[str, np.ndarray]:
        """Relative displacement u, relative velocity v and absolute acceleration aabs of DOF i."""
        return {"u": self[f"u{i}"], "v": self[f"v{i}"], "aabs": self[f"aabs{i}"]}

    def device(self, d: int) -> dict[str, np.ndarray]:
        """Relative displacement s, velocity sdot, force F and phase (0 stick, +-1 slip) of device d."""
        return {
            "s": self[f"s{d}"],
            "sdot": self[f"sdot{d}"],
            "F": self[f"F{d}"],
            "phase": self[f"phase{d}"],
        }

    def peak(self, name: str, t_range: tuple[float, float] | None = None) -> float:
        """Largest |name| (``'aabs2'``, ``'u1'``, ``'F1'``, ...) over the run, or over the rows
        with ``t_range[0] <= t <= t_range[1]``.

        For the exact technique it is exact: its history holds, in ``peak_<name>``, the
        maxima since the previous row (extrema between rows and one-sided values at events
        included), so this is the true peak over the time from the range's first row to its
        last. Otherwise it is the largest sampled value of the rows in the range."""
        t = self.time
        if t_range is None:
            rows = np.arange(len(t))
        else:
            rows = np.nonzero((t >= t_range[0] - 1e-12) & (t <= t_range[1] + 1e-12))[0]
        if rows.size == 0:
            raise ValueError(f"no history row in the time range {t_range}")
        values = np.abs(self[name][rows])
        if f"peak_{name}" not in self:
            return float(values.max())
        envelope = self[f"peak_{name}"][rows[1:]]
        return float(max(values[0], envelope.max(initial=0.0)))

    def label(self, name: str) -> str:
        """Axis label 'name [unit]'."""
        unit = self.units.get(name, "")
        return f"{name} [{_UNITS_LABEL.get(unit, unit)}]" if unit and unit != "-" else name

    # --- engineering outputs ------------------------------------------------------------

    def _labels(self, key: str, count: int, default: str) -> list[str]:
        names = list(self.summary.get(key) or [])
        return names[:count] + [f"{default} {i}" for i in range(len(names) + 1, count + 1)]

    @property
    def dof_labels(self) -> list[str]:
        """The deck's label of each DOF ('DOF i' when not given)."""
        return self._labels("dof_labels", self.n_dof, "DOF")

    @property
    def device_labels(self) -> list[str]:
        """The deck's label of each device ('device d', 'brace b', 'isolator i' by default)."""
        return self._labels("device_labels", self.n_devices, "device")

    @property
    def n_storeys(self) -> int:
        return int(self.summary.get("n_storeys", sum(n.startswith("drift") for n in self.names)))

    @property
    def storey_labels(self) -> list[str]:
        """The deck's label of each storey ('storey s' when not given)."""
        return self._labels("storey_labels", self.n_storeys, "storey")

    def storey(self, s: int) -> dict[str, np.ndarray]:
        """Drift and storey shear V of storey s (1-based) over time (decks with &storeys)."""
        return {"drift": self[f"drift{s}"], "V": self[f"V{s}"]}

    @property
    def base_shear(self) -> np.ndarray:
        """Base shear over time (column Vb, decks with &storeys)."""
        return self["Vb"]

    def device_results(self) -> DeviceResults:
        """Per device: dissipated energy, slip travel, slip excursions, peak force and
        residual slip, from the summary (keys ``dissipated_energy_J``, ``slip_travel_m``,
        ``slip_excursions``, ``peak_force_N``, ``residual_s_m``)."""
        s = self.summary
        if "dissipated_energy_J" not in s:
            raise KeyError("the summary has no per-device energies (written by an older frictiondyn)")
        return DeviceResults(
            self.device_labels,
            _floats(s["dissipated_energy_J"]),
            _floats(s["slip_travel_m"]),
            np.array(s["slip_excursions"], dtype=int),
            _floats(s["peak_force_N"]),
            _floats(s["residual_s_m"]),
        )

    def modes(self, system: str = "stuck") -> Modes:
        """The natural modes of the 'stuck' or the 'free' system from the summary."""
        if system not in ("stuck", "free"):
            raise ValueError(f"system must be 'stuck' or 'free', not {system!r}")
        s = self.summary
        if f"modes_{system}_status" not in s:
            raise KeyError("the summary has no modes (written by an older frictiondyn)")
        periods = _floats(s[f"periods_{system}_s"])
        # a rigid-body mode: the summary's period and xi are null (0 in older summaries)
        rigid = np.isnan(periods) | (periods == 0.0)
        periods[rigid] = np.inf
        shapes = np.array(s[f"mode_shapes_{system}"], dtype=float).reshape(len(periods), self.n_dof)
        return Modes(
            system,
            s[f"modes_{system}_status"],
            periods,
            shapes,
            _floats(s[f"modal_mass_ratio_{system}"]),
            np.where(rigid, np.nan, _floats(s[f"modal_xi_{system}"])),
        )

    def to_dataframe(self, index: str | None = "t"):
        """The history as a pandas DataFrame (pandas is optional: ImportError without it).
        Columns are the names (``u1``, ``aabs1``, ...), indexed by ``index`` (time by
        default; None for a plain range); ``df.attrs["units"]`` maps each name to its unit
        and ``df.attrs["labels"]`` holds the DOF, device and storey labels."""
        try:
            import pandas as pd
        except ImportError:  # pragma: no cover - depends on the environment
            raise ImportError(
                "Result.to_dataframe needs pandas (pip install pandas); the history is "
                "also Result.data with Result.names"
            ) from None
        df = pd.DataFrame(self.data, columns=list(self.names))
        if index is not None:
            df = df.set_index(index)
        df.attrs["units"] = dict(self.units)
        df.attrs["labels"] = {
            "dof": self.dof_labels,
            "device": self.device_labels,
            "storey": self.storey_labels,
        }
        return df

    def summary_json(self) -> str:
        """The summary as JSON text: as the library wrote it (reals with 17 significant
        digits) while ``summary`` is unchanged, else ``json.dumps`` of the dict."""
        text = self.summary_text
        if text is not None and json.loads(text or "{}") == self.summary:
            return text
        return json.dumps(self.summary, indent=2)

    def _header(self) -> str:
        return ",".join(f"{n}[{self.units[n]}]" for n in self.names)

    def to_csv(self, path: str | os.PathLike) -> Path:
        """Write the history (header ``name[unit],...``, ``es24.16e3`` values) and the summary
        next to it (``<stem>.summary.json`` for ``<stem>.csv``, any case; ``<name>.summary.json``
        for any other name, as ``from_files`` looks for it) with the library's writer, exactly
        as the executable does; each file goes to a temporary name renamed when complete.

        Why a new session: a Result holds none (it may come from arrays, from files or from a
        session closed since), and only the library's writer gives the executable's bytes; so
        the Result's header, summary and history are handed to a session made for this call
        (which copies the history: the memory of one more history while it writes)."""
        path = Path(path)
        summary = _summary_path(path)
        with Session._adopt(self.data, self._header(), self.summary_json()) as session:
            session._write_files(path, summary, self.data)
        return path

    def write_summary(self, path: str | os.PathLike) -> Path:
        """Write the summary JSON alone with the library's writer, as the executable does."""
        path = Path(path)
        empty = np.zeros((0, len(self.names)))
        with Session._adopt(empty, self._header(), self.summary_json()) as session:
            session._write_files(None, path, None)
        return path

    def to_parquet(self, path: str | os.PathLike) -> Path:
        """Write the history to a Parquet file (a column a quantity, float64; the units and the
        summary JSON in the schema's metadata, ``frictiondyn.units`` and
        ``frictiondyn.summary``), atomically as to_npz; needs pyarrow
        (``pip install frictiondyn[parquet]``). Raises OutputError when it cannot be written."""
        pq = _pyarrow_parquet()
        import pyarrow as pa

        path = Path(path)
        table = pa.table({n: np.ascontiguousarray(self.data[:, k]) for k, n in enumerate(self.names)})
        table = table.replace_schema_metadata({
            "frictiondyn.units": json.dumps({n: self.units[n] for n in self.names}),
            "frictiondyn.summary": self.summary_json(),
        })
        return _write_replacing(path, lambda tmp: pq.write_table(table, tmp))

    def to_npz(self, path: str | os.PathLike) -> Path:
        """Write names, units, data and the summary (as JSON) to a .npz file (``.npz`` is
        added to a name without it, as numpy does) and return its path. The file is written
        under a temporary name in the same folder and renamed when complete, so that an
        earlier file of the name is replaced whole or not at all. Raises OutputError (naming
        the file and the system's reason) when it cannot be written; nothing is left then."""
        path = Path(path)
        if path.suffix != ".npz":
            path = path.with_name(path.name + ".npz")

        def write(tmp: Path) -> None:
            with open(tmp, "xb") as f:
                np.savez(
                    f,
                    names=np.array(self.names),
                    units=np.array([self.units[n] for n in self.names]),
                    data=self.data,
                    summary=np.array(self.summary_json()),
                )
                f.flush()
                os.fsync(f.fileno())

        return _write_replacing(path, write)


def _write_replacing(path: Path, write: Callable[[Path], object]) -> Path:
    """write(tmp) to a temporary name beside path, then renamed over it: an earlier file of
    the name is replaced whole or not at all; OutputError (the file and the system's reason)
    when it cannot be written, and nothing left then."""
    tmp = path.with_name(f".{path.name}.{os.getpid()}.{threading.get_ident()}.tmp")
    try:
        write(tmp)
        os.replace(tmp, path)
    except BaseException as e:
        with contextlib.suppress(OSError):
            tmp.unlink(missing_ok=True)
        if isinstance(e, OSError):
            raise OutputError(f"cannot write '{path}': {e.strerror or e}") from None
        raise
    return path


def _pyarrow_parquet():
    try:
        import pyarrow.parquet as pq
    except ImportError:
        raise ImportError("Parquet needs pyarrow: pip install frictiondyn[parquet]") from None
    return pq


def read_history(path: str | os.PathLike, summary: str | os.PathLike | None | bool = None) -> Result:
    """The executable's history CSV with its summary JSON (``Result.from_files``: the one next
    to it by default, FileNotFoundError when missing; ``summary=False``: none)."""
    return Result.from_files(path, summary)


def read_summary(path: str | os.PathLike) -> dict:
    """The executable's summary JSON (UTF-8; an undefined value, JSON null, is None:
    docs/namelist.md, "Undefined values")."""
    return json.loads(Path(path).read_text(encoding="utf-8"))
