"""Plots of a launch study: the hottest launch, temperatures and estimates, metrics per launch.

Every axis is labelled in words with its unit; legends sit outside the data; one panel per TCU where six
overlapping series would hide each other.
"""
from __future__ import annotations

from pathlib import Path

import numpy as np

from ..model import KELVIN
from .simulate import LaunchResult

STYLE = {"naive": "-", "aware": "--", "aware_estimated": "-.", "adaptive": ":", "adaptive_aware_estimated": (0, (5, 1, 1, 1, 1, 1)),
         "production": (0, (3, 1, 1, 1))}
#: facing temperature above which organic facings are damaged (fade, glazing), °C; shaded when reached
FACING_DAMAGE_LIMIT_DEGC = 350.0
#: the metrics-per-launch panels below the per-TCU ones: (column, axis label)
METRIC_PANELS = (("tracking_error_rms_Nm", "tracking error, RMS [N·m]\n(delivered − demanded torque)"),
                 ("lockup_accel_step_m_s2", "acceleration step at lock-up [m/s²]\n(a lurch if large)"))


def _spans(t: np.ndarray, mask: np.ndarray) -> list[tuple[float, float]]:
    """(start, end) times of the runs where ``mask`` is true."""
    mask = np.asarray(mask, bool)
    if not mask.any():
        return []
    edges = np.flatnonzero(np.diff(np.r_[0, mask.astype(int), 0]))
    return [(float(t[a]), float(t[min(b, len(t) - 1)])) for a, b in zip(edges[::2], edges[1::2])]


def _shade(ax, t, mask, color: str, label: str) -> bool:
    """Shade the time spans where ``mask`` holds (one legend entry); whether there were any."""
    spans = _spans(t, mask)
    for k, (a, b) in enumerate(spans):
        ax.axvspan(a, max(b, a + 1e-3), color=color, alpha=0.15, lw=0, label=label if k == 0 else None)
    return bool(spans)


def _legend_outside(ax, **kw) -> None:
    ax.legend(loc="upper left", bbox_to_anchor=(1.01, 1.0), borderaxespad=0.0, fontsize=7, **kw)


def _default_table_range() -> tuple[float, float]:
    from ..model import load_table
    theta = load_table().theta_degC
    return float(np.min(theta)), float(np.max(theta))


def plot_launches(results: dict[str, LaunchResult], out: Path,
                  table_range_degC: tuple[float, float] | None = None) -> list[Path]:
    """``launch_last.png``, ``launch_temperatures.png`` and ``launch_metrics.png`` in ``out``.

    ``table_range_degC``: the temperatures the TCUs' table set covers (default: the shipped set's); the
    temperature plot shades where θ_cs leaves it and where θ_cm passes the facings' damage limit.
    """
    return [_plot_last(results, out), _plot_temperatures(results, out, table_range_degC or _default_table_range()),
            _plot_metrics(results, out)]


