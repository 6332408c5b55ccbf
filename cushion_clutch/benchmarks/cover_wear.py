"""Clamp load and closed capacity of the default cover versus facing wear, over the whole allowed range.

Everything from the Python reference model (:mod:`cushion_clutch.model.cover`) on the shipped default
tables and the default cover: the closed clamp load (bearing lifted) at 20/195/300 degC (theta_cs =
theta_cm) from new facings to the cover's wear limit (:func:`~cushion_clutch.model.cover.wear_limit`),
the wear reserve (:func:`~cushion_clutch.model.cover.wear_reserve`: closed capacity at 20 degC down to
1.25 x 240 N.m) and the release compliance derived from the fingers
(:func:`~cushion_clutch.model.cover.finger_compliance`). Writes the figure and the table into
``docs/explanation/cover.md`` (between its ``cover_wear`` markers)::

    python -m cushion_clutch.benchmarks.cover_wear [--png docs/cover_wear.png] [--md docs/explanation/cover.md]
"""
from __future__ import annotations

import argparse
import datetime
from pathlib import Path

import numpy as np

TEMPS_DEGC = (20.0, 195.0, 300.0)
TABLE_WEARS_MM = (0.0, 0.25, 0.5, 0.75, 1.0, 1.25, 1.5, 1.75, 2.0)
START, END = "<!-- cover_wear:start (written by python -m cushion_clutch.benchmarks.cover_wear) -->", \
    "<!-- cover_wear:end -->"


def facts() -> dict:
    """The default cover's wear limit, wear reserve, gain and finger compliance, and the model objects."""
    from cushion_clutch.model import ClutchParameters, load_table
    from cushion_clutch.model import clutch_model as cm
    from cushion_clutch.model.cover import (ENGINE_TORQUE_NM, RESERVE_FACTOR, CoverMap, finger_compliance, wear_limit,
                                            wear_reserve)

    table, p = load_table(), ClutchParameters()
    gain = p.n_surfaces * p.mu * p.R_eq
    limit = wear_limit(p.cover, p.lever_ratio, table, p.x_kiss_ref, cm.THETA_MIN_K, cm.THETA_MAX_K)
    reserve = wear_reserve(p.cover, p.lever_ratio, table, p.x_kiss_ref, gain, limit_m=limit)
    return dict(table=table, p=p, g=CoverMap(p.cover, p.lever_ratio), gain=gain, limit=limit, reserve=reserve,
                need=RESERVE_FACTOR * ENGINE_TORQUE_NM, engine=ENGINE_TORQUE_NM, factor=RESERVE_FACTOR,
                fingers=finger_compliance(p.cover, p.lever_ratio))


def closed_load(f: dict, wear_m: float, theta_degC: float) -> float:
    """Closed clamp load (N) at ``wear_m`` and ``theta_degC`` (theta_cs = theta_cm)."""
    th = theta_degC + 273.15
    return f["g"].prepare(th, th, wear_m, f["table"], f["p"].x_kiss_ref).clamp_installed()


def table_rows(f: dict) -> list[str]:
    """Markdown: clamp load and closed torque versus wear at the three temperatures."""
    head = "| facing wear (mm) | " + " | ".join(f"clamp {t:g} degC (N) | torque {t:g} degC (N.m)" for t in TEMPS_DEGC)
    rows = [head + " |", "|---" * (1 + 2 * len(TEMPS_DEGC)) + "|"]
    for w in TABLE_WEARS_MM:
        cells = [f"{w:.2f}"]
        for t in TEMPS_DEGC:
            load = closed_load(f, w * 1e-3, t)
            cells += [f"{load:.0f}", f"{f['gain'] * load:.1f}"]
        rows.append("| " + " | ".join(cells) + " |")
    return rows


