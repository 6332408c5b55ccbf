"""Plot of a tolerance study's P5/P50/P95 bands."""
from __future__ import annotations

from pathlib import Path

import numpy as np

from ...plotting import finish_figure, plt


def plot_bands(bands, summ, path: Path, title: str) -> Path:
    """F(u, theta), delta_kiss(theta) and T(x_to, theta): P5-P95 band, P50 and the nominal spring."""
    fig, axes = plt.subplots(3, 1, figsize=(8, 12))
    colors = plt.cm.plasma(np.linspace(0.0, 0.8, len(bands.temperatures_degC)))
    nominal = summ[0]
    ax = axes[0]
    for t, c in zip(bands.temperatures_degC, colors):
        lo, mid, hi = bands.force_N[t]
        ax.fill_between(bands.u_m * 1e3, lo / 1e3, hi / 1e3, color=c, alpha=0.25)
        ax.plot(bands.u_m * 1e3, mid / 1e3, color=c, label=f"{t:g} °C: P50, band P5–P95")
        ax.plot(bands.u_m * 1e3, [nominal.table.force(float(u), t) / 1e3 for u in bands.u_m], "--", color=c,
                lw=0.8)
    ax.set(xlabel="compression from the kiss point u [mm]", ylabel="spring force F [kN]",
           title=f"{title}\nF(u, θ) (dashed: nominal spring)")
    ax = axes[1]
    t = np.array(bands.temperatures_degC)
    lo, mid, hi = bands.delta_kiss_m * 1e3
    ax.fill_between(t, lo, hi, color="C0", alpha=0.25, label="P5–P95")
    ax.plot(t, mid, "C0-o", label="P50")
    for s in summ[1:]:
        ax.plot(t, [s.delta_kiss_m[x] * 1e3 for x in t], ".", color="0.5", ms=3)
    ax.plot(t, [nominal.delta_kiss_m[x] * 1e3 for x in t], "k--", lw=0.8, label="nominal")
    ax.set(xlabel="cushion-spring temperature θ [°C]", ylabel="kiss-point shift δ_kiss [mm]",
           title="Kiss-point shift δ_kiss(θ) (grey: samples)")
    ax = axes[2]
    for t, c in zip(bands.temperatures_degC, colors):
        lo, mid, hi = bands.torque_Nm[t]
        ax.fill_between(bands.x_to_m * 1e3, lo, hi, color=c, alpha=0.25)
        ax.plot(bands.x_to_m * 1e3, mid, color=c, label=f"{t:g} °C")
    ax.axvline(bands.x_half_m * 1e3, color="k", lw=0.8, ls=":", label="nominal half-engaged x_to")
    ax.set(xlabel="throwout-bearing position x_to [mm]", ylabel="clutch torque T [N·m]",
           title="Torque characteristic T(x_to, θ), FMU model with default clutch parameters")
    return finish_figure(fig, axes, path)
