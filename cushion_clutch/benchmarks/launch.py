"""Benchmark: real-time factor of a launch scenario for every TCU variant, or the launch results page.

    python -m cushion_clutch.benchmarks.launch [--scenario NAME|FILE] [--backend native|python] [--repeat N]
        [--plant native|python]
    python -m cushion_clutch.benchmarks.launch --markdown [--scenarios default,trailer,creep,cooldown,fade,wear,wear_learned,tolerance,protection]
    python -m cushion_clutch.benchmarks.launch --markdown --out docs/results/launch.md

The first form also times one FMU step (set inputs, doStep, get outputs)
through the master's cffi client and through fmpy's ``FMU2Slave`` in the
same run. ``--markdown`` runs every TCU on each scenario with the committed
tables and prints the summary tables (the columns of ``launch_summary.csv``),
the naive / aware_estimated ratio of the characteristic error, the
production TCU against issue 17's targets (:func:`production_line`) and the
real-time factors; with ``--out`` it writes them as the documentation's results page, headed by the
command, commit, machine and date, and ending with the check figures (:func:`check_table`: the first
``CHECK_LAUNCHES`` launches of ``default``, per launch and TCU) that ``tests/test_docs.py`` reruns.
Machines are noisy: compare figures from one run, or medians (``--repeat``).
"""
from __future__ import annotations

import argparse
import statistics
import tempfile
import time
from pathlib import Path
from typing import Iterator


def _fmu_call_us(fmu: Path, n: int = 50000) -> tuple[float, float]:
    """Microseconds per step: the cffi client and fmpy FMU2Slave (name-based set/get)."""
    from fmpy import extract, read_model_description
    from fmpy.fmi2 import FMU2Slave

    from cushion_clutch.launch.fmu_client import INPUTS, OUTPUTS, ClutchFmu

    c = ClutchFmu(fmu, {})
    t0 = time.perf_counter()
    for k in range(n):
        c.step(k * 1e-3, 1e-3, 0.005, 400.0, 10.0 + k * 1e-6)      # a changing input: every step sets it
    ours = (time.perf_counter() - t0) / n * 1e6
    c.close()
    md = read_model_description(str(fmu))
    vr = {v.name: v.valueReference for v in md.modelVariables}
    unzip = extract(str(fmu))
    s = FMU2Slave(guid=md.guid, unzipDirectory=unzip, modelIdentifier=md.coSimulation.modelIdentifier)
    s.instantiate()
    s.setupExperiment(startTime=0.0)
    s.enterInitializationMode()
    s.exitInitializationMode()
    vin, vout = [vr[x] for x in INPUTS], [vr[x] for x in OUTPUTS]
    t0 = time.perf_counter()
    for k in range(n):
        s.setReal(vin, [0.005, 400.0, 10.0 + k * 1e-6])
        s.doStep(k * 1e-3, 1e-3)
        s.getReal(vout)
    theirs = (time.perf_counter() - t0) / n * 1e6
    s.terminate()
    s.freeInstance()
    return ours, theirs


#: issue 17's targets for the production TCU: worst characteristic error (3 % of the engine's 240 N.m peak)
#: and worst cushion-spring temperature error through the cool-down; naive at least this factor worse
PRODUCTION_CHARACTERISTIC_NM, PRODUCTION_COOLDOWN_THETA_K, NAIVE_OVER_PRODUCTION = 7.2, 15.0, 2.0


def production_line(results, group: str) -> str:
    """One line: the production TCU in ``group`` against its targets (measured values, target in brackets)."""
    from cushion_clutch.launch.report import summary_rows

    rows = {r["tcu"]: r for r in summary_rows(results) if r["group"] == group}
    if "production" not in rows:
        return f"{group}: production: –"
    p = rows["production"]
    ch, th = p["characteristic_error_max_Nm_worst"], p["theta_cs_error_K_worst"]
    text = (f"{group}: production worst characteristic_error_max_Nm {ch:.3f} "
            f"(target <= {PRODUCTION_CHARACTERISTIC_NM:g})")
    if "naive" in rows and ch > 0:
        text += (f", naive / production {rows['naive']['characteristic_error_max_Nm_worst'] / ch:.1f}x "
                 f"(target >= {NAIVE_OVER_PRODUCTION:g}x in default and wear)")
    text += f", theta_cs_error_K worst {th:+.1f} K"
    if group == "cool-down":
        text += f" (target |.| <= {PRODUCTION_COOLDOWN_THETA_K:g} K)"
    return text


