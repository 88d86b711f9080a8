#!/usr/bin/env bash
# Set up frictiondyn on a fresh machine: the Fortran compiler, LAPACK and SuiteSparse's CHOLMOD
# (the sparse path of wide-band structures; the build works without it) from Debian (when
# missing), a virtual environment in .venv, and the package (library, executable, Python
# driver) built by meson-python and installed into it.
set -euo pipefail
cd "$(dirname "$0")/.."

need=()
if command -v dpkg >/dev/null 2>&1; then
  for pkg in gfortran liblapack-dev pkg-config libsuitesparse-dev; do
    dpkg -s "$pkg" >/dev/null 2>&1 || need+=("$pkg")
  done
fi
if [ ${#need[@]} -gt 0 ]; then
  echo "setup: installing ${need[*]} from Debian" >&2
  if [ "$(id -u)" = 0 ]; then SUDO=""; else SUDO="sudo"; fi
  $SUDO apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq "${need[@]}" >/dev/null
fi
command -v gfortran >/dev/null 2>&1 || { echo "setup: gfortran is required" >&2; exit 1; }

PY=${PYTHON:-python3}
if [ ! -x .venv/bin/python ]; then
  echo "setup: creating .venv" >&2
  "$PY" -m venv .venv
fi
.venv/bin/python -m pip install -q --upgrade pip >/dev/null
echo "setup: building and installing frictiondyn into .venv (meson-python)" >&2
.venv/bin/python -m pip install -q ".[test]"
