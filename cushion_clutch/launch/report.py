"""Run a launch scenario with both TCUs and write the time series, metrics and plots."""
from __future__ import annotations

import csv
from pathlib import Path
from typing import Callable

import numpy as np

from ..fmu_src.clutch_model import KELVIN, SpringTable
from .simulate import COLUMNS, LaunchResult, simulate_launches
from .scenario import Scenario

METRIC_COLUMNS = ("tcu", "launch", "theta_cs_start_degC", "torque_error_rms_Nm", "torque_error_max_Nm",
                  "kiss_point_error_mm", "engagement_time_s", "slip_energy_kJ", "peak_jerk_m_s3",
                  "engine_stall")


def run_both(fmu: Path, sc: Scenario, table: SpringTable,
             progress: Callable[[str, float], None] | None = None) -> dict[str, LaunchResult]:
    """The naive and the temperature-aware TCU on the same scenario."""
    out = {}
    for aware in (False, True):
        name = "aware" if aware else "naive"
        cb = (lambda t, n=name: progress(n, t)) if progress else None
        out[name] = simulate_launches(fmu, sc, table, aware, progress=cb)
    return out


def write_outputs(results: dict[str, LaunchResult], out: Path) -> list[Path]:
    """``launch_<tcu>.csv`` time series, ``launch_metrics.csv`` and PNG plots."""
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
    paths += plot_launches(results, out)
    return paths


def metrics_table(results: dict[str, LaunchResult]) -> str:
    """The per-launch metrics of both TCUs as aligned text."""
    head = (f"{'launch':>6} {'theta_cs':>8} | {'RMS err [N.m]':>15} | {'max err [N.m]':>15} | "
            f"{'kiss err [mm]':>15} | {'t_eng [s]':>13} | {'E_slip [kJ]':>13} | {'jerk [m/s3]':>13} | stall")
    sub = (f"{'':>6} {'[degC]':>8} | {'naive':>7} {'aware':>7} | {'naive':>7} {'aware':>7} | "
           f"{'naive':>7} {'aware':>7} | {'naive':>6} {'aware':>6} | {'naive':>6} {'aware':>6} | "
           f"{'naive':>6} {'aware':>6} | n/a")
    lines = [head, sub]
    nv, aw = results["naive"].metrics, results["aware"].metrics
    for a, b in zip(nv, aw):
        lines.append(
            f"{a['launch']:>6d} {a['theta_cs_start_degC']:>8.1f} | {a['torque_error_rms_Nm']:>7.2f} "
            f"{b['torque_error_rms_Nm']:>7.2f} | {a['torque_error_max_Nm']:>7.2f} {b['torque_error_max_Nm']:>7.2f} | "
            f"{a['kiss_point_error_mm']:>7.3f} {b['kiss_point_error_mm']:>7.3f} | "
            f"{a['engagement_time_s']:>6.3f} {b['engagement_time_s']:>6.3f} | {a['slip_energy_kJ']:>6.2f} "
            f"{b['slip_energy_kJ']:>6.2f} | {a['peak_jerk_m_s3']:>6.1f} {b['peak_jerk_m_s3']:>6.1f} | "
            f"{'y' if a['engine_stall'] else 'n'}/{'y' if b['engine_stall'] else 'n'}")
    return "\n".join(lines)


def plot_launches(results: dict[str, LaunchResult], out: Path) -> list[Path]:
    """Speeds, bearing, torque demanded vs delivered (last launch), temperatures over all launches."""
    import matplotlib.pyplot as plt

    from ..plotting import finish_figure

    nv, aw = results["naive"].series, results["aware"].series
    last = nv["launch"].max()
    sel_n, sel_a = nv["launch"] == last, aw["launch"] == last
    t0 = nv["time_s"][sel_n][0]
    fig, axes = plt.subplots(3, 1, figsize=(9, 9), sharex=True)
    tn, ta = nv["time_s"][sel_n] - t0, aw["time_s"][sel_a] - t0
    ax = axes[0]
    ax.plot(tn, nv["w_engine_rad_s"][sel_n] * 30 / np.pi, label="engine (naive)")
    ax.plot(tn, nv["w_disc_rad_s"][sel_n] * 30 / np.pi, label="clutch disc (naive)")
    ax.plot(ta, aw["w_disc_rad_s"][sel_a] * 30 / np.pi, "--", label="clutch disc (aware)")
    ax.set(ylabel="speed [rpm]", title=f"Launch {int(last)} (hot): naive vs temperature-aware TCU")
    ax = axes[1]
    ax.plot(tn, nv["x_to_m"][sel_n] * 1e3, label="x_to naive")
    ax.plot(ta, aw["x_to_m"][sel_a] * 1e3, "--", label="x_to aware")
    ax.plot(tn, nv["x_kiss_m"][sel_n] * 1e3, ":", color="k", label="true kiss point")
    ax.plot(tn, nv["x_kiss_tcu_m"][sel_n] * 1e3, ":", color="C0", label="kiss point assumed (naive)")
    ax.set(ylabel="bearing [mm]")
    ax = axes[2]
    ax.plot(tn, nv["torque_demand_Nm"][sel_n], color="k", label="demanded")
    ax.plot(tn, nv["torque_capacity_Nm"][sel_n], label="delivered (naive)")
    ax.plot(ta, aw["torque_capacity_Nm"][sel_a], "--", label="delivered (aware)")
    ax.set(ylabel="clutch torque [N·m]", xlabel="time since launch start [s]", xlim=(0, 4))
    p1 = finish_figure(fig, axes, out / "launch_last.png", fontsize=8)

    fig, ax = plt.subplots(figsize=(9, 4))
    ax.plot(nv["time_s"], nv["theta_cm_K"] - KELVIN, label="facing θ_cm")
    ax.plot(nv["time_s"], nv["theta_cs_K"] - KELVIN, label="cushion spring θ_cs (FMU)")
    ax.plot(aw["time_s"], aw["theta_cs_tcu_K"] - KELVIN, "--", label="θ_cs estimated by the aware TCU")
    ax.set(xlabel="time [s]", ylabel="temperature [°C]", title="Temperatures over the repeated launches")
    return [p1, finish_figure(fig, ax, out / "launch_temperatures.png")]
