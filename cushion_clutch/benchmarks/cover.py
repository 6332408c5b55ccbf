"""Cover characteristics: torque, clamp and bearing force vs x_to; kiss-point budget; closed capacity.

Everything from the Python reference model (:mod:`cushion_clutch.model.cover`) on the shipped
default tables and the default cover, at 20/195/300 degC (theta_cs = theta_cm) and
0/0.5/1 mm facing wear. Prints Markdown tables and writes the figure::

    python -m cushion_clutch.benchmarks.cover [--png docs/cover_characteristics.png]
"""
from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np

TEMPS_DEGC = (20.0, 195.0, 300.0)
WEARS_M = (0.0, 0.0005, 0.001)
ENGINE_PEAK_NM = 240.0


def curves(x_to: np.ndarray, theta_degC: float, wear_m: float = 0.0):
    """(torque N.m, clamp force N, bearing force N) along ``x_to`` (m)."""
    from cushion_clutch.model import ClutchParameters, load_table, outputs

    table, p = load_table(), ClutchParameters(facing_wear=wear_m)
    out = [outputs(float(x), theta_degC + 273.15, table, p) for x in x_to]
    return (np.array([o.torque for o in out]), np.array([o.clamp_force for o in out]),
            np.array([o.bearing_force for o in out]))


def budget_rows() -> list[str]:
    """Markdown rows of the kiss-point budget (mm at the bearing) and the closed capacity."""
    from cushion_clutch.model import ClutchParameters, load_table
    from cushion_clutch.model.cover import CoverMap

    table, p = load_table(), ClutchParameters()
    g = CoverMap(p.cover, p.lever_ratio)
    gain = p.n_surfaces * p.mu * p.R_eq
    rows = ["| theta (degC) | wear (mm) | cushion | facing | pressure plate | flywheel | wear | compliance | "
            "total shift | x_kiss (mm) | closed clamp (N) | closed torque (N.m) | / 240 N.m |",
            "|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|"]
    for t in TEMPS_DEGC:
        for w in WEARS_M:
            b = g.kiss_budget(t + 273.15, t + 273.15, w, table, p.x_kiss_ref)
            cells = [b[k] * 1e3 for k in ("cushion", "facing", "pressure_plate", "flywheel", "wear", "compliance",
                                          "total")]
            rows.append(f"| {t:g} | {w * 1e3:g} | " + " | ".join(f"{c:+.3f}" for c in cells)
                        + f" | {(p.x_kiss_ref + b['total']) * 1e3:.3f} | {b['clamp_closed_N']:.0f} | "
                        f"{gain * b['clamp_closed_N']:.1f} | {gain * b['clamp_closed_N'] / ENGINE_PEAK_NM:.2f} |")
    return rows


def figure(path: Path) -> list[str]:
    """Write the three-panel figure; returns Markdown rows of the release-force peak per temperature."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    x = np.linspace(0.0, 0.02, 2001)
    fig, ax = plt.subplots(3, 1, figsize=(7.5, 9.0), sharex=True)
    rows = ["| theta (degC) | release-force peak (N) | at x_to (mm) | bearing force open, x_to = 0 (N) | "
            "lift-off x_to (mm) | closed torque (N.m) |", "|---:|---:|---:|---:|---:|---:|"]
    for t, colour in zip(TEMPS_DEGC, ("tab:blue", "tab:orange", "tab:red")):
        tq, fpp, fto = curves(x, t)
        ax[0].plot(x * 1e3, tq, color=colour, label=f"{t:g} degC")
        ax[1].plot(x * 1e3, fpp / 1e3, color=colour)
        ax[2].plot(x * 1e3, fto / 1e3, color=colour)
        k = int(np.argmax(fto))
        lift = x[np.argmax(fto == 0.0)] if np.any(fto == 0.0) else float("nan")
        rows.append(f"| {t:g} | {fto[k]:.0f} | {x[k] * 1e3:.2f} | {fto[0]:.0f} | {lift * 1e3:.2f} | {tq[-1]:.1f} |")
    tq_w, _, _ = curves(x, 20.0, 0.001)
    ax[0].plot(x * 1e3, tq_w, color="tab:blue", ls="--", label="20 degC, 1 mm wear")
    ax[0].axhline(ENGINE_PEAK_NM, color="grey", lw=0.8, ls=":")
    ax[0].text(0.2, ENGINE_PEAK_NM + 5, "engine peak 240 N.m", color="grey", fontsize=8)
    ax[0].set_ylabel("torque (N.m)")
    ax[1].set_ylabel("clamp force F_pp (kN)")
    ax[2].set_ylabel("bearing force F_to (kN)")
    ax[2].set_xlabel("bearing position x_to (mm), 0 = open")
    ax[0].legend(fontsize=8, loc="lower right")
    ax[0].set_title("Default cover: diaphragm spring (Almen-Laszlo), lever 3, cushion tables")
    for a in ax:
        a.grid(alpha=0.3)
    fig.tight_layout()
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return rows


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--png", type=Path, default=Path("docs/cover_characteristics.png"))
    args = ap.parse_args(argv)
    print("\n".join(figure(args.png)))
    print()
    print("\n".join(budget_rows()))
    print(f"\nfigure: {args.png}")


if __name__ == "__main__":
    main()
