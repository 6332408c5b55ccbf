"""Benchmark: FE cases per minute of a tolerance study on a Dask LocalCluster of 1 and of 2 workers.

Each configuration solves the same samples (nominal + ``--samples`` drawn,
default spring, ``--temperatures``) into its own empty cache, with
single-threaded worker processes. Prints the cases per minute, the speed-up
of 2 workers over 1, the median ccx time per case, and the projected wall
time of 200 samples x 5 temperatures on a cluster of ``--cores`` single-threaded
workers: ``ceil(cases / cores)`` rounds of the measured mean case time,
divided by the parallel efficiency measured with 2 workers here.

    python -m cushion_clutch.benchmarks.tolerance [--samples 3] [--temperatures 20 195] [--mesh-size 2e-3]
"""
from __future__ import annotations

import argparse
import math
import tempfile
import time
from pathlib import Path

import numpy as np


def measure(samples, temperatures, workers: int, cache: Path) -> tuple[float, list[float]]:
    """Wall time (s) of solving every case on a LocalCluster of ``workers``, and ccx's time per case."""
    from cushion_clutch.fe.studies.tolerance import run_study
    start = time.perf_counter()
    results = run_study(samples, temperatures, cache_dir=cache, workers=workers)
    wall = time.perf_counter() - start
    return wall, [o.stats.wall_time_s for r in results for o in r.values()]


def main(argv=None) -> None:
    import logging

    from cushion_clutch.fe.params import load_params
    from cushion_clutch.fe.studies.tolerance import make_samples

    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--samples", type=int, default=3, help="drawn samples (plus the nominal spring)")
    ap.add_argument("--temperatures", type=float, nargs="+", default=[20.0, 195.0])
    ap.add_argument("--mesh-size", type=float, default=2e-3)
    ap.add_argument("--cores", type=int, default=64, help="cluster size for the projection")
    ap.add_argument("--project-samples", type=int, default=200)
    ap.add_argument("--project-temperatures", type=int, default=5)
    args = ap.parse_args(argv)
    logging.getLogger("distributed").setLevel(logging.WARNING)
    temps = tuple(sorted(args.temperatures))
    base = load_params().replace(mesh={"element_size_m": args.mesh_size}, sweep={"temperatures_degC": temps})
    samples = make_samples(base, args.samples, seed=0)
    cases = len(samples) * len(temps)
    rates, walls, ccx_times = {}, {}, []
    with tempfile.TemporaryDirectory() as tmp:
        for workers in (1, 2):
            wall, per_case = measure(samples, temps, workers, Path(tmp) / f"cache_{workers}")
            walls[workers], rates[workers] = wall, cases / wall * 60.0
            ccx_times += per_case
            print(f"LocalCluster, {workers} single-threaded worker(s): {cases} FE cases "
                  f"({len(samples)} springs x {len(temps)} temperatures, mesh {args.mesh_size * 1e3:g} mm) in "
                  f"{wall:.1f} s = {rates[workers]:.2f} cases/min", flush=True)
    speedup = rates[2] / rates[1]
    case_s = walls[1] / cases                       # one worker: wall time per case incl. overheads
    efficiency = min(1.0, speedup / 2.0)
    n = (args.project_samples + 1) * args.project_temperatures
    rounds = math.ceil(n / args.cores)
    ideal = rounds * case_s
    print(f"speed-up 2 workers / 1 worker: {speedup:.2f} (parallel efficiency {efficiency:.0%}); "
          f"median ccx time per case {np.median(ccx_times):.1f} s, wall per case on 1 worker {case_s:.1f} s")
    print(f"projection: {args.project_samples} samples + nominal x {args.project_temperatures} temperatures "
          f"= {n} cases on {args.cores} single-threaded workers: {rounds} rounds x {case_s:.1f} s = "
          f"{ideal / 60:.1f} min at full efficiency, {ideal / efficiency / 60:.1f} min at the measured "
          f"{efficiency:.0%} (per-core speed of this machine; a 0.5 mm case costs 10-20x more)")


if __name__ == "__main__":
    main()
