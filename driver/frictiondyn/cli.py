"""The command line: ``python -m frictiondyn run | plot | compare | paper``.

- ``run DECK [--plot] [--out DIR] [--quiet]``: run a deck through the extension and write its
  history CSV and summary JSON with the library's writer, exactly as the ``frictiondyn``
  executable does (same files, same format, the history written as the run goes), into the
  deck's ``&output`` directory or ``--out``; a progress bar on a terminal (not with
  ``--quiet``); Ctrl-C stops the run and leaves no output.
- ``plot RESULT``: PNGs of a result (a CSV written by ``run`` or the executable, or a .npz
  from ``Result.to_npz``), next to it or in ``--out``.
- ``compare A B [...]``: overlay two or more results (CSV, .npz, or decks, which are run)
  and print the differences of their peaks.
- ``converge DECK [--factor F] [--levels L] [--rtol R] [--no-law] [--json FILE]``: a
  time-step convergence study: the deck at n1, F·n1, F²·n1 side by side (and a regularized
  law's eps or f refined); prints what moves and each kind of quantity's estimated error with
  its method; exit status 3 when a change or an estimated error exceeds the tolerance
  (``frictiondyn.convergence``).
- ``paper OUTDIR``: the paper's Table 1 classification and Figs. 2, 3a, 3b, 4a, 4b.
- ``sweep SPEC.toml`` / ``sweep collect DIR`` / ``sweep plot DIR X Y``: parameter sweeps,
  locally or as a Slurm job array (``frictiondyn.sweep``, docs/batch.md).

Errors print one line ``frictiondyn: error: ...`` on standard error and exit with status 1.
"""

from __future__ import annotations

import argparse
import json
import os
import sys
import warnings
from collections.abc import Sequence
from pathlib import Path

from . import __version__
from ._api import FrictiondynError, FrictiondynWarning, Result, Session, _summary_path, run, summary_warnings

__all__ = ["load_result", "main"]


class CliError(Exception):
    """A problem with the command line's input; printed as one line, exit status 1."""


# ---------------------------------------------------------------------------------------
# Reading results
# ---------------------------------------------------------------------------------------


def load_result(path: str | os.PathLike) -> Result:
    """A Result from a history CSV (with its summary JSON when present), a .npz written by
    ``Result.to_npz``, or a deck (.nml, run through the extension)."""
    p = Path(path)
    if not p.exists():
        raise CliError(f"{p}: no such file")
    suffix = p.suffix.lower()
    try:
        if suffix == ".csv":  # its summary when present (plots need none)
            return Result.from_files(p, None if _summary_path(p).exists() else False)
        if suffix == ".npz":
            return Result.from_npz(p)
        if suffix == ".parquet":
            _need_pyarrow(str(p))
            return Result.from_parquet(p)
    except (OSError, ValueError, KeyError) as exc:
        raise CliError(f"{p}: not a frictiondyn result ({exc})") from None
    if suffix in (".nml", ".namelist", ".in"):
        return run(p)
    raise CliError(f"{p}: expected a history .csv, a .npz, a .parquet or a deck .nml")


def _need_pyarrow(what: str) -> None:
    """Parquet needs pyarrow, an optional dependency: a CliError saying so when it is missing."""
    try:
        import pyarrow  # noqa: F401
    except ImportError:
        raise CliError(f"{what}: Parquet needs pyarrow: pip install frictiondyn[parquet]") from None


def _stem(path: Path) -> str:
    return path.name.rsplit(".", 1)[0] if "." in path.name else path.name


# ---------------------------------------------------------------------------------------
# Commands
# ---------------------------------------------------------------------------------------


