#!/usr/bin/env bash
# Micro-benchmark of the effective-stiffness kernel (fortran/linalg/fd_banded.f90): builds
# bench/bench_banded.f90 with the kernel's modules (gfortran -O3, LAPACK and BLAS, as the
# release build) in a scratch directory and runs it. Not part of the build or the tests.
#
#   bash bench/banded.sh            # the table: dense vs banded, n = 2 .. 10000
#   bash bench/banded.sh calibrate  # per-column cost of an update and of a refactorization
#   bash bench/banded.sh alloc      # valgrind: heap allocations after set-up do not grow
#   bash bench/banded.sh small|wide # the dense crossover; bands that are a fraction of n
#   bash bench/banded.sh cholmod    # CHOLMOD on a chain, for comparison (libsuitesparse-dev)
set -euo pipefail
cd "$(dirname "$0")/.."
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
src=(fortran/core/fd_kinds.f90 fortran/core/fd_error.f90 fortran/core/fd_textio.f90 fortran/model/fd_names.f90
     fortran/model/fd_model.f90 fortran/model/fd_kinematics.f90 fortran/linalg/fd_lapack.f90 fortran/linalg/fd_rcm.f90
     fortran/linalg/fd_banded.f90 bench/bench_banded.f90)
gfortran -O3 -frecursive -ffree-line-length-132 -J "$out" -o "$out/bench_banded" "${src[@]}" \
  $(pkg-config --libs lapack blas 2>/dev/null || echo -llapack -lblas)
mode=${1:-table}
if [ "$mode" = cholmod ]; then
  [ -f /usr/include/suitesparse/cholmod.h ] || { echo "cholmod: apt-get install libsuitesparse-dev" >&2; exit 1; }
  gcc -O2 -o "$out/cholmod_chain" bench/cholmod_chain.c -lcholmod -lm
  "$out/cholmod_chain"
elif [ "$mode" = alloc ]; then
  command -v valgrind >/dev/null || { echo "alloc: valgrind is required" >&2; exit 1; }
  for n in 50 500; do
    valgrind "$out/bench_banded" alloc $n 2>&1 | grep -aE "stats|total heap usage" | sed "s/^/N = $n: /"
  done
else
  "$out/bench_banded" "$mode"
fi
