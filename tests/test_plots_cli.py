"""Plots (labels with units, one line per result) and the command line
(python -m frictiondyn run | plot | compare | paper)."""

from __future__ import annotations

import json
import re
import shutil
import subprocess
import sys
from pathlib import Path

import frictiondyn
import numpy as np
import pytest
from conftest import FIG3_REVERSALS, FIG3_VIOLATIONS, INPUTS, MU, TABLE1, P
from frictiondyn import Output, Result, plots
from frictiondyn.paper import paper_analysis
from oracles import PAPER_OBSERVATION

PNG = b"\x89PNG\r\n\x1a\n"


def is_png(path: Path) -> bool:
    return path.is_file() and path.stat().st_size > 1000 and path.read_bytes()[:8] == PNG


@pytest.fixture(scope="module")
def short_runs() -> dict[str, Result]:
    """Test 4 for 3 s with both laws, a row every dt1."""
    out = {}
    for law in ("hysteretic", "velocity"):
        a = paper_analysis(4, law, duration=3.0)
        a.output = Output(output_every=1)
        out[law] = a.run(name=f"short_{law}.nml")
    return out


# --- plots --------------------------------------------------------------------------------


def test_plot_acceleration_overlays_one_line_per_result(short_runs, tmp_path):
    runs = [short_runs["hysteretic"], short_runs["velocity"]]
    path = tmp_path / "a.png"
    fig = plots.plot_acceleration(runs, 2, path, t_range=(2.0, 3.0))
    assert is_png(path)
    ax = fig.axes[0]
    assert ax.get_xlabel() == "time [s]" and ax.get_ylabel() == "absolute acceleration [m/s²]"
    assert ax.get_title() == "DOF 2: absolute acceleration"
    lines = ax.get_lines()
    assert len(lines) == 2
    assert [t.get_text() for t in ax.get_legend().get_texts()] == [
        "short_hysteretic",
        "short_velocity",
    ]
    # the lines are the data in the window, not something else
    x, y = lines[1].get_data()
    w = (runs[1].time >= 2.0) & (runs[1].time <= 3.0)
    assert np.array_equal(x, runs[1].time[w]) and np.array_equal(y, runs[1]["aabs2"][w])
    assert x[0] >= 2.0 and x[-1] <= 3.0


def test_plot_relative_velocity_with_band(short_runs, tmp_path):
    r = short_runs["hysteretic"]
    fig = plots.plot_relative_velocity(r, 1, tmp_path / "v.png", band=1e-3, labels=["hysteretic"])
    assert is_png(tmp_path / "v.png")
    ax = fig.axes[0]
    assert ax.get_xlabel() == "time [s]" and ax.get_ylabel() == "relative velocity [m/s]"
    lines = ax.get_lines()
    assert len(lines) == 3  # s' and the +-eps1 band
    assert lines[1].get_ydata()[0] == 1e-3 and lines[2].get_ydata()[0] == -1e-3
    assert ax.get_legend() is None  # one result: no legend


def test_plot_hysteresis_loops_are_bounded_by_p_mu(short_runs, tmp_path):
    runs = list(short_runs.values())
    fig = plots.plot_hysteresis(runs, 1, tmp_path / "h.png", labels=["hys", "vel"])
    assert is_png(tmp_path / "h.png")
    ax = fig.axes[0]
    assert ax.get_xlabel() == "relative displacement [m]"
    assert ax.get_ylabel() == "friction force [N]"
    lines = ax.get_lines()
    assert len(lines) == 2
    for ln in lines:  # the loops reach, and never exceed, the slip force P mu
        assert np.max(np.abs(ln.get_ydata())) == pytest.approx(P * MU, rel=1e-12)


def test_plot_phase_steps_between_stick_and_slip(short_runs, tmp_path):
    fig = plots.plot_phase(list(short_runs.values()), 1, tmp_path / "p.png")
    assert is_png(tmp_path / "p.png")
    ax = fig.axes[0]
    assert ax.get_xlabel() == "time [s]" and ax.get_ylabel() == "phase"
    lines = ax.get_lines()
    assert len(lines) == 2 and all(ln.get_drawstyle() == "steps-post" for ln in lines)
    assert set(np.unique(lines[1].get_ydata())) == {-1.0, 0.0, 1.0}
    assert [t.get_text() for t in ax.get_yticklabels()] == ["slip \u2212", "stick", "slip +"]