def _print_summary(result: Result, deck: str) -> None:
    s = result.summary
    print(f"frictiondyn: {deck}")
    period = s.get("period_stuck_s")
    stuck = (f"rigid-link period {period:.6g} s" if period
             else "rigid-link period not defined (with every device a rigid link the structure has no free DOF "
                  "or a rigid-body mode)")
    print(
        f"  {stuck}; steps dt1 {s['steps_dt1']}, nested {s.get('steps_nested', 0)}, dt2 {s['steps_dt2']}, "
        f"finer {s['steps_finer']}"
    )
    if s.get("steps_implicit", 0) + s.get("implicit_fallbacks", 0) > 0:
        print(
            f"  implicit phases: {s['steps_implicit']} dt1 steps settled ({s['implicit_redos']} trials "
            f"redone), {s['implicit_fallbacks']} refined as the paper's"
        )
    laws = s.get("device_law", [])
    for d in range(result.n_devices):
        law = f" ({laws[d]})" if d < len(laws) else ""
        print(
            f"  device {d + 1}{law}: stick->slip {s['stick_to_slip'][d]}, "
            f"slip->stick {s['slip_to_stick'][d]}, slip reversals {s['slip_reversals'][d]}, "
            f"peak |F| {s['peak_force_N'][d]:.6g} N"
        )
    for i in range(result.n_dof):
        print(
            f"  dof {i + 1}: peak |u| {s['peak_u_m'][i]:.6g} m, "
            f"peak |a_abs| {s['peak_aabs_mps2'][i]:.6g} m/s2"
        )
    storeys = result.storey_labels
    for k in range(result.n_storeys):
        height = (s.get("storey_height_m") or [0.0] * result.n_storeys)[k]
        ratio = (s.get("peak_drift_ratio") or [0.0] * result.n_storeys)[k]
        extra = f" ({100 * ratio:.3g} %)" if height > 0 else ""
        print(
            f"  {storeys[k]}: peak drift {s['peak_drift_m'][k]:.6g} m{extra}, residual "
            f"{s['residual_drift_m'][k]:.3g} m, peak shear {s['peak_storey_shear_N'][k]:.6g} N"
        )
    if "peak_base_shear_N" in s:
        print(f"  peak base shear {s['peak_base_shear_N']:.6g} N")
    print(f"  correctness violations: {s['correctness_violations']}")
    for message in summary_warnings(s):
        print(f"frictiondyn: warning: {message}", file=sys.stderr)


def _trange(value: Sequence[float] | None) -> tuple[float, float] | None:
    if value is None:
        return None
    t0, t1 = float(value[0]), float(value[1])
    if not t1 > t0:
        raise CliError(f"--t-range {t0:g} {t1:g}: the end must be after the start")
    return t0, t1


class _ProgressBar:
    """A progress bar in seconds of simulated time on standard error, when it is a terminal
    (nothing in a pipe or a batch log); the solve's progress callback."""

    def __init__(self, enabled: bool) -> None:
        self.bar = None
        self.enabled = enabled

    def __call__(self, t: float, duration: float) -> None:
        if not self.enabled:
            return
        if self.bar is None:
            import shutil

            from tqdm import tqdm

            width = shutil.get_terminal_size((80, 24)).columns or 80  # 0 on a bare pty
            self.bar = tqdm(
                total=duration, unit="s", unit_scale=False, leave=False, file=sys.stderr,
                ncols=width,
                bar_format="{desc}{percentage:3.0f}%|{bar}| t = {n:.2f} of {total:.2f} s "
                "[{elapsed}<{remaining}]", desc="frictiondyn: ",
            )
        self.bar.n = min(t, duration)
        self.bar.refresh()

    def close(self) -> None:
        if self.bar is not None:
            self.bar.close()


def _tolerance_outputs(args: argparse.Namespace) -> tuple[Result, Path | None, Path]:
    """A tolerance run: the chosen run written as the executable writes one, its summary with
    the estimated errors and what was chosen, and the SHA-256 of the deck given (the run chosen
    is of a deck written from it; the summary rewritten whole, then renamed)."""
    from .tolerance import tolerance_run

    result, report, session = tolerance_run(args.deck, args.tolerance, args.tolerance_floor)
    with session:
        csv, summ = session.write(args.out)
    data = json.loads(summ.read_text())
    data.update({k: result.summary[k]
                 for k in ("estimated_error", "estimate_method", "tolerance_run", "deck_sha256")})
    temp = summ.with_name(summ.name + ".tolerance.tmp")
    temp.write_text(json.dumps(data, indent=2) + "\n")
    os.replace(temp, summ)
    print(str(report))
    return result, csv, summ


