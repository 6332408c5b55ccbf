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

from .page import add_draft_option


def _fmu_call_us(fmu: Path, n: int = 50000) -> tuple[float, float]:
    """Microseconds per step: the cffi client and fmpy FMU2Slave (name-based set/get)."""
    from fmpy import extract, read_model_description
    from fmpy.fmi2 import FMU2Slave

    from cushion_clutch.launch.plant.fmu_client import INPUTS, OUTPUTS, ClutchFmu

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


#: the page's words and units for the summarised metrics (launch_summary.csv's column, words, format); the
#: full per-metric table names each column of launch_summary.csv in words
METRIC_WORDS = {
    "characteristic_error_rms_Nm": ("characteristic error, RMS over the launch [N·m]", ".3f"),
    "characteristic_error_max_Nm": ("characteristic error, largest in the launch [N·m]", ".3f"),
    "tracking_error_rms_Nm": ("torque tracking error, RMS [N·m]", ".2f"),
    "tracking_error_max_Nm": ("torque tracking error, largest [N·m]", ".2f"),
    "creep_error_Nm": ("creep torque error [N·m]", ".2f"),
    "lockup_accel_step_m_s2": ("acceleration step at lock-up [m/s²]", ".3f"),
    "shuffle_amplitude_m_s2": ("shuffle amplitude after lock-up [m/s²]", ".2f"),
    "kiss_point_error_mm": ("kiss-point error [mm]", ".3f"),
    "theta_cs_error_K": ("cushion-spring temperature error of the TCU [K]", ".1f"),
    "engagement_time_s": ("engagement time [s]", ".2f"),
    "slip_energy_kJ": ("slip energy [kJ]", ".1f"),
    "peak_theta_cm_degC": ("peak facing temperature in the launch [°C]", ".0f"),
    "peak_theta_cs_degC": ("peak cushion-spring temperature in the launch [°C]", ".0f"),
    "beyond_tables_s": ("time beyond the tables' temperatures [s]", ".1f"),
    "above_damage_s": ("time above the facing damage temperature [s]", ".1f"),
}
#: the key-figures table: (header in words with unit, function of a summary row giving the cell)
KEY_HEADERS = ("TCU", "launches", "worst characteristic error [N·m]", "characteristic error RMS, mean [N·m]",
               "worst θ_cs error [K]", "peak facing θ_cm [°C]", "peak cushion spring θ_cs [°C]", "locked up",
               "inhibited")


def _fmt(value: float, spec: str) -> str:
    return "–" if value != value else format(value, spec)


def _breakable(name: str) -> str:
    """A TCU name that a narrow table column may wrap after its underscores (HTML ``<wbr>``, no character)."""
    return name.replace("_", "_<wbr>")


def key_table(rows: list[dict], group: str) -> str:
    """Markdown: the few figures that matter per TCU in ``group`` (rows of ``report.summary_rows``): the
    worst launch's largest characteristic error, the launches' mean RMS characteristic error, the worst
    θ_cs estimate error, the plant's peak facing and cushion-spring temperatures over the run, the launches
    that locked up and those the thermal protection inhibited."""
    lines = ["| " + " | ".join(KEY_HEADERS) + " |", "|---|" + "--:|" * (len(KEY_HEADERS) - 1)]
    for r in rows:
        if r["group"] != group:
            continue
        cells = [_breakable(r["tcu"]), str(r["n"]), _fmt(r["characteristic_error_max_Nm_worst"], ".3f"),
                 _fmt(r["characteristic_error_rms_Nm_mean"], ".3f"), _fmt(r["theta_cs_error_K_worst"], "+.1f"),
                 _fmt(r["plant_theta_cm_peak_degC"], ".0f"), _fmt(r["plant_theta_cs_peak_degC"], ".0f"),
                 f"{r['n'] - r['no_lockup']}\u00a0of\u00a0{r['n']}", str(r["inhibited_launches"])]
        lines.append("| " + " | ".join(cells) + " |")
    return "\n".join(lines)


