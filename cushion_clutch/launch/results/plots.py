"""Plots of a launch study: the hottest launch, temperatures and estimates, metrics per launch.

Every axis is labelled in words with its unit; legends sit outside the data and quote values, not
configuration keys; one panel per TCU where six overlapping series would hide each other, and each TCU's
estimates are drawn against its own plant (each TCU drives, and heats, its own clutch). Launches that the
thermal protection inhibited and launches that never locked up are marked and counted. Every figure carries
the scenario's name, the project's version and the command in its footer and in the PNG's ``Description``.
"""
from __future__ import annotations

import math
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from ...model import KELVIN
from .series import LaunchResult

if TYPE_CHECKING:
    from .provenance import Provenance

STYLE = {"naive": "-", "aware": "--", "aware_estimated": "-.", "adaptive": ":", "adaptive_aware_estimated": (0, (5, 1, 1, 1, 1, 1)),
         "production": (0, (3, 1, 1, 1))}
#: facing temperature above which organic facings are damaged (fade, glazing), °C; shaded when reached
FACING_DAMAGE_LIMIT_DEGC = 350.0
#: the metrics-per-launch panels below the per-TCU ones: (column, axis label)
METRIC_PANELS = (("tracking_error_rms_Nm", "tracking error, RMS [N·m]\n(delivered − demanded torque)"),
                 ("lockup_accel_step_m_s2", "acceleration step at lock-up [m/s²]\n(a lurch if large)"))
#: marks of the launches without lock-up
INHIBITED_LABEL = "launch inhibited by the thermal protection (no launch)"
NO_LOCKUP_LABEL = "launched, never locked up"
INHIBITED_COLOR, NO_LOCKUP_COLOR = "0.55", "C4"


def _spans(t: np.ndarray, mask: np.ndarray) -> list[tuple[float, float]]:
    """(start, end) times of the runs where ``mask`` is true."""
    mask = np.asarray(mask, bool)
    if not mask.any():
        return []
    edges = np.flatnonzero(np.diff(np.r_[0, mask.astype(int), 0]))
    return [(float(t[a]), float(t[min(b, len(t) - 1)])) for a, b in zip(edges[::2], edges[1::2])]


def _shade(ax, t, mask, color: str, label: str, alpha: float = 0.15, **kw) -> bool:
    """Shade the time spans where ``mask`` holds (one legend entry); whether there were any."""
    spans = _spans(t, mask)
    for k, (a, b) in enumerate(spans):
        ax.axvspan(a, max(b, a + 1e-3), color=color, alpha=alpha, lw=0, label=label if k == 0 else None, **kw)
    return bool(spans)


def _legend_outside(ax, handles=None, labels=None, **kw) -> None:
    if handles is None:
        ax.legend(loc="upper left", bbox_to_anchor=(1.01, 1.0), borderaxespad=0.0, fontsize=7, **kw)
    else:
        ax.legend(handles, labels, loc="upper left", bbox_to_anchor=(1.01, 1.0), borderaxespad=0.0, fontsize=7,
                  **kw)


def _figure_legend(axes, anchor) -> None:
    """One legend beside ``anchor`` with every label of ``axes`` once (panels carry different marks)."""
    seen: dict[str, object] = {}
    for ax in axes:
        for h, lab in zip(*ax.get_legend_handles_labels()):
            seen.setdefault(lab, h)
    _legend_outside(anchor, list(seen.values()), list(seen))


def _integer_ticks(ax) -> None:
    from matplotlib.ticker import MaxNLocator
    ax.xaxis.set_major_locator(MaxNLocator(integer=True))


def _default_table_range() -> tuple[float, float]:
    from ...model import load_table
    theta = load_table().theta_degC
    return float(np.min(theta)), float(np.max(theta))


