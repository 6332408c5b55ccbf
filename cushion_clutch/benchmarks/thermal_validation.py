"""The plant's thermal network against published figures: writes ``docs/thermal_validation.png`` and prints the numbers.

    python -m cushion_clutch.benchmarks.thermal_validation [--out docs/thermal_validation.png]
        [--write docs/explanation/thermal.md]

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

Every number printed comes from these runs. ``--write PAGE`` also runs the duty table's other scenarios
(:data:`DUTY_SCENARIOS`: ``fade``, ``creep``) and rewrites the two marked blocks of ``PAGE``
(``docs/explanation/thermal.md``): the validation table (:data:`VALIDATION_BEGIN` ... :data:`VALIDATION_END`)
and the duty table of the shipped scenarios (:data:`DUTY_BEGIN` ... :data:`DUTY_END`); the page's prose refers
to them and types no measured number.
"""
from __future__ import annotations

import argparse
import dataclasses
import math
import tempfile
import time
from pathlib import Path

import numpy as np

from ..model import KELVIN

#: published figures (see the module docstring and docs/explanation/thermal.md)
FACINGS_REPEATED_DEGC = (300.0, 350.0)      # Kimmig & Agner 2006 via the seed paper, after repeated engagements
DAMAGE_DEGC = (350.0, 400.0)                # ditto: permanent damage starts
RISE_PER_ENGAGEMENT_K = (30.0, 35.0)        # Pisaturo & Senatore 2016 (FE), interface, each engagement

#: the marked blocks of docs/explanation/thermal.md that ``--write`` rewrites
VALIDATION_BEGIN = "<!-- thermal_validation table: begin -->"
VALIDATION_END = "<!-- thermal_validation table: end -->"
DUTY_BEGIN = "<!-- thermal_validation duty: begin -->"
DUTY_END = "<!-- thermal_validation duty: end -->"
#: the rows of the duty table: (shipped scenario run with the naive TCU or None, label, duty in words)
DUTY_ROWS = (
    ("default", "`default`, `wear`, `tolerance`", "1.9 t car, 8 % uphill, 12 launches 60 s apart"),
    ("trailer", "`trailer`", "car + caravan 3.5 t, 12 % ramp in a queue, 12 starts 60 s apart, pedal 0.8/1.0, "
                             "engine target 2800 rpm"),
    (None, "`cooldown`", "`trailer`, then 6 launches every 5 min"),
    ("fade", "`fade`", "16 `trailer` starts 90 s apart, organic-facing μ(θ, ω) table read at the friction surface"),
    ("creep", "`creep`", "flat, every node soaked at 150 °C (after a climb), 12 creep launches 20 s apart"),
)
#: the scenarios that ``--write`` runs (the figure needs only ``default`` and ``trailer``)
DUTY_SCENARIOS = tuple(name for name, _, _ in DUTY_ROWS if name is not None)


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


def summary(res) -> dict:
    """One run's figures for the page: ranges over its launches and maxima over the run.

    ``slip_kJ`` and ``surface_rise_K`` are (min, max) over the launches (:func:`per_launch`); the ``*_max_degC``
    are maxima of the series; ``cm_step_K`` and ``plate_step_K`` are θ_cm and the pressure-plate bulk at the last
    launch's start minus those at the one before (how fast the clutch still warms, K per launch); ``locked`` counts
    the launches that locked up, of ``n``.
    """
    r = per_launch(res)
    s = res.series
    cm = [x["theta_cm_start_degC"] for x in r]
    pp = [x["pressure_plate_start_degC"] for x in r]
    return {"n": len(r),
            "locked": sum(not math.isnan(m["engagement_time_s"]) for m in res.metrics),
            "slip_kJ": (min(x["slip_kJ"] for x in r), max(x["slip_kJ"] for x in r)),
            "surface_rise_K": (min(x["surface_rise_K"] for x in r), max(x["surface_rise_K"] for x in r)),
            "theta_cm_max_degC": float(s["theta_cm_K"].max() - KELVIN),
            "theta_cs_max_degC": float(s["theta_cs_K"].max() - KELVIN),
            "surface_max_degC": float(s["theta_surface_K"].max() - KELVIN),
            "plate_max_degC": float(s["theta_pressure_plate_K"].max() - KELVIN),
            "theta_cm_start_degC": cm[0],
            "cm_step_K": cm[-1] - cm[-2] if len(cm) > 1 else math.nan,
            "plate_step_K": pp[-1] - pp[-2] if len(pp) > 1 else math.nan}


def _span(lo_hi: tuple[float, float], unit: str) -> str:
    lo, hi = (f"{v:.0f}" for v in lo_hi)
    return f"{lo} {unit}" if lo == hi else f"{lo}–{hi} {unit}"


def _side(lo_hi: tuple[float, float], band: tuple[float, float]) -> str:
    """Where a (min, max) range lies against a published band: 'lower', 'higher', 'within' or 'across'."""
    if lo_hi[1] < band[0]:
        return "lower"
    if lo_hi[0] > band[1]:
        return "higher"
    return "within" if band[0] <= lo_hi[0] and lo_hi[1] <= band[1] else "across"


