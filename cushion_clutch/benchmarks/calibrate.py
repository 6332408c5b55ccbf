"""Benchmark: calibrate 2-3 parameters of the default spring at the 2 mm mesh.

The "measurement" is the FE curve (20 degC, one pair) of the default spring
with known perturbed parameters plus 1 % noise; the calibration starts from
the default and must find them again. Prints the recovered values, the
errors, FE case count and wall time, and writes the Fig. 9 style PNG.

    python -m cushion_clutch.benchmarks.calibrate [--fit wave_height_m,thickness_m] [--png fig.png]
"""
from __future__ import annotations

import argparse
import tempfile
from pathlib import Path

import numpy as np

#: perturbation factors of the "true" spring
TRUTH = {"wave_height_m": 1.08, "thickness_m": 0.95, "far_end_stiffness_N_per_m": 1.3}


def main(argv=None) -> None:
    from cushion_clutch.fe.studies.calibrate import Measured, calibrate, fit_keys, with_values
    from cushion_clutch.fe.studies.calibration_report import plot_calibration, report_text
    from cushion_clutch.fe.params import load_params
    from cushion_clutch.fe.sweep import run_sweep
    from cushion_clutch.fe.tables import curve_from_case

    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--fit", default="wave_height_m,thickness_m")
    ap.add_argument("--mesh", type=float, default=2e-3)
    ap.add_argument("--jobs", type=int, default=2)
    ap.add_argument("--png", type=Path, default=None)
    args = ap.parse_args(argv)
    names = args.fit.split(",")
    base = load_params().replace(mesh={"element_size_m": args.mesh},
                                 sweep={"temperatures_degC": (20.0,)})
    keys = fit_keys(base, names)
    start = np.array([getattr(getattr(base, s), k) for s, k in keys])
    true = start * np.array([TRUTH[k] for _, k in keys])
    with tempfile.TemporaryDirectory() as tmp:
        truth = with_values(base, keys, true)
        case = next(iter(run_sweep(truth, cache_dir=Path(tmp) / "truth", jobs=1).values()))
        c = curve_from_case(case.result, 1, truth.sweep.kiss_force_N)
        u = np.linspace(0.0, 0.95 * c.u_m[-1], 30)
        f = np.interp(u, c.u_m, c.force_N) * (1 + 0.01 * np.random.default_rng(1).standard_normal(len(u)))
        cal = calibrate(base, Measured(u, np.maximum.accumulate(f), "pair"), names,
                        cache_dir=Path(tmp) / "cal", jobs=args.jobs)
    print(report_text(cal), end="")
    for n, v, t in zip(cal.names, cal.values, true):
        print(f"{n}: true {t:.5g}, recovered {v:.5g} ({v / t - 1:+.2%})")
    print(f"calibration of {len(names)} parameters at {args.mesh * 1e3:g} mm: {cal.wall_time_s:.0f} s wall, "
          f"{cal.fe_cases} FE cases, {args.jobs} jobs")
    if args.png:
        plot_calibration(cal, args.png, "Default spring at 2 mm: FE against a noisy FE 'measurement'")
        print(f"wrote {args.png}")


if __name__ == "__main__":
    main()
