"""Run a launch scenario with every TCU variant; write time series, metrics, summary and plots."""
from __future__ import annotations

import csv
import math
from pathlib import Path
from typing import Callable, Iterable

from ..model import SpringTable
from .metrics import METRIC_COLUMNS, SUMMARY, summarise
from .scenario import Scenario
from .simulate import COLUMNS, LaunchResult, simulate_launches
from .tcu import VARIANTS

#: the summary's groups of launches: (name, selector)
GROUPS = (("hot", lambda r: r["hot"] and r["phase"] == "repeated"),
          ("cool-down", lambda r: r["phase"] == "cool-down"),
          ("all", lambda r: True))


def run_all(fmu: Path, sc: Scenario, table: SpringTable, variants: Iterable[str] = tuple(VARIANTS),
            progress: Callable[[str, float], None] | None = None) -> dict[str, LaunchResult]:
    """Every TCU variant on the same scenario and plant FMU."""
    out = {}
    for name in variants:
        cb = (lambda t, n=name: progress(n, t)) if progress else None
        out[name] = simulate_launches(fmu, sc, table, name, progress=cb)
    return out


def run_both(fmu: Path, sc: Scenario, table: SpringTable,
             progress: Callable[[str, float], None] | None = None) -> dict[str, LaunchResult]:
    """The naive and the ideal temperature-aware TCU (the study before the estimated variants)."""
    return run_all(fmu, sc, table, ("naive", "aware"), progress)


def summary_rows(results: dict[str, LaunchResult]) -> list[dict]:
    """One row per group with launches and TCU variant: mean and worst of the summarised metrics."""
    rows = []
    for group, select in GROUPS:
        for name, res in results.items():
            s = summarise(res.metrics, select)
            if s["n"]:
                rows.append({"group": group, "tcu": name, **s})
    return rows


def write_outputs(results: dict[str, LaunchResult], out: Path) -> list[Path]:
    """``launch_<tcu>.csv`` time series, ``launch_metrics.csv``, ``launch_summary.csv`` and PNG plots."""
    from .plots import plot_launches

    out.mkdir(parents=True, exist_ok=True)
    paths = []
    for name, res in results.items():
        path = out / f"launch_{name}.csv"
        with open(path, "w", newline="") as fh:
            w = csv.writer(fh)
            w.writerow(COLUMNS)
            for row in res.series:
                w.writerow([f"{v:.9g}" for v in row])
        paths.append(path)
    path = out / "launch_metrics.csv"
    with open(path, "w", newline="") as fh:
        w = csv.writer(fh)
        w.writerow(METRIC_COLUMNS)
        for name, res in results.items():
            for m in res.metrics:
                w.writerow([name] + [m[c] for c in METRIC_COLUMNS[1:]])
    paths.append(path)
    rows = summary_rows(results)
    path = out / "launch_summary.csv"
    with open(path, "w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=list(rows[0]))
        w.writeheader()
        w.writerows(rows)
    paths.append(path)
    paths += plot_launches(results, out)
    return paths


def _f(v: float, fmt: str) -> str:
    return "–" if isinstance(v, float) and math.isnan(v) else format(v, fmt)


def metrics_table(results: dict[str, LaunchResult]) -> str:
    """Per launch: theta_cs at the start, then RMS torque error and kiss-point error of every variant."""
    names = list(results)
    first = results[names[0]].metrics
    head = "| launch | θ_cs start [°C] | " + " | ".join(f"RMS err {n} [N·m]" for n in names) + " | " + \
        " | ".join(f"kiss err {n} [mm]" for n in names) + " |"
    lines = [head, "|" + "---|" * (2 + 2 * len(names))]
    for i, m in enumerate(first):
        cells = [str(m["launch"]) + ("c" if m["phase"] == "cool-down" else ""), _f(m["theta_cs_start_degC"], ".1f")]
        cells += [_f(results[n].metrics[i]["torque_error_rms_Nm"], ".2f") for n in names]
        cells += [_f(results[n].metrics[i]["kiss_point_error_mm"], ".3f") for n in names]
        lines.append("| " + " | ".join(cells) + " |")
    return "\n".join(lines)


SUMMARY_LABELS = {"torque_error_rms_Nm": "RMS err [N·m]", "torque_error_max_Nm": "max err [N·m]",
                  "kiss_point_error_mm": "kiss err [mm]", "theta_cs_error_K": "θ_cs err [K]",
                  "creep_shortfall_Nm": "creep shortfall [N·m]", "engagement_time_s": "t_eng [s]",
                  "slip_energy_kJ": "E_slip [kJ]", "lockup_jerk_m_s3": "lock-up jerk [m/s³]"}


def summary_table(results: dict[str, LaunchResult]) -> str:
    """Markdown: per group and variant, ``mean / worst`` of each summarised metric."""
    cols = [c for c, _ in SUMMARY]
    lines = ["| launches | TCU | n | " + " | ".join(SUMMARY_LABELS[c] + " mean / worst" for c in cols) + " | stalls |",
             "|" + "---|" * (4 + len(cols))]
    fmt = {"kiss_point_error_mm": ".3f", "engagement_time_s": ".3f", "theta_cs_error_K": ".1f",
           "lockup_jerk_m_s3": ".1f"}
    for r in summary_rows(results):
        if r["group"] == "all" and any(x["group"] != "all" for x in summary_rows(results)):
            continue
        cells = [r["group"], r["tcu"], str(r["n"])]
        cells += [f"{_f(r[c + '_mean'], fmt.get(c, '.2f'))} / {_f(r[c + '_worst'], fmt.get(c, '.2f'))}" for c in cols]
        lines.append("| " + " | ".join(cells + [str(r["stalls"])]) + " |")
    return "\n".join(lines)