def markdown(scenarios: list[str], backend: str = "native", keep: dict | None = None) -> Iterator[str]:
    """The launch results of every scenario as Markdown (summary table, ratio, real-time factors), one
    scenario at a time; ``keep`` (a dict) receives every scenario's results by name."""
    from cushion_clutch.data import DEFAULT_TABLES
    from cushion_clutch.model import load_table
    from cushion_clutch.launch.driveline import first_mode_hz
    from cushion_clutch.launch.plant import build_plant_fmu
    from cushion_clutch.errors import FmuCallError
    from cushion_clutch.launch.report import ratio_line, run_all, summary_table
    from cushion_clutch.launch.tcu import VARIANTS
    from cushion_clutch.launch.scenario import load_scenario, scenario_path

    with tempfile.TemporaryDirectory() as tmp:
        for name in scenarios:
            parts = []
            sc = load_scenario(scenario_path(name))
            fmu = build_plant_fmu(DEFAULT_TABLES, sc, Path(tmp) / name / "CushionClutch.fmu", backend=backend)
            table = load_table(sc.tables_path("tcu") or DEFAULT_TABLES)
            results, failed = {}, {}
            for variant in VARIANTS:      # one at a time: a run that leaves the model's domain is reported, not hidden
                try:
                    results.update(run_all(fmu, sc, table, (variant,)))
                except (ValueError, FmuCallError) as exc:
                    failed[variant] = str(exc).splitlines()[0]
            groups = sorted({g for r in results.values() for m in r.metrics
                             for g in (("hot",) if m["hot"] and m["phase"] == "repeated" else ())
                             + (("cool-down",) if m["phase"] == "cool-down" else ())})
            sim = sc.run.duration()
            if keep is not None:
                keep[name] = results
            parts.append(f"## `{name}`: {sc.description}\n\n"
                         f"levels {', '.join(sc.driver.levels)}; first driveline mode "
                         f"{first_mode_hz(sc):.2f} Hz\n\n" + summary_table(results, ("all",)))
            for g in groups:
                parts.append(f"Group `{g}`:\n\n" + summary_table(results, (g,)))
                parts.append("- " + ratio_line(results, g))
                parts.append("- " + production_line(results, g))
            if failed:
                parts.append("- stopped outside the model's domain (no row above): " + "; ".join(
                    f"`{n}`: {msg}" for n, msg in failed.items()))
            parts.append("- real-time factor (wall / CPU time): " + ", ".join(
                f"{n} {sim / r.wall_time_s:.0f}x / {sim / r.cpu_time_s:.0f}x" for n, r in results.items()))
            yield "\n\n".join(parts)


#: launches of the shipped ``default`` scenario whose per-launch figures the results page carries for the check
CHECK_LAUNCHES = 3
#: the check table's columns: (metric, header, format)
CHECK_COLUMNS = (("theta_cs_start_degC", "θ_cs start [°C]", ".2f"),
                 ("characteristic_error_max_Nm", "char. err max [N·m]", ".3f"),
                 ("characteristic_error_rms_Nm", "char. err RMS [N·m]", ".3f"),
                 ("tracking_error_rms_Nm", "tracking RMS [N·m]", ".3f"),
                 ("theta_cs_error_K", "θ_cs err [K]", ".2f"),
                 ("engagement_time_s", "engagement [s]", ".3f"))


def check_table(results, launches: int = CHECK_LAUNCHES) -> str:
    """Markdown: the first ``launches`` launches' figures per launch and TCU (no timings: they are exact)."""
    lines = ["| launch | TCU | " + " | ".join(h for _, h, _ in CHECK_COLUMNS) + " |",
             "|" + "---|" * (2 + len(CHECK_COLUMNS))]
    for name, res in results.items():
        for m in res.metrics[:launches]:
            cells = ["–" if m[c] != m[c] else format(m[c], f) for c, _, f in CHECK_COLUMNS]
            lines.append(f"| {m['launch']} | {name} | " + " | ".join(cells) + " |")
    return "\n".join(lines)


def check_run(backend: str = "native", launches: int = CHECK_LAUNCHES) -> str:
    """The check table from a fresh run of the first ``launches`` launches of ``default`` (the same
    configuration as the full run, fewer launches: earlier launches do not depend on later ones)."""
    import dataclasses

    from cushion_clutch.data import DEFAULT_TABLES
    from cushion_clutch.model import load_table
    from cushion_clutch.launch.plant import build_plant_fmu
    from cushion_clutch.launch.report import run_all
    from cushion_clutch.launch.scenario import load_scenario, scenario_path

    sc = load_scenario(scenario_path("default"))
    sc = dataclasses.replace(sc, run=dataclasses.replace(sc.run, launches=launches))
    with tempfile.TemporaryDirectory() as tmp:
        fmu = build_plant_fmu(DEFAULT_TABLES, sc, Path(tmp) / "CushionClutch.fmu", backend=backend)
        return check_table(run_all(fmu, sc, load_table(sc.tables_path("tcu") or DEFAULT_TABLES)), launches)


