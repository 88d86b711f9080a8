#!/usr/bin/env bash
# Quick start: set up, then run one bundled deck (default: the paper's test 4 with the
# velocity model of friction) and say where its outputs went.
set -euo pipefail
cd "$(dirname "$0")/.."
bash tools/setup.sh
deck=${1:-inputs/test4_velocity.nml}
.venv/bin/frictiondyn "$deck"
