"""Command line: ``cushion-clutch <command>``. Only this module prints."""
from __future__ import annotations

import argparse
import contextlib
import logging
import sys
import threading
import time
from pathlib import Path

from .data import DEFAULT_TABLES, tables_root
from .errors import (CalculixNotFoundError, ClusterError, FmuError, ParameterError, RunInterrupted, SweepError,
                     TableError)


def _guard_out(out: Path, force: bool) -> Path:
    """Refuse an output folder inside the shipped table sets unless ``--force``."""
    if not force and out.resolve().is_relative_to(tables_root().resolve()):
        raise ParameterError([f"--out {out} is inside the table sets shipped with cushion-clutch; give "
                              "another --out, or --force to overwrite them"])
    return out


def _fmu_arg(args: argparse.Namespace, stage: Path) -> Path:
    """The checked ``--fmu``, or an FMU built from ``--tables`` into the output stage."""
    from .fmu.build import build_fmu
    from .fmu.check import check_fmu
    if args.fmu:
        return check_fmu(args.fmu)
    _check_tables(args.tables)
    with _slow_notice(ZIG_NOTICE):
        return build_fmu(Path(args.tables), stage / "CushionClutch.fmu", backend=args.backend)


def _ssp_arg(args: argparse.Namespace) -> Path | None:
    """``--fmu`` if it names an SSP archive (``.ssp``); a ``--parameter-set`` without one is refused."""
    fmu = getattr(args, "fmu", None)
    if fmu and Path(fmu).suffix.lower() == ".ssp":
        return Path(fmu)
    if getattr(args, "parameter_set", None):
        raise ParameterError([f"--parameter-set {args.parameter_set}: needs --fmu with an .ssp archive "
                              "(cushion-clutch export-ssp writes one)"])
    return None


def _sweep(args: argparse.Namespace) -> int:
    from rich.progress import BarColumn, Progress, TextColumn, TimeElapsedColumn

    from .fe.params import load_params
    from .fe.plots import plot_force_deflection, plot_kiss_shift
    from .fe.sweep import build_tables, run_sweep
    from .model.table_format import read_tables

    params = load_params(args.spring)
    if args.mesh_size is not None:
        params = params.replace(mesh={"element_size_m": args.mesh_size})
    out = _guard_out(Path(args.out) if args.out else Path("lookup_tables") / params.name, args.force)
    args.resume_hint = (f"finished cases are kept in {Path(args.cache) / params.name}; run the same "
                        "command again to resume from them")
    from .outputs import check_writable
    check_writable(out)                                     # before any ccx run
    expected = params.solver.compression_increments + 8
    start = time.perf_counter()
    with Progress(TextColumn("{task.description}"), BarColumn(), TextColumn("{task.fields[status]}"),
                  TimeElapsedColumn()) as bar:
        tasks = {t: bar.add_task(f"θ = {t:>5g} °C", total=expected, status="queued")
                 for t in params.sweep.temperatures_degC}

        def progress(theta: float, event: str, value: float) -> None:
            task = tasks[theta]
            if event == "increment":
                bar.update(task, completed=min(value, expected), status=f"increment {int(value)}")
            elif event == "start":
                bar.update(task, status="running ccx")
            elif event == "done":
                bar.update(task, completed=expected, status="done")
            elif event == "failed":
                bar.update(task, status="[red]failed")

        outcomes = run_sweep(params, cache_dir=Path(args.cache), jobs=args.jobs,
                             scheduler=args.scheduler, progress=progress)
    wall = time.perf_counter() - start
    from .outputs import OutputSet
    with OutputSet(out, "tables") as stage:                 # the table set lands whole or not at all
        curves, shifts = build_tables(params, outcomes, stage, wall_time_s=wall)
        tables = read_tables(stage)
        plot_force_deflection(tables, stage / "force_deflection.png", f"Spring '{params.name}' (CalculiX)")
        plot_kiss_shift(tables, stage / "kiss_point.png")
    print(f"tables written to {out} in {wall:.1f} s (mesh {params.mesh.element_size_m * 1e3:g} mm)")
    prog, crest = tables.metadata["progressivity"], tables.metadata["kiss_point"]
    print(f"{'theta [degC]':>12} {'delta_kiss [mm]':>15} {'crest growth [mm]':>18} {'F full [N]':>10} "
          f"{'k20/k50/k90 [kN/mm]':>20} {'k90/k20':>8} {'increments':>10}")      # 99 columns
    for c in curves:
        o, k = outcomes[c.theta_degC], prog[f"{c.theta_degC:g}"]
        ks = "/".join(f"{k[n] / 1e6:.2f}" for n in ("k20_N_per_m", "k50_N_per_m", "k90_N_per_m"))
        print(f"{c.theta_degC:>12g} {shifts[c.theta_degC] * 1e3:>15.4f} "
              f"{crest[f'{c.theta_degC:g}']['crest_growth_m'] * 1e3:>18.4f} {c.force_N[-1]:>10.0f} "
              f"{ks:>20} {k['k90_over_k20']:>8.2f} {o.stats.increments:>10d}")
    return 0


def _calibrate(args: argparse.Namespace) -> int:
    from .fe.studies.calibrate import calibrate, parse_bounds
    from .fe.studies.calibration_report import calibrated_params, params_toml, plot_calibration, report_text
    from .fe.studies.measured import parse_measured
    from .fe.params import load_params

    params = load_params(args.spring)
    if args.mesh_size is not None:
        params = params.replace(mesh={"element_size_m": args.mesh_size})
    measured = parse_measured(args.measured, args.basis, params.material.reference_temperature_degC)
    out = Path(args.out)
    cal = calibrate(params, measured, [n.strip() for n in args.fit.split(",") if n.strip()],
                    parse_bounds(args.bounds), cache_dir=Path(args.cache), jobs=args.jobs,
                    scheduler=args.scheduler, mesh_check=not args.no_mesh_check,
                    on_case=lambda n: print(f"FE case {n} done", file=sys.stderr, flush=True))
    report = report_text(cal)
    result = calibrated_params(cal, args.name or f"{params.name}_calibrated")
    out.parent.mkdir(parents=True, exist_ok=True)
    out.write_text(params_toml(result, f"calibrated by cushion-clutch calibrate to "
                                       f"{', '.join(m.source for m in measured)}\n" + report), encoding="utf-8")
    out.with_suffix(".txt").write_text(report, encoding="utf-8")
    png = plot_calibration(cal, out.with_suffix(".png"),
                           f"Spring '{params.name}': FE against {', '.join(Path(m.source).name for m in measured)}")
    print(report + f"wrote {out} (spring '{result.name}'), {out.with_suffix('.txt')} and {png}")
    warnings = cal.warnings()
    if warnings:
        print("warning: calibration not to be trusted as is: " + "; ".join(warnings), file=sys.stderr)
    return 0


