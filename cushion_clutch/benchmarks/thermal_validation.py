"""The plant's thermal network against published figures: writes ``docs/thermal_validation.png`` and prints the numbers.

    python -m cushion_clutch.benchmarks.thermal_validation [--out docs/thermal_validation.png]

Runs the shipped ``default`` and ``trailer`` scenarios with the ``naive`` TCU (the plant does not depend on the
TCU's thermal model; the naive TCU is the cheapest) on the network, and ``default`` once more on the lumped
450 J/K facing, and compares:

* the temperature history over twelve engagements 60 s apart with the facing temperatures that the seed paper
  quotes from Kimmig & Agner (LuK Symposium 2006) for repeated engagements, 300-350 degC, and its damage
  threshold 350-400 degC;
* the friction surface's rise within each engagement (the metal's 1 mm surface node) with the 30-35 K per
  engagement of Pisaturo & Senatore (Applied Thermal Engineering 93, 2016, an FE model driven by launch
  simulations);
* the surface node under a constant flux with the semi-infinite body's closed form
  ``dT = 2 q'' sqrt(t) / (e sqrt(pi))``.

Every number printed comes from these runs; ``docs/explanation/thermal.md`` quotes them.
"""
from __future__ import annotations

import argparse
import dataclasses
import math
import tempfile
from pathlib import Path

import numpy as np

from ..model import KELVIN

#: published figures (see the module docstring and docs/explanation/thermal.md)
FACINGS_REPEATED_DEGC = (300.0, 350.0)      # Kimmig & Agner 2006 via the seed paper, after repeated engagements
DAMAGE_DEGC = (350.0, 400.0)                # ditto: permanent damage starts
RISE_PER_ENGAGEMENT_K = (30.0, 35.0)        # Pisaturo & Senatore 2016 (FE), interface, each engagement


def per_launch(res) -> list[dict]:
    """Per launch: slip energy (kJ), the surface's rise within it (K), temperatures at its start and end (degC)."""
    s = res.series
    rows = []
    for m in res.metrics:
        sel = s["launch"] == m["launch"]
        surf = s["theta_surface_K"][sel]
        rows.append({"launch": m["launch"], "slip_kJ": m["slip_energy_kJ"],
                     "surface_rise_K": float(surf.max() - surf[0]),
                     "surface_max_degC": float(surf.max() - KELVIN),
                     "theta_cm_start_degC": float(s["theta_cm_K"][sel][0] - KELVIN),
                     "pressure_plate_start_degC": float(s["theta_pressure_plate_K"][sel][0] - KELVIN),
                     "theta_cs_start_degC": m["theta_cs_start_degC"]})
    return rows


def semi_infinite(p, q_W: float = 10e3, t_end: float = 5.0, dt: float = 0.01) -> tuple[np.ndarray, np.ndarray,
                                                                                      np.ndarray]:
    """(t s, surface node rise K, closed form K) for ``q_W`` into one metal surface, the rest adiabatic."""
    from ..model.thermal_network import N_NODES, SURFACES, ThermalNetwork

    net = ThermalNetwork(p, 293.15, 293.15)
    net.shares = [0.0] * N_NODES
    net.shares[SURFACES[1]] = 1.0
    n = int(round(t_end / dt))
    t = np.arange(1, n + 1) * dt
    rise = np.empty(n)
    for k in range(n):
        net.step(dt, q_W, 0.0, 0.0, False)
        rise[k] = net.theta[SURFACES[1]] - 293.15
    closed = 2.0 * q_W / p.area_m2 * np.sqrt(t) / (p.metal_effusivity_W_s05_per_m2_K * math.sqrt(math.pi))
    return t, rise, closed


