"""Run a launch scenario with every TCU variant; write time series, metrics, summary and plots."""
from __future__ import annotations

import csv
import math
import textwrap
from pathlib import Path
from typing import Callable, Iterable

import numpy as np

from ..model import KELVIN, ClutchParameters, SpringTable
from .results.metrics import METRIC_COLUMNS, SUMMARY, add_temperature_metrics, summarise
from .scenario.load import Scenario
from .results.series import COLUMNS, LaunchResult
from .simulate import simulate_launches
from .tcu.controller import VARIANTS
from .results.provenance import Provenance

#: the summary's groups of launches: (name, selector)
GROUPS = (("hot", lambda r: r["hot"] and r["phase"] == "repeated"),
          ("cool-down", lambda r: r["phase"] == "cool-down"),
          ("all", lambda r: True))


def lockup_counts(res: LaunchResult) -> dict:
    """How a TCU's launches ended: ``n`` launches, ``locked`` (locked up), ``inhibited`` (the thermal protection
    inhibited the launch: no launch), ``no_lockup`` (launched, never locked up) and ``stalls``."""
    locked = [not math.isnan(m["engagement_time_s"]) for m in res.metrics]
    inhibited = [m["protection_level"] >= 3 and not ok for m, ok in zip(res.metrics, locked)]
    return {"n": len(res.metrics), "locked": sum(locked), "inhibited": sum(inhibited),
            "no_lockup": sum(not ok and not inh for ok, inh in zip(locked, inhibited)),
            "stalls": sum(bool(m["engine_stall"]) for m in res.metrics)}


def lockup_lines(results: dict[str, LaunchResult], width: int = 100) -> str:
    """A heading, then one line per TCU: how many of its launches locked up, how many the thermal protection
    inhibited (no launch) and how many launched but never locked up (a longer line continues indented); a run
    that stopped early (the plant left the model's domain) says where and why."""
    out = ["launches locked up per TCU (inhibited: the TCU's thermal protection allowed no launch):"]
    for name, res in results.items():
        c = lockup_counts(res)
        rest = [f"{c['inhibited']} inhibited" if c["inhibited"] else "",
                f"{c['no_lockup']} launched but never locked up" if c["no_lockup"] else "",
                f"{c['stalls']} engine stalls" if c["stalls"] else ""]
        head = f"{name}: {c['locked']} of {c['n']} launches locked up"
        tail = ", ".join(r for r in rest if r)
        if not tail:
            out.append(head)
        elif len(head) + 2 + len(tail) <= width:
            out.append(f"{head}; {tail}")
        else:
            out += [head + ";", f"  {tail}"]
        if res.stopped:                       # the plant left the model's domain: the run ended early
            out += textwrap.wrap(f"{name} STOPPED EARLY, {res.stopped}", width, subsequent_indent="  ")
    return "\n".join(out)


def run_all(fmu: Path, sc: Scenario, table: SpringTable, variants: Iterable[str] = tuple(VARIANTS),
            progress: Callable[[str, float], None] | None = None,
            plant_start: dict | None = None) -> dict[str, LaunchResult]:
    """Every TCU variant on the same scenario and plant FMU; each launch's metrics carry the peak temperatures
    and the time beyond the tables and above the facing damage limit (metrics.add_temperature_metrics).
    ``plant_start``: the plant's start values from an SSP parameter set (``simulate.plant_start_values``)."""
    out = {}
    damage = ClutchParameters().facing_damage_temperature_K
    for name in variants:
        cb = (lambda t, n=name: progress(n, t)) if progress else None
        out[name] = simulate_launches(fmu, sc, table, name, progress=cb, plant_start=plant_start)
        add_temperature_metrics(out[name].metrics, out[name].series, table.theta_min_K, table.theta_max_K, damage)
    return out


def run_both(fmu: Path, sc: Scenario, table: SpringTable,
             progress: Callable[[str, float], None] | None = None,
            plant_start: dict | None = None) -> dict[str, LaunchResult]:
    """The naive and the ideal temperature-aware TCU (the study before the estimated variants)."""
    return run_all(fmu, sc, table, ("naive", "aware"), progress)


