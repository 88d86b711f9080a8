"""python -m frictiondyn run DECK: run a deck with the installed executable."""

from __future__ import annotations

import argparse
import sys

from . import RunFailed, run_executable


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m frictiondyn")
    sub = parser.add_subparsers(dest="command", required=True)
    p_run = sub.add_parser("run", help="run one namelist deck")
    p_run.add_argument("deck")
    args = parser.parse_args(argv)
    if args.command == "run":
        try:
            run = run_executable(args.deck)
        except RunFailed as exc:
            print(f"error: {exc}", file=sys.stderr)
            return 1
        sys.stdout.write(run.stdout)
        sys.stderr.write(run.stderr)
    return 0


if __name__ == "__main__":
    sys.exit(main())
