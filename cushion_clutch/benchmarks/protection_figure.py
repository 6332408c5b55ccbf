"""The thermal-protection figure of the documentation (``docs/protection.png``): the shipped ``protection``
scenario run with the naive (unprotected), the aware (protected on the true temperature) and the production
TCU (protected on its own estimate).

Top: each TCU's plant facing temperature, the protected TCUs' plant friction surface (the hotter, dotted; the
protection acts on the hotter of facings and surface) and production's facing estimate (dashed) against the
protection thresholds; middle: the protection level of the two protected TCUs; bottom: each launch's slip energy (an
inhibited launch has none). Prints each TCU's peak plant facing temperature and its inhibited launches.

    python -m cushion_clutch.benchmarks.protection_figure [--png docs/protection.png]
"""
from __future__ import annotations

import argparse
import tempfile
from pathlib import Path

import numpy as np

TCUS = ("naive", "aware", "production")
COLOURS = {"naive": "tab:red", "aware": "tab:green", "production": "tab:blue"}


def run() -> tuple[object, dict]:
    """The ``protection`` scenario and its results for :data:`TCUS` (``report.run_all``)."""
    from cushion_clutch.data import DEFAULT_TABLES
    from cushion_clutch.launch.plant.build import build_plant_fmu
    from cushion_clutch.launch.report import run_all
    from cushion_clutch.launch.scenario import load_scenario, scenario_path
    from cushion_clutch.model import load_table

    sc = load_scenario(scenario_path("protection"))
    with tempfile.TemporaryDirectory() as tmp:
        fmu = build_plant_fmu(DEFAULT_TABLES, sc, Path(tmp) / "CushionClutch.fmu")
        return sc, run_all(fmu, sc, load_table(sc.tables_path("tcu") or DEFAULT_TABLES), TCUS)


def figure(sc, results: dict, path: Path) -> list[str]:
    """Write the three-panel figure to ``path``; returns one line per TCU (peak, inhibited launches)."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from cushion_clutch.launch.tcu.protection import LEVEL_NAMES
    from cushion_clutch.launch.report import peaks
    from cushion_clutch.model import KELVIN, ClutchParameters

    prot = sc.protection
    fig, ax = plt.subplots(3, 1, figsize=(11.0, 10.0))
    lines = []
    for name, res in results.items():
        s = res.series
        t_min = s["time_s"] / 60.0
        label = "plant facings (no protection)" if name == "naive" else "plant facings"
        ax[0].plot(t_min, s["theta_cm_K"] - KELVIN, color=COLOURS[name], lw=1.0, label=f"{name}: {label}")
        if name != "naive":         # what the protection watches besides the facings (and the damage limit's)
            ax[0].plot(t_min, s["theta_surface_K"] - KELVIN, color=COLOURS[name], lw=0.7, ls=":",
                       label=f"{name}: plant friction surface (the hotter)")
        if name == "production":
            ax[0].plot(t_min, s["theta_cm_tcu_K"] - KELVIN, color=COLOURS[name], lw=1.0, ls="--",
                       label=f"{name}: its estimate")
        if name != "naive":
            what = "the true temperature" if name == "aware" else "its estimate"
            ax[1].step(t_min, s["protection_level"], where="post", color=COLOURS[name], label=f"{name} ({what})")
        k = peaks(res)
        lines.append(f"{name}: peak plant facing temperature {k['plant_theta_cm_peak_degC']:.0f} degC, "
                     f"friction surface {np.nanmax(s['theta_surface_K']) - KELVIN:.0f} degC, "
                     f"theta_cs {k['plant_theta_cs_peak_degC']:.0f} degC; "
                     f"{k['inhibited_launches']} inhibited launches")
    damage = ClutchParameters().facing_damage_temperature_K - KELVIN
    marks = [(damage, "damage (seed paper)")]
    if prot is not None:
        marks += [(prot.inhibit_degC, "inhibit"), (prot.limit_degC, "limit"), (prot.warn_degC, "warn")]
    for value, text in marks:
        ax[0].axhline(value, color="k", lw=0.6, ls=":")
        ax[0].annotate(f"{text} {value:.0f} °C", (1.005, value), xycoords=("axes fraction", "data"), va="center",
                       fontsize=8)
    ax[0].set(xlabel="time [min]", ylabel="temperature [°C]")
    ax[0].legend(fontsize=8, loc="lower right")
    ax[1].set_yticks(range(len(LEVEL_NAMES)), LEVEL_NAMES)
    ax[1].set(xlabel="time [min]", ylabel="protection level")
    ax[1].legend(fontsize=8, loc="upper left")
    width = 0.8 / len(results)
    for i, (name, res) in enumerate(results.items()):
        n = np.array([m["launch"] for m in res.metrics], dtype=float)
        e = np.array([m["slip_energy_kJ"] for m in res.metrics], dtype=float)
        ax[2].bar(n + (i - 1) * width, np.nan_to_num(e), width=width, color=COLOURS[name], label=name)
    ax[2].set(xlabel="launch (no bar: launch inhibited)", ylabel="slip energy [kJ]")
    ax[2].xaxis.get_major_locator().set_params(integer=True)
    ax[2].legend(fontsize=8, loc="upper right")
    fig.suptitle(f"Thermal protection, scenario '{sc.name}': {sc.description}", fontsize=10)
    fig.tight_layout()
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=100)
    plt.close(fig)
    return lines


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--png", type=Path, default=Path("docs/protection.png"))
    args = ap.parse_args(argv)
    sc, results = run()
    print("\n".join(figure(sc, results, args.png)))
    print(f"figure: {args.png}")


if __name__ == "__main__":
    main()
