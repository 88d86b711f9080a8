"""The Python side of the fuzz campaign: a long-lived interpreter that runs case after case
through the package's API (one JSON request a line on stdin, one JSON answer a line on
stdout). The parent (run.py) bounds each case in time, restarts the worker when it dies or
hangs, and counts those as failures. The address space is limited to what the interpreter
uses after its imports plus --mem MiB, so that memory the deck asks for and cannot be had
shows as what it becomes (an exception, or the death of the interpreter).

For each case: the deck file through Session (read, solve, result; then write: the files
the executable writes), and its text through run_text (read from memory), whose outcome must
be the Session's before it writes.
"""

from __future__ import annotations

import hashlib
import json
import os
import resource
import sys
import traceback


def vm_bytes() -> int:
    with open("/proc/self/status") as fh:
        for line in fh:
            if line.startswith("VmSize:"):
                return int(line.split()[1]) * 1024
    return 0


def outcome_of(fn):
    import frictiondyn

    try:
        return {"status": "ok", "value": fn()}
    except frictiondyn.FrictiondynError as exc:
        return {"status": "error", "type": type(exc).__name__, "message": str(exc)}
    except BaseException as exc:  # noqa: BLE001 - a wrong exception type is what is looked for
        return {
            "status": "wrong",
            "type": type(exc).__name__,
            "message": str(exc),
            "traceback": traceback.format_exc()[-2000:],
        }


def run_case(req: dict) -> dict:
    import frictiondyn
    import numpy as np

    os.chdir(req["dir"])
    deck = req["deck"]

    session = None

    def by_session():
        nonlocal session
        session = frictiondyn.Session(deck)
        r = session.solve().result()
        return {"shape": list(r.data.shape), "digest": _digest(r)}

    def write():
        csv, summ = session.write()
        return {"history": str(csv) if csv else None, "summary": str(summ)}

    def _digest(r):
        summary = {k: v for k, v in r.summary.items() if k != "run_time_s"}
        data = np.ascontiguousarray(r.data).tobytes()
        return [hashlib.sha256(data).hexdigest(), json.dumps(summary, sort_keys=True)]

    def by_text():
        with open(deck, "rb") as fh:
            text = fh.read().decode("utf-8", "surrogateescape")
        r = frictiondyn.run_text(text, deck, base_dir="")
        return {"shape": list(r.data.shape), "digest": _digest(r)}

    out = {"session": outcome_of(by_session)}
    try:
        if out["session"]["status"] == "ok":
            out["write"] = outcome_of(write)
    finally:
        if session is not None:
            session.close()
    if os.path.isfile(deck):
        out["text"] = outcome_of(by_text)
    return out


def main() -> None:
    mem = int(sys.argv[1]) if len(sys.argv) > 1 else 2048
    import frictiondyn  # noqa: F401 - imported before the limit is set
    import numpy  # noqa: F401

    if not os.environ.get("FRICTIONDYN_CHECKED"):  # else the sanitizer's bound (run.py)
        limit = vm_bytes() + mem * 2**20
        resource.setrlimit(resource.RLIMIT_AS, (limit, limit))
    for line in sys.stdin:
        req = json.loads(line)
        try:
            answer = run_case(req)
        except BaseException as exc:  # noqa: BLE001
            answer = {"session": {"status": "wrong", "type": type(exc).__name__,
                                  "message": str(exc), "traceback": traceback.format_exc()}}
        sys.stdout.write(json.dumps(answer) + "\n")
        sys.stdout.flush()


if __name__ == "__main__":
    main()
