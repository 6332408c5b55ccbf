"""Matplotlib PNG plots of the tables (paper Figs. 11 and 12 style)."""
from __future__ import annotations

from pathlib import Path

import numpy as np

from ..plotting import finish_figure, plt
from ..model.table_format import TableSet


def plot_force_deflection(tables: TableSet, path: Path, title: str = "") -> Path:
    """F(u) family over temperature, u from the 20 degC kiss point (paper Fig. 11)."""
    ref = int(np.argmin(np.abs(tables.theta_degC - 20.0)))
    fig, (ax, zoom) = plt.subplots(1, 2, figsize=(11, 4.5))
    for t, u, f, d in zip(tables.theta_degC, tables.u_m, tables.force_N, tables.delta_kiss_m):
        shift = d - tables.delta_kiss_m[ref]
        for a in (ax, zoom):
            a.plot((u - shift) * 1e3, f / 1e3, label=f"{t:g} °C")
    ax.set(xlabel="compression from the 20 °C kiss point u [mm]", ylabel="spring force F [kN]",
           title=title or "Cushion spring load-deflection")
    zoom.set(xlim=(-0.2, 0.4), ylim=(0, 0.6), xlabel="u [mm]", ylabel="F [kN]",
             title="zoom: the kiss point moves with temperature")
    ax.legend()
    return finish_figure(fig, [ax, zoom], path, legend=False)


def plot_kiss_shift(tables: TableSet, path: Path) -> Path:
    """delta_kiss(theta): growth of the free height of one pair."""
    fig, ax = plt.subplots(figsize=(5.5, 4))
    ax.plot(tables.theta_degC, tables.delta_kiss_m * 1e3, "o-", label="kiss-point shift (10 N point)")
    kp = tables.metadata.get("kiss_point", {})
    if kp:
        ax.plot(tables.theta_degC, [kp[f"{t:g}"]["crest_growth_m"] * 1e3 for t in tables.theta_degC],
                "s--", label="crest growth from heating alone")
    ax.set(xlabel="cushion-spring temperature θ [°C]", ylabel="growth of the pair's free height [mm]",
           title="Thermal growth of the pair's free height")
    return finish_figure(fig, ax, path, legend=bool(kp))