CHECK_HEADING = "## Check figures"
PAGE_INTRO = ("Every TCU on each scenario with the committed tables and the native FMU. \"worst\" is the worst "
              "launch of the group; `hot`: θ_cs ≥ 100 °C at the launch start. Column names are those of "
              "`launch_summary.csv`; what each metric shows and hides: [a launch study]"
              "(../tutorials/launch_study.md). Real-time factors depend on the machine and its load.")


def write_page(out: Path, scenarios: list[str], backend: str, argv) -> None:
    """The results page: every scenario's tables, then the check figures of ``default``."""
    from .page import results_page

    keep: dict = {}
    with results_page(out, "Launch results", "cushion_clutch.benchmarks.launch", argv, PAGE_INTRO) as page:
        for part in markdown(scenarios, backend, keep):
            page.markdown(part)
        check = (check_table(keep["default"]) if "default" in keep else check_run(backend))
        page.markdown(f"{CHECK_HEADING}\n\nThe first {CHECK_LAUNCHES} launches of `default`, per launch and "
                      "TCU. `tests/test_docs.py` reruns them and fails when a figure differs, so a stale page "
                      f"fails CI.\n\n{check}")


def main(argv=None) -> None:
    from cushion_clutch.data import DEFAULT_TABLES
    from cushion_clutch.model import load_table
    from cushion_clutch.launch.plant import build_plant_fmu
    from cushion_clutch.launch.scenario import DEFAULT_SCENARIO, load_scenario, scenario_path
    from cushion_clutch.launch.simulate import simulate_launches
    from cushion_clutch.launch.tcu import VARIANTS

    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--scenario", default=str(DEFAULT_SCENARIO))
    ap.add_argument("--backend", default="native", choices=("native", "python"))
    ap.add_argument("--repeat", type=int, default=1, help="runs per variant; the median is printed")
    ap.add_argument("--plant", default="native", choices=("native", "python"),
                    help="the launch loop's plant steps: compiled blocks (default) or the Python loop (the reference)")
    ap.add_argument("--markdown", action="store_true", help="print the launch results tables")
    ap.add_argument("--scenarios", default="default,trailer,creep,cooldown,fade,wear,wear_learned,tolerance,protection", help="with --markdown")
    ap.add_argument("--out", type=Path, help="with --markdown: write the results page (e.g. docs/results/launch.md)")
    args = ap.parse_args(argv)
    if args.markdown and args.out:
        write_page(args.out, args.scenarios.split(","), args.backend, argv)
        return
    if args.markdown:
        for part in markdown(args.scenarios.split(","), args.backend):
            print(part + "\n", flush=True)
        return
    sc = load_scenario(scenario_path(args.scenario))
    sim = sc.run.duration()
    steps = sim / sc.run.step_s
    with tempfile.TemporaryDirectory() as tmp:
        fmu = build_plant_fmu(DEFAULT_TABLES, sc, Path(tmp) / "CushionClutch.fmu", backend=args.backend)
        ours, theirs = _fmu_call_us(fmu)
        print(f"FMU step (set 3 inputs, doStep, get 3 outputs), {args.backend} FMU: {ours:.2f} us through the "
              f"cffi client, {theirs:.2f} us through fmpy FMU2Slave ({theirs / ours:.1f}x)")
        for name in VARIANTS:
            runs = [simulate_launches(fmu, sc, load_table(sc.tables_path("tcu") or DEFAULT_TABLES), name,
                                      plant=args.plant) for _ in range(args.repeat)]
            wall = statistics.median(r.wall_time_s for r in runs)
            cpu = statistics.median(r.cpu_time_s for r in runs)
            print(f"{name:>24} TCU: {sim:g} s simulated in {wall:.2f} s wall -> real-time factor "
                  f"{sim / wall:.0f}x ({wall / steps * 1e6:.2f} us per {sc.run.step_s * 1e3:g} ms step); "
                  f"CPU time {cpu:.2f} s -> {sim / cpu:.0f}x; {runs[0].quiet_s / sim:.0%} of the time in quiet "
                  f"steps")


if __name__ == "__main__":
    main()