def _simulate(args: argparse.Namespace) -> int:
    import csv

    from .launch.fleet.engagements import (EngagementCycle, plot_engagements, plot_thermal_step,
                                     plot_torque_characteristic, simulate)
    from .model import ClutchParameters, load_table
    from .outputs import OutputSet

    out = _guard_out(Path(args.out), args.force)
    ssp = _ssp_arg(args)
    if not ssp:
        _check_tables(args.tables)
        table = load_table(args.tables)
    with OutputSet(out, "simulate") as stage:              # checks --out before the simulation
        starts, p = None, ClutchParameters()
        if ssp:
            from .fmu.ssp import chosen_tables, plant_from_ssp
            fmu, starts = plant_from_ssp(ssp, args.parameter_set, stage / "ssp")
            table = load_table(chosen_tables(fmu, starts, stage / "ssp" / "tables"))
            p = ClutchParameters.from_flat({k: v for k, v in starts.items() if k in ClutchParameters.RANGES})
            which = f"{fmu.name} of {ssp}, parameter set {args.parameter_set or 'new'}"
        else:
            fmu = _fmu_arg(args, stage)
            which = args.fmu or f"the {args.backend} FMU built from {args.tables}"
        print(f"simulating {args.engagements} engagements with {which} (fmpy, step {args.step:g} s) ...")
        start = time.perf_counter()
        res = simulate(fmu, EngagementCycle(), n_engagements=args.engagements, step_s=args.step, start_values=starts)
        wall = time.perf_counter() - start
        with open(stage / "engagements.csv", "w", newline="") as fh:
            w = csv.writer(fh)
            w.writerow(["time_s", "x_to_m", "theta_cm_K", "torque_Nm", "force_N", "theta_cs_K", "u_f_m",
                        "x_kiss_m"])
            for row in res:
                w.writerow([f"{v:.9g}" for v in row])
        plots = [plot_engagements(res, stage / "engagements.png"),
                 plot_torque_characteristic(table, stage / "torque_characteristic.png", p),
                 plot_thermal_step(stage / "thermal_step_response.png", p)]
    plots = [out / p.name for p in plots]
    period = EngagementCycle().period_s
    print(f"{'engagement':>10} {'theta_cm max [degC]':>20} {'theta_cs max [degC]':>20} "
          f"{'x_kiss min [mm]':>16} {'T max [N.m]':>12}")
    for k in range(args.engagements):
        m = (res["time"] >= k * period) & (res["time"] < (k + 1) * period)
        print(f"{k + 1:>10d} {res['theta_cm'][m].max() - 273.15:>20.1f} "
              f"{res['theta_cs'][m].max() - 273.15:>20.1f} {res['x_kiss'][m].min() * 1e3:>16.4f} "
              f"{res['torque'][m].max():>12.1f}")
    sim_time = res["time"][-1]
    print(f"simulated {sim_time:g} s in {wall:.2f} s wall ({sim_time / wall:.0f}x real time); wrote "
          f"{out / 'engagements.csv'} and " + ", ".join(str(p) for p in plots))
    return 0


def _launch(args: argparse.Namespace) -> int:
    from rich.progress import Progress

    from .fmu.check import check_fmu
    from .model import load_table
    from .launch.plant.build import build_plant_fmu
    from .launch.report import (Provenance, lockup_lines, peak_lines, ratio_line, run_all, series_interval_s,
                                summary_rows, write_outputs)
    from .launch.scenario import load_scenario, scenario_path
    from .launch.tcu.controller import VARIANTS
    from .outputs import OutputSet

    sc = load_scenario(scenario_path(args.scenario))
    out = _guard_out(Path(args.out), args.force)
    ssp = _ssp_arg(args)
    _check_tables(sc.tables_path("tcu") or args.tables)
    table = load_table(sc.tables_path("tcu") or args.tables)     # a scenario may name the TCUs' table set
    prov = Provenance(sc.name, _command_line(args), sc.run.hot_degC)
    output_set = OutputSet(out, "launch", {**prov.as_dict(), "every": args.every})
    plant_start = None
    with output_set as stage:                              # checks --out before the simulation
        if ssp:
            from .fmu.ssp import plant_from_ssp
            fmu, plant_start = plant_from_ssp(ssp, args.parameter_set, stage / "ssp")
            print(f"plant: {fmu.name} of {ssp} with parameter set {args.parameter_set or 'new'}")
        elif args.fmu:
            fmu = check_fmu(args.fmu)
        else:
            _check_tables(args.tables)
            with _slow_notice(ZIG_NOTICE):
                fmu = build_plant_fmu(Path(args.tables), sc, stage / "CushionClutch.fmu", backend=args.backend)
        total = sc.run.duration()
        start = time.perf_counter()
        with Progress(refresh_per_second=2) as bar:        # the bar's thread competes for the GIL
            tasks = {n: bar.add_task(f"{n} TCU", total=total) for n in VARIANTS}
            results = run_all(fmu, sc, table, progress=lambda n, t: bar.update(tasks[n], completed=t),
                              plant_start=plant_start)
            for task in tasks.values():
                bar.update(task, completed=total)
        wall = time.perf_counter() - start
        paths = write_outputs(results, stage, prov, every=args.every)
        size = sum(p.stat().st_size for p in stage.rglob("*") if p.is_file())
        interval = series_interval_s(results, args.every)
        output_set.info.update({"simulation_wall_s": round(wall, 1), "series_interval_s": interval,
                                "bytes_written": size})
    paths = [out / p.relative_to(stage) for p in paths]
    print(launch_terminal_table(summary_rows(results)))
    print()
    print(ratio_line(results, "hot"))
    print(lockup_lines(results))
    print(peak_lines(results))
    for name, res in results.items():
        e = res.energy
        print(f"{name}: energy residual {e.residual():.3g} J of {e.engine_work / 1e3:.1f} kJ; "
              f"{total / res.wall_time_s:.0f}x real time (CPU {total / res.cpu_time_s:.0f}x)")
    every = "every recorded row" if args.every == 1 else f"one recorded row in {args.every} (--every {args.every})"
    print(f"scenario '{sc.name}': {len(results[next(iter(results))].metrics)} launches with {len(results)} TCUs "
          f"simulated in {wall:.1f} s; {len(paths)} files, {_size(size)}, written to {out}")
    print(f"time series launch_<tcu>.csv: {every}, rows at least {interval * 1e3:.0f} ms of simulated time apart")
    print(f"every metric per launch: {out / 'launch_metrics.csv'}")
    print(f"mean and worst per group: {out / 'launch_summary.csv'}")
    return 0