def launch_status(m: dict) -> str:
    """How a launch ended: ``locked``, ``inhibited`` (the thermal protection: no launch) or ``no lock-up``."""
    if not math.isnan(m["engagement_time_s"]):
        return "locked"
    return "inhibited" if m["protection_level"] >= 3 else "no lock-up"


def _counts(res: LaunchResult) -> str:
    """``k/n locked up`` and the inhibited and never-locked-up launches, for a panel's title."""
    status = [launch_status(m) for m in res.metrics]
    text = f"{status.count('locked')}/{len(status)} locked up"
    if status.count("inhibited"):
        text += f" · {status.count('inhibited')} inhibited"
    if status.count("no lock-up"):
        text += f" · {status.count('no lock-up')} never locked"
    return text


def plot_launches(results: dict[str, LaunchResult], out: Path,
                  table_range_degC: tuple[float, float] | None = None,
                  provenance: "Provenance | None" = None) -> list[Path]:
    """``launch_last.png``, ``launch_temperatures.png`` and ``launch_metrics.png`` in ``out``.

    ``table_range_degC``: the temperatures the TCUs' table set covers (default: the shipped set's); the
    temperature plot shades where θ_cs leaves it and where θ_cm passes the facings' damage limit.
    ``provenance``: the scenario, version and command written on every figure (None: "unnamed").
    """
    from .provenance import Provenance
    prov = provenance or Provenance("unnamed")
    return [_plot_last(results, out, prov), _plot_temperatures(results, out, table_range_degC or _default_table_range(),
                                                               prov),
            _plot_metrics(results, out, prov)]