def test_plot_columns_and_compare(short_runs, tmp_path):
    runs = list(short_runs.values())
    fig = plots.plot_columns(runs, "u1", tmp_path / "c.png", x="ag")
    assert is_png(tmp_path / "c.png")
    ax = fig.axes[0]
    assert ax.get_xlabel() == "ag [m/s²]" and ax.get_ylabel() == "u1 [m]"
    assert len(ax.get_lines()) == 2
    fig = plots.plot_compare(runs, tmp_path / "cmp.png", t_range=(2.0, 3.0))
    assert is_png(tmp_path / "cmp.png")
    assert len(fig.axes) == 3  # aabs1, aabs2, device 1 loop
    assert [a.get_ylabel() for a in fig.axes] == [
        "absolute acceleration [m/s²]",
        "absolute acceleration [m/s²]",
        "friction force [N]",
    ]
    assert all(len(a.get_lines()) == 2 for a in fig.axes)


def test_plot_into_given_axes_and_bad_column(short_runs):
    from matplotlib.figure import Figure

    fig = Figure()
    ax1, ax2 = fig.subplots(1, 2)
    got = plots.plot_acceleration(short_runs["velocity"], 1, ax=ax2)
    assert got is fig and len(ax2.get_lines()) == 1 and len(ax1.get_lines()) == 0
    with pytest.raises(KeyError, match="aabs3"):
        plots.plot_acceleration(short_runs["velocity"], 3)


# --- command line -------------------------------------------------------------------------


def cli(*args: str, cwd: Path) -> subprocess.CompletedProcess:
    return subprocess.run(
        [sys.executable, "-m", "frictiondyn", *args],
        cwd=cwd,
        capture_output=True,
        text=True,
        timeout=120,
    )


def announced(stdout: str, key: str) -> list[str]:
    return [m.group(1) for m in re.finditer(rf"^\s*{key}: (.+)$", stdout, re.M)]


@pytest.mark.parametrize("name", ["test4_velocity", "fig3_coarse"])
def test_cli_run_writes_what_the_executable_writes(name, tmp_path):
    shutil.copy(INPUTS / f"{name}.nml", tmp_path / f"{name}.nml")
    r = cli("run", f"{name}.nml", "--plot", "--plots", "all", cwd=tmp_path)
    assert r.returncode == 0, r.stderr
    assert announced(r.stdout, "history") == [f"out/{name}.csv"]
    assert announced(r.stdout, "summary") == [f"out/{name}.summary.json"]
    pngs = announced(r.stdout, "plot")
    assert len(pngs) == 2 + 3  # aabs1, aabs2; sdot1, hysteresis1, phase1
    assert all(is_png(tmp_path / p) for p in pngs)
    (tmp_path / "out").rename(tmp_path / "cli")
    # the executable on the same deck: the very same files, byte for byte, except the
    # summary's run time
    exe = frictiondyn.run_executable(f"{name}.nml", cwd=tmp_path)
    assert (tmp_path / f"cli/{name}.csv").read_bytes() == exe.history_path.read_bytes()
    mine = (tmp_path / f"cli/{name}.summary.json").read_text().splitlines()
    theirs = exe.summary_path.read_text().splitlines()
    assert len(mine) == len(theirs) > 30
    differ = [(a, b) for a, b in zip(mine, theirs, strict=True) if a != b]
    assert all('"run_time_s"' in a and '"run_time_s"' in b for a, b in differ)
    # the key figures printed are the summary's
    s = exe.summary()
    assert f"stick->slip {s['stick_to_slip'][0]}," in r.stdout
    assert f"peak |a_abs| {s['peak_aabs_mps2'][0]:.6g} m/s2" in r.stdout
    assert f"correctness violations: {s['correctness_violations']}" in r.stdout
    if name == "fig3_coarse":  # the violations are also a warning, as the executable's
        assert s["correctness_violations"] == FIG3_VIOLATIONS
        assert "violate the correctness condition" in r.stderr