def _command_line(args: argparse.Namespace) -> str:
    """The command as it was typed (``cushion-clutch`` and its arguments), for the outputs' provenance."""
    import shlex
    return shlex.join(["cushion-clutch", *getattr(args, "argv", [])])


def _size(n: int) -> str:
    """A byte count for people: ``812 kB``, ``72.4 MB``."""
    return f"{n / 1e6:.1f} MB" if n >= 1e6 else f"{n / 1e3:.0f} kB"


def _positive_int(text: str) -> int:
    """argparse type: a whole number >= 1."""
    try:
        value = int(text)
    except ValueError:
        value = 0
    if value < 1:
        raise argparse.ArgumentTypeError(f"{text!r}: must be a whole number >= 1")
    return value


#: the launch summary's terminal columns: (summary key, header, format); the rest is in launch_summary.csv
TERMINAL_COLUMNS = (("characteristic_error_max_Nm_worst", "err max", ".2f"),
                    ("characteristic_error_rms_Nm_mean", "err rms", ".2f"),
                    ("tracking_error_rms_Nm_worst", "track rms", ".2f"),
                    ("creep_error_Nm_worst", "creep err", ".2f"),
                    ("theta_cs_error_K_worst", "θ_cs err", ".1f"),
                    ("engagement_time_s_mean", "engage", ".2f"))
TERMINAL_LEGEND = ("err max / err rms: characteristic error (believed - true torque) [N.m], worst max / mean RMS;\n"
                   "track rms: tracking error, worst RMS [N.m]; creep err: worst [N.m]; θ_cs err: worst [K];\n"
                   "engage: mean time to lock-up [s] of the launches that locked up ('-': none did; the lines\n"
                   "'<TCU>: k of n launches locked up' below count them)")


def launch_terminal_table(rows: list[dict], width: int = 100) -> str:
    """The launch summary for a terminal, at most ``width`` columns: per group and TCU the worst (or mean)
    of a few metrics (:data:`TERMINAL_LEGEND`). Every column is in ``launch_summary.csv``."""
    import math

    def cell(v, fmt):
        return "-" if isinstance(v, float) and math.isnan(v) else format(v, fmt)

    head = f"{'launches':<10}{'TCU':<25}{'n':>3}" + "".join(f"{h:>10}" for _, h, _ in TERMINAL_COLUMNS)
    lines = [head[:width], "-" * min(len(head), width)]
    for r in rows:
        line = f"{r['group']:<10}{r['tcu']:<25}{r['n']:>3}" + "".join(
            f"{cell(r.get(k, float('nan')), f):>10}" for k, _, f in TERMINAL_COLUMNS)
        lines.append(line[:width])
    lines.append(TERMINAL_LEGEND)
    return "\n".join(lines)


def _fleet(args: argparse.Namespace) -> int:
    from rich.progress import BarColumn, MofNCompleteColumn, Progress, TextColumn, TimeElapsedColumn, \
        TimeRemainingColumn

    from .launch.fleet.run import PARTS, run_fleet
    from .launch.fleet.population import load_population, population_path

    pop = load_population(population_path(args.population))
    tcus = tuple(t.strip() for t in args.tcus.split(",") if t.strip())
    out = _guard_out(Path(args.out), args.force)
    _check_tables(args.tables)
    args.resume_hint = f"finished samples are kept in {out / PARTS}; run the same command again to resume"
    with Progress(TextColumn("{task.description}"), BarColumn(), MofNCompleteColumn(), TimeElapsedColumn(),
                  TimeRemainingColumn(), refresh_per_second=2) as bar:
        task = bar.add_task(f"fleet '{pop.name}': samples", total=args.samples)
        res = run_fleet(pop, Path(args.tables), out, args.samples, tcus, args.seed, scheduler=args.scheduler,
                        jobs=args.jobs, serial=args.serial, backend=args.backend,
                        progress=lambda done, total: bar.update(task, completed=done))
    print(fleet_terminal_table(res.summary))
    print(f"{res.ran} sample(s) run, {res.kept} kept from an earlier run; {res.launches_run} launches in "
          f"{res.wall_s:.1f} s on {res.workers} worker(s): {res.launches_per_s_per_core:.2f} launches/s per core")
    print(f"{len(res.paths)} files written to {out}: " + ", ".join(p.name for p in res.paths))
    return 0


#: the fleet summary's terminal rows: metrics shown per TCU
FLEET_TERMINAL = ("characteristic_error_max_Nm", "tracking_error_max_Nm", "engagement_time_s", "peak_theta_cm_degC",
                  "stranded")


def fleet_terminal_table(summary: list[dict]) -> str:
    """P50/P95/P99/max per TCU of a few metrics (every metric is in fleet_summary.csv)."""
    import math
    lines = [f"{'TCU':<26}{'metric (worst of a sample)':<30}{'P50':>9}{'P95':>9}{'P99':>9}{'max':>9}"]
    lines.append("-" * len(lines[0]))
    for r in summary:
        if r["metric"] in FLEET_TERMINAL:
            lines.append(f"{r['tcu']:<26}{r['metric']:<30}" + "".join(
                f"{'-' if math.isnan(r[k]) else format(r[k], '.2f'):>9}" for k in ("p50", "p95", "p99", "max")))
    lines.append("stranded: launches of a sample without lock-up, possible and not inhibited")
    return "\n".join(lines)


def _export(args: argparse.Namespace) -> int:
    from .fmu.exports import build, export_mat, export_modelica

    from .model.table_format import read_tables
    from .outputs import OutputSet

    out = _guard_out(Path(args.out), args.force)
    _check_tables(args.tables)
    read_tables(Path(args.tables))                          # a clear TableError first
    data = build(Path(args.tables))                         # the model on every grid, once for both files
    with OutputSet(out, "export") as stage:
        mat = export_mat(data, stage / "cushion_spring_tables.mat")
        mo = export_modelica(data, stage / "cushion_spring_tables.txt")
    mat, mo = out / mat.name, out / mo.name
    print(f"wrote {mat} (Simulink 2-D Lookup Table) and {mo} (Modelica CombiTable2Ds, #1 format)")
    return 0


def _check(args: argparse.Namespace) -> int:
    from .fe.params import DEFAULT_SPRING, load_params
    if args.spring_file and args.spring and Path(args.spring_file) != Path(args.spring):
        raise ParameterError([f"two springs given ({args.spring_file} and --spring {args.spring}); give one"])
    spring = args.spring_file or args.spring or DEFAULT_SPRING
    p = load_params(spring)
    print(f"{spring}: spring '{p.name}' is valid ({p.n_pairs} pairs, "
          f"{len(p.sweep.temperatures_degC)} temperatures)")
    return 0