def validation_markdown(m: dict[str, dict], lumped: dict, semi_worst: float, command: str) -> str:
    """The validation table of the page (between :data:`VALIDATION_BEGIN` and :data:`VALIDATION_END`).

    ``m``: :func:`summary` of the ``default`` and ``trailer`` runs; ``lumped``: of ``default`` on the lumped
    facing; ``semi_worst``: the surface node's worst relative deviation from the semi-infinite body, 1.
    """
    d, t = m["default"], m["trailer"]
    lo, hi = FACINGS_REPEATED_DEGC
    dlo, dhi = DAMAGE_DEGC
    rlo, rhi = RISE_PER_ENGAGEMENT_K
    hot = max(t["theta_cm_max_degC"], t["surface_max_degC"])
    reach = ("reached only by heavy duty" if hot >= lo else "not reached even by the heavy duty")
    reach += "; the everyday duty stays far below" if d["theta_cm_max_degC"] < lo - 100 else \
        "; the everyday duty comes within 100 K"
    sd, st = _side(d["surface_rise_K"], RISE_PER_ENGAGEMENT_K), _side(t["surface_rise_K"], RISE_PER_ENGAGEMENT_K)
    start = d["theta_cm_start_degC"]
    ratio = (lumped["theta_cm_max_degC"] - start) / (d["theta_cm_max_degC"] - start)
    rows = [
        f"| facings reach {lo:.0f}–{hi:.0f} °C after repeated engagements; permanent damage from {dlo:.0f}–{dhi:.0f} "
        f"°C | Kimmig & Agner 2006, as quoted by the seed paper (section 3) | `default` "
        f"({_span(d['slip_kJ'], 'kJ')} per launch): θ_cm {d['theta_cm_max_degC']:.0f} °C after twelve launches, "
        f"still rising ≈ {d['cm_step_K']:.0f} K per launch; "
        f"`trailer` ({_span(t['slip_kJ'], 'kJ')}): θ_cm {t['theta_cm_max_degC']:.0f} °C, friction surface "
        f"{t['surface_max_degC']:.0f} °C, pressure plate {t['plate_max_degC']:.0f} °C, still rising "
        f"≈ {t['cm_step_K']:.0f} K per launch (θ_cm between the last two launches' starts); `fade` (sixteen trailer starts): see "
        f"the duty table below | {reach} |",
        f"| interface temperature rises {rlo:.0f}–{rhi:.0f} °C in each engagement | Pisaturo & Senatore, Appl. "
        f"Therm. Eng. 93 (2016) 958–966 (FE, driven by launch and up-shift simulations) | "
        f"{_span(d['surface_rise_K'], 'K')} per default launch ({_span(d['slip_kJ'], 'kJ')}), "
        f"{_span(t['surface_rise_K'], 'K')} per trailer start ({_span(t['slip_kJ'], 'kJ')}) | ours {sd} at "
        f"{d['slip_kJ'][1]:.0f} kJ, {st} at {t['slip_kJ'][1]:.0f} kJ (see below) |",
        f"| the lumped 450 J/K plant: {lumped['theta_cm_max_degC']:.0f} °C facings after twelve default launches "
        f"| this project before issue 25 | the network: {d['theta_cm_max_degC']:.0f} °C for the same duty | the "
        f"lumped plant's rise from {start:.0f} °C is {ratio:.1f} times the network's |",
        f"| surface under constant flux, semi-infinite body | closed form | within {semi_worst * 100:.1f} % over "
        f"0.25–5 s at 10 ms steps | test bound 8 % |",
    ]
    return "\n".join([f"<!-- written by `{command}`; do not edit -->", "",
                      "| published figure | source | model (this network) | agreement |", "|---|---|---|---|",
                      *rows]) + "\n"


def duty_markdown(m: dict[str, dict], command: str) -> str:
    """The duty table of the shipped scenarios (between :data:`DUTY_BEGIN` and :data:`DUTY_END`);
    ``m``: :func:`summary` of each scenario of :data:`DUTY_SCENARIOS`."""
    lines = [f"<!-- written by `{command}`; do not edit -->", "",
             "| scenario | duty | slip per launch | launches locked up | θ_cm max | θ_cs max | friction surface max |",
             "|---|---|---|---|---|---|---|"]
    for name, label, duty in DUTY_ROWS:
        if name is None:
            lines.append(f"| {label} | {duty} | as `trailer` | as `trailer` | as `trailer` | as `trailer` "
                         "| as `trailer` |")
            continue
        r = m[name]
        lines.append(f"| {label} | {duty} | {_span(r['slip_kJ'], 'kJ')} | {r['locked']} of {r['n']} | "
                     f"{r['theta_cm_max_degC']:.0f} °C | {r['theta_cs_max_degC']:.0f} °C | "
                     f"{r['surface_max_degC']:.0f} °C |")
    lines += ["", "(naive TCU, the plant's network; maxima over the whole run; a launch locks up when the clutch "
                  "stops slipping within the drive time.)"]
    return "\n".join(lines) + "\n"


