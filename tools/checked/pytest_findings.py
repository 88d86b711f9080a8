"""pytest plugin of the checked build (tools/test_checked.sh): a finding of gfortran's
run-time checks or of the sanitizers fails the test that made it, even where the test itself
would not see it.

- the output a test printed in-process (the extension writes to the process's stderr, which
  pytest captures and shows only for failing tests) is searched after each test;
- the output of every subprocess a test runs through communicate() (subprocess.run with
  capture_output, check_output, ...: the executable, python -m frictiondyn, ...) is searched
  as it comes back, whatever the test then asserts on the exit status;
- leak detection is turned on for every run of the executable (Popen);
- a sanitizer report file that appears during a test under $FRICTIONDYN_FINDINGS (the
  sanitizers' log_path) is that test's finding.
"""

from __future__ import annotations

import os
import re
import subprocess
from pathlib import Path

import pytest

FINDING = re.compile(
    r"Fortran runtime (error|warning)|Program received signal|AddressSanitizer|LeakSanitizer|"
    r"runtime error:"
)
FIND = Path(os.environ.get("FRICTIONDYN_FINDINGS", "build/checked-findings"))
_seen: list[str] = []  # findings of subprocesses since the current test started

_communicate = subprocess.Popen.communicate
_init = subprocess.Popen.__init__


def init(self, args, *rest, **kwargs):
    """Leak detection on in the executable (off in Python, whose interpreter never frees
    some of what it allocates): a run of frictiondyn that ends normally frees everything."""
    program = args[0] if isinstance(args, (list, tuple)) and args else args
    named = isinstance(program, (str, os.PathLike))
    if named and os.path.basename(os.fspath(program)) == "frictiondyn":
        env = dict(kwargs.get("env") or os.environ)
        env["ASAN_OPTIONS"] = env.get("ASAN_OPTIONS", "") + ":detect_leaks=1"
        kwargs["env"] = env
    _init(self, args, *rest, **kwargs)


def _text(out) -> str:
    if out is None:
        return ""
    return out.decode("utf-8", "replace") if isinstance(out, bytes) else out


def communicate(self, *args, **kwargs):
    out, err = _communicate(self, *args, **kwargs)
    for stream in (out, err):
        text = _text(stream)
        m = FINDING.search(text)
        if m:
            start = max(0, m.start() - 300)
            _seen.append(f"{self.args!r}:\n{text[start:start + 3000]}")
    return out, err


subprocess.Popen.communicate = communicate
subprocess.Popen.__init__ = init


# what the sanitizer writes when an allocation fails under a memory bound (a test's or the
# fuzz campaign's: allocator_may_return_null): malloc returns NULL, as it should
BOUNDED = re.compile(r"==\d+==WARNING: AddressSanitizer failed to allocate 0x[0-9a-f]+ bytes")


def is_finding(path: Path) -> bool:
    """A sanitizer report other than the warnings of a bounded allocation."""
    lines = [ln for ln in path.read_text(errors="replace").splitlines() if ln.strip()]
    return not all(BOUNDED.fullmatch(ln.strip()) for ln in lines)


def _reports() -> set[str]:
    return {p.name for p in FIND.glob("*")} if FIND.is_dir() else set()


@pytest.hookimpl(hookwrapper=True)
def pytest_runtest_protocol(item, nextitem):
    item._checked_before = _reports()
    _seen.clear()
    yield


@pytest.hookimpl(hookwrapper=True)
def pytest_runtest_makereport(item, call):
    outcome = yield
    report = outcome.get_result()
    found = []
    for title, text in report.sections:
        # a phase's report carries the output of the phases before it too ("Captured stderr
        # call" again in teardown's): each output is searched in its own phase's report only
        if title.startswith("Captured") and title.endswith(report.when) and FINDING.search(text):
            found.append(f"{title}:\n{text[-3000:]}")
    if report.when == "teardown" or report.when == "call":
        found.extend(_seen)
        _seen.clear()
        new = _reports() - item._checked_before
        item._checked_before |= new
        for name in sorted(n for n in new if is_finding(FIND / n)):
            found.append(f"{FIND / name}:\n{(FIND / name).read_text(errors='replace')[:3000]}")
    if found and report.outcome != "failed":
        report.outcome = "failed"
        report.longrepr = "checked build: a finding\n\n" + "\n\n".join(found)