def cmd_run(args: argparse.Namespace) -> int:
    trange = _trange(args.t_range)
    from .plots import plot_kinds

    kinds = plot_kinds(args.plots)
    if args.parquet:  # before the run: nothing is written when it cannot be
        _need_pyarrow("--parquet")
    if args.tolerance is not None or args.tolerance_floor is not None or _asks_tolerance(args.deck):
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", FrictiondynWarning)
            result, csv, summ = _tolerance_outputs(args)
    else:
        bar = _ProgressBar(sys.stderr.isatty() and not args.quiet)
        with Session(args.deck) as session:  # the deck is read once; the library writes
            # the history goes to its file as the run goes (memory does not grow with the
            # duration); it is also kept in memory only for the plots
            session.stream(args.out)
            try:
                session.solve(progress=bar, history=args.plot or args.parquet)
            finally:
                bar.close()
            with warnings.catch_warnings():  # _print_summary prints them, as the executable does
                warnings.simplefilter("ignore", FrictiondynWarning)
                result = session.result()
            csv, summ = session.write()
    _print_summary(result, args.deck)
    if csv is not None:
        print(f"  history: {csv}")
    if args.parquet:
        stem = summ.name[: -len(".summary.json")]
        print(f"  history: {result.to_parquet(summ.parent / (stem + '.parquet'))}")
    print(f"  summary: {summ}")
    _plots(args, result, summ, trange, kinds)
    return 0


def _asks_tolerance(deck: str) -> bool:
    """Whether a deck gives &integration tolerance (the library refuses it as one setting)."""
    try:
        Session(deck).close()
    except FrictiondynError as exc:
        return "is a tolerance run" in str(exc)
    return False


def _plots(args: argparse.Namespace, result: Result, summ: Path, trange, kinds) -> None:
    if args.plot:
        from . import plots

        for p in plots.plot_all(
            result,
            summ.parent,
            summ.name[: -len(".summary.json")],
            t_range=trange,
            units=args.units,
            dpi=args.dpi,
            kinds=kinds,
        ):
            print(f"  plot: {p}")


def cmd_plot(args: argparse.Namespace) -> int:
    from . import plots

    path = Path(args.result)
    trange = _trange(args.t_range)
    kinds = plots.plot_kinds(args.plots)
    result = load_result(path)
    directory = Path(args.out) if args.out else path.parent
    directory.mkdir(parents=True, exist_ok=True)
    for p in plots.plot_all(
        result, directory, _stem(path), t_range=trange, units=args.units, dpi=args.dpi,
        kinds=kinds,
    ):
        print(f"plot: {p}")
    return 0


def _peak_rows(
    results: list[Result], t_range: tuple[float, float] | None
) -> list[tuple[str, str, list[float]]]:
    """(quantity, unit, peak of each result). Without a time range the summaries' peaks
    (over every accepted step) are used when all results have them."""
    from .plots import window

    n_dof = min(r.n_dof for r in results)
    n_dev = min(r.n_devices for r in results)
    use_summary = t_range is None and all("peak_aabs_mps2" in r.summary for r in results)
    rows = []
    for col, key, count in (
        ("aabs", "peak_aabs_mps2", n_dof),
        ("u", "peak_u_m", n_dof),
        ("F", "peak_force_N", n_dev),
        ("s", "peak_s_m", n_dev),
    ):
        for k in range(1, count + 1):
            name = f"{col}{k}"
            if use_summary:
                vals = [float(r.summary[key][k - 1]) for r in results]
            else:
                vals = [float(abs(r[name][window(r, t_range)]).max()) for r in results]
            unit = results[0].units.get(name, "")
            rows.append((name, unit, vals))
    return rows