def full_table(rows: list[dict], group: str) -> str:
    """Markdown: every summarised metric (a row each, in words with its unit and its ``launch_summary.csv``
    name) against the TCUs (a column each), as ``mean / worst`` over the launches of ``group``."""
    rows = [r for r in rows if r["group"] == group]
    lines = ["| metric (mean / worst) | " + " | ".join(_breakable(r["tcu"]) for r in rows) + " |",
             "|---|" + "--:|" * len(rows)]
    for col, (words, spec) in METRIC_WORDS.items():
        cells = [f"{_fmt(r[col + '_mean'], spec)} / {_fmt(r[col + '_worst'], spec)}" for r in rows]
        lines.append(f"| {words} (`{col}`) | " + " | ".join(cells) + " |")
    lines.append("| engine stalls | " + " | ".join(str(r["stalls"]) for r in rows) + " |")
    lines.append("| launches without lock-up | " + " | ".join(str(r["no_lockup"]) for r in rows) + " |")
    return "\n".join(lines)


def collapsible(summary: str, body: str) -> str:
    """Markdown: ``body`` in an HTML ``<details>`` block (closed) headed by ``summary``."""
    return (f"```{{raw}} html\n<details class=\"cc-details\"><summary>{summary}</summary>\n```\n\n{body}\n\n"
            "```{raw} html\n</details>\n```")


GROUP_WORDS = {"all": "all launches", "hot": "hot launches (θ_cs ≥ 100 °C at the start)",
               "cool-down": "the cool-down launches"}


def scenario_markdown(name: str, sc, results, mode_hz: float) -> str:
    """One scenario's part of the page: the key figures of all launches (and of each group), the group's
    ratio and production lines, the full per-metric tables (collapsed) and the real-time factors."""
    from cushion_clutch.launch.report import ratio_line, summary_rows

    rows = summary_rows(results)
    groups = [g for g in ("hot", "cool-down") if any(r["group"] == g for r in rows)]
    parts = [f"## `{name}`: {sc.description}\n\nlevels {', '.join(sc.driver.levels)}; first driveline mode "
             f"{mode_hz:.2f} Hz; peak temperatures are the plant's over the whole run\n\n"
             + key_table(rows, "all")]
    for g in groups:
        parts.append(f"Launches of group `{g}` ({GROUP_WORDS[g]}):\n\n" + key_table(rows, g))
        parts.append("- " + ratio_line(results, g) + "\n- " + production_line(results, g))
    stopped = [f"`{n}` {r.stopped}" for n, r in results.items() if r.stopped]
    if stopped:                             # the plant left the model's domain: those rows hold fewer launches
        parts.append("- **stopped early** (the rows above hold the launches up to it): " + "; ".join(stopped))
    full = "\n\n".join(f"{GROUP_WORDS[g].capitalize()}:\n\n{full_table(rows, g)}" for g in ["all", *groups])
    parts.append(collapsible(f"Every metric of <code>{name}</code> (mean / worst per TCU)", full))
    sim = sc.run.duration()
    parts.append("- real-time factor (wall / CPU time): " + ", ".join(
        f"{n} {sim / r.wall_time_s:.0f}x / {sim / r.cpu_time_s:.0f}x" for n, r in results.items()))
    return "\n\n".join(parts)


def markdown(scenarios: list[str], backend: str = "native", keep: dict | None = None,
             launches: int | None = None) -> Iterator[str]:
    """The launch results of every scenario as Markdown (:func:`scenario_markdown`), one scenario at a time;
    ``keep`` (a dict) receives every scenario's results by name; ``launches`` shortens every scenario's run
    to its first launches (a quick look or a test; the page's figures come from the full runs)."""
    import dataclasses

    from cushion_clutch.data import DEFAULT_TABLES
    from cushion_clutch.model import load_table
    from cushion_clutch.launch.plant.driveline import first_mode_hz
    from cushion_clutch.launch.plant.build import build_plant_fmu
    from cushion_clutch.launch.report import run_all
    from cushion_clutch.launch.scenario import load_scenario, scenario_path

    with tempfile.TemporaryDirectory() as tmp:
        for name in scenarios:
            sc = load_scenario(scenario_path(name))
            if launches is not None:
                sc = dataclasses.replace(sc, run=dataclasses.replace(
                    sc.run, launches=launches, cool_launches=min(sc.run.cool_launches, launches)))
            fmu = build_plant_fmu(DEFAULT_TABLES, sc, Path(tmp) / name / "CushionClutch.fmu", backend=backend)
            results = run_all(fmu, sc, load_table(sc.tables_path("tcu") or DEFAULT_TABLES))
            if keep is not None:
                keep[name] = results
            yield scenario_markdown(name, sc, results, first_mode_hz(sc))


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
    from cushion_clutch.launch.plant.build import build_plant_fmu
    from cushion_clutch.launch.report import run_all
    from cushion_clutch.launch.scenario import load_scenario, scenario_path

    sc = load_scenario(scenario_path("default"))
    sc = dataclasses.replace(sc, run=dataclasses.replace(sc.run, launches=launches))
    with tempfile.TemporaryDirectory() as tmp:
        fmu = build_plant_fmu(DEFAULT_TABLES, sc, Path(tmp) / "CushionClutch.fmu", backend=backend)
        return check_table(run_all(fmu, sc, load_table(sc.tables_path("tcu") or DEFAULT_TABLES)), launches)


