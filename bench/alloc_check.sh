#!/usr/bin/env bash
# The time-step loop allocates nothing: valgrind's heap count of the executable on the same
# deck for two durations (the second twice the first) must be the same. Decks: the paper's
# test 4 with both laws (2 DOFs, the kernel's dense path) and a 100-storey building with a
# damper in every storey under a recorded motion (banded path, rank-one updates, history
# streamed to its file every record step).
#
#   bash bench/alloc_check.sh            # needs valgrind (apt-get install valgrind)
#
# Prints, per deck, the allocations of both runs and the steps they took; exits 1 when the
# counts differ by more than a few (the summary's number formatting allocates a handful,
# independent of the duration).
set -euo pipefail
cd "$(dirname "$0")/.."
command -v valgrind >/dev/null || { echo "alloc_check: valgrind is required" >&2; exit 2; }
EXE=${FRICTIONDYN_EXE:-.venv/bin/frictiondyn}
PY=${PYTHON:-.venv/bin/python}
WORK=$(mktemp -d)
trap 'rm -rf "$WORK"' EXIT

for law in hysteretic velocity; do
  for d in 2.0 4.0; do
    sed "s/duration = 40.0/duration = $d/" "inputs/test4_$law.nml" > "$WORK/t4_${law}_$d.nml"
  done
done
"$PY" - "$WORK" <<'EOF'
import sys
from pathlib import Path
import numpy as np
import frictiondyn as fd

work = Path(sys.argv[1])
n = 100
t = np.arange(0, 4.0 + 1e-9, 0.01)
acc = 3.0 * np.sin(2 * np.pi * 1.3 * t) * np.minimum(t, 1.0)
for d in (2.0, 4.0):
    an = fd.Analysis(
        masses=[1.0e4] * n,
        springs=[fd.Spring(i + 1, i, 2.0e8) for i in range(n)],
        damping=fd.Damping.rayleigh(0.2, 1.0e-3),
        devices=[fd.Device(i + 1, i, 2.0e4 * (n - i) / n + 5.0e3, 1.0, "hysteretic", f=1.0e-4)
                 for i in range(n)],
        excitation=fd.Record(0.01, values=acc, duration=d),
        integration=fd.Integration(n1=10, n2=10),
        output=fd.Output(dir="out", name=f"b{int(d)}"),
    )
    an.write_deck(work / f"building_{d}.nml")
EOF

status=0
for deck in t4_hysteretic t4_velocity building; do
  counts=()
  for d in 2.0 4.0; do
    line=$(cd "$WORK" && valgrind "$OLDPWD/$EXE" "${deck}_$d.nml" 2>&1 >"${deck}_$d.out" | grep "total heap usage")
    allocs=$(echo "$line" | sed -E 's/.*usage: ([0-9,]+) allocs.*/\1/' | tr -d ,)
    steps=$(grep -E "steps dt1" "$WORK/${deck}_$d.out" | sed -E 's/.*steps dt1 ([0-9]+), dt2 ([0-9]+), finer ([0-9]+).*/\1 + \2 + \3/')
    echo "$deck, duration $d s: $allocs allocations; steps dt1 + dt2 + finer = $steps"
    counts+=("$allocs")
  done
  diff=$(( counts[1] - counts[0] ))
  if [ "${diff#-}" -gt 8 ]; then
    echo "  FAIL: the longer run allocated $diff more times" ; status=1
  else
    echo "  same count (difference $diff): nothing allocated per step"
  fi
done
exit $status