@contextlib.contextmanager
def _slow_notice(message: str, after_s: float = 5.0):
    """Print ``message`` on stderr once if the block is still running after ``after_s`` (zig's first build
    compiles its C libraries for every target: minutes without a word otherwise)."""
    timer = threading.Timer(after_s, lambda: print(message, file=sys.stderr, flush=True))
    timer.daemon = True
    timer.start()
    try:
        yield
    finally:
        timer.cancel()


#: said while an FMU build takes longer than a warm zig cache needs
ZIG_NOTICE = ("building the FMU's binaries with zig ... (the first build on a machine compiles zig's C "
              "libraries for every target: a few minutes; later builds take seconds)")


def _check_tables(folder) -> None:
    """A clear error for a ``--tables`` folder that is missing or holds no table set (before any work)."""
    from .model.table_format import REQUIRED_FILES
    folder = Path(folder)
    if not folder.is_dir():
        raise TableError(f"--tables {folder}: table folder does not exist (it must hold "
                         f"{' and '.join(REQUIRED_FILES)}, as written by cushion-clutch sweep)")
    missing = [n for n in REQUIRED_FILES if not (folder / n).is_file()]
    if missing:
        raise TableError(f"--tables {folder}: no table set there ({', '.join(missing)} missing; a table set is "
                         "the folder cushion-clutch sweep writes, e.g. lookup_tables/<spring>)")


def _build_fmu(args: argparse.Namespace) -> int:
    from .fmu.build import build_from_args, table_folders
    for folder in table_folders(args):
        _check_tables(folder)
    with _slow_notice(ZIG_NOTICE):
        report = build_from_args(args)
    print(report)
    return 0


def _export_ssp(args: argparse.Namespace) -> int:
    from .fmu.build import table_folders
    from .fmu.ssp import export_from_args
    if not args.fmu:
        for folder in table_folders(args):
            _check_tables(folder)
    with _slow_notice(ZIG_NOTICE):
        rep = export_from_args(args)
    print(f"wrote {rep.path}: {len(rep.files)} files, SSD and {len(rep.sets)} SSV parameter sets validated "
          f"against the SSP 1.0 schemas; bound to the FMU: {args.bind}")
    for name, description in rep.sets:
        print(f"  {name}: {description}")
    if len(rep.table_sets) > 1:
        print("the FMU's parameter spring: " + ", ".join(f"{v} = {n}" for v, n, _ in rep.table_sets))
    return 0


def _import_scan(args: argparse.Namespace) -> int:
    from .fe.scan.importer import import_scan

    res = import_scan(args.scan, args.spring, args.out, unit=args.unit, face=args.face, datum=args.datum,
                      crop=args.crop)
    f, fr = res.fit, res.frame
    print(f"{args.scan}: {res.n_read} points read, {res.n_on_sector} on the paddle sector, "
          f"{res.n_rejected} rejected as outliers")
    print(f"rivet-zone datum ({args.datum}): tilt {fr.tilt_rad * 1e3:.3f} mrad about an axis at "
          f"{fr.tilt_axis_deg:.1f} deg, axial offset {fr.offset_m * 1e3:.4f} mm removed "
          f"({fr.rivet_points} points, flatness RMS {fr.rivet_rms_m * 1e6:.2f} um)")
    print(f"mid-surface fit residual: RMS {f.rms_m * 1e6:.2f} um, max {f.max_m * 1e6:.2f} um; "
          f"peak height {f.peak_m * 1e3:.4f} mm")
    c = res.coverage
    print(f"coverage: {len(c.gaps)} gap(s) (nodes > {c.distance_limit_m * 1e3:.2f} mm from every point), "
          + (f"largest {c.gaps[0].describe()}" if c.gaps else "none") + "; none on the wave beyond the limits")
    print(f"wrote {res.toml}, {res.surface}, {res.plot} and {res.coverage_plot}")
    return 0


def _heat_path(args: argparse.Namespace) -> int:
    from .data import DEFAULT_SPRING
    from .fe.heat_params import HeatPathParams
    from .fe.heat_path import run_heat_path
    from .fe.params import load_params

    if not args.out:
        raise ParameterError(["--out is required: the folder for heat_path.json, the plot and the series"])
    params = load_params(args.spring)
    out = Path(args.out)
    if out.exists() and not out.is_dir():
        raise ParameterError([f"--out {out} is a file; give a folder"])
    from .outputs import check_writable
    check_writable(out)
    start = time.perf_counter()

    def progress(msg: str) -> None:
        print(f"[{time.perf_counter() - start:6.0f} s] {msg}", flush=True)

    command = ("cushion-clutch heat-path" + (f" --spring {Path(args.spring).name}" if args.spring != DEFAULT_SPRING
                                             else "") + f" --out {out.name}" + (" --coarse" if args.coarse else "")
               + (" --no-uncertainty" if args.no_uncertainty else "")
               + (" --kiss-shift" if args.kiss_shift else ""))                # no paths in the provenance
    source = (f"{params.name} (shipped)" if Path(args.spring).resolve() == Path(DEFAULT_SPRING).resolve()
              else Path(args.spring).name)
    if args.jobs is None or args.jobs < 1:
        raise ParameterError([f"--jobs {args.jobs}: must be at least 1"])
    res = run_heat_path(params, HeatPathParams(), out, coarse=args.coarse, uncertainty=not args.no_uncertainty,
                        jobs=args.jobs, progress=progress, spring_source=source, command=command,
                        kiss_shift=args.kiss_shift)
    u = res["uncertainty"]

    def band(key: str) -> str:
        return f" (-{u[key]['minus_fraction']:.0%}/+{u[key]['plus_fraction']:.0%})" if key in u else ""
    print(f"U = {res['U_W_per_K']:.3g} W/K{band('U_W_per_K')}, H = {res['H_W_per_K']:.3g} W/K{band('H_W_per_K')}, "
          f"C = {res['C_J_per_K']:.3g} J/K{band('C_J_per_K')}, tau = {res['tau_s']:.3g} s{band('tau_s')} "
          f"(paper: 0.1 W/K, 0.04 W/K, 1 J/K, 7.1 s)")
    print(f"C / (steel mass {res['steel_mass_kg'] * 1e3:.1f} g x c {res['steel_specific_heat_J_per_kg_K']:g} J/(kg K)) = "
          f"{res['C_over_mass_c']:.3f}; energy balance error {res['energy_balance_error']:.2e}; "
          f"tau change between the two finest meshes {res['tau_mesh_change']:.1%}")
    print(f"first-order ODE against the FE: RMS {res['ode_rms_error_K']:.3g} K, max {res['ode_max_error_K']:.3g} K "
          f"(theta_cs rise {res['theta_cs_max_rise_K']:.3g} K); two lags: RMS {res['two_lags']['rms_error_K']:.3g} K")
    ks = res.get("kiss_shift")
    if ks:
        d = {k: ("failed" if v is None else f"{v * 1e3:.3f} mm") for k, v in ks["delta_kiss_m"].items()}
        print(f"kiss shift at {ks['theta_degC']:g} degC (paper: 0.1 mm): " + ", ".join(f"{k} {v}" for k, v in d.items())
              + f" (kappa FE {ks['kappa_fe']:.3f}, spring file {ks['kappa_spring']:g})")
    for w in res["warnings"]:
        print(f"warning: {w}", file=sys.stderr)
    print(f"wrote {out / 'heat_path.json'}, heat_path.png, heat_path_series.csv, heat_path_set.toml, "
          f"heat_path_numbers.md in {time.perf_counter() - start:.0f} s")
    return 0