def peaks(res: LaunchResult) -> dict:
    """The plant's peak facing and cushion-spring temperatures and the TCU's peak facing estimate over the
    run (degC, from the recorded time series), the launches the thermal protection inhibited, and how a
    production TCU started (``tcu_start``: reset or learned; its standstill touch-point error, um)."""
    s = res.series
    est = s["theta_cm_tcu_K"]
    ko = res.key_on
    ss = ko.standstill if ko is not None else None
    return {"plant_theta_cm_peak_degC": float(s["theta_cm_K"].max()) - KELVIN,
            "plant_theta_cs_peak_degC": float(s["theta_cs_K"].max()) - KELVIN,
            "tcu_theta_cm_peak_degC": (float(np.nanmax(est)) - KELVIN) if np.isfinite(est).any() else math.nan,
            "inhibited_launches": sum(m["protection_level"] >= 3 for m in res.metrics),
            "tcu_start": ko.start if ko is not None else "",
            "standstill_kiss_error_um": (ss.kiss_error_m * 1e6 if ss is not None and ss.ok else math.nan)}


def summary_rows(results: dict[str, LaunchResult]) -> list[dict]:
    """One row per group with launches and TCU variant: mean and worst of the summarised metrics, and the
    run's :func:`peaks`."""
    rows = []
    for group, select in GROUPS:
        for name, res in results.items():
            s = summarise(res.metrics, select)
            if s["n"]:
                rows.append({"group": group, "tcu": name, **s, **peaks(res)})
    return rows


def peak_lines(results: dict[str, LaunchResult]) -> str:
    """One line per TCU: the peak temperatures of the plant it drove, its own peak estimate (if it has a thermal
    model), the launches its protection inhibited, and (production) how it started."""
    out = []
    for name, res in results.items():
        k = peaks(res)
        # within 100 columns: the TCU on its own line, then peaks, then (production) how it started
        est = k["tcu_theta_cm_peak_degC"]
        est = "no estimate" if math.isnan(est) else f"its estimate {est:.0f}"
        out.append(f"{name + ':':<25} peak theta_cm {k['plant_theta_cm_peak_degC']:.0f} degC ({est}), "
                   f"theta_cs {k['plant_theta_cs_peak_degC']:.0f} degC; {k['inhibited_launches']} inhibited")
        if k["tcu_start"]:
            out.append(f"  {name} started {k['tcu_start']}; standstill touch point "
                       f"{_f(k['standstill_kiss_error_um'], '.1f')} um off")
    return "\n".join(out)


