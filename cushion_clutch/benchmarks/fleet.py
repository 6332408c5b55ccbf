"""Issue 38's figures: the fleet on Dask, its throughput, the duty cycles' restarts to damage, physical launches.

    python -m cushion_clutch.benchmarks.fleet --part possible,duty,bar,identity,scaling,aware --work W
    python -m cushion_clutch.benchmarks.fleet --page docs/results/fleet.md --work W

Each part keeps its figures in ``W/<part>.json`` (the fleet runs their outputs in ``W``, resumable), the page
is written from those that exist, so a part that did not run is said to be missing, never guessed:

* ``possible``: per shipped scenario and demand level, the engine's largest torque at the pedal against the
  torque that holds the car on the grade (:func:`~cushion_clutch.launch.results.metrics.launch_capability`);
* ``duty``: ``hill_restart`` and ``hill_fade`` with naive (no estimate, no protection), aware_estimated and
  production, with and without protection: restarts to damage (facings or friction surface above 350 degC,
  LuK 2006), peak temperature, inhibited and stranded launches. A run whose facings leave the clutch FMU's
  800 K input range stops there; it is rerun up to the launch before, and the page says so;
* ``bar``: ``cushion-clutch fleet --population default --samples N --tcus naive,production --jobs 2 --seed 1``;
* ``identity``: the same with ``--samples 20 --jobs 1``: are its rows those of samples 0-19 of ``bar``?
* ``scaling``: launches per second per core on 1 and 2 workers (fresh runs of ``--scaling-samples``), the
  parallel efficiency, the load average around each (the machine is shared: contended figures say so);
* ``aware``: aware_estimated on the same samples as ``bar``.
"""
from __future__ import annotations

import argparse
import json
import math
import os
import shutil
import sys
import time
from pathlib import Path

PARTS = ("possible", "duty", "bar", "identity", "scaling", "aware", "big")
DUTIES = ("hill_restart", "hill_fade")
METRICS = ("characteristic_error_max_Nm", "characteristic_error_rms_Nm", "tracking_error_max_Nm",
           "engagement_time_s", "peak_theta_cm_degC", "stranded", "lockups")


def _load() -> list[float]:
    return [round(x, 2) for x in os.getloadavg()]


def part_possible(work: Path) -> dict:
    from cushion_clutch.launch.results.metrics import launch_capability, launch_possible
    from cushion_clutch.launch.scenario import load_scenario, scenario_path, shipped_names
    rows = []
    for name in shipped_names():
        sc = load_scenario(scenario_path(name))
        for level in dict.fromkeys(sc.driver.levels):
            engine, load = launch_capability(sc, level)
            possible = launch_possible(sc, level)
            rows.append({"scenario": name, "level": level, "pedal": sc.driver.pedal(level),
                         "mass_kg": sc.vehicle.mass_kg, "grade_percent": sc.vehicle.slope_percent,
                         "engine_Nm": engine, "load_Nm": load, "possible": possible})
    return {"rows": rows}


def _duty_run(fmu, sc, table, tcu):
    """Simulate the duty; a run whose plant leaves the FMU's domain (a facing past 800 K) stops at the refused step
    and keeps the launches before it (``LaunchResult.stopped``); the note then says where and why."""
    from cushion_clutch.launch.report import run_all
    res = run_all(fmu, sc, table, (tcu,))[tcu]
    return res, (f"stopped early, {res.stopped[:160]}" if res.stopped else None)