def _tolerance(args: argparse.Namespace) -> int:
    import numpy as np
    from rich.progress import BarColumn, MofNCompleteColumn, Progress, TextColumn, TimeElapsedColumn

    from .fe.params import load_params
    from .fe.studies.tolerance_report import RANK_BY, tolerance_study
    from .fmu.build import build_fmu

    if not args.verbose:
        import distributed  # noqa: F401 - its import sets its loggers' levels; quieten them after
        logging.getLogger("distributed").setLevel(logging.WARNING)
    params = load_params(args.spring)
    if args.mesh_size is not None:
        params = params.replace(mesh={"element_size_m": args.mesh_size})
    out = Path(args.out)
    if out.resolve().is_relative_to(tables_root().resolve()):
        raise ParameterError([f"--out {out} is inside the table sets shipped with cushion-clutch; give another"])
    if args.fmu:
        from .fmu.build import check_output
        check_output(args.fmu)                          # before the study, not after it
    with Progress(TextColumn("{task.description}"), BarColumn(), MofNCompleteColumn(),
                  TextColumn("{task.fields[status]}"), TimeElapsedColumn()) as bar:
        task = bar.add_task(f"{args.samples} samples + nominal", total=None, status="")

        def progress(done: int, total: int, cached: int) -> None:
            bar.update(task, completed=done, total=total, status=f"FE cases ({cached} from the cache)")

        res = tolerance_study(params, samples=args.samples, temperatures=tuple(args.temperatures), out=out,
                              method=args.method, seed=args.seed, rank_by=args.rank_by,
                              cache_dir=Path(args.cache), scheduler=args.scheduler, workers=args.workers,
                              progress=progress,
                              build_band=(lambda folders: build_fmu(folders, Path(args.fmu))) if args.fmu else None)
    b = res.bands
    print(f"{res.cases} FE cases ({res.cases_from_cache} from the cache) in {res.wall_time_s:.1f} s")
    print(f"{'theta [degC]':>12} {'delta_kiss P5/P50/P95 [mm]':>28} "
          f"{f'F(u = {b.u_m[-1] * 1e3:.3f} mm) P5/P50/P95 [N]':>34}")
    for j, t in enumerate(b.temperatures_degC):
        f = b.force_N[t][:, -1]
        print(f"{t:>12g} {'/'.join(f'{v * 1e3:.4f}' for v in b.delta_kiss_m[:, j]):>28} "
              f"{'/'.join(f'{v:.0f}' for v in f):>34}")
    full = np.array([r[f"force_full_{b.ref_degC:g}degC_N"] for r in b.rows[1:]])
    kiss = np.array([r[f"delta_kiss_{b.kiss_theta_degC:g}degC_m"] for r in b.rows[1:]])
    for label, v, scale, unit in ((f"delta_kiss({b.kiss_theta_degC:g} degC)", kiss, 1e3, "mm"),
                                  (f"force at full compression ({b.ref_degC:g} degC)", full, 1.0, "N")):
        p5, p50, p95 = np.percentile(v, [5, 50, 95]) * scale
        print(f"{label}: P5 {p5:.4g}, P50 {p50:.4g}, P95 {p95:.4g} {unit}; band width P95-P5 "
              f"{p95 - p5:.4g} {unit}")
    for q, (index, value, target) in res.picks.items():
        x_ref = next(s.x_kiss_ref_m for s in res.summaries if s.sample.index == index)
        print(f"P{q:02.0f} table set {res.sets[q]}: sample {index} (value {value:.4g}, P{q:02.0f} {target:.4g}; "
              f"ranked by {RANK_BY[args.rank_by]}); its own x_kiss_ref = {x_ref * 1e3:.4f} mm "
              f"(build-fmu takes it from metadata.json)")
    for w in res.warnings:
        print(f"warning: {w}", file=sys.stderr)
    print("wrote " + ", ".join(str(f) for f in res.files))
    if res.band_fmu is not None:
        from .fmu.table_sets import fmu_sets
        print(f"wrote {res.band_fmu}: one FMU for the band, parameter spring: "
              + ", ".join(f"{s['value']} = {s['name']}" for s in fmu_sets(res.band_fmu)))
    return 0


#: the top-level description of ``cushion-clutch --help``
DESCRIPTION = ("Temperature-aware dry-clutch torque characteristics: CalculiX sweeps of a cushion spring -> "
               "lookup tables -> a clutch FMU (FMI 2.0/3.0, Co-Simulation and Model Exchange) -> launch "
               "simulations with six TCU variants.")
EPILOG = ("examples:\n"
          "  cushion-clutch launch --out out              # the main job: build the FMU, run the launches\n"
          "  cushion-clutch build-fmu --out CushionClutch.fmu\n"
          "  cushion-clutch <command> --help              # options and an example of each command\n"
          "documentation: docs/ (sphinx-build docs docs/_build/html)")


def _command(sub, name: str, func, summary: str, description: str, example: str) -> argparse.ArgumentParser:
    """A subcommand with its one-line summary, a description, one example, and the global options
    (``-v``, ``--debug``) accepted after the subcommand too."""
    p = sub.add_parser(name, help=summary, description=description, epilog=f"example:\n  {example}",
                       formatter_class=argparse.RawDescriptionHelpFormatter)
    _global_options(p, argparse.SUPPRESS)
    p.set_defaults(func=func)
    return p


