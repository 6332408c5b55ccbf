"""Command line: ``cushion-clutch <job>``. Only this module prints."""
from __future__ import annotations

import argparse
import logging
import sys
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
    return build_fmu(Path(args.tables), stage / "CushionClutch.fmu", backend=args.backend)


def _sweep(args: argparse.Namespace) -> int:
    from rich.progress import BarColumn, Progress, TextColumn, TimeElapsedColumn

    from .fe.params import load_params
    from .fe.plots import plot_force_deflection, plot_kiss_shift
    from .fe.sweep import build_tables, run_sweep
    from .fe.tables import read_tables

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
    print(f"{'theta [degC]':>12} {'delta_kiss [mm]':>16} {'crest growth [mm]':>18} {'F full [N]':>11} "
          f"{'k20/k50/k90 [kN/mm]':>20} {'k90/k20':>8} {'increments':>10}")
    for c in curves:
        o, k = outcomes[c.theta_degC], prog[f"{c.theta_degC:g}"]
        ks = "/".join(f"{k[n] / 1e6:.2f}" for n in ("k20_N_per_m", "k50_N_per_m", "k90_N_per_m"))
        print(f"{c.theta_degC:>12g} {shifts[c.theta_degC] * 1e3:>16.4f} "
              f"{crest[f'{c.theta_degC:g}']['crest_growth_m'] * 1e3:>18.4f} {c.force_N[-1]:>11.0f} "
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
                    scheduler=args.scheduler,
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

    from .launch.engagements import (EngagementCycle, plot_engagements, plot_thermal_step,
                                     plot_torque_characteristic, simulate)
    from .model import load_table
    from .outputs import OutputSet

    out = _guard_out(Path(args.out), args.force)
    table = load_table(args.tables)
    with OutputSet(out, "simulate") as stage:              # checks --out before the simulation
        fmu = _fmu_arg(args, stage)
        print(f"simulating {args.engagements} engagements with {fmu} (fmpy, step {args.step:g} s) ...")
        start = time.perf_counter()
        res = simulate(fmu, EngagementCycle(), n_engagements=args.engagements, step_s=args.step)
        wall = time.perf_counter() - start
        with open(stage / "engagements.csv", "w", newline="") as fh:
            w = csv.writer(fh)
            w.writerow(["time_s", "x_to_m", "theta_cm_K", "torque_Nm", "force_N", "theta_cs_K", "u_f_m",
                        "x_kiss_m"])
            for row in res:
                w.writerow([f"{v:.9g}" for v in row])
        plots = [plot_engagements(res, stage / "engagements.png"),
                 plot_torque_characteristic(table, stage / "torque_characteristic.png"),
                 plot_thermal_step(stage / "thermal_step_response.png")]
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
    from .launch.plant import build_plant_fmu
    from .launch.report import metrics_table, peak_lines, ratio_line, run_all, summary_table, write_outputs
    from .launch.scenario import load_scenario, scenario_path
    from .launch.tcu import VARIANTS
    from .outputs import OutputSet

    sc = load_scenario(scenario_path(args.scenario))
    out = _guard_out(Path(args.out), args.force)
    table = load_table(sc.tables_path("tcu") or args.tables)     # a scenario may name the TCUs' table set
    with OutputSet(out, "launch") as stage:                # checks --out before the simulation
        fmu = (check_fmu(args.fmu) if args.fmu else
               build_plant_fmu(Path(args.tables), sc, stage / "CushionClutch.fmu", backend=args.backend))
        total = sc.run.duration()
        start = time.perf_counter()
        with Progress(refresh_per_second=2) as bar:        # the bar's thread competes for the GIL
            tasks = {n: bar.add_task(f"{n} TCU", total=total) for n in VARIANTS}
            results = run_all(fmu, sc, table, progress=lambda n, t: bar.update(tasks[n], completed=t))
            for task in tasks.values():
                bar.update(task, completed=total)
        wall = time.perf_counter() - start
        paths = write_outputs(results, stage)
    paths = [out / p.relative_to(stage) for p in paths]
    print(metrics_table(results))
    print()
    print(summary_table(results))
    print()
    print(ratio_line(results, "hot"))
    print(peak_lines(results))
    for name, res in results.items():
        e = res.energy
        print(f"{name}: energy balance residual {e.residual():.3g} J of {e.engine_work / 1e3:.1f} kJ engine "
              f"work; real-time factor {total / res.wall_time_s:.0f}x (CPU time {total / res.cpu_time_s:.0f}x)")
    print(f"scenario '{sc.name}': {len(results[next(iter(results))].metrics)} launches with {len(results)} TCUs "
          f"in {wall:.1f} s; wrote " + ", ".join(str(p) for p in paths))
    return 0


def _export(args: argparse.Namespace) -> int:
    from .fe.exports import export_mat, export_modelica

    from .fe.tables import read_tables
    from .outputs import OutputSet

    out = _guard_out(Path(args.out), args.force)
    read_tables(Path(args.tables))                          # a clear TableError first
    with OutputSet(out, "export") as stage:
        mat = export_mat(Path(args.tables), stage / "cushion_spring_tables.mat")
        mo = export_modelica(Path(args.tables), stage / "cushion_spring_tables.txt")
    mat, mo = out / mat.name, out / mo.name
    print(f"wrote {mat} (Simulink 2-D Lookup Table) and {mo} (Modelica CombiTable2Ds, #1 format)")
    return 0


def _check(args: argparse.Namespace) -> int:
    from .fe.params import load_params
    p = load_params(args.spring)
    print(f"{args.spring}: spring '{p.name}' is valid ({p.n_pairs} pairs, "
          f"{len(p.sweep.temperatures_degC)} temperatures)")
    return 0


def _build_fmu(args: argparse.Namespace) -> int:
    from .fmu.build import build_from_args
    print(build_from_args(args))
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


def _tolerance(args: argparse.Namespace) -> int:
    import numpy as np
    from rich.progress import BarColumn, MofNCompleteColumn, Progress, TextColumn, TimeElapsedColumn

    from .fe.params import load_params
    from .fe.studies.tolerance_report import RANK_BY, tolerance_study

    if not args.verbose:
        import distributed  # noqa: F401 - its import sets its loggers' levels; quieten them after
        logging.getLogger("distributed").setLevel(logging.WARNING)
    params = load_params(args.spring)
    if args.mesh_size is not None:
        params = params.replace(mesh={"element_size_m": args.mesh_size})
    out = Path(args.out)
    if out.resolve().is_relative_to(tables_root().resolve()):
        raise ParameterError([f"--out {out} is inside the table sets shipped with cushion-clutch; give another"])
    with Progress(TextColumn("{task.description}"), BarColumn(), MofNCompleteColumn(),
                  TextColumn("{task.fields[status]}"), TimeElapsedColumn()) as bar:
        task = bar.add_task(f"{args.samples} samples + nominal", total=None, status="")

        def progress(done: int, total: int, cached: int) -> None:
            bar.update(task, completed=done, total=total, status=f"FE cases ({cached} from the cache)")

        res = tolerance_study(params, samples=args.samples, temperatures=tuple(args.temperatures), out=out,
                              method=args.method, seed=args.seed, rank_by=args.rank_by,
                              cache_dir=Path(args.cache), scheduler=args.scheduler, workers=args.workers,
                              progress=progress)
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
    return 0


def build_parser() -> argparse.ArgumentParser:
    from .fmu.build import add_backend, add_build_arguments
    from .fe.params import DEFAULT_SPRING
    from .launch.scenario import DEFAULT_SCENARIO
    from .fe.cases import DEFAULT_CACHE

    parser = argparse.ArgumentParser(prog="cushion-clutch", description=__doc__)
    parser.add_argument("-v", "--verbose", action="store_true", help="log progress details")
    parser.add_argument("--debug", action="store_true", help="show the traceback of an error")
    sub = parser.add_subparsers(dest="job", required=True)

    sw = sub.add_parser("sweep", help="run the CalculiX temperature sweep and write lookup tables")
    sw.add_argument("--spring", default=DEFAULT_SPRING, help="spring parameter TOML")
    sw.add_argument("--out", help="table folder (default ./lookup_tables/<spring name>)")
    sw.add_argument("--force", action="store_true", help="allow overwriting a table set shipped with the package")
    sw.add_argument("--mesh-size", type=float, help="override mesh.element_size_m [m]")
    sw.add_argument("--jobs", type=int, help="parallel ccx jobs (default: cores)")
    sw.add_argument("--scheduler", help="Dask scheduler address, e.g. tcp://host:8786")
    sw.add_argument("--cache", default=DEFAULT_CACHE, help="case cache folder")
    sw.set_defaults(func=_sweep)

    ca = sub.add_parser("calibrate", help="fit spring parameters to a measured load-deflection curve")
    ca.add_argument("--measured", required=True, action="append",
                    help="CSV u_m,force_N, u from the reference temperature's kiss point, as measured (noise "
                         "kept): FILE (reference temperature) or THETA_DEGC=FILE; repeat for hot curves, "
                         "e.g. --measured 20=bench20.csv --measured 195=bench195.csv")
    ca.add_argument("--basis", choices=("pair", "spring"), default="pair",
                    help="the measured force is of one paddle pair (default) or the whole spring")
    ca.add_argument("--spring", default=DEFAULT_SPRING, help="start parameter TOML")
    ca.add_argument("--fit", required=True, help="comma-separated keys, e.g. wave_height_m,thickness_m")
    ca.add_argument("--bounds", help="NAME=LOWER:UPPER,... (default: start value +-30 %%)")
    ca.add_argument("--out", required=True, help="calibrated TOML (report .txt and .png beside it)")
    ca.add_argument("--name", help="name of the calibrated spring (default: <spring name>_calibrated)")
    ca.add_argument("--mesh-size", type=float, help="override mesh.element_size_m [m]")
    ca.add_argument("--jobs", type=int, default=2, help="parallel ccx jobs")
    ca.add_argument("--scheduler", help="Dask scheduler address, e.g. tcp://host:8786")
    ca.add_argument("--cache", default=DEFAULT_CACHE, help="case cache folder")
    ca.set_defaults(func=_calibrate)

    sm = sub.add_parser("simulate", help="repeated engagements through the FMU with fmpy, with plots")
    sm.add_argument("--fmu", help="FMU to simulate (default: build one from --tables into --out)")
    sm.add_argument("--tables", default=DEFAULT_TABLES, help="table folder")
    add_backend(sm)
    sm.add_argument("--out", default="out", help="output folder")
    sm.add_argument("--force", action="store_true", help="allow writing into a shipped table set")
    sm.add_argument("--engagements", type=int, default=12, help="number of engagements (60 s apart)")
    sm.add_argument("--step", type=float, default=0.1, help="communication step [s]")
    sm.set_defaults(func=_simulate)

    la = sub.add_parser("launch", help="repeated launches with the five TCU variants (main job)")
    la.add_argument("--scenario", default=DEFAULT_SCENARIO,
                    help="scenario TOML, or a shipped one: default, creep, cooldown, fade, wear, tolerance")
    la.add_argument("--fmu", help="clutch FMU (default: build one from --tables into --out)")
    la.add_argument("--tables", default=DEFAULT_TABLES, help="table folder")
    add_backend(la)
    la.add_argument("--out", default="out", help="output folder")
    la.add_argument("--force", action="store_true", help="allow writing into a shipped table set")
    la.set_defaults(func=_launch)

    ex = sub.add_parser("export", help="write the tables for Simulink (.mat) and Modelica (CombiTable)")
    ex.add_argument("--tables", default=DEFAULT_TABLES, help="table folder")
    ex.add_argument("--out", default="out", help="output folder")
    ex.add_argument("--force", action="store_true", help="allow writing into a shipped table set")
    ex.set_defaults(func=_export)

    bf = sub.add_parser("build-fmu", help="build the clutch FMU from a table set (native C by default)")
    add_build_arguments(bf)
    bf.set_defaults(func=_build_fmu)

    im = sub.add_parser("import-scan", help="fit a scanned paddle's mid-surface and write a spring TOML using it")
    im.add_argument("scan", help="point cloud CSV (x,y,z header) or STL/PLY/OBJ surface")
    im.add_argument("--spring", default=DEFAULT_SPRING, help="base spring TOML (plan shape, rivet zone, material)")
    im.add_argument("--out", required=True, help="spring TOML to write (the surface .npz and PNG go next to it)")
    im.add_argument("--unit", choices=("um", "mm", "cm", "in", "m"), default="mm",
                    help="length unit of the scan (default mm)")
    im.add_argument("--face", choices=("top", "bottom", "mid"), default="top",
                    help="scanned face: top (away from the carrier, default), bottom, or mid-surface")
    im.add_argument("--datum", choices=("rigid", "offset"), default="rigid",
                    help="fit tilt and offset on the rivet zone (default) or the offset only")
    im.add_argument("--crop", action="store_true", help="drop points off the paddle sector instead of refusing")
    im.set_defaults(func=_import_scan)

    to = sub.add_parser("tolerance", help="tolerance study: sampled springs swept on Dask, P5/P50/P95 bands")
    to.add_argument("--spring", default=DEFAULT_SPRING, help="spring TOML with a [tolerances] table")
    to.add_argument("--samples", type=int, default=16, help="number of drawn springs (default 16)")
    to.add_argument("--method", choices=("lhs", "mc"), default="lhs", help="Latin hypercube or Monte Carlo")
    to.add_argument("--seed", type=int, default=0, help="random seed (default 0)")
    to.add_argument("--temperatures", type=float, nargs="+", default=[20.0, 195.0, 300.0],
                    help="temperatures [degC] (default 20 195 300; must include the reference)")
    to.add_argument("--mesh-size", type=float, help="override mesh.element_size_m [m]")
    to.add_argument("--scheduler", help="Dask scheduler address, e.g. tcp://host:8786 (default: a LocalCluster)")
    to.add_argument("--workers", type=int, help="LocalCluster worker processes, one thread each (default: cores)")
    to.add_argument("--rank-by", choices=("torque", "force", "kiss"), default="torque",
                    help="figure that picks the P5/P95 samples (default: torque at the nominal half-engaged "
                         "bearing position, 20 degC)")
    to.add_argument("--out", default="lookup_tables",
                    help="folder for <name>_tolerance/ and the <name>_p05/, <name>_p95/ table sets "
                         "(default ./lookup_tables)")
    to.add_argument("--cache", default=DEFAULT_CACHE, help="case cache folder (shared with sweep)")
    to.set_defaults(func=_tolerance)

    ck = sub.add_parser("check-spring", help="validate a spring parameter TOML")
    ck.add_argument("spring")
    ck.set_defaults(func=_check)
    return parser


def main(argv: list[str] | None = None) -> int:
    args = build_parser().parse_args(argv)
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