def part_duty(work: Path) -> dict:
    import dataclasses

    from cushion_clutch.data import DEFAULT_TABLES
    from cushion_clutch.launch.fleet.duty import DAMAGE_DEGC, peak_degC, restarts_to_damage
    from cushion_clutch.launch.plant.build import build_plant_fmu
    from cushion_clutch.launch.scenario import load_scenario, scenario_path
    from cushion_clutch.model import load_table

    rows = []
    for name in DUTIES:
        sc = load_scenario(scenario_path(name))
        table = load_table(sc.tables_path("tcu") or DEFAULT_TABLES)
        fmu = build_plant_fmu(Path(DEFAULT_TABLES), sc, work / "duty_fmu" / name / "CushionClutch.fmu")
        for tcu, prot in (("naive", False), ("aware_estimated", False), ("aware_estimated", True),
                          ("production", False), ("production", True)):
            s = dataclasses.replace(sc, protection=dataclasses.replace(sc.protection, enabled=prot))
            t0 = time.perf_counter()
            res, note = _duty_run(fmu, s, table, tcu)
            m = res.metrics
            rows.append({"scenario": name, "tcu": tcu, "protection": prot, "launches": sc.run.launches,
                         "simulated": len(m), "restarts_to_damage": restarts_to_damage(res.series, DAMAGE_DEGC),
                         "peak_degC": peak_degC(res.series), "lockups": sum(math.isfinite(x["engagement_time_s"])
                                                                           for x in m),
                         "inhibited": sum(x["protection_level"] >= 3 for x in m),
                         "stranded": sum(bool(x["stranded"]) for x in m),
                         "impossible": sum(not x["launch_possible"] for x in m), "note": note,
                         "wall_s": time.perf_counter() - t0})
            print(rows[-1], flush=True)
    return {"rows": rows, "damage_degC": DAMAGE_DEGC}


def _fleet(work: Path, folder: str, samples: int, tcus, jobs: int | None, serial=False) -> dict:
    from cushion_clutch.data import DEFAULT_TABLES
    from cushion_clutch.launch.fleet.run import run_fleet
    from cushion_clutch.launch.fleet.population import load_population, population_path
    pop = load_population(population_path("default"))
    load0 = _load()
    res = run_fleet(pop, Path(DEFAULT_TABLES), work / folder, samples, tcus, 1, jobs=jobs, serial=serial,
                    progress=lambda d, t: print(f"\r{folder}: {d}/{t}", end="", flush=True))
    print()
    return {"folder": folder, "samples": samples, "tcus": list(tcus), "jobs": jobs, "ran": res.ran, "kept": res.kept,
            "wall_s": res.wall_s, "workers": res.workers, "launches_run": res.launches_run,
            "launches_per_s_per_core": res.launches_per_s_per_core, "load_before": load0, "load_after": _load(),
            "summary": res.summary}


def part_bar(work: Path, samples: int) -> dict:
    return _fleet(work, "fleet_naive_production", samples, ("naive", "production"), 2)


def part_aware(work: Path, samples: int) -> dict:
    return _fleet(work, "fleet_aware_estimated", samples, ("aware_estimated",), 2)


def part_big(work: Path, samples: int) -> dict:
    """naive, production (resuming the bar's folder) and aware_estimated on ``samples`` samples."""
    return {"runs": [_fleet(work, "fleet_naive_production", samples, ("naive", "production"), 2),
                     _fleet(work, "fleet_aware_estimated", samples, ("aware_estimated",), 2)]}


def part_identity(work: Path) -> dict:
    from cushion_clutch.launch.fleet.run import SAMPLES_FILE, read_samples
    out = _fleet(work, "fleet_naive_production_20_jobs1", 20, ("naive", "production"), 1)
    a = read_samples(work / "fleet_naive_production_20_jobs1" / SAMPLES_FILE)
    b = [r for r in read_samples(work / "fleet_naive_production" / SAMPLES_FILE) if r["sample"] < 20]
    same = len(a) == len(b) and all(
        set(x) == set(y) and all(x[k] == y[k] or (isinstance(x[k], float) and math.isnan(x[k]) and math.isnan(y[k]))
                                 for k in x) for x, y in zip(a, b))
    out["identical"] = bool(same)
    out["rows"] = len(a)
    return out


