#!/usr/bin/env bash
# The whole test suite again in a checked build (docs/reliability.md, "The checked build"):
# gfortran's run-time checks (-fcheck=all) and floating-point traps
# (-ffpe-trap=invalid,zero,overflow), with the address and undefined-behaviour sanitizers
# (-Db_sanitize=address,undefined), for the library, the executable and the f2py extension.
#
#   bash tools/test_checked.sh [pytest arguments]     (CI: .ci/run, after tools/test.sh)
#
# Its builds and environment are its own and are kept for the next run: build/checked-unit
# (the Fortran unit suites), build/checked-pkg and .venv-checked (the package, installed by
# meson-python). It runs, each with no finding allowed:
#   1. the Fortran unit suites (meson test);
#   2. the executable on every bundled deck, leak detection on;
#   3. pytest, in a Python that preloads libasan (the interpreter is not instrumented; the
#      extension is), leak detection off in Python (the interpreter's own allocations would
#      be reported) and on in every run of the executable.
# A finding is any sanitizer report (written to files under build/checked-findings, so that
# one made by a subprocess whose output a test keeps is not lost), any gfortran run-time
# error or warning (an array temporary, an out-of-bounds index, a trapped floating-point
# exception) in the output of the unit suites, of the decks or of any test (in-process or
# from a subprocess a test ran: tools/checked/pytest_findings.py), and any failing test.
set -euo pipefail
cd "$(dirname "$0")/.."
ROOT=$PWD
FFLAGS_CHECKED="-fcheck=all -ffpe-trap=invalid,zero,overflow -fno-omit-frame-pointer"
SANITIZE=(-Db_sanitize=address,undefined -Db_lundef=false)
VENV=.venv-checked
FIND=$ROOT/build/checked-findings
FINDINGS_RE='Fortran runtime (error|warning)|Program received signal|AddressSanitizer|LeakSanitizer|runtime error:'
t0=$SECONDS

command -v gfortran >/dev/null || bash tools/setup.sh   # the compiler and LAPACK, as for the normal build
libasan=$(gcc -print-file-name=libasan.so)
if [ ! -e "$libasan" ] || [ "$libasan" = libasan.so ]; then
  echo "test_checked: gcc's libasan.so was not found (Debian: libgcc-12-dev)" >&2
  exit 1
fi

# the environment: the package with its test extras, built (in pip's isolated build
# environment, as tools/setup.sh builds it) in a build directory kept for the next run
if [ ! -x $VENV/bin/python ]; then
  "${PYTHON:-python3}" -m venv $VENV
fi
$VENV/bin/python -m pip install -q --upgrade pip >/dev/null
echo "test_checked: building the package (build/checked-pkg)" >&2
$VENV/bin/python -m pip install -q \
  -Cbuild-dir=build/checked-pkg \
  -Csetup-args=-Dbuildtype=debugoptimized \
  -Csetup-args="${SANITIZE[0]}" -Csetup-args="${SANITIZE[1]}" \
  "-Csetup-args=-Dfortran_args=$FFLAGS_CHECKED" \
  ".[test]"

echo "test_checked: building the unit suites (build/checked-unit) (at $((SECONDS - t0)) s)" >&2
if [ ! -f build/checked-unit/build.ninja ]; then
  $VENV/bin/meson setup build/checked-unit -Dpython=false --buildtype=debugoptimized \
    "${SANITIZE[@]}" "-Dfortran_args=$FFLAGS_CHECKED" >/dev/null
fi
$VENV/bin/meson compile -C build/checked-unit >/dev/null

rm -rf "$FIND"
mkdir -p "$FIND"
export UBSAN_OPTIONS="halt_on_error=1:print_stacktrace=1:log_path=$FIND/ubsan"
ASAN_BASE="allocator_may_return_null=1:log_path=$FIND/asan"
export GFORTRAN_ERROR_BACKTRACE=1

found=0
report() {  # report NAME FILE: the findings in a test's output
  if grep -Eq "$FINDINGS_RE" "$2"; then
    echo "test_checked: FINDING in $1:" >&2
    grep -E -B2 -A8 "$FINDINGS_RE" "$2" | head -40 >&2
    found=1
  fi
}

echo "test_checked: 1. the Fortran unit suites (at $((SECONDS - t0)) s)" >&2
# leak detection off here: the harness leaks, not the library (test-drive's registries are
# built by array constructors of a type with allocatable components, whose temporaries
# gfortran 12 never frees); the library's allocations are checked by the runs of 2. and 3.
ASAN_OPTIONS="$ASAN_BASE:detect_leaks=0" \
  $VENV/bin/meson test -C build/checked-unit --suite unit --print-errorlogs || found=1
report "the unit suites" build/checked-unit/meson-logs/testlog.txt

echo "test_checked: 2. the executable on every bundled deck (at $((SECONDS - t0)) s)" >&2
exe=$VENV/bin/frictiondyn
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
for deck in inputs/*.nml; do
  name=$(basename "$deck" .nml)
  mkdir -p "$work/$name"
  find inputs -maxdepth 1 -type f -exec cp {} "$work/$name/" \;
  if ! (cd "$work/$name" && ASAN_OPTIONS="$ASAN_BASE:detect_leaks=1" \
        "$ROOT/$exe" "$name.nml" >out.txt 2>err.txt); then
    echo "test_checked: $deck failed:" >&2
    cat "$work/$name/err.txt" >&2
    found=1
  fi
  report "$deck" "$work/$name/err.txt"
done

echo "test_checked: 3. pytest (the executable and the extension) (at $((SECONDS - t0)) s)" >&2
# libstdc++ preloaded too: loaded later (by matplotlib's C++ extensions), its exceptions
# would reach the sanitizer's interceptor of __cxa_throw before it could find the real one
export LD_PRELOAD="$libasan $(gcc -print-file-name=libstdc++.so)"
export ASAN_OPTIONS="$ASAN_BASE:detect_leaks=0"
export FRICTIONDYN_CHECKED=1   # tests that limit memory with setrlimit do it the sanitizer's way
# the instrumented code is about 4 times slower (the fuzz campaign's longest case, 180 of seed
# 2024: 6.8 s in the normal build, 28 s here): the fuzz campaign's time bound of a case
# (tests/fuzz/run.py, time_scale) is scaled by as much, so that it bounds the same work
export FRICTIONDYN_TIME_SCALE=${FRICTIONDYN_TIME_SCALE:-4}
export PYTHONPATH=$ROOT/tools/checked${PYTHONPATH:+:$PYTHONPATH}
export FRICTIONDYN_FINDINGS=$FIND
status=0
$VENV/bin/python -m pytest -p pytest_findings "$@" || status=$?
unset LD_PRELOAD

for f in "$FIND"/*; do
  [ -e "$f" ] || continue
  # an allocation refused under a test's memory bound (allocator_may_return_null) is no finding
  grep -vEq '^==[0-9]+==WARNING: AddressSanitizer failed to allocate 0x[0-9a-f]+ bytes$|^$' "$f" || continue
  echo "test_checked: FINDING ($f):" >&2
  head -60 "$f" >&2
  found=1
done
echo "test_checked: $(( (SECONDS - t0) / 60 )) min $(( (SECONDS - t0) % 60 )) s" >&2
if [ $status -ne 0 ] || [ $found -ne 0 ]; then
  echo "test_checked: FAILED (pytest status $status, findings $found)" >&2
  exit 1
fi
echo "test_checked: no finding" >&2