def rewrite(page: Path, begin: str, end: str, block: str) -> None:
    """Replace the text between the markers ``begin`` and ``end`` of ``page`` (each must occur once)."""
    text = page.read_text(encoding="utf-8")
    if text.count(begin) != 1 or text.count(end) != 1 or text.index(begin) > text.index(end):
        raise ValueError(f"{page}: needs one {begin!r} followed by one {end!r}")
    head, rest = text.split(begin, 1)
    _, tail = rest.split(end, 1)
    page.write_text(head + begin + "\n" + block + end + tail, encoding="utf-8")


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


def semi_worst(p) -> float:
    """The surface node's worst relative deviation from the semi-infinite body over 0.25-5 s, 1."""
    t, rise, closed = semi_infinite(p)
    sel = t >= 0.25
    return float(np.max(np.abs(rise[sel] - closed[sel]) / closed[sel]))


def measure(names=DUTY_SCENARIOS, progress=None) -> tuple[dict, object, float]:
    """Run the shipped scenarios ``names`` with the naive TCU, and ``default`` on the lumped 450 J/K facing.

    Returns ``({name: LaunchResult}, lumped LaunchResult, wall time s)``; ``progress(message)`` after each run.
    """
    from ..data import DEFAULT_TABLES
    from ..fmu.build import build_fmu
    from ..launch.scenario import load_scenario, scenario_path
    from ..launch.simulate import simulate_launches
    from ..model import load_table

    table = load_table()
    t0 = time.perf_counter()
    runs = {}
    with tempfile.TemporaryDirectory() as tmp:
        fmu = build_fmu(DEFAULT_TABLES, Path(tmp) / "CushionClutch.fmu")
        for name in names:
            t1 = time.perf_counter()
            runs[name] = simulate_launches(fmu, load_scenario(scenario_path(name)), table, "naive")
            if progress is not None:
                progress(f"ran {name} ({time.perf_counter() - t1:.1f} s)")
        sc = load_scenario()
        lumped = simulate_launches(fmu, dataclasses.replace(
            sc, plant_thermal=dataclasses.replace(sc.plant_thermal, enabled=False)), table, "naive")
    return runs, lumped, time.perf_counter() - t0


def page_blocks(runs: dict, lumped, worst: float, page: str = "docs/explanation/thermal.md"
                ) -> list[tuple[str, str, str]]:
    """``(begin marker, end marker, block)`` for each generated block of the page, from :func:`measure`'s runs
    (every scenario of :data:`DUTY_SCENARIOS`) and :func:`semi_worst`."""
    m = {name: summary(res) for name, res in runs.items()}
    command = f"python -m cushion_clutch.benchmarks.thermal_validation --write {page}"
    return [(VALIDATION_BEGIN, VALIDATION_END, validation_markdown(m, summary(lumped), worst, command)),
            (DUTY_BEGIN, DUTY_END, duty_markdown(m, command))]


def page_block_text(text: str, begin: str, end: str) -> str:
    """The text between ``begin`` and ``end`` of a page's ``text`` as :func:`rewrite` writes it."""
    return text.split(begin, 1)[1].split(end, 1)[0].removeprefix("\n")


def main(argv: list[str] | None = None) -> None:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from ..launch.scenario import load_scenario

    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", default="docs/thermal_validation.png")
    ap.add_argument("--write", type=Path, default=None,
                    help="page whose marked blocks to rewrite (docs/explanation/thermal.md); also runs "
                         + ", ".join(n for n in DUTY_SCENARIOS if n not in ("default", "trailer")))
    ap.add_argument("--no-figure", action="store_true", help="do not draw the figure (--out)")
    args = ap.parse_args(argv)
    if args.write is not None:
        text = args.write.read_text(encoding="utf-8")       # fail before the runs, not after
        missing = [k for k in (VALIDATION_BEGIN, VALIDATION_END, DUTY_BEGIN, DUTY_END) if text.count(k) != 1]
        if missing:
            raise SystemExit(f"{args.write}: each marker must occur once: {', '.join(missing)}")
    names = DUTY_SCENARIOS if args.write is not None else ("default", "trailer")
    runs, lumped, wall_s = measure(names, progress=lambda m: print(m, flush=True))
    print(f"all runs: {wall_s:.0f} s wall time", flush=True)
    if args.no_figure:
        _report(args, runs, lumped, semi_worst(load_scenario().plant_thermal))
        return
    sc = load_scenario()

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
    rows = {name: per_launch(res) for name, res in runs.items() if name in ("default", "trailer")}
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
    _report(args, runs, lumped, semi_worst(sc.plant_thermal))


def _report(args, runs: dict, lumped, worst: float) -> None:
    print(f"semi-infinite check: worst relative deviation over 0.25-5 s {worst:.3f}")
    if args.write is not None:
        m = {name: summary(res) for name, res in runs.items()}
        for name, x in m.items():
            print(f"{name}: " + ", ".join(f"{k} {v}" for k, v in x.items()))
        for begin, end, block in page_blocks(runs, lumped, worst):
            rewrite(args.write, begin, end, block)
        print(f"wrote the blocks of {args.write}")


if __name__ == "__main__":
    main()