def part_scaling(work: Path, samples: int) -> dict:
    runs = []
    for jobs in (1, 2):
        folder = f"scaling_jobs{jobs}"
        shutil.rmtree(work / folder, ignore_errors=True)
        runs.append(_fleet(work, folder, samples, ("naive", "production"), jobs))
    t1, t2 = runs[0]["launches_per_s_per_core"], runs[1]["launches_per_s_per_core"]
    return {"runs": runs, "efficiency_2": t2 / t1 if t1 > 0 else math.nan}


def _f(v, fmt=".2f") -> str:
    return "–" if v is None or (isinstance(v, float) and math.isnan(v)) else format(v, fmt)


def write_page(work: Path, page: Path, argv: list[str]) -> None:
    from cushion_clutch.benchmarks.page import results_page
    got = {p: json.loads((work / f"{p}.json").read_text()) for p in PARTS if (work / f"{p}.json").is_file()}
    with results_page(page, "Fleet study, duty cycles, stranded launches", "cushion_clutch.benchmarks.fleet",
                      argv) as out:
        out.markdown(INTRO)
        out.markdown("## The production TCU over the fleet\n")
        runs = [(r, ", ".join(r["tcus"])) for r in got["big"]["runs"]] if "big" in got else \
            [(got[p], label) for p, label in (("bar", "naive and production"), ("aware", "aware_estimated"))
             if p in got]
        if not runs:
            out.markdown("*No fleet run for this page.*\n")
        for g, label in runs:
            out.markdown(f"Population `default`, samples 0-{g['samples'] - 1}, seed 1, {label}: {g['ran']} samples "
                         f"run ({g['kept']} kept from an earlier run) in {g['wall_s']:.0f} s on {g['workers']} "
                         f"worker(s); load average {g['load_before'][0]} before, {g['load_after'][0]} after.\n")
            lines = ["| TCU | metric (worst of a sample's launches) | P50 | P95 | P99 | max |", "|---|---|---|---|---|---|"]
            lines += [f"| {r['tcu']} | {r['metric']} | {_f(r['p50'])} | {_f(r['p95'])} | {_f(r['p99'])} | {_f(r['max'])} |"
                      for r in g["summary"] if r["metric"] in METRICS]
            out.markdown("\n".join(lines) + "\n")
        if "bar" in got:
            g = got["bar"]
            out.markdown(f"### The bar: `cushion-clutch fleet --population default --samples {g['samples']} --tcus "
                         f"naive,production --jobs 2 --seed 1`\n")
            p99 = next((r["p99"] for r in got["bar"]["summary"] if r["tcu"] == "production"
                        and r["metric"] == "characteristic_error_max_Nm"), math.nan)
            out.markdown(f"Bar: production's P99 of `characteristic_error_max_Nm` {_f(p99)} N·m (at most 9.4 N·m: "
                         f"{'met' if p99 <= 9.4 else 'NOT met'}); the run took {got['bar']['wall_s'] / 60:.1f} min "
                         f"on 2 workers (at most 15 min on two idle cores: "
                         f"{'met' if got['bar']['wall_s'] <= 900 else 'not met on this machine'}, "
                         f"load average {got['bar']['load_before'][0]}).\n")
            from cushion_clutch.launch.fleet.run import SAMPLES_FILE, plot_fleet, read_samples
            rows, tcus = [], []
            for g, _ in runs:
                rows += read_samples(work / g["folder"] / SAMPLES_FILE)
                tcus += g["tcus"]
            png = page.parent.parent / "images" / "fleet_default.png"
            out.written.append(png)                 # the page's own figure: not a change of the measured code
            plot_fleet(rows, tcus, png, f"population 'default', {runs[0][0]['samples']} samples, seed 1")
            out.markdown("![fleet](../images/fleet_default.png)\n\nCDF of the characteristic error per TCU (the worst "
                         "of each sample's launches), and the error against the ambient temperature and the facing "
                         "wear (drawn by this benchmark from the runs' `fleet_samples.parquet`).\n")
        if "identity" in got:
            g = got["identity"]
            out.markdown(f"Reproducibility: `--samples 20 --jobs 1` gave {g['rows']} rows, "
                         f"{'identical to' if g['identical'] else 'DIFFERENT from'} samples 0-19 of the 200-sample "
                         f"run on 2 workers.\n")
        out.markdown("## Throughput and parallel efficiency\n")
        every = [(p, r) for p in ("bar", "identity", "aware") if p in got for r in [got[p]]]
        every += [("big", r) for r in got.get("big", {}).get("runs", [])]
        every += [("scaling", r) for r in got.get("scaling", {}).get("runs", [])]
        if every:
            lines = ["| part | TCUs | workers | samples run | launches | wall [s] | launches/s per core | load average "
                     "before / after |", "|---|---|---|---|---|---|---|---|"]
            lines += [f"| {p} | {', '.join(r['tcus'])} | {r['workers']} | {r['ran']} | {r['launches_run']} | "
                      f"{r['wall_s']:.0f} | {r['launches_per_s_per_core']:.2f} | {r['load_before'][0]} / "
                      f"{r['load_after'][0]} |" for p, r in every if r["ran"]]
            out.markdown("Every fleet run of this page (the wall time from the checked cluster to the last sample; "
                         "the FMU builds and the cluster's start excluded; launches of every TCU):\n\n"
                         + "\n".join(lines) + "\n")
        if "scaling" in got:
            g = got["scaling"]
            lines = ["| workers | samples | launches | wall [s] | launches/s per core | load average before / after |",
                     "|---|---|---|---|---|---|"]
            lines += [f"| {r['workers']} | {r['samples']} | {r['launches_run']} | {r['wall_s']:.1f} | "
                      f"{r['launches_per_s_per_core']:.3f} | {r['load_before'][0]} / {r['load_after'][0]} |"
                      for r in g["runs"]]
            out.markdown("\n".join(lines))
            contended = max(max(r["load_before"][0], r["load_after"][0]) for r in g["runs"]) > 1.5
            out.markdown(f"\nParallel efficiency at 2 workers ({g['runs'][0]['samples']} samples each, fresh runs): "
                         f"{g['efficiency_2']:.2f} (launches/s per core at 2 workers over that at 1; short runs "
                         f"count the workers' start-up). " + ("**Contended:** the machine's load average exceeded its "
                                                        "2 cores during these runs (other jobs), so the figures "
                                                        "are lower bounds, not the code's speed."
                                                        if contended else "") + "\n")
        else:
            out.markdown("*Part `scaling` did not run for this page.*\n")
        out.markdown(DUTY_INTRO)
        if "duty" in got:
            lines = ["| duty | TCU | protection | launches run | restarts to damage | peak facing / surface [degC] | "
                     "lock-ups | inhibited | stranded | note |", "|---|---|---|---|---|---|---|---|---|---|"]
            lines += [f"| {r['scenario']} | {r['tcu']} | {'on' if r['protection'] else 'off'} | "
                      f"{r['simulated']} of {r['launches']} | {r['restarts_to_damage'] or 'none'} | "
                      f"{r['peak_degC']:.0f} | {r['lockups']} | {r['inhibited']} | {r['stranded']} | "
                      f"{(r['note'] or '').split(' (')[0]} |" for r in got["duty"]["rows"]]
            out.markdown("\n".join(lines) + "\n")
        else:
            out.markdown("*Part `duty` did not run for this page.*\n")
        out.markdown(POSSIBLE_INTRO)
        if "possible" in got:
            lines = ["| scenario | level | pedal | mass [kg] | grade [%] | engine at the pedal [N·m] | holding torque "
                     "[N·m] | possible |", "|---|---|---|---|---|---|---|---|"]
            lines += [f"| {r['scenario']} | {r['level']} | {r['pedal']:.2f} | {r['mass_kg']:.0f} | "
                      f"{r['grade_percent']:.0f} | {r['engine_Nm']:.0f} | {r['load_Nm']:.0f} | "
                      f"{'yes' if r['possible'] else 'no'} |" for r in got["possible"]["rows"]]
            out.markdown("\n".join(lines))


