"""Benchmark: wall time of the default 5-temperature sweep at several meshes.

Prints the wall time per mesh and the largest relative force difference of
each mesh against the finest, over u between the kiss point and 90 % of the
full compression (the stiff end is reported separately).

    python -m cushion_clutch.benchmarks.sweep [--sizes 2e-3 1e-3 0.5e-3]
"""
from __future__ import annotations

import argparse
import tempfile
import time
from pathlib import Path

import numpy as np


def compare(coarse, fine) -> tuple[float, float]:
    """Largest relative force difference (body, stiff end) of two table sets."""
    body = end = 0.0
    for uc, fc, uf, ff in zip(coarse.u_m, coarse.force_N, fine.u_m, fine.force_N):
        u_max = min(uc[-1], uf[-1])
        u = uf[(uf > 0) & (uf <= 0.9 * u_max)]
        rel = np.abs(np.interp(u, uc, fc) / np.interp(u, uf, ff) - 1)
        body = max(body, float(rel.max()))
        u_end = uf[(uf > 0.9 * u_max) & (uf <= u_max)]
        if len(u_end):
            end = max(end, float(np.max(np.abs(np.interp(u_end, uc, fc) / np.interp(u_end, uf, ff) - 1))))
    return body, end


def main(argv=None) -> None:
    from cushion_clutch.fe.params import load_params
    from cushion_clutch.fe.sweep import build_tables, run_sweep
    from cushion_clutch.fe.tables import read_tables

    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--sizes", type=float, nargs="+", default=[2e-3, 1e-3, 0.5e-3])
    ap.add_argument("--jobs", type=int, default=None)
    ap.add_argument("--cache", type=Path, default=None,
                    help="case cache to fill (default: a temporary one, so every case is solved)")
    args = ap.parse_args(argv)
    tables = {}
    with tempfile.TemporaryDirectory() as tmp:
        for size in args.sizes:
            p = load_params().replace(mesh={"element_size_m": size})
            t0 = time.perf_counter()
            outcomes = run_sweep(p, cache_dir=args.cache or Path(tmp) / f"cache_{size:g}", jobs=args.jobs)
            wall = time.perf_counter() - t0
            out = Path(tmp) / f"tables_{size:g}"
            build_tables(p, outcomes, out, wall_time_s=wall)
            tables[size] = read_tables(out)
            o = next(iter(outcomes.values()))
            d195 = dict(zip(tables[size].theta_degC, tables[size].delta_kiss_m)).get(195.0, float("nan"))
            print(f"mesh {size * 1e3:4.2f} mm: {o.n_elements:5d} elements, sweep wall time "
                  f"{wall:7.1f} s, delta_kiss(195 C) = {d195 * 1e3:.4f} mm, "
                  f"F_full(20 C) = {tables[size].force_N[0][-1]:.0f} N", flush=True)
    finest = min(args.sizes)
    for size in args.sizes:
        if size != finest:
            body, end = compare(tables[size], tables[finest])
            print(f"mesh {size * 1e3:.2f} mm vs {finest * 1e3:.2f} mm: largest relative force "
                  f"difference {body:.2%} (u up to 90 % of full compression), {end:.2%} at the stiff end")


if __name__ == "__main__":
    main()
