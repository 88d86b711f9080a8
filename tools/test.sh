#!/usr/bin/env bash
# Set up, then run the whole test suite: the Fortran unit tests and the reference outputs of
# that build's executable (meson test, in a build of the library without Python), and pytest
# against the installed package and executable.
set -euo pipefail
cd "$(dirname "$0")/.."
bash tools/setup.sh
if [ ! -f build/unit/build.ninja ]; then
  .venv/bin/meson setup build/unit -Dpython=false --buildtype=debugoptimized >/dev/null
fi
.venv/bin/meson compile -C build/unit >/dev/null
.venv/bin/meson test -C build/unit --suite unit --suite reference --print-errorlogs
.venv/bin/python -m pytest "$@"