def cmd_compare(args: argparse.Namespace) -> int:
    from . import plots

    paths = [Path(p) for p in args.results]
    labels = args.labels if args.labels else [_stem(p) for p in paths]
    if len(labels) != len(paths):
        raise CliError(f"--labels gives {len(labels)} names for {len(paths)} results")
    if len(set(labels)) < len(labels):
        labels = [f"{i + 1}: {x}" for i, x in enumerate(labels)]
    trange = _trange(args.t_range)
    results = [load_result(p) for p in paths]
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    if min(r.n_dof for r in results) != max(r.n_dof for r in results):
        print(
            "frictiondyn: warning: the results have different numbers of DOFs; comparing "
            "the common ones",
            file=sys.stderr,
        )
    written = [out / f"{args.name}.png"]
    kw = {"t_range": trange, "labels": labels, "units": args.units, "dpi": args.dpi}
    plots.plot_compare(results, written[0], **kw)
    for i in range(1, min(min(r.n_dof for r in results), 10) + 1):
        written.append(out / f"{args.name}_aabs{i}.png")
        plots.plot_acceleration(results, i, written[-1], **kw)
    for d in range(1, min(min(r.n_devices for r in results), 10) + 1):
        written.append(out / f"{args.name}_hysteresis{d}.png")
        plots.plot_hysteresis(results, d, written[-1], **kw)
    if all(r.n_storeys and "drift1" in r for r in results):
        for kind, func in (
            ("drift_profile", plots.plot_drift_profile),
            ("acceleration_profile", plots.plot_acceleration_profile),
        ):
            written.append(out / f"{args.name}_{kind}.png")
            func(results, written[-1], labels=labels, units=args.units, dpi=args.dpi)
    where = "whole run" if trange is None else f"t = {trange[0]:g} ... {trange[1]:g} s"
    print(f"peaks ({where}); difference relative to {labels[0]}:")
    for i, lab in enumerate(labels):
        print(f"  [{i + 1}] {lab}")
    for name, unit, vals in _peak_rows(results, trange):
        ref = vals[0]
        cells = [f"{vals[0]:.6g}"]
        for v in vals[1:]:
            rel = f" ({100 * (v - ref) / ref:+.2f} %)" if ref != 0 else ""
            cells.append(f"{v:.6g} [{v - ref:+.3g}{rel}]")
        print(f"  peak |{name}| [{unit}]: " + "; ".join(cells))
    for p in written:
        print(f"plot: {p}")
    return 0


def cmd_converge(args: argparse.Namespace) -> int:
    from .convergence import step_convergence

    target = Path(args.json) if args.json else None
    if target is not None and not target.parent.is_dir():  # before the study, not after it
        raise CliError(f"--json {target}: its directory {target.parent} does not exist")
    report = step_convergence(
        args.deck, factor=args.factor, levels=args.levels, rtol=args.rtol, threads=args.threads,
        law=not args.no_law,
    )
    print(report)
    if target is not None:
        tmp = target.with_name(f".{target.name}.{os.getpid()}.tmp")
        try:
            tmp.write_text(json.dumps(report.to_dict(), indent=1) + "\n")
            os.replace(tmp, target)
        finally:
            tmp.unlink(missing_ok=True)
        print(f"  report: {target}")
    return 0 if report.converged else 3


def cmd_paper(args: argparse.Namespace) -> int:
    from .paper import reproduce

    rep = reproduce(args.outdir, progress=not args.quiet)
    print("Table 1, steady state (last 10 cycles):")
    for s in rep.table:
        mark = "agrees" if s.agrees else "DIFFERS"
        print(f"  test {s.test} {s.law:<10}: {s.classification:<12} (paper: {s.paper}) {mark}")
    n = rep.numbers
    print(
        f"Fig. 3: coarse deck {int(n['coarse.correctness_violations'])} correctness "
        f"violations, {int(n['coarse.slip_reversals'])} slip reversals; corrected "
        f"{int(n['hysteretic.correctness_violations'])} and "
        f"{int(n['hysteretic.slip_reversals'])}"
    )
    print(
        f"Fig. 4: steady-state peak |a_abs| hysteretic vs velocity: upper "
        f"{100 * n['fig4.peak_aabs1_rel_diff']:+.2f} %, lower "
        f"{100 * n['fig4.peak_aabs2_rel_diff']:+.2f} %"
    )
    for p in rep.figures.values():
        print(f"figure: {p}")
    print(f"report: {rep.report}")
    return 0