def _plot_last(results: dict[str, LaunchResult], out: Path) -> Path:
    """The hottest launch: speeds, bearing positions, and per TCU the torques (one panel each)."""
    import matplotlib.pyplot as plt

    from ..plotting import finish_figure

    any_res = next(iter(results.values()))
    hottest = max(any_res.metrics, key=lambda m: m["theta_cs_start_degC"])["launch"]
    theta0 = max(m["theta_cs_start_degC"] for m in any_res.metrics)
    names = list(results)
    ncols = 3
    nrows = 2 + -(-len(names) // ncols)
    fig = plt.figure(figsize=(12, 3.0 * nrows))
    grid = fig.add_gridspec(nrows, ncols)
    ax_speed = fig.add_subplot(grid[0, :])
    ax_bear = fig.add_subplot(grid[1, :], sharex=ax_speed)
    lock = max((m["engagement_time_s"] for r in results.values() for m in r.metrics
                if m["launch"] == hottest and m["engagement_time_s"] == m["engagement_time_s"]), default=3.0)
    xlim = (0, min(12.0, lock + 1.5))
    torque_axes = []
    for i, (name, res) in enumerate(results.items()):
        s = res.series
        sel = np.flatnonzero(s["launch"] == hottest)
        t = s["time_s"][sel] - s["time_s"][sel][0]
        sel, t = sel[t <= xlim[1]], t[t <= xlim[1]]                   # the window shown (autoscaled y)
        ls = STYLE.get(name, "-")
        ax_speed.plot(t, s["w_disc_rad_s"][sel] * 30 / np.pi, linestyle=ls, color=f"C{i}", label=f"disc, {name}")
        ax_bear.plot(t, s["x_to_m"][sel] * 1e3, linestyle=ls, color=f"C{i}", label=f"bearing, {name}")
        ax_bear.plot(t, s["x_kiss_tcu_m"][sel] * 1e3, linestyle=ls, color=f"C{i}", alpha=0.5, lw=0.8)
        if i == 0:
            ax_speed.plot(t, s["w_engine_rad_s"][sel] * 30 / np.pi, color="grey", label=f"engine, {name}")
            ax_bear.plot(t, s["x_kiss_m"][sel] * 1e3, color="k", lw=1.5, label="true kiss point")
        ax = fig.add_subplot(grid[2 + i // ncols, i % ncols], sharex=ax_speed,
                             sharey=torque_axes[0] if torque_axes else None)
        torque_axes.append(ax)
        ax.plot(t, s["torque_capacity_Nm"][sel], color="C0", lw=1.0,
                label="capacity (what the clutch could transmit;\nrises off the axis after lock-up)")
        ax.plot(t, s["torque_clutch_Nm"][sel], color="C3", lw=1.5, label="transmitted (engine side of the disc)")
        ax.plot(t, s["torque_demand_Nm"][sel], color="k", lw=1.0, linestyle="--", label="demanded by the TCU")
        ax.set_title(name, fontsize=9)
        if i % ncols == 0:
            ax.set_ylabel("clutch torque [N·m]")
        if i // ncols == (len(names) - 1) // ncols:
            ax.set_xlabel("time since the launch slot's start [s]")
    ax_speed.set(ylabel="speed [rpm]", xlim=xlim,
                 title=f"Launch {hottest}, the hottest start (θ_cs {theta0:.0f} °C): pre-fill, then the launch")
    ax_bear.set(ylabel="bearing position [mm]\n(thin: kiss point the TCU believes)")
    _legend_outside(ax_speed)
    _legend_outside(ax_bear)
    top = 1.25 * max(max(np.max(np.abs(ln.get_ydata())) for ln in ax.lines[1:]) for ax in torque_axes)
    torque_axes[0].set_ylim(top=max(top, 10.0))          # the transmitted torque readable; capacity may leave
    _legend_outside(torque_axes[min(ncols, len(torque_axes)) - 1])
    for ax in [ax_speed, ax_bear, *torque_axes]:
        ax.grid(True, alpha=0.3)
    return finish_figure(fig, [], out / "launch_last.png", legend=False)


def _plot_temperatures(results: dict[str, LaunchResult], out: Path, table_range: tuple[float, float]) -> Path:
    """θ_cm and θ_cs of the plant and the estimates of the TCUs with a thermal model of their own, with the
    spans outside the tables and above the facings' damage limit shaded."""
    import matplotlib.pyplot as plt

    from ..plotting import finish_figure

    any_res = next(iter(results.values()))
    fig, ax = plt.subplots(figsize=(11, 4.5))
    s = any_res.series
    t = s["time_s"]
    theta_cm, theta_cs = s["theta_cm_K"] - KELVIN, s["theta_cs_K"] - KELVIN
    lo, hi = table_range
    _shade(ax, t, (theta_cs < lo) | (theta_cs > hi), "C1",
           f"θ_cs outside the tables ({lo:g}–{hi:g} °C): clamped")
    if _shade(ax, t, theta_cm > FACING_DAMAGE_LIMIT_DEGC, "C3",
              f"θ_cm above the facings' damage limit ({FACING_DAMAGE_LIMIT_DEGC:g} °C)"):
        ax.axhline(FACING_DAMAGE_LIMIT_DEGC, color="C3", lw=0.8, linestyle=":")
    ax.plot(t, theta_cm, color="C3", label="facing θ_cm (plant)")
    ax.plot(t, theta_cs, color="C0", label="cushion spring θ_cs (FMU)")
    # the estimates of the TCUs with their own thermal model: the lumped observer and the production EKF
    for name, ls, what in (("aware_estimated", "--", "observer"), ("production", ":", "production EKF")):
        est = results.get(name)
        if est is None:
            continue
        e = est.series
        ax.plot(e["time_s"], e["theta_cm_tcu_K"] - KELVIN, linestyle=ls, color="C3", label=f"θ_cm estimated ({what})")
        ax.plot(e["time_s"], e["theta_cs_tcu_K"] - KELVIN, linestyle=ls, color="C0", label=f"θ_cs estimated ({what})")
    ax.set(xlabel="time [s]", ylabel="temperature [°C]",
           title="Temperatures over the launches: plant and the TCUs' own (mismatched) models")
    ax.grid(True, alpha=0.3)
    _legend_outside(ax)
    return finish_figure(fig, [], out / "launch_temperatures.png", legend=False)


def _plot_metrics(results: dict[str, LaunchResult], out: Path) -> Path:
    """Characteristic error per launch, one panel per TCU (same scale), then tracking error and lock-up step
    for all TCUs; hot launches shaded."""
    import matplotlib.pyplot as plt

    from ..plotting import finish_figure

    names = list(results)
    ncols = 3
    rows_tcu = -(-len(names) // ncols)
    fig = plt.figure(figsize=(12, 2.6 * (rows_tcu + len(METRIC_PANELS))))
    grid = fig.add_gridspec(rows_tcu + len(METRIC_PANELS), ncols)
    top = None
    first = next(iter(results.values())).metrics
    hot = [m["launch"] for m in first if m["hot"]]

    def shade_hot(ax):
        for k, n in enumerate(hot):
            ax.axvspan(n - 0.5, n + 0.5, color="C1", alpha=0.08, lw=0, label="hot launch (θ_cs at its start ≥ run.hot_degC)"
                       if k == 0 else None)

    for i, (name, res) in enumerate(results.items()):
        ax = fig.add_subplot(grid[i // ncols, i % ncols], sharey=top, sharex=top)
        top = top or ax
        n = [m["launch"] for m in res.metrics]
        shade_hot(ax)
        ax.plot(n, [m["characteristic_error_rms_Nm"] for m in res.metrics], marker="o", ms=3, color=f"C{i}",
                label="RMS")
        ax.plot(n, [m["characteristic_error_max_Nm"] for m in res.metrics], marker="^", ms=3, lw=0.8,
                color=f"C{i}", alpha=0.6, label="max")
        ax.set_title(name, fontsize=9)
        ax.grid(True, alpha=0.3)
        if i % ncols == 0:
            ax.set_ylabel("characteristic error [N·m]\n(believed − true torque)", fontsize=8)
        if i == ncols - 1:
            _legend_outside(ax)
    for r, (col, label) in enumerate(METRIC_PANELS):
        ax = fig.add_subplot(grid[rows_tcu + r, :])
        shade_hot(ax)
        for i, (name, res) in enumerate(results.items()):
            ax.plot([m["launch"] for m in res.metrics], [m[col] for m in res.metrics], marker="o", ms=3,
                    linestyle=STYLE.get(name, "-"), color=f"C{i}", label=name)
        ax.set_ylabel(label, fontsize=8)
        ax.grid(True, alpha=0.3)
        _legend_outside(ax)
        if r == len(METRIC_PANELS) - 1:
            ax.set_xlabel("launch number")
    fig.suptitle("Metrics per launch and TCU", fontsize=11)
    fig.tight_layout()
    return finish_figure(fig, [], out / "launch_metrics.png", legend=False)