def _global_options(p: argparse.ArgumentParser, default) -> None:
    """``-v/--verbose`` and ``--debug``; on a subcommand their default is SUPPRESS, so that the value given
    before the subcommand survives."""
    p.add_argument("-v", "--verbose", action="store_true", default=default, help="log progress details")
    p.add_argument("--debug", action="store_true", default=default, help="show the traceback of an error")


def _out(p: argparse.ArgumentParser, help: str, **kw) -> None:
    """``-o/--out``: the one name of every command's output (a folder, or the file a command writes)."""
    p.add_argument("-o", "--out", help=help, **kw)


def _jobs(p: argparse.ArgumentParser, help: str, dest: str = "jobs", **kw) -> None:
    """``-j/--jobs`` (``--workers`` accepted as an alias): parallel FE jobs or worker processes."""
    p.add_argument("-j", "--jobs", "--workers", dest=dest, type=int, help=help, **kw)


def _force(p: argparse.ArgumentParser) -> None:
    p.add_argument("--force", action="store_true", help="allow writing into a table set shipped with the package")


def build_parser() -> argparse.ArgumentParser:
    """The ``cushion-clutch`` argument parser (also what the documentation's CLI reference is generated from)."""
    from . import __version__
    parser = argparse.ArgumentParser(prog="cushion-clutch", description=DESCRIPTION, epilog=EPILOG,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--version", action="version", version=f"cushion-clutch {__version__}")
    _global_options(parser, False)
    sub = parser.add_subparsers(dest="job", required=True, metavar="<command>")
    _simulation_commands(sub)
    _fmu_commands(sub)
    _fe_commands(sub)
    return parser


def _simulation_commands(sub) -> None:
    """``launch``, ``fleet`` and ``simulate``: the commands that run the clutch FMU."""
    from .fmu.build import add_backend
    from .launch.scenario import DEFAULT_SCENARIO
    from .launch.tcu.controller import VARIANTS

    la = _command(sub, "launch", _launch, f"repeated launches with the {len(VARIANTS)} TCU variants (main job)",
                  f"Build the clutch FMU from --tables (or take --fmu), run a launch scenario with each of the "
                  f"{len(VARIANTS)} TCU variants ({', '.join(VARIANTS)}) and write time series, metrics, a "
                  "summary and plots to --out. The terminal shows a short summary; the full tables are the "
                  "CSV files.",
                  "cushion-clutch launch --scenario creep --out out_creep")
    la.add_argument("--scenario", default=DEFAULT_SCENARIO,
                    help="scenario TOML, or a shipped one: default, trailer, creep, cooldown, fade, wear, wear_learned, tolerance, "
                         "protection, hill_restart, hill_fade")
    la.add_argument("--fmu", help="clutch FMU, or an SSP archive (.ssp, from export-ssp) whose FMU is the plant "
                                  "(default: build one from --tables into --out)")
    la.add_argument("--parameter-set", help="with an .ssp: the plant's parameter set (default new); the scenario "
                                            "still sets ambient, soak, kiss-point offset and a wear it states")
    la.add_argument("--tables", default=DEFAULT_TABLES, help="table folder")
    add_backend(la)
    _out(la, "output folder (default: out)", default="out")
    la.add_argument("--every", type=_positive_int, default=1, metavar="N",
                    help="write every N-th row of the time series launch_<tcu>.csv (default 1: every recorded "
                         "row, one per 10 simulation steps); metrics, summary and plots use every row")
    _force(la)

    fl = _command(sub, "fleet", _fleet, "a population of vehicles, drivers and clutches, each TCU, on Dask",
                  "Draw --samples samples (vehicle mass, trailer, grade, ambient and start temperature, pedal, "
                  "launch interval, spring tolerance, facing wear, noise seeds) from a population TOML, run each "
                  "sample's launches with each of --tcus on a Dask cluster (a LocalCluster of --jobs workers, or "
                  "--scheduler), and write fleet_samples.parquet (one row per sample and TCU: each metric's worst "
                  "over the sample's launches), fleet_summary.csv (P50/P95/P99/max per TCU and metric) and "
                  "fleet.png. Reproducible by --seed; a rerun into the same --out resumes.",
                  "cushion-clutch fleet --population default --samples 200 --tcus naive,production --jobs 2 "
                  "--seed 1 --out out_fleet")
    fl.add_argument("--population", default="default", help="population TOML, or a shipped one: default")
    fl.add_argument("--samples", type=int, default=200, help="number of samples, 0 .. N-1 (default 200)")
    fl.add_argument("--tcus", default="naive,aware_estimated,production",
                    help=f"comma-separated TCU variants (default naive,aware_estimated,production; "
                         f"allowed {', '.join(VARIANTS)})")
    fl.add_argument("--seed", type=int, default=0, help="random seed of the samples (default 0)")
    _jobs(fl, "LocalCluster worker processes, one thread each (default: cores)")
    fl.add_argument("--scheduler", help="Dask scheduler address, e.g. tcp://host:8786 (default: a LocalCluster)")
    fl.add_argument("--serial", action="store_true", help="run the samples one after the other in this process")
    fl.add_argument("--tables", default=DEFAULT_TABLES, help="table folder (the plant's and TCUs' unless the "
                                                            "population's spring sets name others)")
    add_backend(fl)
    _out(fl, "output folder (default: out_fleet)", default="out_fleet")
    _force(fl)

    sm = _command(sub, "simulate", _simulate, "repeated engagements through the FMU with fmpy, with plots",
                  "Drive the clutch FMU through fmpy over repeated engagements 60 s apart (bearing ramp, "
                  "hold, open; a prescribed facing temperature) and write engagements.csv and three plots.",
                  "cushion-clutch simulate --engagements 4 --out out_sim")
    sm.add_argument("--fmu", help="FMU to simulate, or an SSP archive (.ssp, from export-ssp) with its FMU "
                                  "(default: build one from --tables into --out)")
    sm.add_argument("--parameter-set", help="with an .ssp: the parameter set to simulate with (default new)")
    sm.add_argument("--tables", default=DEFAULT_TABLES, help="table folder")
    add_backend(sm)
    _out(sm, "output folder (default: out)", default="out")
    _force(sm)
    sm.add_argument("--engagements", type=int, default=12, help="number of engagements (60 s apart)")
    sm.add_argument("--step", type=float, default=0.1, help="communication step [s]")


def _fmu_commands(sub) -> None:
    """``build-fmu``, ``export-ssp`` and ``export``: the commands that package the tables for a host."""
    from .fmu.build import add_build_arguments

    bf = _command(sub, "build-fmu", _build_fmu, "build the clutch FMU from a table set (native C by default)",
                  "Build CushionClutch.fmu with the table set in its resources: the native C FMU (FMI 2.0 "
                  "or 3.0, Co-Simulation and Model Exchange, binaries for Linux, Windows and macOS) or the "
                  "pythonfmu FMU. The output must be a new or existing file ending in .fmu, not a folder.",
                  "cushion-clutch build-fmu --fmi-version 3 --out CushionClutch3.fmu")
    add_build_arguments(bf)

    sp = _command(sub, "export-ssp", _export_ssp, "write the clutch FMU with its parameter sets as an SSP archive",
                  "Write an SSP 1.0 archive (.ssp) holding the clutch FMU (from --fmu, or built from --tables, "
                  "which may be given more than once), SystemStructure.ssd declaring it, and an SSV parameter set "
                  "per wear state, thermal set and table set carried, each value bound by name with its unit. "
                  "Every file is validated against the SSP 1.0 schemas shipped with FMPy.",
                  "cushion-clutch export-ssp --tables lookup_tables/default --tables soft -o Clutch.ssp")
    sp.add_argument("--tables", type=Path, action="append", default=None,
                    help="table folder; more than once: one FMU carrying every set (default: the default set)")
    sp.add_argument("--fmu", help="put this clutch FMU in the archive instead of building one")
    sp.add_argument("--fmi-version", type=int, choices=(2, 3), default=2, help="FMI version of the FMU built")
    sp.add_argument("-o", "--out", dest="output", type=Path, default=Path("CushionClutch.ssp"),
                    help="archive to write, ending in .ssp (default CushionClutch.ssp)")
    sp.add_argument("--bind", default="new",
                    help="the parameter set the SSD binds to the FMU, which a tool applies on import (default new)")

    ex = _command(sub, "export", _export, "write the tables for Simulink (.mat) and Modelica (CombiTable)",
                  "Write cushion_spring_tables.mat (Simulink 2-D Lookup Tables, and a 3-D clamp-force table in "
                  "x_to, theta_cs, theta_cm for the n-D Lookup Table) and cushion_spring_tables.txt (Modelica "
                  "CombiTable2Ds/1Ds, #1 format) with the cushion force, the kiss-point shift, the kiss point at "
                  "the bearing and the cover's clamp and bearing force maps; each file states the torque formula, "
                  "the parameters its tables assume and the measured error of a linear lookup.",
                  "cushion-clutch export --tables lookup_tables/default --out out_tables")
    ex.add_argument("--tables", default=DEFAULT_TABLES, help="table folder")
    _out(ex, "output folder (default: out)", default="out")
    _force(ex)


def _fe_commands(sub) -> None:
    """``sweep``, ``check-spring``, ``calibrate``, ``import-scan``, ``heat-path`` and ``tolerance``: the
    commands of the FE stage (CalculiX)."""
    from .fe.cases import DEFAULT_CACHE
    from .fe.params import DEFAULT_SPRING

    sw = _command(sub, "sweep", _sweep, "run the CalculiX temperature sweep and write lookup tables",
                  "Solve the spring's paddle pair with CalculiX at every sweep temperature (one ccx job per "
                  "core, cached per case) and write the table set F(u, theta), kiss-point shift, crest growth "
                  "and metadata, with plots. Needs ccx on the PATH.",
                  "cushion-clutch sweep --spring my_spring.toml --out lookup_tables/my_spring")
    sw.add_argument("--spring", default=DEFAULT_SPRING, help="spring parameter TOML")
    _out(sw, "table folder (default ./lookup_tables/<spring name>)")
    _force(sw)
    sw.add_argument("--mesh-size", type=float, help="override mesh.element_size_m [m]")
    _jobs(sw, "parallel ccx jobs (default: cores)")
    sw.add_argument("--scheduler", help="Dask scheduler address, e.g. tcp://host:8786")
    sw.add_argument("--cache", default=DEFAULT_CACHE, help="case cache folder")

    ck = _command(sub, "check-spring", _check, "validate a spring parameter TOML",
                  "Load a spring TOML and name every bad key with its allowed range (exit 2), or say it is "
                  "valid.", "cushion-clutch check-spring --spring my_spring.toml")
    ck.add_argument("spring_file", nargs="?", metavar="SPRING", help="spring TOML (or --spring)")
    ck.add_argument("--spring", help="spring TOML (default: the shipped default spring)")

    ca = _command(sub, "calibrate", _calibrate, "fit spring parameters to a measured load-deflection curve",
                  "Fit chosen spring keys to bench curves (cold, and hot for the thermal keys) by bounded "
                  "least squares on FE runs; write the calibrated spring TOML with a report (.txt) and a "
                  "plot (.png) beside it.",
                  "cushion-clutch calibrate --measured bench.csv --fit wave_height_m,thickness_m "
                  "--out calibrated.toml")
    ca.add_argument("--measured", required=True, action="append",
                    help="CSV u_m,force_N, u from the reference temperature's kiss point, as measured (noise "
                         "kept): FILE (reference temperature) or THETA_DEGC=FILE; repeat for hot curves, "
                         "e.g. --measured 20=bench20.csv --measured 195=bench195.csv. Comment lines "
                         "'# free_height_m = ...' and '# free_height_sd_m = ...' give the pair's free height "
                         "from a datum and its 1-sigma [m]")
    ca.add_argument("--basis", choices=("pair", "spring"), default="pair",
                    help="the measured force is of one paddle pair (default) or the whole spring")
    ca.add_argument("--spring", default=DEFAULT_SPRING, help="start parameter TOML")
    ca.add_argument("--fit", required=True, help="comma-separated keys, e.g. wave_height_m,thickness_m")
    ca.add_argument("--bounds", help="NAME=LOWER:UPPER,... (default: start value +-30 %%)")
    _out(ca, "calibrated spring TOML to write (report .txt and .png beside it)", required=True)
    ca.add_argument("--name", help="name of the calibrated spring (default: <spring name>_calibrated)")
    ca.add_argument("--mesh-size", type=float, help="override mesh.element_size_m [m]")
    _jobs(ca, "parallel ccx jobs (default 2)", default=2)
    ca.add_argument("--scheduler", help="Dask scheduler address, e.g. tcp://host:8786")
    ca.add_argument("--cache", default=DEFAULT_CACHE, help="case cache folder")
    ca.add_argument("--no-mesh-check", action="store_true",
                    help="skip the FE run on a 1.5x finer mesh: the 1-sigma then lacks its mesh term (the report "
                         "says so)")

    im = _command(sub, "import-scan", _import_scan,
                  "fit a scanned paddle's mid-surface and write a spring TOML using it",
                  "Read a scanned paddle (point cloud or triangulated surface) in disc coordinates, check "
                  "units, frame and coverage, fit its mid-surface with a bicubic spline and write a spring "
                  "TOML whose geometry.surface_file is that surface (the .npz and plots beside it).",
                  "cushion-clutch import-scan paddle.csv --out scanned.toml")
    im.add_argument("scan", help="point cloud CSV (x,y,z header) or STL/PLY/OBJ surface")
    im.add_argument("--spring", default=DEFAULT_SPRING, help="base spring TOML (plan shape, rivet zone, material)")
    _out(im, "spring TOML to write (the surface .npz and PNGs go next to it)", required=True)
    im.add_argument("--unit", choices=("um", "mm", "cm", "in", "m"), default="mm",
                    help="length unit of the scan (default mm)")
    im.add_argument("--face", choices=("top", "bottom", "mid"), default="top",
                    help="scanned face: top (away from the carrier, default), bottom, or mid-surface")
    im.add_argument("--datum", choices=("rigid", "offset"), default="rigid",
                    help="fit tilt and offset on the rivet zone (default) or the offset only")
    im.add_argument("--crop", action="store_true", help="drop points off the paddle sector instead of refusing")

    hp = _command(sub, "heat-path", _heat_path,
                  "identify the cushion spring's heat path (U, H, C) from a transient thermal CalculiX FE",
                  "Solve a transient heat-transfer FE of one paddle pair's sector of the disc (facing, paddle, "
                  "rivets, carrier, with contact conductances and films) under a launch-like flux history on "
                  "two or three meshes, and fit the paper's first-order ODE (eq. 2-4) of the cushion-spring "
                  "temperature to it: U, H, C and tau for the whole disc, with uncertainties from re-solving at "
                  "the bounds of the uncertain inputs, the ODE's error, a two-time-constant alternative, the "
                  "energy balance and the mesh change of tau. Writes heat_path.json, a plot, the time series, "
                  "a thermal parameter set (TOML) and a markdown table for the docs. Needs ccx on the PATH.",
                  "cushion-clutch heat-path --coarse --out out_heat")
    hp.add_argument("--spring", default=DEFAULT_SPRING, help="spring parameter TOML (geometry of the paddles)")
    _out(hp, "output folder (required)")
    hp.add_argument("--coarse", action="store_true", help="two coarse meshes (6 and 4 mm) and larger time steps: "
                                                          "a quick check, not the shipped numbers")
    hp.add_argument("--no-uncertainty", action="store_true",
                    help="skip the re-solves at the uncertain inputs' bounds (no uncertainty in the output)")
    hp.add_argument("--kiss-shift", action="store_true",
                    help="also solve the paddle FE at 195 degC under the FE's temperature field and uniformly "
                         "(kiss shift, in heat_path.json; the table sets are not changed)")
    _jobs(hp, "parallel ccx jobs (default 2)", default=2)

    to = _command(sub, "tolerance", _tolerance, "tolerance study: sampled springs swept on Dask, P5/P50/P95 bands",
                  "Draw springs from the [tolerances] of a spring TOML (Latin hypercube or Monte Carlo), sweep "
                  "each on Dask (a LocalCluster, or --scheduler), write P5/P50/P95 bands of force, kiss-point "
                  "shift and torque, and the P5 and P95 table sets.",
                  "cushion-clutch tolerance --samples 16 --jobs 2 --out lookup_tables")
    to.add_argument("--spring", default=DEFAULT_SPRING, help="spring TOML with a [tolerances] table")
    to.add_argument("--samples", type=int, default=16, help="number of drawn springs (default 16)")
    to.add_argument("--method", choices=("lhs", "mc"), default="lhs", help="Latin hypercube or Monte Carlo")
    to.add_argument("--seed", type=int, default=0, help="random seed (default 0)")
    to.add_argument("--temperatures", type=float, nargs="+", default=[20.0, 195.0, 300.0],
                    help="temperatures [degC] (default 20 195 300; must include the reference)")
    to.add_argument("--mesh-size", type=float, help="override mesh.element_size_m [m]")
    to.add_argument("--scheduler", help="Dask scheduler address, e.g. tcp://host:8786 (default: a LocalCluster)")
    _jobs(to, "LocalCluster worker processes, one thread each (default: cores)", dest="workers")
    to.add_argument("--rank-by", choices=("torque", "force", "kiss"), default="torque",
                    help="figure that picks the P5/P95 samples (default: torque at the nominal half-engaged "
                         "bearing position, 20 degC)")
    _out(to, "folder for <name>_tolerance/ and the <name>_p05/, <name>_p95/ table sets (default ./lookup_tables)",
         default="lookup_tables")
    to.add_argument("--cache", default=DEFAULT_CACHE, help="case cache folder (shared with sweep)")
    to.add_argument("--fmu", type=Path, help="also write one native FMU (.fmu) carrying the nominal, P5 and P95 table "
                                             "sets, chosen by its parameter spring")



def main(argv: list[str] | None = None) -> int:
    args = build_parser().parse_args(argv)
    args.argv = list(sys.argv[1:] if argv is None else argv)          # the command, for the outputs' provenance
    logging.basicConfig(level=logging.INFO if args.verbose else logging.WARNING,
                        format="%(levelname)s %(name)s: %(message)s")
    from . import interrupt
    try:
        with interrupt.handle_signals():
            return args.func(args)
    except RunInterrupted as exc:
        hint = getattr(args, "resume_hint", "no output set was written")
        print(f"\n{exc}: stopped; {hint}", file=sys.stderr)
        return exc.exit_code
    except KeyboardInterrupt:
        print("\ninterrupted; no output set was written", file=sys.stderr)
        return 130
    except (ParameterError, TableError, FmuError, CalculixNotFoundError, OSError, ValueError) as exc:
        if args.debug:
            raise
        print(f"error: {_one_message(exc)}", file=sys.stderr)
        return 2
    except (SweepError, ClusterError) as exc:
        if args.debug:
            raise
        print(f"error: {exc}", file=sys.stderr)
        return 1
    except Exception as exc:  # noqa: BLE001 - the CLI never shows a traceback unless --debug
        if args.debug:
            raise
        print(f"error: {type(exc).__name__}: {exc} (run with --debug for the traceback)", file=sys.stderr)
        return 1


def _one_message(exc: BaseException) -> str:
    """An exception as one message; OS errors name the file."""
    if isinstance(exc, OSError) and exc.filename and str(exc.filename) not in str(exc.strerror or ""):
        return f"{exc.filename}: {exc.strerror or exc}"
    return str(exc)


if __name__ == "__main__":
    sys.exit(main())
