"""Command line: ``cushion-clutch <job>``. Only this module prints."""
from __future__ import annotations

import argparse
import logging
import sys
import time
from pathlib import Path

from .data import DEFAULT_TABLES, tables_root
from .errors import CalculixNotFoundError, ParameterError, SweepError, TableError


def _sweep(args: argparse.Namespace) -> int:
    from rich.progress import BarColumn, Progress, TextColumn, TimeElapsedColumn

    from .fe.params import load_params
    from .fe.plots import plot_force_deflection, plot_kiss_shift
    from .fe.sweep import build_tables, run_sweep
    from .fe.tables import read_tables

    params = load_params(args.spring)
    if args.mesh_size is not None:
        params = params.replace(mesh={"element_size_m": args.mesh_size})
    out = Path(args.out) if args.out else Path("lookup_tables") / params.name
    if not args.force and out.resolve().is_relative_to(tables_root().resolve()):
        raise ParameterError([f"--out {out} is a table set shipped with cushion-clutch; give another --out, "
                              "or --force to overwrite it"])
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
    curves, shifts = build_tables(params, outcomes, out, wall_time_s=wall)
    tables = read_tables(out)
    plot_force_deflection(tables, out / "force_deflection.png", f"Spring '{params.name}' (CalculiX)")
    plot_kiss_shift(tables, out / "kiss_point.png")
    print(f"tables written to {out} in {wall:.1f} s (mesh {params.mesh.element_size_m * 1e3:g} mm)")
    print(f"{'theta [degC]':>12} {'delta_kiss [mm]':>16} {'F full [N]':>11} {'increments':>10}")
    for c in curves:
        o = outcomes[c.theta_degC]
        print(f"{c.theta_degC:>12g} {shifts[c.theta_degC] * 1e3:>16.4f} {c.force_N[-1]:>11.0f} "
              f"{o.stats.increments:>10d}")
    return 0


def _simulate(args: argparse.Namespace) -> int:
    import csv

    from .fmu.engagements import (EngagementCycle, plot_engagements, plot_thermal_step,
                              plot_torque_characteristic, simulate)
    from .fmu.build import build_fmu
    from .fmu.model import load_table

    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    fmu = Path(args.fmu) if args.fmu else build_fmu(Path(args.tables), out / "CushionClutch.fmu",
                                                    backend=args.backend)
    print(f"simulating {args.engagements} engagements with {fmu} (fmpy, step {args.step:g} s) ...")
    start = time.perf_counter()
    res = simulate(fmu, EngagementCycle(), n_engagements=args.engagements, step_s=args.step)
    wall = time.perf_counter() - start
    with open(out / "engagements.csv", "w", newline="") as fh:
        w = csv.writer(fh)
        w.writerow(["time_s", "x_to_m", "theta_cm_K", "torque_Nm", "force_N", "theta_cs_K", "u_f_m", "x_kiss_m"])
        for row in res:
            w.writerow([f"{v:.9g}" for v in row])
    plots = [plot_engagements(res, out / "engagements.png"),
             plot_torque_characteristic(load_table(args.tables), out / "torque_characteristic.png"),
             plot_thermal_step(out / "thermal_step_response.png")]
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

    from .fmu.model import load_table
    from .launch.plant import build_plant_fmu
    from .launch.report import metrics_table, run_all, summary_table, write_outputs
    from .launch.scenario import load_scenario, scenario_path
    from .launch.tcu import VARIANTS

    sc = load_scenario(scenario_path(args.scenario))
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    fmu = Path(args.fmu) if args.fmu else build_plant_fmu(Path(args.tables), sc, out / "CushionClutch.fmu",
                                                          backend=args.backend)
    total = sc.run.duration()
    start = time.perf_counter()
    with Progress(refresh_per_second=2) as bar:        # the bar's thread competes for the GIL
        tasks = {n: bar.add_task(f"{n} TCU", total=total) for n in VARIANTS}
        results = run_all(fmu, sc, load_table(args.tables),
                          progress=lambda n, t: bar.update(tasks[n], completed=t))
        for task in tasks.values():
            bar.update(task, completed=total)
    wall = time.perf_counter() - start
    paths = write_outputs(results, out)
    print(metrics_table(results))
    print()
    print(summary_table(results))
    print()
    for name, res in results.items():
        e = res.energy
        print(f"{name}: energy balance residual {e.residual():.3g} J of {e.engine_work / 1e3:.1f} kJ engine "
              f"work; real-time factor {total / res.wall_time_s:.0f}x")
    print(f"scenario '{sc.name}': {len(results[next(iter(results))].metrics)} launches with {len(results)} TCUs "
          f"in {wall:.1f} s; wrote " + ", ".join(str(p) for p in paths))
    return 0


def _export(args: argparse.Namespace) -> int:
    from .fmu.exports import export_mat, export_modelica

    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    mat = export_mat(Path(args.tables), out / "cushion_spring_tables.mat")
    mo = export_modelica(Path(args.tables), out / "cushion_spring_tables.txt")
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


def build_parser() -> argparse.ArgumentParser:
    from .fmu.build import add_backend, add_build_arguments
    from .fe.params import DEFAULT_SPRING
    from .launch.scenario import DEFAULT_SCENARIO
    from .fe.sweep import DEFAULT_CACHE

    parser = argparse.ArgumentParser(prog="cushion-clutch", description=__doc__)
    parser.add_argument("-v", "--verbose", action="store_true", help="log progress details")
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

    sm = sub.add_parser("simulate", help="repeated engagements through the FMU with fmpy, with plots")
    sm.add_argument("--fmu", help="FMU to simulate (default: build one from --tables into --out)")
    sm.add_argument("--tables", default=DEFAULT_TABLES, help="table folder")
    add_backend(sm)
    sm.add_argument("--out", default="out", help="output folder")
    sm.add_argument("--engagements", type=int, default=12, help="number of engagements (60 s apart)")
    sm.add_argument("--step", type=float, default=0.1, help="communication step [s]")
    sm.set_defaults(func=_simulate)

    la = sub.add_parser("launch", help="repeated launches with the five TCU variants (main job)")
    la.add_argument("--scenario", default=DEFAULT_SCENARIO,
                    help="scenario TOML, or a shipped one: default, cooldown, fade")
    la.add_argument("--fmu", help="clutch FMU (default: build one from --tables into --out)")
    la.add_argument("--tables", default=DEFAULT_TABLES, help="table folder")
    add_backend(la)
    la.add_argument("--out", default="out", help="output folder")
    la.set_defaults(func=_launch)

    ex = sub.add_parser("export", help="write the tables for Simulink (.mat) and Modelica (CombiTable)")
    ex.add_argument("--tables", default=DEFAULT_TABLES, help="table folder")
    ex.add_argument("--out", default="out", help="output folder")
    ex.set_defaults(func=_export)

    bf = sub.add_parser("build-fmu", help="build the clutch FMU from a table set (native C by default)")
    add_build_arguments(bf)
    bf.set_defaults(func=_build_fmu)

    ck = sub.add_parser("check-spring", help="validate a spring parameter TOML")
    ck.add_argument("spring")
    ck.set_defaults(func=_check)
    return parser


def main(argv: list[str] | None = None) -> int:
    args = build_parser().parse_args(argv)
    logging.basicConfig(level=logging.INFO if args.verbose else logging.WARNING,
                        format="%(levelname)s %(name)s: %(message)s")
    try:
        return args.func(args)
    except (ParameterError, TableError, CalculixNotFoundError) as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 2
    except SweepError as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 1


if __name__ == "__main__":
    sys.exit(main())