def figure(f: dict, path: Path) -> None:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    w = np.linspace(0.0, f["limit"], 241)
    fig, ax = plt.subplots(figsize=(8.0, 4.8))
    for t in TEMPS_DEGC:
        ax.plot(w * 1e3, [closed_load(f, float(x), t) for x in w], label=f"closed clamp load, {t:g} degC")
    new = closed_load(f, 0.0, 20.0)
    ax.axhline(new, color="0.4", ls=":", lw=1, label=f"new load at 20 degC ({new:.0f} N)")
    ax.axhline(f["need"] / f["gain"], color="tab:red", ls="--", lw=1,
               label=f"{f['factor']:g} x {f['engine']:g} N.m / (n mu R_eq) = {f['need'] / f['gain']:.0f} N")
    ax.axvline(f["reserve"] * 1e3, color="tab:red", lw=1)
    ax.text(f["reserve"] * 1e3, ax.get_ylim()[0], f" wear reserve\n {f['reserve'] * 1e3:.2f} mm", color="tab:red",
            va="bottom", fontsize=8)
    ax.axvline(f["limit"] * 1e3, color="k", lw=1)
    ax.text(f["limit"] * 1e3, ax.get_ylim()[0], f"wear limit \n{f['limit'] * 1e3:.2f} mm ", ha="right", va="bottom",
            fontsize=8)
    ax.set_xlabel("facing wear (mm)")
    ax.set_ylabel("closed clamp load F_pp (N)")
    ax.set_title("Default cover: clamp load vs facing wear, up to the wear limit (theta_cs = theta_cm)")
    sec = ax.secondary_yaxis("right", functions=(lambda y: y * f["gain"], lambda y: y / f["gain"]))
    sec.set_ylabel("closed torque n mu R_eq F_pp (N.m)")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8, loc="lower left", bbox_to_anchor=(0.0, 0.12))
    fig.tight_layout()
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=110)
    plt.close(fig)


def markdown(f: dict, png: Path) -> str:
    from cushion_clutch.model import clutch_model as cm

    p = f["p"]
    today = datetime.date.today().isoformat()
    return "\n".join([
        START,
        f"Written by `python -m cushion_clutch.benchmarks.cover_wear` on {today} from the Python reference model, "
        "the shipped default tables and the default cover "
        f"(diaphragm thickness {p.cover.diaphragm_thickness_m * 1e3:g} mm, installed deflection "
        f"{p.cover.installed_deflection_m * 1e3:g} mm, release compliance {p.cover.release_compliance_m_per_N:g} m/N; "
        f"n mu R_eq = {f['gain']:.5f} m).",
        "",
        f"- wear limit (the diaphragm still holds the fully compressed cushion at every temperature pair in "
        f"[{cm.THETA_MIN_K:g}, {cm.THETA_MAX_K:g}] K): **{f['limit'] * 1e3:.3f} mm**",
        f"- wear reserve (closed capacity at 20 degC >= {f['factor']:g} x {f['engine']:g} N.m = {f['need']:g} N.m): "
        f"**{f['reserve'] * 1e3:.3f} mm**",
        f"- finger bending compliance at the bearing (derived): {f['fingers'] * 1e6:.3f} um/N of the "
        f"{p.cover.release_compliance_m_per_N * 1e6:g} um/N release compliance",
        "",
        *table_rows(f),
        "",
        f"![clamp load versus facing wear]({Path('..') / png.name})",
        END])


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--png", type=Path, default=Path("docs/cover_wear.png"))
    ap.add_argument("--md", type=Path, default=Path("docs/explanation/cover.md"))
    args = ap.parse_args(argv)
    f = facts()
    figure(f, args.png)
    block = markdown(f, args.png)
    print(block)
    if args.md.exists():
        text = args.md.read_text()
        if START in text and END in text:
            text = text[:text.index(START)] + block + text[text.index(END) + len(END):]
            args.md.write_text(text)
            print(f"\nupdated {args.md}")
    print(f"figure: {args.png}")


if __name__ == "__main__":
    main()
