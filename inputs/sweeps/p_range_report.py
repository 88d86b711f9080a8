"""The range of normal force P in which the paper's Table 1 observation holds, from the
sweep inputs/sweeps/p_range.toml: a test slides in steady state when its device still
makes stick-to-slip transitions between t = 30 s and t = 40 s.

    python inputs/sweeps/p_range_report.py sweeps/p_range
"""

import sys

from frictiondyn.sweep import read_results

OBSERVED = {1: "stick", 2: "stick", 3: "stick-slip", 4: "stick-slip", 5: "stick"}


def main(directory: str) -> int:
    rows = read_results(directory)
    bad = [r for r in rows if r["status"] != "done"]
    if bad:
        print(f"{len(bad)} run(s) not complete: run the sweep again", file=sys.stderr)
        return 1
    s2s: dict[tuple[int, float], dict[float, int]] = {}
    for r in rows:
        test = int(r["deck"].rsplit("test", 1)[1][0])  # the base deck, ../testN_velocity.nml
        key = (test, float(r["friction.p"]))
        s2s.setdefault(key, {})[float(r["excitation.duration"])] = int(r["stick_to_slip[1]"])
    ps = sorted({p for _, p in s2s})
    print("steady-state sliding (stick-to-slip transitions between 30 s and 40 s):")
    print("P [N]   " + "  ".join(f"test {t}" for t in range(1, 6)))
    holds = []
    for p in ps:
        slides = {t: s2s[(t, p)][40.0] - s2s[(t, p)][30.0] for t in range(1, 6)}
        ok = all((slides[t] > 0) == (OBSERVED[t] == "stick-slip") for t in range(1, 6))
        holds.append((p, ok))
        print(f"{p:6.2f}  " + "  ".join(f"{slides[t]:6d}" for t in range(1, 6))
              + ("   observation holds" if ok else ""))
    inside = [p for p, ok in holds if ok]
    if inside:
        lo = max((p for p, ok in holds if not ok and p < min(inside)), default=float("nan"))
        hi = min((p for p, ok in holds if not ok and p > max(inside)), default=float("nan"))
        print(f"the observation holds for P in [{min(inside):g}, {max(inside):g}] N of the grid: "
              f"its lower end lies in ({lo:g}, {min(inside):g}], its upper end in "
              f"[{max(inside):g}, {hi:g})")
    return 0


if __name__ == "__main__":
    raise SystemExit(main(sys.argv[1] if len(sys.argv) > 1 else "sweeps/p_range"))
