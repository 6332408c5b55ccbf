"""What a bench curve tells about each spring parameter: sensitivities of the measured quantities (issue 37).

For the default spring at 20 degC, each of ``wave_height_m``, ``thickness_m`` and ``wave_tilt_m`` is raised
by ``--step`` (5 %) and the FE rerun; printed per parameter, as d ln X / d ln p:

- the pair force at fixed compressions u from its own kiss point (the curve a bench measures from the kiss
  point), at u / u_end = 0.2 ... 0.95, u_end the base curve's last point, and its RMS over those points;
- the pair's free height at the kiss force (plate to plate from a datum; :func:`pair_free_height`), also
  in um per 1 %;
- the travel from the kiss point to the end of the FE's compression (``solver.flatten_fraction`` of the
  wave height past the initial gap) and the force there.

The table goes between the markers of ``--write PAGE`` (the calibration tutorial), or to stdout.

    python -m cushion_clutch.benchmarks.identifiability [--mesh 2e-3] [--write docs/tutorials/own_spring.md]
"""
from __future__ import annotations

import argparse
import sys
import tempfile
from pathlib import Path

import numpy as np

MARK_BEGIN = "<!-- identifiability numbers: begin -->"
MARK_END = "<!-- identifiability numbers: end -->"
#: compressions from the kiss point at which the force is compared, fraction of the base curve's last point
FRACTIONS = (0.2, 0.4, 0.6, 0.8, 0.95)
PARAMETERS = ("wave_height_m", "thickness_m", "wave_tilt_m")


def sensitivities(base, step: float, cache: Path, jobs: int = 2) -> tuple[list[dict], dict]:
    """One row per parameter of :data:`PARAMETERS`: d ln X / d ln p of each measured quantity (one-sided step)."""
    from concurrent.futures import ThreadPoolExecutor

    from cushion_clutch.fe.studies.tolerance_report import pair_free_height
    from cushion_clutch.fe.sweep import run_sweep
    from cushion_clutch.fe.tables import curve_from_case

    def solve(p):
        o = next(iter(run_sweep(p, cache_dir=cache, jobs=1).values()))
        return curve_from_case(o.result, 1, p.sweep.kiss_force_N), pair_free_height(p, o)

    specs = [base] + [base.replace(geometry={k: getattr(base.geometry, k) * (1 + step)}) for k in PARAMETERS]
    with ThreadPoolExecutor(max_workers=jobs) as pool:
        (c0, h0), *others = list(pool.map(solve, specs))
    u = np.array(FRACTIONS) * c0.u_m[-1]
    f0 = np.interp(u, c0.u_m, c0.force_N)
    dl = np.log1p(step)
    rows = []
    for key, (c, h) in zip(PARAMETERS, others):
        s = np.log(np.interp(u, c.u_m, c.force_N) / f0) / dl
        rows.append({"parameter": key, "force": s, "force_rms": float(np.sqrt(np.mean(s ** 2))),
                     "free_height": float(np.log(h / h0) / dl), "free_height_um_per_pct": (h - h0) / step * 0.01e6,
                     "travel": float(np.log(c.u_m[-1] / c0.u_m[-1]) / dl),
                     "force_end": float(np.log(c.force_N[-1] / c0.force_N[-1]) / dl)})
    return rows, {"u_end_m": float(c0.u_m[-1]), "free_height_m": float(h0), "force_end_N": float(c0.force_N[-1])}


def markdown(rows: list[dict], base_values: dict, base, step: float, command: str) -> str:
    """The block for the tutorial: a table of the sensitivities and the base values it was taken at."""
    head = " | ".join(f"F at u/u_end {x:g}" for x in FRACTIONS)
    lines = [f"<!-- written by `{command}`; do not edit -->", "",
             f"Default spring (carrier clearance {base.geometry.carrier_clearance_m * 1e3:g} mm), 20 °C, "
             f"{base.mesh.element_size_m * 1e3:g} mm {base.mesh.element_type} mesh, "
             f"{base.solver.compression_increments} increments, one-sided steps of {step:.0%}; d ln X / d ln p "
             f"(0.1: a 1 % change of p moves X by 0.1 %). Base: u_end = {base_values['u_end_m'] * 1e3:.3f} mm, "
             f"free height {base_values['free_height_m'] * 1e3:.4f} mm, force at u_end "
             f"{base_values['force_end_N']:.0f} N per pair.", "",
             f"| parameter | {head} | RMS of F | free height | free height [µm per 1 %] | travel kiss to end "
             f"| F at end |",
             "|---" * (len(FRACTIONS) + 6) + "|"]
    for r in rows:
        lines.append(f"| `{r['parameter']}` | " + " | ".join(f"{v:+.2f}" for v in r["force"])
                     + f" | {r['force_rms']:.2f} | {r['free_height']:+.3f} | {r['free_height_um_per_pct']:+.1f} "
                       f"| {r['travel']:+.3f} | {r['force_end']:+.2f} |")
    return "\n".join(lines) + "\n"


def rewrite(page: Path, block: str) -> None:
    """Replace the text between :data:`MARK_BEGIN` and :data:`MARK_END` of ``page``."""
    text = page.read_text(encoding="utf-8")
    head, rest = text.split(MARK_BEGIN, 1)
    _, tail = rest.split(MARK_END, 1)
    page.write_text(head + MARK_BEGIN + "\n" + block + MARK_END + tail, encoding="utf-8")


def main(argv=None) -> None:
    from cushion_clutch.fe.params import load_params

    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--mesh", type=float, default=2e-3, help="element size, m")
    ap.add_argument("--increments", type=int, default=30, help="compression increments")
    ap.add_argument("--step", type=float, default=0.05, help="relative step of each parameter")
    ap.add_argument("--clearance", type=float, default=None,
                    help="geometry.carrier_clearance_m, m (default: the spring's)")
    ap.add_argument("--jobs", type=int, default=2)
    ap.add_argument("--write", type=Path, default=None, help="page whose marked block to rewrite")
    args = ap.parse_args(argv)
    base = load_params().replace(mesh={"element_size_m": args.mesh},
                                 solver={"compression_increments": args.increments},
                                 sweep={"temperatures_degC": (20.0,)})
    if args.clearance is not None:
        base = base.replace(geometry={"carrier_clearance_m": args.clearance})
    with tempfile.TemporaryDirectory() as tmp:
        rows, base_values = sensitivities(base, args.step, Path(tmp), args.jobs)
    command = "python -m cushion_clutch.benchmarks.identifiability " + " ".join(
        str(a) for a in (argv if argv is not None else sys.argv[1:]))
    block = markdown(rows, base_values, base, args.step, command.strip())
    if args.write:
        rewrite(args.write, block)
    sys.stdout.write(block)


if __name__ == "__main__":
    main()
