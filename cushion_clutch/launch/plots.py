"""Plots of a launch study: the hottest launch, temperatures and estimates, metrics per launch."""
from __future__ import annotations

from pathlib import Path

import numpy as np

from ..model import KELVIN
from .simulate import LaunchResult

STYLE = {"naive": "-", "aware": "--", "aware_estimated": "-.", "adaptive": ":", "adaptive_aware_estimated": (0, (5, 1, 1, 1, 1, 1)),
         "production": (0, (3, 1, 1, 1))}


def plot_launches(results: dict[str, LaunchResult], out: Path) -> list[Path]:
    """``launch_last.png``, ``launch_temperatures.png`` and ``launch_metrics.png`` in ``out``."""
    import matplotlib.pyplot as plt

    from ..plotting import finish_figure

    any_res = next(iter(results.values()))
    hottest = max(any_res.metrics, key=lambda m: m["theta_cs_start_degC"])["launch"]
    fig, axes = plt.subplots(3, 1, figsize=(9, 10), sharex=True)
    for i, (name, res) in enumerate(results.items()):
        s = res.series
        sel = s["launch"] == hottest
        t = s["time_s"][sel] - s["time_s"][sel][0]
        ls = STYLE.get(name, "-")
        axes[0].plot(t, s["w_disc_rad_s"][sel] * 30 / np.pi, linestyle=ls, color=f"C{i}", label=f"disc ({name})")
        axes[1].plot(t, s["x_to_m"][sel] * 1e3, linestyle=ls, color=f"C{i}", label=f"x_to ({name})")
        axes[1].plot(t, s["x_kiss_tcu_m"][sel] * 1e3, linestyle=ls, color=f"C{i}", alpha=0.5, lw=0.8)
        axes[2].plot(t, s["torque_capacity_Nm"][sel], linestyle=ls, color=f"C{i}", label=f"delivered ({name})")
        if i == 0:
            axes[0].plot(t, s["w_engine_rad_s"][sel] * 30 / np.pi, color="grey", label="engine (naive)")
            axes[1].plot(t, s["x_kiss_m"][sel] * 1e3, color="k", lw=1.5, label="true kiss point")
            axes[2].plot(t, s["torque_demand_Nm"][sel], color="k", lw=1.5, label="demanded (naive)")
    axes[0].set(ylabel="speed [rpm]", title=f"Launch {hottest} (hottest start): the {len(results)} TCUs")
    axes[1].set(ylabel="bearing [mm] (thin: kiss point believed)")
    lock = max((m["engagement_time_s"] for r in results.values() for m in r.metrics
                if m["launch"] == hottest and m["engagement_time_s"] == m["engagement_time_s"]), default=3.0)
    axes[2].set(ylabel="clutch torque [N·m]", xlim=(0, min(12.0, lock + 1.5)),
                xlabel="time since the launch slot's start [s] (pre-fill, then the pedal)")
    p1 = finish_figure(fig, axes, out / "launch_last.png", fontsize=7)

    fig, ax = plt.subplots(figsize=(9, 4.5))
    s = any_res.series
    ax.plot(s["time_s"], s["theta_cm_K"] - KELVIN, color="C3", label="facing θ_cm (plant)")
    ax.plot(s["time_s"], s["theta_cs_K"] - KELVIN, color="C0", label="cushion spring θ_cs (FMU)")
    # the estimates of the TCUs with their own thermal model: the lumped observer and the production EKF
    for name, ls, what in (("aware_estimated", "--", "observer"), ("production", ":", "production EKF")):
        est = results.get(name)
        if est is None:
            continue
        e = est.series
        ax.plot(e["time_s"], e["theta_cm_tcu_K"] - KELVIN, linestyle=ls, color="C3", label=f"θ_cm estimated ({what})")
        ax.plot(e["time_s"], e["theta_cs_tcu_K"] - KELVIN, linestyle=ls, color="C0", label=f"θ_cs estimated ({what})")
    ax.set(xlabel="time [s]", ylabel="temperature [°C]",
           title="Temperatures over the launches: plant and the TCUs' mismatched models")
    p2 = finish_figure(fig, ax, out / "launch_temperatures.png")

    fig, axes = plt.subplots(3, 1, figsize=(9, 9), sharex=True)
    for i, (name, res) in enumerate(results.items()):
        n = [m["launch"] for m in res.metrics]
        ls = STYLE.get(name, "-")
        for ax, col in zip(axes, ("characteristic_error_rms_Nm", "tracking_error_rms_Nm", "lockup_accel_step_m_s2")):
            ax.plot(n, [m[col] for m in res.metrics], marker="o", ms=3, linestyle=ls, color=f"C{i}", label=name)
    axes[0].set(ylabel="characteristic_error_rms_Nm\n(believed − true at actual x)",
                title="Metrics per launch and TCU")
    axes[0].set_yscale("symlog", linthresh=0.01)
    axes[1].set(ylabel="tracking_error_rms_Nm\n(delivered − demanded)")
    axes[2].set(ylabel="lockup_accel_step_m_s2", xlabel="launch")
    p3 = finish_figure(fig, axes, out / "launch_metrics.png", fontsize=7)
    return [p1, p2, p3]