def cmd_spectrum(args: argparse.Namespace) -> int:
    import numpy as np

    from .spectrum import G, default_periods, plot_spectra, response_spectrum

    periods = default_periods()
    if args.periods is not None:
        t0, t1, n = args.periods
        if not (0 < t0 < t1) or int(n) < 2:
            raise ValueError("--periods T0 T1 N needs 0 < T0 < T1 and N >= 2")
        periods = np.concatenate([[0.0], np.logspace(np.log10(t0), np.log10(t1), int(n))])
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    spectra = []
    for source in args.sources:
        s = response_spectrum(source, periods=periods, xi=args.xi, format=args.format,
                              units=args.record_units, scale=args.scale, dt=args.dt, kind=args.kind)
        spectra.append(s)
        csv_path = s.to_csv(out / (Path(source).stem + ".spectrum.csv"))
        k = int(np.argmax(s.psa))
        print(f"{source}: PGA {s.psa[0] / G:.4g} g; PSA peaks at {s.psa[k] / G:.4g} g, "
              f"T = {s.periods[k]:.4g} s (xi = {s.xi:g})")
        print(f"  spectrum: {csv_path}")
    if args.plot:
        png = plot_spectra(spectra, out / (args.name + ".png"), dpi=args.dpi or 150)
        print(f"  plot: {png}")
    return 0