INTRO = """`cushion-clutch fleet` draws samples of the `default` population
(`cushion_clutch/launch/populations/default.toml`: car mass 1450-2150 kg, one drive in ten with a 500-1350 kg
trailer, grades 0-20 %, ambient -30..40 degC, start temperature up to 40 K above ambient, pedal 0.3-1.0
correlated with the mass, a launch every 20-120 s, nine in ten springs nominal and one in ten the P95 spring,
facing wear up to 0.5 mm the TCUs do not know, noise seeds per sample), runs each sample's five launches with
each TCU on a local Dask cluster and keeps of every launch metric the worst over the sample's launches. The
default tables reach down to -40 degC; the P95 spring's tables (the tolerance study's, not swept again) start
at 20 degC and clamp the characteristic below it (plant and TCUs alike; `beyond_tables_s` counts it), so a cold
sample with that spring measures no temperature error. How to run it: [the fleet tutorial](../tutorials/fleet.md).
"""

DUTY_INTRO = """## Duty cycles: restarts to damage

`hill_restart` (90 restarts on 12 % at full load with a trailer, 3500 kg: LuK Symposium 2006 "Double Clutch -
Wet or Dry", SAE 2026-26-0434) and `hill_fade` (150 launches on 15 % with cooling: SAE 2021-26-0329). Restarts
to damage: the first restart at which the plant's facings or its metal friction surface pass 350 degC, the
lower bound of the damage range LuK give (350-400 degC). naive has no temperature estimate and cannot
protect. A run whose facings leave the clutch FMU's input range (800 K) is stopped there by the FMU and
rerun up to the launch before (the note says where).
"""