def write_outputs(results: dict[str, LaunchResult], out: Path, provenance: Provenance | None = None,
                  every: int = 1) -> list[Path]:
    """``launch_<tcu>.csv`` time series, ``launch_metrics.csv``, ``launch_summary.csv`` and PNG plots.

    ``every``: the time series keep every ``every``-th recorded row (1: all); the metrics, the summary and the
    plots always use every recorded row. ``provenance``: scenario, version and command on every plot (None: a
    scenario named "unnamed").
    """
    from .results.plots import plot_launches

    if not (isinstance(every, int) and every >= 1):
        raise ValueError(f"every = {every!r}: must be a whole number >= 1 (keep every N-th row of the time series)")
    out.mkdir(parents=True, exist_ok=True)
    paths = []
    for name, res in results.items():
        path = out / f"launch_{name}.csv"
        with open(path, "w", newline="") as fh:
            w = csv.writer(fh)
            w.writerow(COLUMNS)
            for row in res.series[::every]:
                w.writerow([f"{v:.9g}" for v in row])
        paths.append(path)
    path = out / "launch_metrics.csv"
    with open(path, "w", newline="") as fh:
        w = csv.writer(fh)
        w.writerow(METRIC_COLUMNS)
        for name, res in results.items():
            for m in res.metrics:
                w.writerow([name] + [m.get(c, math.nan) for c in METRIC_COLUMNS[1:]])
    paths.append(path)
    rows = summary_rows(results)
    path = out / "launch_summary.csv"
    with open(path, "w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=list(rows[0]))
        w.writeheader()
        w.writerows(rows)
    paths.append(path)
    paths += plot_launches(results, out, provenance=provenance)
    return paths


def series_interval_s(results: dict[str, LaunchResult], every: int = 1) -> float:
    """The time between two rows of the written time series, s (the smallest step between recorded rows,
    times ``every``; NaN for fewer than two rows)."""
    t = next(iter(results.values())).series["time_s"]
    return round(float(np.min(np.diff(t))) * every, 9) if len(t) > 1 else math.nan


def _f(v: float, fmt: str) -> str:
    return "–" if isinstance(v, float) and math.isnan(v) else format(v, fmt)


def metrics_table(results: dict[str, LaunchResult]) -> str:
    """Per launch: demand level, theta_cs at the start, then the characteristic error (RMS) of every variant."""
    names = list(results)
    first = results[names[0]].metrics
    head = ("| launch | demand | θ_cs start [°C] | " +
            " | ".join(f"char. err RMS {n} [N·m]" for n in names) + " |")
    lines = [head, "|" + "---|" * (3 + len(names))]
    for i, m in enumerate(first):
        cells = [str(m["launch"]) + ("c" if m["phase"] == "cool-down" else ""), m["demand_level"] or "–",
                 _f(m["theta_cs_start_degC"], ".1f")]
        cells += [_f(results[n].metrics[i]["characteristic_error_rms_Nm"], ".3f") for n in names]
        lines.append("| " + " | ".join(cells) + " |")
    return "\n".join(lines)


#: the summary table's columns: (column, label, format)
SUMMARY_LABELS = {
    "characteristic_error_rms_Nm": ("characteristic_error_rms_Nm", ".3f"),
    "characteristic_error_max_Nm": ("characteristic_error_max_Nm", ".3f"),
    "tracking_error_rms_Nm": ("tracking_error_rms_Nm", ".2f"),
    "tracking_error_max_Nm": ("tracking_error_max_Nm", ".2f"),
    "creep_error_Nm": ("creep_error_Nm", ".2f"),
    "lockup_accel_step_m_s2": ("lockup_accel_step_m_s2", ".3f"),
    "shuffle_amplitude_m_s2": ("shuffle_amplitude_m_s2", ".2f"),
    "kiss_point_error_mm": ("kiss_point_error_mm", ".3f"),
    "theta_cs_error_K": ("theta_cs_error_K", ".1f"),
    "engagement_time_s": ("engagement_time_s", ".2f"),
    "slip_energy_kJ": ("slip_energy_kJ", ".1f"),
    "peak_theta_cm_degC": ("peak_theta_cm_degC", ".0f"),
    "peak_theta_cs_degC": ("peak_theta_cs_degC", ".0f"),
    "beyond_tables_s": ("beyond_tables_s", ".1f"),
    "above_damage_s": ("above_damage_s", ".1f"),
}


def summary_table(results: dict[str, LaunchResult], groups: tuple[str, ...] | None = None) -> str:
    """Markdown: per group and variant, ``mean / worst`` of each summarised metric (column names as in
    ``launch_summary.csv``). ``groups`` None: every group but "all" when another group has launches."""
    cols = [c for c, _ in SUMMARY]
    rows = summary_rows(results)
    if groups is None:
        groups = tuple(g for g, _ in GROUPS if g != "all" or all(r["group"] == "all" for r in rows))
    lines = ["| launches | TCU | n | " + " | ".join(SUMMARY_LABELS[c][0] + " mean / worst" for c in cols) +
             " | stalls | no lock-up |",
             "|" + "---|" * (5 + len(cols))]
    for r in rows:
        if r["group"] not in groups:
            continue
        cells = [r["group"], r["tcu"], str(r["n"])]
        cells += [f"{_f(r[c + '_mean'], SUMMARY_LABELS[c][1])} / {_f(r[c + '_worst'], SUMMARY_LABELS[c][1])}"
                  for c in cols]
        lines.append("| " + " | ".join(cells + [str(r["stalls"]), str(r["no_lockup"])]) + " |")
    return "\n".join(lines)


def ratio_line(results: dict[str, LaunchResult], group: str = "hot") -> str:
    """The naive / aware_estimated ratio of the worst characteristic error in ``group`` (one line)."""
    worst = {r["tcu"]: r["characteristic_error_max_Nm_worst"] for r in summary_rows(results) if r["group"] == group}
    if "naive" not in worst or "aware_estimated" not in worst:
        return f"{group}: naive / aware_estimated characteristic error: –"
    n, a = worst["naive"], worst["aware_estimated"]
    ratio = n / a if a > 0 else math.inf
    return (f"{group}: worst characteristic_error_max_Nm naive {n:.3f} / aware_estimated {a:.3f} = "
            f"{ratio:.1f}x")