CHECK_HEADING = "## Check figures"
PAGE_INTRO = ("Every TCU on each scenario with the committed tables and the native FMU. Each scenario first "
              "gives its key figures per TCU: the worst launch's largest characteristic error (the TCU's torque "
              "characteristic against the plant's), the mean over the launches of its RMS, the worst error of "
              "the TCU's cushion-spring temperature θ_cs, the plant's peak facing and cushion-spring "
              "temperatures over the run, how many launches locked up and how many the thermal protection "
              "inhibited. `hot`: θ_cs ≥ 100 °C at the launch start. Every metric (mean / worst of the group's "
              "launches, named in words and by its `launch_summary.csv` column) is in the collapsed section "
              "below each scenario; what each metric shows and hides: [a launch study]"
              "(../tutorials/launch_study.md). Real-time factors depend on the machine and its load.")


def write_page(out: Path, scenarios: list[str], backend: str, argv, launches: int | None = None) -> None:
    """The results page: every scenario's tables, then the check figures of ``default``."""
    from .page import results_page

    keep: dict = {}
    with results_page(out, "Launch results", "cushion_clutch.benchmarks.launch", argv, PAGE_INTRO) as page:
        for part in markdown(scenarios, backend, keep, launches):
            page.markdown(part)
        full_default = "default" in keep and (launches is None or launches >= CHECK_LAUNCHES)
        check = check_table(keep["default"]) if full_default else check_run(backend)
        page.markdown(f"{CHECK_HEADING}\n\nThe first {CHECK_LAUNCHES} launches of `default`, per launch and "
                      "TCU. `tests/test_docs.py` reruns them and fails when a figure differs, so a stale page "
                      f"fails CI.\n\n{check}")


def main(argv=None) -> None:
    from cushion_clutch.data import DEFAULT_TABLES
    from cushion_clutch.model import load_table
    from cushion_clutch.launch.plant.build import build_plant_fmu
    from cushion_clutch.launch.scenario import DEFAULT_SCENARIO, load_scenario, scenario_path
    from cushion_clutch.launch.simulate import simulate_launches
    from cushion_clutch.launch.tcu.controller import VARIANTS

    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--scenario", default=str(DEFAULT_SCENARIO))
    ap.add_argument("--backend", default="native", choices=("native", "python"))
    ap.add_argument("--repeat", type=int, default=1, help="runs per variant; the median is printed")
    ap.add_argument("--plant", default="native", choices=("native", "python"),
                    help="the launch loop's plant steps: compiled blocks (default) or the Python loop (the reference)")
    ap.add_argument("--markdown", action="store_true", help="print the launch results tables")
    ap.add_argument("--scenarios", default="default,trailer,creep,cooldown,fade,wear,wear_learned,tolerance,protection", help="with --markdown")
    ap.add_argument("--out", type=Path, help="with --markdown: write the results page (e.g. docs/results/launch.md)")
    add_draft_option(ap)
    ap.add_argument("--launches", type=int, help="with --markdown: only each scenario's first N launches "
                    "(a quick look at the layout; the committed page comes from the full runs)")
    args = ap.parse_args(argv)
    if args.launches is not None and args.launches < 1:
        ap.error(f"--launches {args.launches}: must be at least 1")
    if args.markdown and args.out:
        write_page(args.out, args.scenarios.split(","), args.backend, argv, args.launches)
        return
    if args.markdown:
        for part in markdown(args.scenarios.split(","), args.backend, launches=args.launches):
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