POSSIBLE_INTRO = """## Which launches are physically possible

Per shipped scenario and demand level: the engine's largest net torque at the pedal over its speed range
(creep: the idle governor's full throttle at idle) against the clutch torque that holds the car on the grade,
both at the disc; possible when it exceeds it and, at best, gets the car within the pedal time to the engine
speed that holds it (`launch_possible`). A launch without lock-up is *stranded* only when it is possible and the protection did not
inhibit it (`stranded` in `launch_metrics.csv`); the others count as impossible.
"""


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--part", default="", help="comma-separated parts: " + ", ".join(PARTS))
    ap.add_argument("--work", default="fleet_benchmark", help="working folder (fleet runs, part results)")
    ap.add_argument("--samples", type=int, default=200, help="samples of the bar and aware parts (default 200)")
    ap.add_argument("--big-samples", type=int, default=1000, help="samples of the big part (default 1000)")
    ap.add_argument("--scaling-samples", type=int, default=30, help="samples of each scaling run (default 30)")
    ap.add_argument("--page", help="write the results page (from the parts' results in --work)")
    args = ap.parse_args(argv)
    work = Path(args.work)
    work.mkdir(parents=True, exist_ok=True)
    for part in [p for p in args.part.split(",") if p]:
        if part not in PARTS:
            print(f"unknown part {part!r}; allowed {', '.join(PARTS)}", file=sys.stderr)
            return 2
        t0 = time.perf_counter()
        fn = {"possible": lambda: part_possible(work), "duty": lambda: part_duty(work),
              "bar": lambda: part_bar(work, args.samples), "identity": lambda: part_identity(work),
              "scaling": lambda: part_scaling(work, args.scaling_samples),
              "aware": lambda: part_aware(work, args.samples),
              "big": lambda: part_big(work, args.big_samples)}[part]
        res = fn()
        res["part_wall_s"] = time.perf_counter() - t0
        (work / f"{part}.json").write_text(json.dumps(res, indent=1, default=str))
        print(f"part {part}: {res['part_wall_s']:.0f} s", flush=True)
    if args.page:
        write_page(work, Path(args.page), list(sys.argv[1:] if argv is None else argv))
        print(f"wrote {args.page}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