def main(argv: list[str] | None = None) -> None:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from ..data import DEFAULT_TABLES
    from ..fmu.build import build_fmu
    from ..launch.scenario import load_scenario, scenario_path
    from ..launch.simulate import simulate_launches
    from ..model import load_table

    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", default="docs/thermal_validation.png")
    args = ap.parse_args(argv)
    table = load_table()
    with tempfile.TemporaryDirectory() as tmp:
        fmu = build_fmu(DEFAULT_TABLES, Path(tmp) / "CushionClutch.fmu")
        runs = {name: simulate_launches(fmu, load_scenario(scenario_path(name)), table, "naive")
                for name in ("default", "trailer")}
        sc = load_scenario()
        lumped = simulate_launches(fmu, dataclasses.replace(
            sc, plant_thermal=dataclasses.replace(sc.plant_thermal, enabled=False)), table, "naive")

    fig, ax = plt.subplots(1, 3, figsize=(16, 4.8))
    a = ax[0]
    for name, res, ls in (("trailer", runs["trailer"], "-"), ("default", runs["default"], "--")):
        s = res.series
        t = s["time_s"] / 60.0
        a.plot(t, s["theta_surface_K"] - KELVIN, ls, color="tab:red", lw=0.8, label=f"{name}: friction surface (1 mm)")
        a.plot(t, s["theta_cm_K"] - KELVIN, ls, color="tab:orange", label=f"{name}: facings (theta_cm)")
        a.plot(t, s["theta_pressure_plate_K"] - KELVIN, ls, color="tab:blue", label=f"{name}: pressure-plate bulk")
        a.plot(t, s["theta_cs_K"] - KELVIN, ls, color="tab:green", label=f"{name}: cushion spring")
    s = lumped.series
    a.plot(s["time_s"] / 60.0, s["theta_cm_K"] - KELVIN, ":", color="k", label="default, lumped 450 J/K facing")
    a.axhspan(*FACINGS_REPEATED_DEGC, color="tab:orange", alpha=0.15,
              label="facings after repeated engagements\n(Kimmig & Agner 2006, via the seed paper)")
    a.axhspan(*DAMAGE_DEGC, color="tab:red", alpha=0.1, label="permanent damage starts (ditto)")
    a.set_xlabel("time [min]")
    a.set_ylabel("temperature [degC]")
    a.set_title("Twelve engagements 60 s apart")
    a.legend(fontsize=6.5, loc="upper left")
    a.set_ylim(0, 420)

    a = ax[1]
    rows = {name: per_launch(res) for name, res in runs.items()}
    for name, mk in (("default", "o"), ("trailer", "s")):
        r = rows[name]
        a.plot([x["slip_kJ"] for x in r], [x["surface_rise_K"] for x in r], mk, label=f"{name} (network)")
    a.axhspan(*RISE_PER_ENGAGEMENT_K, color="tab:red", alpha=0.15,
              label="30-35 K per engagement\n(Pisaturo & Senatore 2016, FE)")
    a.set_xlabel("slip energy of the engagement [kJ]")
    a.set_ylabel("friction-surface rise within the engagement [K]")
    a.set_title("Surface rise per engagement")
    a.set_xlim(left=0)
    a.set_ylim(bottom=0)
    a.legend(fontsize=7)

    a = ax[2]
    t, rise, closed = semi_infinite(sc.plant_thermal)
    a.plot(t, closed, "k-", label="semi-infinite body, 2 q'' sqrt(t) / (e sqrt(pi))")
    a.plot(t, rise, "--", color="tab:red", label="network surface node (1 mm), 10 ms steps")
    a.set_xlabel("time [s]")
    a.set_ylabel("surface rise [K]")
    a.set_title("Constant flux 295 kW/m2 into cast iron")
    a.legend(fontsize=7)
    fig.tight_layout()
    out = Path(args.out)
    out.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(out, dpi=110)

    print(f"wrote {out}")
    for name, r in rows.items():
        print(f"\n{name}: launch | slip kJ | surface rise K | surface max degC | theta_cm start | pp bulk start | "
              "theta_cs start")
        for x in r:
            print(f"  {x['launch']:2d} | {x['slip_kJ']:6.1f} | {x['surface_rise_K']:5.1f} | "
                  f"{x['surface_max_degC']:6.1f} | {x['theta_cm_start_degC']:6.1f} | "
                  f"{x['pressure_plate_start_degC']:6.1f} | {x['theta_cs_start_degC']:6.1f}")
        s = runs[name].series
        print(f"  max: theta_cm {s['theta_cm_K'].max() - KELVIN:.1f} degC, surface "
              f"{s['theta_surface_K'].max() - KELVIN:.1f} degC, pressure plate "
              f"{s['theta_pressure_plate_K'].max() - KELVIN:.1f} degC, theta_cs {s['theta_cs_K'].max() - KELVIN:.1f} degC")
    print(f"\ndefault on the lumped 450 J/K facing: theta_cm max {lumped.series['theta_cm_K'].max() - KELVIN:.1f} degC,"
          f" theta_cs max {lumped.series['theta_cs_K'].max() - KELVIN:.1f} degC")
    worst = float(np.max(np.abs(rise[t >= 0.25] - closed[t >= 0.25]) / closed[t >= 0.25]))
    print(f"semi-infinite check: worst relative deviation over 0.25-5 s {worst:.3f}")


if __name__ == "__main__":
    main()
