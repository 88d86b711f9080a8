#!/usr/bin/env bash
# Set up, then run the whole test suite against the installed package and executable.
set -euo pipefail
cd "$(dirname "$0")/.."
bash tools/setup.sh
.venv/bin/python -m pytest "$@"
