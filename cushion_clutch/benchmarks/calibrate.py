"""Benchmark: calibrate 2-3 parameters of the default spring at the 2 mm mesh, from raw curves.

The "measurement" is the FE curve of the default spring with known perturbed
parameters plus 1 % noise, kept raw (noisy, not made monotone: a running
maximum would bias the curve upwards), and the pair's free height with a
10 um 1-sigma (``--free-height-sd 0``: a bench without that datum, where the
wave height is poorly identified and the report says so); the calibration
starts from the default and must find them again. ``--hot`` adds a 195 degC curve (u from
the 20 degC kiss point) and fits a thermal key too. Prints the report, the
recovered values, the errors, FE case count and wall time; writes the Fig. 9
style PNG.

    python -m cushion_clutch.benchmarks.calibrate [--fit wave_height_m,thickness_m] [--hot] [--png fig.png]

Limit: the measurement comes from the same FE model (same mesh), so it shows
what the fit recovers from noise, not how well the model follows a real bench.
"""
from __future__ import annotations

import argparse
import tempfile
from pathlib import Path

import numpy as np

#: perturbation factors of the "true" spring
TRUTH = {"wave_height_m": 1.08, "thickness_m": 0.95, "far_end_stiffness_N_per_m": 1.3,
         "temperature_ratio": 0.8, "wave_tilt_m": 1.2}


def synthetic_curves(truth, temperatures, cache: Path, noise: float = 0.01, points: int = 30, seed: int = 1,
                     free_height_sd_m: float = 0.0):
    """Noisy FE 'measurements' of ``truth`` at ``temperatures``, u from the reference kiss point; with
    ``free_height_sd_m`` > 0 each carries the pair's free height with that much noise (m)."""
    from cushion_clutch.fe.studies.measured import Measured
    from cushion_clutch.fe.studies.tolerance_report import pair_free_height
    from cushion_clutch.fe.sweep import run_sweep
    from cushion_clutch.fe.tables import curve_from_case, kiss_shift

    ref = truth.material.reference_temperature_degC
    p = truth.replace(sweep={"temperatures_degC": tuple(sorted({ref, *temperatures}))})
    cases = run_sweep(p, cache_dir=cache, jobs=len(p.sweep.temperatures_degC))
    curves = {t: curve_from_case(o.result, 1, p.sweep.kiss_force_N) for t, o in cases.items()}
    shift = kiss_shift(list(curves.values()), ref)
    rng = np.random.default_rng(seed)
    out = []
    for t in temperatures:
        c = curves[t]
        u = np.linspace(-shift[t] + 0.02e-3, 0.95 * c.u_m[-1] - shift[t], points)
        f = np.interp(u + shift[t], c.u_m, c.force_N)
        f = f * (1 + noise * rng.standard_normal(points))
        h = (pair_free_height(p, cases[t]) + free_height_sd_m * rng.standard_normal() if free_height_sd_m > 0
             else None)
        out.append(Measured(u, f, "pair", float(t), f"FE truth at {t:g} degC + {noise:.0%} noise",
                            h, free_height_sd_m if h is not None else None))
    return out


def main(argv=None) -> None:
    from cushion_clutch.fe.studies.calibrate import calibrate, fit_keys, with_values
    from cushion_clutch.fe.studies.calibration_report import plot_calibration, report_text
    from cushion_clutch.fe.joint import resolve_far_end
    from cushion_clutch.fe.params import load_params

    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--fit", default=None, help="keys to fit (default: wave_height_m,thickness_m; "
                                                "with --hot: thickness_m,temperature_ratio)")
    ap.add_argument("--truth", default=None, help="keys perturbed in the truth (default: the fitted ones)")
    ap.add_argument("--hot", action="store_true", help="also a 195 degC curve")
    ap.add_argument("--free-height-sd", type=float, default=10e-6,
                    help="1-sigma of the measured free height, m (0: no free height measured)")
    ap.add_argument("--mesh", type=float, default=2e-3)
    ap.add_argument("--jobs", type=int, default=2)
    ap.add_argument("--png", type=Path, default=None)
    args = ap.parse_args(argv)
    names = (args.fit or ("thickness_m,temperature_ratio" if args.hot else "wave_height_m,thickness_m")).split(",")
    base = load_params().replace(mesh={"element_size_m": args.mesh}, sweep={"temperatures_degC": (20.0,)})
    base = resolve_far_end(base)       # the predicted joint as a number, so that it can be perturbed and fitted
    tkeys = fit_keys(base, (args.truth or ",".join(names)).split(","))
    true_all = np.array([getattr(getattr(base, s), k) * TRUTH[k] for s, k in tkeys])
    with tempfile.TemporaryDirectory() as tmp:
        truth = with_values(base, tkeys, true_all)
        measured = synthetic_curves(truth, (20.0, 195.0) if args.hot else (20.0,), Path(tmp) / "truth",
                                    free_height_sd_m=args.free_height_sd)
        cal = calibrate(base, measured, names, cache_dir=Path(tmp) / "cal", jobs=args.jobs)
    print(report_text(cal), end="")
    true = {f"{s}.{k}": v for (s, k), v in zip(tkeys, true_all)}
    for n, v, s0, sd in zip(cal.names, cal.values, cal.start, cal.std):
        t = true.get(n, s0)
        print(f"{n}: true {t:.5g}, recovered {v:.5g} ({v / t - 1:+.2%}, {(v - t) / sd:+.2f} of its 1-sigma "
              f"{sd / abs(v):.2%})")
    print(f"calibration of {len(names)} parameters at {args.mesh * 1e3:g} mm: {cal.wall_time_s:.0f} s wall, "
          f"{cal.fe_cases} FE cases, {args.jobs} jobs")
    if args.png:
        plot_calibration(cal, args.png, "Default spring at 2 mm: FE against a noisy FE 'measurement'")
        print(f"wrote {args.png}")


if __name__ == "__main__":
    main()
