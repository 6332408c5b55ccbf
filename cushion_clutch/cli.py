"""Command line: ``cushion-clutch <job>``. Only this module prints."""
from __future__ import annotations

import argparse
import logging
import sys
import time
from pathlib import Path

from .errors import CalculixNotFoundError, ParameterError, SweepError, TableError

REPO = Path(__file__).resolve().parents[1]
DEFAULT_TABLES = REPO / "lookup_tables" / "default"


def _sweep(args: argparse.Namespace) -> int:
    from rich.progress import BarColumn, Progress, TextColumn, TimeElapsedColumn

    from .params import load_params
    from .plots import plot_force_deflection, plot_kiss_shift
    from .sweep import build_tables, run_sweep
    from .tables import read_tables

    params = load_params(args.spring)
    if args.mesh_size is not None:
        params = params.replace(mesh={"element_size_m": args.mesh_size})
    out = Path(args.out) if args.out else REPO / "lookup_tables" / params.name
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


def _check(args: argparse.Namespace) -> int:
    from .params import load_params
    p = load_params(args.spring)
    print(f"{args.spring}: spring '{p.name}' is valid ({p.n_pairs} pairs, "
          f"{len(p.sweep.temperatures_degC)} temperatures)")
    return 0


def build_parser() -> argparse.ArgumentParser:
    from .params import DEFAULT_SPRING
    from .sweep import DEFAULT_CACHE

    parser = argparse.ArgumentParser(prog="cushion-clutch", description=__doc__)
    parser.add_argument("-v", "--verbose", action="store_true", help="log progress details")
    sub = parser.add_subparsers(dest="job", required=True)

    sw = sub.add_parser("sweep", help="run the CalculiX temperature sweep and write lookup tables")
    sw.add_argument("--spring", default=DEFAULT_SPRING, help="spring parameter TOML")
    sw.add_argument("--out", help="table folder (default lookup_tables/<spring name>)")
    sw.add_argument("--mesh-size", type=float, help="override mesh.element_size_m [m]")
    sw.add_argument("--jobs", type=int, help="parallel ccx jobs (default: cores)")
    sw.add_argument("--scheduler", help="Dask scheduler address, e.g. tcp://host:8786")
    sw.add_argument("--cache", default=DEFAULT_CACHE, help="case cache folder")
    sw.set_defaults(func=_sweep)

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