def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="python -m frictiondyn",
        description="Dynamic analysis of structures with friction devices.",
    )
    parser.add_argument("--version", action="version", version=f"frictiondyn {__version__}")
    sub = parser.add_subparsers(dest="command", required=True, metavar="COMMAND")

    trange = {
        "nargs": 2,
        "type": float,
        "metavar": ("T0", "T1"),
        "help": "plot only t0 <= t <= t1 [s] (default: the last 5 cycles of a harmonic run, "
        "the whole of any other)",
    }
    units = {
        "metavar": "UNITS",
        "help": "units of the plots, e.g. mm,kN,g (length m/cm/mm, force N/kN/MN, "
        "acceleration m/s2/cm/s2/g, velocity m/s/cm/s/mm/s; default SI)",
    }
    dpi = {"type": int, "default": None, "help": "resolution of the PNGs (default 150; 300 for a report)"}
    which = {
        "metavar": "SET",
        "help": "which PNGs: 'key' (default: the roof's acceleration, the hysteresis of the most "
        "loaded device, with storeys the drift and acceleration profiles and the base shear, with "
        "rigid floors the roof's orbit and the braces in plan), 'all', or kinds separated by "
        "commas: aabs, sdot, hysteresis, phase, drift_profile, acceleration_profile, storey_loop, "
        "base_shear, orbit, device_plan",
    }
    p = sub.add_parser("run", help="run a deck; write its history CSV and summary JSON")
    p.add_argument("deck", help="namelist deck (.nml)")
    p.add_argument(
        "--out", metavar="DIR", help="output directory (default: the deck's &output dir)"
    )
    p.add_argument("--plot", action="store_true", help="also write PNGs next to the outputs")
    p.add_argument("--parquet", action="store_true",
                   help="also write the history as <name>.parquet (needs pyarrow: "
                   "frictiondyn[parquet]); with &output write_history = .false. instead of the CSV")
    p.add_argument("--plots", **which)
    p.add_argument("--t-range", **trange)
    p.add_argument("--quiet", action="store_true", help="no progress bar")
    p.add_argument("--units", **units)
    p.add_argument("--dpi", **dpi)
    p.add_argument(
        "--tolerance", type=float, metavar="T",
        help="a tolerance run: the technique and its steps chosen and refined until the estimated "
        "error of every peak is below T (relative; docs/namelist.md, &integration tolerance)",
    )
    p.add_argument(
        "--tolerance-floor", type=float, metavar="F",
        help="a peak is judged against at least F times the largest of its kind (default 0.01)",
    )
    p.set_defaults(func=cmd_run)

    p = sub.add_parser("plot", help="PNGs of a result (.csv, .npz or .parquet)")
    p.add_argument("result", help="history CSV (with its .summary.json), .npz or .parquet")
    p.add_argument("--out", metavar="DIR", help="where the PNGs go (default: next to RESULT)")
    p.add_argument("--plots", **which)
    p.add_argument("--t-range", **trange)
    p.add_argument("--units", **units)
    p.add_argument("--dpi", **dpi)
    p.set_defaults(func=cmd_plot)

    p = sub.add_parser("compare", help="overlay two or more results; print peak differences")
    p.add_argument("results", nargs="+", metavar="RESULT", help=".csv, .npz, .parquet or deck .nml")
    p.add_argument("--out", metavar="DIR", default=".", help="where the PNGs go (default: .)")
    p.add_argument("--name", default="compare", help="base name of the PNGs (default: compare)")
    p.add_argument("--labels", nargs="+", metavar="LABEL", help="legend names, one per result")
    p.add_argument("--t-range", **trange)
    p.add_argument("--units", **units)
    p.add_argument("--dpi", **dpi)
    p.set_defaults(func=cmd_compare)

    p = sub.add_parser(
        "converge", help="time-step convergence study: the deck at n1, 2 n1, ...; exit 3 if it moves"
    )
    p.add_argument("deck", help="namelist deck (.nml)")
    p.add_argument("--factor", type=int, default=2, help="n1 grows by this each level (default 2)")
    p.add_argument(
        "--levels", type=int, default=2,
        help="finer runs (default 2: n1, factor n1 and factor^2 n1, from which the order is measured)",
    )
    p.add_argument(
        "--rtol", type=float, default=0.01,
        help="largest change allowed between levels, relative (default 0.01)",
    )
    p.add_argument(
        "--no-law", action="store_true",
        help="do not refine a regularized law's eps or f (estimate the step's error alone)",
    )
    p.add_argument("--json", metavar="FILE", help="also write the whole comparison as JSON")
    p.add_argument(
        "--threads", type=int, default=None,
        help="levels run side by side (default: the levels, at most the CPUs available)",
    )
    p.set_defaults(func=cmd_converge)

    p = sub.add_parser("paper", help="recompute the paper's Table 1 and Figs. 2, 3, 4")
    p.add_argument("outdir", help="directory for the PNGs and report.md")
    p.add_argument("--quiet", action="store_true", help="no progress bar")
    p.set_defaults(func=cmd_paper)

    p = sub.add_parser(
        "spectrum", help="elastic response spectra of records (or of decks' table motions)"
    )
    p.add_argument("sources", nargs="+", metavar="RECORD", help="record file (.AT2, ...) or deck .nml")
    p.add_argument("--xi", type=float, default=0.05, help="damping ratio (default 0.05)")
    p.add_argument("--periods", nargs=3, type=float, metavar=("T0", "T1", "N"),
                   help="N periods from T0 to T1 [s], log-spaced, and T = 0 (default 0.01..10 s, 120)")
    p.add_argument("--format", default="auto", help="record_format: auto, at2, values, time_value")
    p.add_argument("--record-units", metavar="UNITS", help="record_units (default: the file's, or m/s2)")
    p.add_argument("--scale", type=float, default=1.0, help="record_scale (default 1)")
    p.add_argument("--dt", type=float, help="dt_record [s] (required but for AT2)")
    p.add_argument("--kind", default="acceleration", help="record_kind: acceleration or displacement")
    p.add_argument("--out", metavar="DIR", default=".", help="where the CSVs and the plot go (default: .)")
    p.add_argument("--plot", action="store_true", help="also plot PSA [g] against T")
    p.add_argument("--name", default="spectrum", help="base name of the plot (default: spectrum)")
    p.add_argument("--dpi", **dpi)
    p.set_defaults(func=cmd_spectrum)

    from .sweep import add_parser as add_sweep_parser

    add_sweep_parser(sub)
    return parser


def _one_line(exc: BaseException) -> str:
    text = str(exc.args[0]) if isinstance(exc, KeyError) and exc.args else str(exc)
    text = " ".join(text.split())
    return text or type(exc).__name__


def main(argv: Sequence[str] | None = None) -> int:
    """Run the command line; return the exit status (0 success, 1 error, 2 usage)."""
    argv = list(sys.argv[1:] if argv is None else argv)
    if argv[:1] == ["sweep"]:  # its own command line (frictiondyn.sweep.main)
        from .sweep import main as sweep_main

        args = argparse.Namespace(command="sweep", func=lambda a: sweep_main(argv[1:]))
    else:
        args = build_parser().parse_args(argv)
    if args.command == "compare" and len(args.results) < 2:
        print("frictiondyn: error: compare needs two or more results", file=sys.stderr)
        return 1
    try:
        return int(args.func(args))
    except BrokenPipeError:  # output piped into e.g. head: stop quietly
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        return 1
    except (FrictiondynError, CliError, OSError, ValueError, KeyError, MemoryError) as exc:
        print(f"frictiondyn: error: {_one_line(exc)}", file=sys.stderr)
        return 1
    except KeyboardInterrupt:
        print("frictiondyn: interrupted", file=sys.stderr)
        return 130
