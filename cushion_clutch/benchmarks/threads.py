"""Benchmark: one temperature case with 1 and with 2 ccx threads (OMP_NUM_THREADS, CCX_NPROC_EQUATION_SOLVER).

A sweep with fewer cases than cores gives each ccx the idle cores as
threads; this measures what that buys for one case. Runs alternate
(1, 2, 1, 2, ...) so that a changing machine load hits both alike; prints each
wall time, the medians, their ratio and the load average before and after.

    python -m cushion_clutch.benchmarks.threads [--mesh 1e-3] [--theta 20] [--repeat 2] [--threads 1 2]
"""
from __future__ import annotations

import argparse
import os
import statistics
import tempfile
import time
from pathlib import Path


def main(argv=None) -> None:
    from cushion_clutch.fe.params import load_params
    from cushion_clutch.fe.cases import solve_case

    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--mesh", type=float, default=1e-3, help="element size, m")
    ap.add_argument("--theta", type=float, default=20.0, help="case temperature, degC")
    ap.add_argument("--repeat", type=int, default=2)
    ap.add_argument("--threads", type=int, nargs="+", default=[1, 2])
    args = ap.parse_args(argv)
    base = load_params().replace(mesh={"element_size_m": args.mesh})
    times: dict[int, list[float]] = {t: [] for t in args.threads}
    forces = {}
    load0 = os.getloadavg()
    with tempfile.TemporaryDirectory(prefix="bench_threads_") as tmp:
        for r in range(args.repeat):
            for t in args.threads:
                p = base.replace(solver={"threads": t})
                start = time.perf_counter()
                out = solve_case(p, args.theta, Path(tmp) / f"t{t}_{r}")
                times[t].append(time.perf_counter() - start)
                forces[t] = float(out.result.force_N[-1])
                print(f"run {r + 1}, {t} thread(s): {times[t][-1]:.1f} s wall, ccx {out.stats.wall_time_s:.1f} s, "
                      f"full force {forces[t]:.2f} N", flush=True)
    load1 = os.getloadavg()
    med = {t: statistics.median(v) for t, v in times.items()}
    first = args.threads[0]
    print(f"{args.mesh * 1e3:g} mm S4, {args.theta:g} degC, {os.cpu_count()} cores; load average "
          f"{load0[0]:.1f} before, {load1[0]:.1f} after")
    for t in args.threads:
        print(f"{t} thread(s): median {med[t]:.1f} s over {len(times[t])} run(s); "
              f"speed-up against {first}: {med[first] / med[t]:.2f}x")
    spread = max(forces.values()) - min(forces.values())
    print(f"full-compression force differs by {spread:.3g} N between thread counts")


if __name__ == "__main__":
    main()
