"""Issue 26's bar for the production TCU: every shipped scenario, naive and production, from the launch metrics.

    python -m cushion_clutch.benchmarks.production_bar [--scenarios default,cooldown,...] [--repeat N] [--seed N]
    python -m cushion_clutch.benchmarks.production_bar --out docs/results/production_bar.md

Per scenario: production's worst characteristic error over all launches (the first included; target
<= 7.2 N.m, 3 % of the engine's 240 N.m peak) and over the hot launches, naive's, every launch starting
below 40 degC where production is more than 0.5 N.m worse than naive (target: none), the largest
|theta_cs error| at a launch start, how the production TCU started (reset / learned; its standstill
touch-point error), the plant's peak temperatures and the CPU-time real-time factors (median of
``--repeat`` runs). Machines are noisy: compare the factors of one run.
"""
from __future__ import annotations

import argparse
import math
import statistics
import sys
import tempfile
from pathlib import Path

SHIPPED = ("default", "trailer", "cooldown", "creep", "fade", "wear", "wear_learned", "tolerance", "protection")


def bar(name: str, repeat: int = 1, seed: int | None = None) -> dict:
    """Run ``name`` with the naive and the production TCU; the bar's figures.

    ``seed``: another realisation of the sensors' noise (``tcu_sensors.seed`` and ``sensors.seed`` both set to
    it; None: the scenario's own), to see how much of a figure is one noise draw.
    """
    import dataclasses

    from cushion_clutch.data import DEFAULT_TABLES
    from cushion_clutch.launch.plant.build import build_plant_fmu
    from cushion_clutch.launch.report import peaks
    from cushion_clutch.launch.scenario import load_scenario, scenario_path
    from cushion_clutch.launch.simulate import simulate_launches
    from cushion_clutch.model import load_table

    sc = load_scenario(scenario_path(name))
    if seed is not None:
        sc = dataclasses.replace(sc, tcu_sensors=dataclasses.replace(sc.tcu_sensors, seed=seed),
                                 sensors=dataclasses.replace(sc.sensors, seed=seed))
    tables = Path(DEFAULT_TABLES)
    table = load_table(sc.tables_path("tcu") or tables)
    with tempfile.TemporaryDirectory() as tmp:
        fmu = build_plant_fmu(tables, sc, Path(tmp) / "CushionClutch.fmu")
        res, rtf = {}, {}
        for v in ("naive", "production"):
            runs = [simulate_launches(fmu, sc, table, v) for _ in range(repeat)]
            res[v] = runs[0]
            rtf[v] = statistics.median(r.sim_time_s / r.cpu_time_s for r in runs)
    n, p = res["naive"].metrics, res["production"].metrics
    ch = "characteristic_error_max_Nm"
    valid = [m for m in p if not math.isnan(m[ch])]
    cold = [(m["launch"], m[ch], a[ch]) for m, a in zip(p, n)
            if m["theta_cs_start_degC"] < 40.0 and not math.isnan(m[ch])]
    return {"scenario": name, "n": len(p),
            "prod_all": max(m[ch] for m in valid),
            "prod_hot": max((m[ch] for m in valid if m["hot"]), default=math.nan),
            "naive_all": max(m[ch] for m in n if not math.isnan(m[ch])),
            "naive_hot": max((m[ch] for m in n if m["hot"] and not math.isnan(m[ch])), default=math.nan),
            "cold": cold, "cold_fail": [c for c in cold if c[1] > c[2] + 0.5],
            "theta_err": max(abs(m["theta_cs_error_K"]) for m in p if not math.isnan(m["theta_cs_error_K"])),
            "rtf_naive": rtf["naive"], "rtf_prod": rtf["production"],
            **{f"prod_{k}": v for k, v in peaks(res["production"]).items()},
            "naive_theta_cm_peak_degC": peaks(res["naive"])["plant_theta_cm_peak_degC"]}


INTRO = """Issue 26's bar for the production TCU, every shipped scenario run with the naive and the production TCU
on the committed tables and the native plant FMU. The bar: production's worst characteristic error over all
launches, the first included, at most 7.2 N.m (3 % of the engine's 240 N.m peak), and on every launch that
starts below 40 degC within 0.5 N.m of naive's or better. Also: the largest |theta_cs error| of production's
estimate at a launch start (target 15 K), how its TCU started (reset: standstill touch-point learning, with
that routine's error; learned: a stored state), the plant's peak temperatures, and the CPU-time real-time
factors (sim time / CPU time; median of `--repeat` runs; machine-dependent, noisy under load). `--seed N`
reruns every scenario with another realisation of the sensors' noise. How the
production TCU works: [the production TCU](../explanation/production_tcu.md)."""

HEADER = ("| scenario | launches | production worst, all [N.m] | production worst, hot [N.m] | naive worst, all [N.m] "
          "| naive worst, hot [N.m] | launches < 40 degC: production / naive [N.m] | bar "
          "| max abs theta_cs error at a start [K] | start, standstill error [um] "
          "| plant peak theta_cm / theta_cs [degC] (naive's theta_cm) | RTF naive / production (CPU) |")


def row(name: str, b: dict) -> str:
    """One Markdown table row of :func:`bar`'s figures."""
    ok = b["prod_all"] <= 7.2 and not b["cold_fail"]
    cold = ", ".join(f"L{k}: {x:.2f} / {y:.2f}" for k, x, y in b["cold"]) or "–"
    return (f"| {name} | {b['n']} | {b['prod_all']:.2f} | {b['prod_hot']:.2f} | {b['naive_all']:.2f} | "
            f"{b['naive_hot']:.2f} | {cold} | {'met' if ok else 'MISSED'} | {b['theta_err']:.1f} | "
            f"{b['prod_tcu_start']}, {b['prod_standstill_kiss_error_um']:.1f} | "
            f"{b['prod_plant_theta_cm_peak_degC']:.0f} / {b['prod_plant_theta_cs_peak_degC']:.0f} "
            f"({b['naive_theta_cm_peak_degC']:.0f}) | {b['rtf_naive']:.0f} / {b['rtf_prod']:.0f} |")


def main(argv: list[str] | None = None) -> None:
    from .page import add_draft_option, results_page

    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--scenarios", default=",".join(SHIPPED), help="comma-separated shipped scenario names")
    ap.add_argument("--repeat", type=int, default=1, help="runs per TCU; the real-time factor is their median")
    ap.add_argument("--seed", type=int, help="sensor-noise seed for every scenario (default: each scenario's own)")
    ap.add_argument("--out", type=Path, help="also write the table as a results page (docs/results/production_bar.md)")
    add_draft_option(ap)
    a = ap.parse_args(argv)
    rows = []
    with results_page(a.out, "Production TCU bar", "cushion_clutch.benchmarks.production_bar", argv,
                      INTRO) as page:
        stream = sys.stderr if a.out is not None else sys.stdout     # the page gets the table, not the progress
        print(HEADER, file=stream)
        for name in a.scenarios.split(","):
            rows.append(row(name, bar(name, a.repeat, a.seed)))
            print(rows[-1], file=stream, flush=True)
        if a.out is not None:
            page.markdown("\n".join([HEADER, "|" + "---|" * 12, *rows]))


if __name__ == "__main__":
    main()