def test_cli_run_out_dir_and_plot_and_compare(tmp_path):
    for law in ("velocity", "hysteretic"):
        a = paper_analysis(4, law, duration=3.0)
        a.write_deck(tmp_path / f"{law}.nml")
    for law in ("velocity", "hysteretic"):
        r = cli("run", f"{law}.nml", "--out", "res", cwd=tmp_path)
        assert r.returncode == 0, r.stderr
        assert announced(r.stdout, "history") == [f"res/{law}.csv"]
        assert not (tmp_path / "out").exists()
    # plot a CSV and an .npz
    r = cli("plot", "res/velocity.csv", "--plots", "all", cwd=tmp_path)
    assert r.returncode == 0, r.stderr
    pngs = announced(r.stdout, "plot")
    assert "res/velocity_aabs1.png" in pngs and len(pngs) == 5
    assert all(is_png(tmp_path / p) for p in pngs)
    Result.from_files(tmp_path / "res/hysteretic.csv").to_npz(tmp_path / "hys.npz")
    r = cli("plot", "hys.npz", "--out", "figs", "--t-range", "2", "3", cwd=tmp_path)
    assert r.returncode == 0, r.stderr
    pngs = announced(r.stdout, "plot")
    assert pngs[0] == "figs/hys_aabs2.png" and all(is_png(tmp_path / p) for p in pngs)  # the roof
    # compare the two laws: the plots and the printed peaks (the summaries' values)
    r = cli(
        "compare", "res/hysteretic.csv", "hys.npz", "velocity.nml", "--out", "cmp", cwd=tmp_path
    )
    assert r.returncode == 0, r.stderr
    pngs = announced(r.stdout, "plot")
    assert pngs == [
        "cmp/compare.png",
        "cmp/compare_aabs1.png",
        "cmp/compare_aabs2.png",
        "cmp/compare_hysteresis1.png",
    ]
    assert all(is_png(tmp_path / p) for p in pngs)
    s_h = json.loads((tmp_path / "res/hysteretic.summary.json").read_text())
    s_v = json.loads((tmp_path / "res/velocity.summary.json").read_text())
    line = next(x for x in r.stdout.splitlines() if "peak |aabs2|" in x)
    h, v = s_h["peak_aabs_mps2"][1], s_v["peak_aabs_mps2"][1]
    assert (
        f"{h:.6g}; {h:.6g} [+0 (+0.00 %)]; {v:.6g} [{v - h:+.3g} "
        f"({100 * (v - h) / h:+.2f} %)]" in line
    )


@pytest.mark.parametrize(
    "args,words",
    [
        (["run", "bad.nml"], ["bad.nml", "&model", "mass(2)", "-2.53"]),
        (["run", "nosuch.nml"], ["nosuch.nml", "does not exist"]),
        (["plot", "nosuch.csv"], ["nosuch.csv", "no such file"]),
        (["plot", "bad.nml.txt"], ["bad.nml.txt", "expected"]),
        (["compare", "bad.nml", "bad.nml"], ["&model", "mass(2)"]),
    ],
    ids=["bad deck", "missing deck", "missing result", "unknown file type", "compare bad deck"],
)
def test_cli_errors_are_one_clean_line(args, words, tmp_path):
    text = (INPUTS / "test4_velocity.nml").read_text().replace("6.301, 2.530", "6.301, -2.53")
    (tmp_path / "bad.nml").write_text(text)
    (tmp_path / "bad.nml.txt").write_text(text)
    r = cli(*args, cwd=tmp_path)
    assert r.returncode == 1
    assert r.stdout == ""
    assert "Traceback" not in r.stderr
    lines = r.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("frictiondyn: error: ")
    for w in words:
        assert w in lines[0], lines[0]
    assert not (tmp_path / "out").exists()  # nothing written for a rejected deck


def test_cli_paper_reproduces_table1_and_writes_the_figures(tmp_path):
    r = cli("paper", "paper_out", cwd=tmp_path)
    assert r.returncode == 0, r.stderr
    out = tmp_path / "paper_out"
    figures = ["fig2", "fig3a", "fig3b", "fig4a", "fig4b", "table1"]
    assert announced(r.stdout, "figure") == [f"paper_out/{f}.png" for f in figures]
    assert all(is_png(out / f"{f}.png") for f in figures)
    assert announced(r.stdout, "report") == ["paper_out/report.md"]
    report = (out / "report.md").read_text()
    rows = re.findall(
        r"^\| (\d) \| [\d.]+ \| [\d.]+ \| (velocity|hysteretic) \| ([a-z -]+) \|", report, re.M
    )
    got = {(int(t), law): cls for t, law, cls in rows}
    assert got == {
        (t, law): PAPER_OBSERVATION[t] for t in TABLE1 for law in ("velocity", "hysteretic")
    }
    assert "All 10 runs agree with the paper: **yes**" in report
    # Fig. 3: the coarse deck's violations and reversals, none in the corrected run
    m = re.search(
        r"coarse run leaves (\d+) correctness violations .* and (\d+) slip reversals", report
    )
    assert m and int(m.group(1)) == FIG3_VIOLATIONS and int(m.group(2)) == FIG3_REVERSALS
    assert "The corrected run: 0 violations, 0 slip reversals" in report
    # Fig. 4: the two laws' steady-state peaks agree within 3 % (measured 0.34 % and 1.74 %)
    diffs = re.findall(r"\| (?:upper|lower) \(m\d\) \| [\d.]+ \| [\d.]+ \| ([+-][\d.]+) %", report)
    assert len(diffs) == 2 and all(abs(float(d)) < 3 for d in diffs)