def _plot_last(results: dict[str, LaunchResult], out: Path, prov: "Provenance") -> Path:
    """The hottest launch: speeds, bearing positions, and per TCU the torques (one panel each)."""
    import matplotlib.pyplot as plt

    from ...plotting import finish_figure

    # the launch whose start is hottest for the most TCUs' plants (each TCU heats its own clutch)
    starts = {name: {m["launch"]: m["theta_cs_start_degC"] for m in res.metrics} for name, res in results.items()}
    first = next(iter(results.values()))
    hottest = max((m["launch"] for m in first.metrics),
                  key=lambda n: max(s.get(n, -math.inf) for s in starts.values()))
    names = list(results)
    ncols = 3
    nrows = 2 + -(-len(names) // ncols)
    fig = plt.figure(figsize=(12, 3.0 * nrows))
    grid = fig.add_gridspec(nrows, ncols)
    ax_speed = fig.add_subplot(grid[0, :])
    ax_bear = fig.add_subplot(grid[1, :], sharex=ax_speed)
    lock = max((m["engagement_time_s"] for r in results.values() for m in r.metrics
                if m["launch"] == hottest and m["engagement_time_s"] == m["engagement_time_s"]), default=None)
    window = min(12.0, lock + 1.5) if lock is not None else min(12.0, max(
        float(np.ptp(r.series["time_s"][r.series["launch"] == hottest])) for r in results.values()))
    xlim = (0, window)
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
            ax_bear.plot(t, s["x_kiss_m"][sel] * 1e3, color="k", lw=1.5, label=f"true kiss point, {name}'s clutch")
        ax = fig.add_subplot(grid[2 + i // ncols, i % ncols], sharex=ax_speed,
                             sharey=torque_axes[0] if torque_axes else None)
        torque_axes.append(ax)
        ax.plot(t, s["torque_capacity_Nm"][sel], color="C0", lw=1.0,
                label="capacity (what the clutch could transmit;\nrises off the axis after lock-up)")
        ax.plot(t, s["torque_clutch_Nm"][sel], color="C3", lw=1.5, label="transmitted (engine side of the disc)")
        ax.plot(t, s["torque_demand_Nm"][sel], color="k", lw=1.0, linestyle="--", label="demanded by the TCU")
        m = next(m for m in res.metrics if m["launch"] == hottest)
        status = launch_status(m)
        how = {"locked": f"locked up at {m['engagement_time_s']:.2f} s",
               "inhibited": "INHIBITED by the thermal protection: no launch",
               "no lock-up": "never locked up"}[status]
        ax.set_title(f"{name}: θ_cs {m['theta_cs_start_degC']:.0f} °C at the start\n{how}", fontsize=8,
                     color="k" if status == "locked" else "C3")
        if status == "inhibited":
            ax.text(0.5, 0.5, "no launch: inhibited\nby the thermal protection", transform=ax.transAxes, ha="center",
                    va="center", color=INHIBITED_COLOR, fontsize=9)
        if i % ncols == 0:
            ax.set_ylabel("clutch torque [N·m]")
        if i // ncols == (len(names) - 1) // ncols:
            ax.set_xlabel("time since the launch slot's start [s]")
    theta_lo = min(s[hottest] for s in starts.values())
    theta_hi = max(s[hottest] for s in starts.values())
    ax_speed.set(ylabel="speed [rpm]", xlim=xlim,
                 title=f"Launch {hottest}, the hottest start (θ_cs {theta_lo:.0f}–{theta_hi:.0f} °C over the TCUs' "
                       f"clutches): pre-fill, then the launch")
    ax_bear.set(ylabel="bearing position [mm]\n(thin: kiss point the TCU believes)")
    _legend_outside(ax_speed)
    _legend_outside(ax_bear)
    top = 1.25 * max(max(np.max(np.abs(ln.get_ydata()), initial=0.0) for ln in ax.lines[1:]) for ax in torque_axes)
    torque_axes[0].set_ylim(top=max(top, 10.0))          # the transmitted torque readable; capacity may leave
    _legend_outside(torque_axes[min(ncols, len(torque_axes)) - 1])
    for ax in [ax_speed, ax_bear, *torque_axes]:
        ax.grid(True, alpha=0.3)
    return finish_figure(fig, [], out / "launch_last.png", legend=False, footer=prov.line())


def _slot_spans(res: LaunchResult, status: str) -> list[tuple[float, float]]:
    """(start, end) times of the launch slots whose launch ended with ``status`` (:func:`launch_status`)."""
    s = res.series
    out = []
    for m in res.metrics:
        if launch_status(m) == status:
            t = s["time_s"][s["launch"] == m["launch"]]
            if len(t):
                out.append((float(t[0]), float(t[-1])))
    return out


def _plot_temperatures(results: dict[str, LaunchResult], out: Path, table_range: tuple[float, float],
                       prov: "Provenance") -> Path:
    """Per TCU (one panel each, same scales): θ_cm and θ_cs of the plant that TCU drove, and what the TCU
    estimates or assumes of them; the spans outside the tables and above the facings' damage limit shaded
    from that plant, the launches it inhibited or never locked up marked."""
    import matplotlib.pyplot as plt

    from ...plotting import finish_figure

    names = list(results)
    ncols = min(3, len(names))
    nrows = -(-len(names) // ncols)
    fig, axes = plt.subplots(nrows, ncols, figsize=(13, 3.2 * nrows + 0.6), sharex=True, sharey=True,
                             squeeze=False)
    lo, hi = table_range
    for i, (name, res) in enumerate(results.items()):
        ax = axes[i // ncols, i % ncols]
        s = res.series
        t = s["time_s"]
        theta_cm, theta_cs = s["theta_cm_K"] - KELVIN, s["theta_cs_K"] - KELVIN
        for k, (a, b) in enumerate(_slot_spans(res, "inhibited")):
            ax.axvspan(a, b, facecolor="none", edgecolor=INHIBITED_COLOR, hatch="///", lw=0,
                       label=INHIBITED_LABEL if k == 0 else None)
        for k, (a, b) in enumerate(_slot_spans(res, "no lock-up")):
            ax.axvspan(a, b, color=NO_LOCKUP_COLOR, alpha=0.10, lw=0, label=NO_LOCKUP_LABEL if k == 0 else None)
        _shade(ax, t, (theta_cs < lo) | (theta_cs > hi), "C1",
               f"θ_cs outside the tables ({lo:g}–{hi:g} °C): clamped", alpha=0.25, ymax=0.06)
        if _shade(ax, t, theta_cm > FACING_DAMAGE_LIMIT_DEGC, "C3",
                  f"θ_cm above the facings' damage limit ({FACING_DAMAGE_LIMIT_DEGC:g} °C)", alpha=0.35, ymin=0.94):
            ax.axhline(FACING_DAMAGE_LIMIT_DEGC, color="C3", lw=0.8, linestyle=":")
        ax.plot(t, theta_cm, color="C3", lw=1.0, label="facing θ_cm (this TCU's plant)")
        ax.plot(t, theta_cs, color="C0", lw=1.0, label="cushion spring θ_cs (this TCU's plant)")
        est_cm = s["theta_cm_tcu_K"] - KELVIN
        if np.isfinite(est_cm).any():
            ax.plot(t, est_cm, color="C3", lw=1.2, linestyle="--", label="θ_cm the TCU estimates")
        ax.plot(t, s["theta_cs_tcu_K"] - KELVIN, color="C0", lw=1.2, linestyle="--",
                label="θ_cs the TCU uses (estimate, truth or fixed)")
        peak = float(np.max(theta_cm))
        ax.set_title(f"{name}: peak θ_cm {peak:.0f} °C\n{_counts(res)}", fontsize=8)
        ax.grid(True, alpha=0.3)
        if i % ncols == 0:
            ax.set_ylabel("temperature [°C]")
        if i // ncols == nrows - 1 or i + ncols >= len(names):
            ax.set_xlabel("time [s]")
        ax.tick_params(labelbottom=True)
    for j in range(len(names), nrows * ncols):
        axes[j // ncols, j % ncols].set_visible(False)
    _figure_legend(axes.flat[:len(names)], axes[0, ncols - 1])
    fig.suptitle(f"Temperatures over the launches, per TCU: the clutch each TCU drove (solid) and what the TCU "
                 f"believes (dashed) — scenario '{prov.scenario}'", fontsize=10)
    return finish_figure(fig, [], out / "launch_temperatures.png", legend=False, footer=prov.line())


def _plot_metrics(results: dict[str, LaunchResult], out: Path, prov: "Provenance") -> Path:
    """Characteristic error per launch, one panel per TCU (same scale, its own hot launches shaded), then
    tracking error and lock-up step for all TCUs; inhibited and never-locked-up launches marked."""
    import matplotlib.pyplot as plt
    from matplotlib.transforms import blended_transform_factory

    from ...plotting import finish_figure

    names = list(results)
    ncols = 3
    rows_tcu = -(-len(names) // ncols)
    fig = plt.figure(figsize=(12, 2.7 * (rows_tcu + len(METRIC_PANELS)) + 0.4))
    grid = fig.add_gridspec(rows_tcu + len(METRIC_PANELS), ncols)
    top = None
    hot_label = ("hot launch of this TCU (θ_cs at its start ≥ "
                 + (f"{prov.hot_degC:g} °C)" if prov.hot_degC is not None else "the scenario's hot threshold)"))
    tcu_axes = []

    def mark_bottom(ax, n, color, label, marker, y=0.04):
        """Marks at the bottom of ``ax`` (axes fraction ``y``) at launch numbers ``n``."""
        tr = blended_transform_factory(ax.transData, ax.transAxes)
        if n:
            ax.plot(n, [y] * len(n), linestyle="none", marker=marker, ms=6, color=color, transform=tr,
                    label=label, clip_on=False)

    for i, (name, res) in enumerate(results.items()):
        ax = fig.add_subplot(grid[i // ncols, i % ncols], sharey=top, sharex=top)
        top = top or ax
        tcu_axes.append(ax)
        n = [m["launch"] for m in res.metrics]
        for k, nn in enumerate(m["launch"] for m in res.metrics if m["hot"]):
            ax.axvspan(nn - 0.5, nn + 0.5, color="C1", alpha=0.10, lw=0, label=hot_label if k == 0 else None)
        ax.plot(n, [m["characteristic_error_rms_Nm"] for m in res.metrics], marker="o", ms=3, color=f"C{i}",
                label="RMS")
        ax.plot(n, [m["characteristic_error_max_Nm"] for m in res.metrics], marker="^", ms=3, lw=0.8,
                color=f"C{i}", alpha=0.6, label="max")
        status = [launch_status(m) for m in res.metrics]
        mark_bottom(ax, [k for k, st in zip(n, status) if st == "inhibited"], INHIBITED_COLOR, INHIBITED_LABEL, "x")
        mark_bottom(ax, [k for k, st in zip(n, status) if st == "no lock-up"], NO_LOCKUP_COLOR, NO_LOCKUP_LABEL, "v")
        ax.set_title(f"{name}\n{_counts(res)}", fontsize=8)
        ax.grid(True, alpha=0.3)
        _integer_ticks(ax)
        if i % ncols == 0:
            ax.set_ylabel("characteristic error [N·m]\n(believed − true torque)", fontsize=8)
    _figure_legend(tcu_axes, tcu_axes[min(ncols, len(tcu_axes)) - 1])
    for r, (col, label) in enumerate(METRIC_PANELS):
        ax = fig.add_subplot(grid[rows_tcu + r, :])
        for i, (name, res) in enumerate(results.items()):
            ax.plot([m["launch"] for m in res.metrics], [m[col] for m in res.metrics], marker="o", ms=3,
                    linestyle=STYLE.get(name, "-"), color=f"C{i}", label=name)
            missing = [m["launch"] for m in res.metrics if launch_status(m) != "locked"]
            mark_bottom(ax, missing, f"C{i}", None, "x", 0.03 + 0.045 * i)     # one row of marks per TCU
        if any(launch_status(m) != "locked" for res in results.values() for m in res.metrics):
            ax.plot([], [], linestyle="none", marker="x", color="0.3",
                    label="× in the band below the data: no lock-up in\nthat launch (inhibited or never locked;\n"
                          "one row and colour per TCU)")
            vals = np.array([m[col] for res in results.values() for m in res.metrics], float)
            vals = vals[np.isfinite(vals)]
            if len(vals):                  # a band below the data for the marks (0.3 of the axis)
                lo, hi = float(vals.min()), float(vals.max())
                span = hi - lo if hi > lo else max(abs(hi), 1.0)
                ax.set_ylim(lo - 0.45 * span, hi + 0.05 * span)
                ax.set_yticks([y for y in ax.get_yticks() if lo - 0.02 * span <= y <= hi + 0.05 * span])
                ax.axhspan(lo - 0.45 * span, lo - 0.04 * span, color="0.93", lw=0, zorder=0)
        ax.set_ylabel(label, fontsize=8)
        ax.grid(True, alpha=0.3)
        _integer_ticks(ax)
        _legend_outside(ax)
        if r == len(METRIC_PANELS) - 1:
            ax.set_xlabel("launch number")
    any_hot = any(m["hot"] for res in results.values() for m in res.metrics)
    threshold = f"{prov.hot_degC:g} °C" if prov.hot_degC is not None else "the hot threshold"
    fig.suptitle(f"Metrics per launch and TCU — scenario '{prov.scenario}' (each TCU's launches on its own clutch; "
                 + ("hot shading from that TCU's clutch)" if any_hot else f"no launch started hot, θ_cs ≥ {threshold})"),
                 fontsize=10)
    return finish_figure(fig, [], out / "launch_metrics.png", legend=False, footer=prov.line())