def test_the_default_plots_are_the_key_ones(tmp_path):
    """run --plot writes the key set: the roof's acceleration, the hysteresis of the device
    whose peak force is largest, and with storeys the profiles and the base shear; --plots
    chooses kinds; an unknown kind is a usage error naming the kinds."""
    shutil.copy(INPUTS / "building5_friction.nml", tmp_path)
    shutil.copy(INPUTS / "synthetic_pga035.AT2", tmp_path)
    deck = (tmp_path / "building5_friction.nml").read_text()
    (tmp_path / "building5_friction.nml").write_text(deck.replace(
        "&excitation", "&storeys\n  n_storeys = 5, node_i = 1, 2, 3, 4, 5, node_j = 0, 1, 2, 3, 4\n/\n"
        "&excitation\n  duration = 3.0"))
    r = cli("run", "building5_friction.nml", "--plot", "--dpi", "60", cwd=tmp_path)
    assert r.returncode == 0, r.stderr
    summ = json.loads((tmp_path / "out/building5_friction.summary.json").read_text())
    top = 1 + max(range(5), key=lambda d: summ["peak_force_N"][d])
    assert announced(r.stdout, "plot") == [
        "out/building5_friction_aabs5.png", f"out/building5_friction_hysteresis{top}.png",
        "out/building5_friction_drift_profile.png",
        "out/building5_friction_acceleration_profile.png",
        "out/building5_friction_base_shear.png"]
    r = cli("plot", "out/building5_friction.csv", "--plots", "phase,storey_loop", "--dpi", "60",
            cwd=tmp_path)
    assert r.returncode == 0, r.stderr
    pngs = announced(r.stdout, "plot")
    assert len(pngs) == 5 + 5 and pngs[0].endswith("_phase1.png")
    r = cli("plot", "out/building5_friction.csv", "--plots", "spin", cwd=tmp_path)
    assert r.returncode == 1 and "not a plot kind (spin)" in r.stderr
    r = cli("plot", "out/building5_friction.csv", "--plots", "orbit", cwd=tmp_path)
    assert r.returncode == 1 and "not a building of rigid floors" in r.stderr


def _num(x: float) -> str:
    """The executable's screen format: four significant digits, fixed from 0.01 to 1e5."""
    if x == 0.0:
        return "0"
    if 0.01 <= abs(x) < 1e5:
        return f"{x:.{max(0, 3 - int(np.floor(np.log10(abs(x)))))}f}"
    return f"{x:.3E}"


def test_the_executables_screen_summary_shows_periods_drifts_and_shears(tmp_path):
    """inputs/building5_dampers.nml (storeys with heights) for 1 s: the screen shows the first
    three periods of the stuck and the free system, each storey's peak drift with its drift
    ratio and its peak shear, the peak base shear and its time, and each device's dissipated
    energy and slip travel: the summary's values, and never a period printed as .000000."""
    text = (INPUTS / "building5_dampers.nml").read_text()
    text = text.replace("record_file = 'synthetic_pga035.AT2'", f"record_file = '{INPUTS / 'synthetic_pga035.AT2'}'")
    text = text.replace("duration = 30.0", "duration = 1.0")
    (tmp_path / "b.nml").write_text(text)
    exe = frictiondyn.run_executable("b.nml", cwd=tmp_path)
    s = exe.summary()
    out = subprocess.run([frictiondyn.executable(), "b.nml"], cwd=tmp_path, capture_output=True,
                         text=True, check=True).stdout
    stuck = ", ".join(_num(t) for t in s["periods_stuck_s"][:3])
    free = ", ".join(_num(t) for t in s["periods_free_s"][:3])
    assert f"  periods: stuck {stuck} s; free {free} s\n" in out
    assert stuck.startswith("0.4478") and free.startswith("0.6332")
    for i in range(5):
        drift, ratio, shear = s["peak_drift_m"][i], s["peak_drift_ratio"][i], s["peak_storey_shear_N"][i]
        assert (f"  storey {i + 1}: peak drift {_num(drift)} m ({_num(100 * ratio)} %), "
                f"peak shear {_num(shear)} N\n") in out
        e, travel = s["dissipated_energy_J"][i], s["slip_travel_m"][i]
        assert f", dissipated {_num(e)} J, slip travel {_num(travel)} m\n" in out
    assert (f"  base shear: peak {_num(s['peak_base_shear_N'])} N at t = "
            f"{_num(s['peak_base_shear_time_s'])} s\n") in out
    assert "rigid-link period not defined" in out and ".000000" not in out
